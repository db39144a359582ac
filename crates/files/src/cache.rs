//! brdfprof's disk cache of compiled outputs (the SPIR-V of `.brdf` kernels; any compile-only target's
//! outputs), under one rule: **an entry is keyed by everything that reaches the compiler and trusted only
//! after its checksum verifies.**
//!
//! - The caller builds the key (`KeyBuilder`) from every input of the compilation: the source and the content
//!   of every file it includes, defines, options, the compiler's and driver's versions, brdfprof's version. The
//!   entry is `<key>.<kind>` in the cache directory.
//! - An entry holds a short text header (format, kind, key, length, SHA-256 of the payload) and the payload.
//!   `get` verifies every field; an entry that fails (cut short, edited, another key's file copied over it)
//!   is reported as `Lookup::Bad`, and `get_or_build` then discards it, rebuilds and replaces it, with a
//!   warning naming the file. A damaged entry can therefore cost a recompilation, never a wrong result.
//! - Entries are written atomically (a temporary file in the directory, renamed over the entry), so a reader
//!   sees a whole entry or none, and concurrent writers of one key leave one whole entry.
//!
//! The directory is `$BRDFPROF_CACHE_DIR`, else `$XDG_CACHE_HOME/brdfprof/kernels`, else
//! `~/.cache/brdfprof/kernels`; an empty `BRDFPROF_CACHE_DIR` turns the disk cache off. `brdfprof cache
//! show|clear` lists and removes brdfprof's entries there (`entries`, `clear`), nothing else.

use anyhow::{Context, Result, anyhow, bail};
use sha2::{Digest, Sha256};
use std::path::{Path, PathBuf};

/// The first line of every entry; the number is the format's version.
const MAGIC: &str = "brdfprof-cache 1";
/// The SPIR-V magic number: entries of brdfprof before the checksummed format were bare SPIR-V `<key>.spv`.
const SPIRV_MAGIC: [u8; 4] = 0x0723_0203u32.to_le_bytes();

fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

/// A cache key: the SHA-256 of every input of a compilation, lowercase hex.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub struct Key(String);

impl Key {
    pub fn hex(&self) -> &str {
        &self.0
    }
}

/// Builds a key from labelled parts; each part is length-prefixed, so no two different lists of parts give
/// the same bytes to hash.
pub struct KeyBuilder(Sha256);

impl KeyBuilder {
    /// A key for outputs of `kind` (the entry's extension: `spv`, ...).
    pub fn new(kind: &str) -> Self {
        KeyBuilder(Sha256::new()).part("kind", kind)
    }

    pub fn part(mut self, label: &str, bytes: impl AsRef<[u8]>) -> Self {
        let bytes = bytes.as_ref();
        for piece in [label.as_bytes(), bytes] {
            self.0.update((piece.len() as u64).to_le_bytes());
            self.0.update(piece);
        }
        self
    }

    pub fn finish(self) -> Key {
        Key(hex(&self.0.finalize()))
    }
}

/// What `Store::get` found.
#[derive(Debug, PartialEq)]
pub enum Lookup {
    Hit(Vec<u8>),
    Miss,
    /// The entry exists but cannot be trusted: why.
    Bad {
        path: PathBuf,
        why: String,
    },
}

/// The cache directory brdfprof uses, or None when the disk cache is off (an empty `BRDFPROF_CACHE_DIR`) or
/// no home is known.
pub fn default_dir() -> Option<PathBuf> {
    if let Some(d) = std::env::var_os("BRDFPROF_CACHE_DIR") {
        return (!d.is_empty()).then(|| PathBuf::from(d));
    }
    let home_cache = || std::env::var_os("HOME").filter(|d| !d.is_empty()).map(|h| PathBuf::from(h).join(".cache"));
    let base = std::env::var_os("XDG_CACHE_HOME").filter(|d| !d.is_empty()).map(PathBuf::from).or_else(home_cache)?;
    Some(base.join("brdfprof").join("kernels"))
}

/// One entry of the directory (`Store::entries`).
#[derive(Clone, Debug, PartialEq)]
pub struct Entry {
    pub path: PathBuf,
    pub kind: String,
    pub bytes: u64,
    /// None: the entry verifies; else why it does not.
    pub damaged: Option<String>,
    /// A bare SPIR-V entry of an older brdfprof (never read, removed by `clear`).
    pub legacy: bool,
}

/// A directory of entries.
#[derive(Clone, Debug)]
pub struct Store {
    dir: PathBuf,
}

/// A kind is the entry's extension: lowercase letters, digits, `_`.
fn valid_kind(kind: &str) -> bool {
    !kind.is_empty() && kind.bytes().all(|b| b.is_ascii_lowercase() || b.is_ascii_digit() || b == b'_')
}

/// `<64 hex digits>.<kind>`: (key, kind).
fn entry_name(name: &str) -> Option<(&str, &str)> {
    let (key, kind) = name.split_once('.')?;
    (key.len() == 64 && key.bytes().all(|b| b.is_ascii_hexdigit() && !b.is_ascii_uppercase()) && valid_kind(kind))
        .then_some((key, kind))
}

/// `.<key>.<kind>.<pid>.<n>.tmp`: a temporary of `put`.
fn is_temporary(name: &str) -> bool {
    name.strip_prefix('.')
        .and_then(|n| n.strip_suffix(".tmp"))
        .and_then(|n| n.split_once('.'))
        .is_some_and(|(key, rest)| entry_name(&format!("{key}.{}", rest.split('.').next().unwrap_or(""))).is_some())
}

/// The entry's header and payload, as `put` writes them.
fn encode(kind: &str, key: &Key, payload: &[u8]) -> Vec<u8> {
    let header = format!(
        "{MAGIC}\nkind: {kind}\nkey: {}\nlength: {}\nsha256: {}\n\n",
        key.hex(),
        payload.len(),
        hex(&Sha256::digest(payload))
    );
    [header.as_bytes(), payload].concat()
}

/// The most header bytes read before the blank line that ends it.
const MAX_HEADER: u64 = 4096;

/// An entry's bytes, read no further than its header says it holds (plus one byte, to tell a longer file):
/// None when there is none; an error, as for a damaged entry, when it is not a regular file (a symbolic link
/// to an endless file, a FIFO) or cannot be read.
fn read_entry(path: &Path) -> std::result::Result<Option<Vec<u8>>, String> {
    use std::io::Read;
    match std::fs::symlink_metadata(path) {
        Err(_) => return Ok(None),
        Ok(m) if !m.file_type().is_file() => {
            return Err("not a regular file (a symbolic link, directory or device)".into());
        }
        Ok(_) => {}
    }
    let mut file = crate::io::open_regular(path).map_err(|e| format!("{e:#}"))?.0;
    let mut bytes = Vec::new();
    (&mut file).take(MAX_HEADER).read_to_end(&mut bytes).map_err(|e| format!("cannot be read ({e})"))?;
    let Some(end) = bytes.windows(2).position(|w| w == b"\n\n") else { return Ok(Some(bytes)) };
    let length = std::str::from_utf8(&bytes[..end])
        .ok()
        .and_then(|h| h.lines().find_map(|l| l.strip_prefix("length: ")?.parse::<u64>().ok()));
    // No length, or one past any entry's: the header alone, which `decode` refuses.
    let Some(length) = length.filter(|&l| l <= MAX_PAYLOAD) else { return Ok(Some(bytes)) };
    let total = (end as u64).saturating_add(3).saturating_add(length);
    if (bytes.len() as u64) > total {
        bytes.truncate(total as usize);
    } else {
        file.take(total - bytes.len() as u64).read_to_end(&mut bytes).map_err(|e| format!("cannot be read ({e})"))?;
    }
    Ok(Some(bytes))
}

/// An entry's header, as `put` writes it.
struct Header {
    /// Bytes of the header and the blank line after it: where the payload starts.
    payload_at: usize,
    length: u64,
    sha256: String,
}

/// The largest payload an entry may hold: more than anything brdfprof stores (a tool's output is bounded by
/// `launch::MAX_OUTPUT_BYTES`), so a header saying more is damaged and nothing past it is read.
const MAX_PAYLOAD: u64 = crate::launch::MAX_OUTPUT_BYTES as u64;

/// The header at the start of `bytes` for an entry of `kind` (and `key`, when given), or why it cannot be
/// trusted.
fn decode_header(bytes: &[u8], kind: &str, key: Option<&str>) -> std::result::Result<Header, String> {
    let end =
        bytes.windows(2).position(|w| w == b"\n\n").ok_or("no header (not a brdfprof cache entry, or cut short)")?;
    let header = std::str::from_utf8(&bytes[..end]).map_err(|_| "the header is not text")?;
    let mut lines = header.lines();
    if lines.next() != Some(MAGIC) {
        return Err(format!("not a `{MAGIC}` entry"));
    }
    let mut field = |name: &str| {
        lines
            .next()
            .and_then(|l| l.strip_prefix(name))
            .and_then(|l| l.strip_prefix(": "))
            .map(str::to_string)
            .ok_or(format!("no `{name}` line"))
    };
    let (k, found_key, length, sha256) = (field("kind")?, field("key")?, field("length")?, field("sha256")?);
    if k != kind {
        return Err(format!("an entry of kind `{k}` where `{kind}` belongs"));
    }
    if key.is_some_and(|key| key != found_key) {
        return Err(format!("the entry of key {}... under another key's name", &found_key[..found_key.len().min(12)]));
    }
    let length = length.parse::<u64>().map_err(|_| format!("the length `{length}` is not a number of bytes"))?;
    if length > MAX_PAYLOAD {
        return Err(format!("the header says {length} bytes of payload, more than any entry holds ({MAX_PAYLOAD})"));
    }
    Ok(Header { payload_at: end + 2, length, sha256 })
}

/// The payload of an entry for `kind` and (when given) `key`, or why it cannot be trusted.
fn decode<'a>(bytes: &'a [u8], kind: &str, key: Option<&str>) -> std::result::Result<&'a [u8], String> {
    let header = decode_header(bytes, kind, key)?;
    let payload = &bytes[header.payload_at..];
    if payload.len() as u64 != header.length {
        return Err(format!("{} bytes of payload where the header says {}", payload.len(), header.length));
    }
    if hex(&Sha256::digest(payload)) != header.sha256 {
        return Err("its content does not match its checksum".into());
    }
    Ok(payload)
}

/// What `entries` finds in a file named like an entry, read in bounded memory: the header (at most
/// `MAX_HEADER` bytes), then the payload streamed through the checksum in blocks, no further than the header's
/// length, which is at most `MAX_PAYLOAD`. None: not brdfprof's; Some((legacy, damaged)).
fn verify_entry(path: &Path, kind: &str, key: &str) -> Option<(bool, Option<String>)> {
    use std::io::Read;
    let mut file = crate::io::open_regular(path).ok()?.0;
    let mut head = Vec::new();
    (&mut file).take(MAX_HEADER).read_to_end(&mut head).ok()?;
    if kind == "spv" && head.starts_with(&SPIRV_MAGIC) {
        return Some((true, None));
    }
    // Named like an entry but not written by brdfprof: not ours (a header cut short still is).
    if !(head.starts_with(MAGIC.as_bytes()) || MAGIC.as_bytes().starts_with(&head)) {
        return None;
    }
    let header = match decode_header(&head, kind, Some(key)) {
        Ok(h) => h,
        Err(why) => return Some((false, Some(why))),
    };
    let mut hasher = Sha256::new();
    hasher.update(&head[header.payload_at.min(head.len())..]);
    let mut seen = (head.len() - header.payload_at.min(head.len())) as u64;
    let mut block = vec![0u8; 1 << 16];
    let mut rest = (&mut file).take((header.length + 1).saturating_sub(seen));
    loop {
        match rest.read(&mut block) {
            Ok(0) => break,
            Ok(n) => {
                hasher.update(&block[..n]);
                seen += n as u64;
            }
            Err(e) => return Some((false, Some(format!("cannot be read ({e})")))),
        }
    }
    let damaged = if seen != header.length {
        Some(format!("{seen} bytes of payload where the header says {}", header.length))
    } else if hex(&hasher.finalize()) != header.sha256 {
        Some("its content does not match its checksum".into())
    } else {
        None
    };
    Some((false, damaged))
}

impl Store {
    pub fn at(dir: &Path) -> Store {
        Store { dir: dir.to_path_buf() }
    }

    /// The store of `default_dir`, or None when the disk cache is off.
    pub fn open_default() -> Option<Store> {
        default_dir().map(|d| Store::at(&d))
    }

    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// Where the entry of `key` for `kind` lives.
    pub fn path(&self, kind: &str, key: &Key) -> PathBuf {
        self.dir.join(format!("{}.{kind}", key.hex()))
    }

    /// The verified payload of `key`, `Miss` when there is none (or it cannot be read), `Bad` when there is one
    /// that does not verify.
    pub fn get(&self, kind: &str, key: &Key) -> Lookup {
        let path = self.path(kind, key);
        match read_entry(&path) {
            Ok(None) => Lookup::Miss,
            Ok(Some(bytes)) => match decode(&bytes, kind, Some(key.hex())) {
                Ok(payload) => Lookup::Hit(payload.to_vec()),
                Err(why) => Lookup::Bad { path, why },
            },
            Err(why) => Lookup::Bad { path, why },
        }
    }

    /// Writes the entry atomically: a temporary beside it (removed on failure and by the signal handler),
    /// then renamed over it.
    pub fn put(&self, kind: &str, key: &Key, payload: &[u8]) -> Result<()> {
        if !valid_kind(kind) {
            bail!("cache kind `{kind}`: lowercase letters, digits and _ only");
        }
        std::fs::create_dir_all(&self.dir)
            .with_context(|| format!("cannot create the cache directory {}", self.dir.display()))?;
        static NEXT: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
        let n = NEXT.fetch_add(1, std::sync::atomic::Ordering::SeqCst);
        let tmp = self.dir.join(format!(".{}.{kind}.{}.{n}.tmp", key.hex(), std::process::id()));
        let made = crate::cleanup::PathGuard::create(&tmp, || std::fs::File::create(&tmp));
        let result = made.and_then(|(_guard, mut f)| {
            std::io::Write::write_all(&mut f, &encode(kind, key, payload))?;
            drop(f);
            std::fs::rename(&tmp, self.path(kind, key))
        });
        if result.is_err() {
            let _ = std::fs::remove_file(&tmp);
        }
        result.with_context(|| format!("cannot write the cache entry {}", self.path(kind, key).display()))
    }

    /// Removes the entry of `key` (a damaged one, before it is replaced).
    pub fn discard(&self, kind: &str, key: &Key) {
        let _ = std::fs::remove_file(self.path(kind, key));
    }

    /// brdfprof's entries in the directory (and the temporaries of interrupted writes, as kind `tmp`), each
    /// verified; other files are not brdfprof's and are left out. No directory: no entries.
    pub fn entries(&self) -> Result<Vec<Entry>> {
        let read = match std::fs::read_dir(&self.dir) {
            Ok(r) => r,
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Vec::new()),
            Err(e) => return Err(anyhow!("cannot read the cache directory {}: {e}", self.dir.display())),
        };
        let mut out = Vec::new();
        for item in read {
            let item = item.with_context(|| format!("cannot read the cache directory {}", self.dir.display()))?;
            let name = item.file_name().to_string_lossy().into_owned();
            let path = item.path();
            if !item.file_type().is_ok_and(|t| t.is_file()) {
                continue;
            }
            let bytes = item.metadata().map_or(0, |m| m.len());
            if is_temporary(&name) {
                out.push(Entry { path, kind: "tmp".into(), bytes, damaged: None, legacy: false });
                continue;
            }
            let Some((key, kind)) = entry_name(&name) else { continue };
            let Some((legacy, damaged)) = verify_entry(&path, kind, key) else { continue };
            out.push(Entry { path, kind: kind.to_string(), bytes, damaged, legacy });
        }
        out.sort_by(|a, b| a.path.cmp(&b.path));
        Ok(out)
    }

    /// Removes brdfprof's entries (damaged and legacy ones included) and temporaries; returns how many files
    /// and bytes went. The directory itself and any other file in it stay.
    pub fn clear(&self) -> Result<(usize, u64)> {
        let mut removed = (0, 0);
        for e in self.entries()? {
            match std::fs::remove_file(&e.path) {
                Ok(()) => removed = (removed.0 + 1, removed.1 + e.bytes),
                Err(err) if err.kind() == std::io::ErrorKind::NotFound => {}
                Err(err) => bail!("cannot remove {}: {err}", e.path.display()),
            }
        }
        Ok(removed)
    }
}

/// The one way to use the cache: the verified entry of `key` if there is one (and `valid` accepts it), else
/// `build`'s output, stored. A damaged entry is discarded, rebuilt and replaced, with a warning naming its
/// file; a store that cannot be written costs a rebuild next time, nothing else. `what` names the output in
/// messages.
pub fn get_or_build(
    store: Option<&Store>,
    kind: &str,
    key: &Key,
    what: &str,
    valid: impl Fn(&[u8]) -> Result<()>,
    build: impl FnOnce() -> Result<Vec<u8>>,
) -> Result<Vec<u8>> {
    let Some(store) = store else { return build() };
    match store.get(kind, key) {
        Lookup::Hit(payload) => match valid(&payload) {
            Ok(()) => return Ok(payload),
            Err(e) => damaged(store, kind, key, what, &format!("{e:#}")),
        },
        Lookup::Bad { why, .. } => damaged(store, kind, key, what, &why),
        Lookup::Miss => {}
    }
    let payload = build()?;
    if let Err(e) = store.put(kind, key, &payload) {
        crate::messages::note_once(format!("{e:#}; {what} is compiled again next time"));
    }
    Ok(payload)
}

fn damaged(store: &Store, kind: &str, key: &Key, what: &str, why: &str) {
    let path = store.path(kind, key);
    crate::messages::warning(format!(
        "the cache entry {} ({what}) is damaged ({why}); discarded, compiled again and replaced",
        path.display()
    ));
    store.discard(kind, key);
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    fn key(text: &str) -> Key {
        KeyBuilder::new("spv").part("source", text).finish()
    }

    #[test]
    fn keys_separate_their_parts() {
        let a = KeyBuilder::new("spv").part("a", "bc").finish();
        let b = KeyBuilder::new("spv").part("ab", "c").finish();
        let c = KeyBuilder::new("nv").part("a", "bc").finish();
        assert!(a != b && a != c && b != c);
        assert_eq!(a, KeyBuilder::new("spv").part("a", "bc").finish());
        assert_eq!(a.hex().len(), 64);
    }

    #[test]
    fn an_entry_round_trips_and_a_miss_is_a_miss() {
        let dir = tempfile::tempdir().unwrap();
        let store = Store::at(&dir.path().join("sub"));
        assert_eq!(store.get("spv", &key("x")), Lookup::Miss);
        store.put("spv", &key("x"), b"payload").unwrap();
        assert_eq!(store.get("spv", &key("x")), Lookup::Hit(b"payload".to_vec()));
        assert_eq!(store.get("spv", &key("y")), Lookup::Miss);
        assert_eq!(std::fs::read_dir(store.dir()).unwrap().count(), 1, "no temporary left");
    }

    #[test]
    fn another_keys_entry_copied_over_is_bad() {
        let dir = tempfile::tempdir().unwrap();
        let store = Store::at(dir.path());
        store.put("spv", &key("x"), b"payload").unwrap();
        std::fs::copy(store.path("spv", &key("x")), store.path("spv", &key("y"))).unwrap();
        assert!(
            matches!(store.get("spv", &key("y")), Lookup::Bad { why, .. } if why.contains("under another key's name"))
        );
    }

    /// An entry that is a symbolic link (here to an endless file) is damaged, not read; an
    /// entry longer than its header says is read no further than that.
    #[test]
    fn a_linked_or_overlong_entry_is_bad_and_read_within_its_length() {
        let dir = tempfile::tempdir().unwrap();
        let store = Store::at(dir.path());
        std::os::unix::fs::symlink("/dev/zero", store.path("spv", &key("z"))).unwrap();
        assert!(matches!(store.get("spv", &key("z")), Lookup::Bad { why, .. } if why.contains("not a regular file")));
        store.put("spv", &key("x"), b"payload").unwrap();
        let mut long = std::fs::read(store.path("spv", &key("x"))).unwrap();
        long.extend(std::iter::repeat_n(b'!', 1 << 20));
        std::fs::write(store.path("spv", &key("x")), &long).unwrap();
        assert_eq!(read_entry(&store.path("spv", &key("x"))).unwrap().unwrap().len(), long.len() - (1 << 20) + 1);
        assert!(
            matches!(store.get("spv", &key("x")), Lookup::Bad { why, .. } if why.contains("bytes of payload where the header says 7"))
        );
    }

    /// The property the cache exists for: whatever happens to an entry's bytes, `get` returns the payload
    /// that was stored or says the entry is bad (or gone), never other bytes.
    #[test]
    fn random_corruption_is_never_taken_for_a_payload() {
        let dir = tempfile::tempdir().unwrap();
        let store = Store::at(dir.path());
        let mut rng = rand_pcg::Pcg64::seed_from_u64(21);
        let payload: Vec<u8> = (0..3000).map(|_| rng.random()).collect();
        let k = key("property");
        let (mut bad, mut intact) = (0, 0);
        for round in 0..2000 {
            store.put("spv", &k, &payload).unwrap();
            let path = store.path("spv", &k);
            let mut bytes = std::fs::read(&path).unwrap();
            match round % 5 {
                0 => {
                    let i = rng.random_range(0..bytes.len());
                    bytes[i] ^= 1 << rng.random_range(0..8);
                }
                1 => bytes.truncate(rng.random_range(0..bytes.len())),
                2 => bytes.extend((0..rng.random_range(1..16)).map(|_| rng.random::<u8>())),
                3 => {
                    let i = rng.random_range(0..bytes.len());
                    bytes[i] = rng.random();
                }
                _ => {
                    for _ in 0..rng.random_range(1..8) {
                        let i = rng.random_range(0..bytes.len());
                        bytes[i] = rng.random();
                    }
                }
            }
            std::fs::write(&path, &bytes).unwrap();
            match store.get("spv", &k) {
                Lookup::Hit(p) => {
                    assert_eq!(p, payload, "round {round}: a corrupted entry gave other bytes");
                    intact += 1;
                }
                Lookup::Bad { .. } => bad += 1,
                Lookup::Miss => panic!("round {round}: an existing entry read as missing"),
            }
        }
        // A random byte can equal the byte it replaces (rounds 3 and 4); everything else must be caught.
        assert!(bad > 1900, "{bad} caught, {intact} unchanged");
    }

    #[test]
    fn get_or_build_replaces_a_damaged_entry() {
        let dir = tempfile::tempdir().unwrap();
        let store = Store::at(dir.path());
        let k = key("z");
        let built = std::cell::Cell::new(0);
        let build = || {
            built.set(built.get() + 1);
            Ok(b"good".to_vec())
        };
        let ok = |_: &[u8]| Ok(());
        assert_eq!(get_or_build(Some(&store), "spv", &k, "test", ok, build).unwrap(), b"good");
        assert_eq!(get_or_build(Some(&store), "spv", &k, "test", ok, build).unwrap(), b"good");
        assert_eq!(built.get(), 1, "the second call is a hit");
        let path = store.path("spv", &k);
        let mut bytes = std::fs::read(&path).unwrap();
        *bytes.last_mut().unwrap() ^= 0x20;
        std::fs::write(&path, bytes).unwrap();
        assert_eq!(get_or_build(Some(&store), "spv", &k, "test", ok, build).unwrap(), b"good");
        assert_eq!(built.get(), 2, "a damaged entry is rebuilt");
        assert_eq!(store.get("spv", &k), Lookup::Hit(b"good".to_vec()), "and replaced");
        // A payload the caller refuses (its checksum fine) is rebuilt too.
        assert_eq!(get_or_build(Some(&store), "spv", &k, "test", |_| bail!("not SPIR-V"), build).unwrap(), b"good");
        assert_eq!(built.get(), 3);
    }

    #[test]
    fn clear_removes_only_brdfprofs_entries() {
        let dir = tempfile::tempdir().unwrap();
        let store = Store::at(dir.path());
        store.put("spv", &key("a"), b"1").unwrap();
        store.put("nvptx", &key("b"), b"22").unwrap();
        let legacy = dir.path().join(format!("{}.spv", key("c").hex()));
        std::fs::write(&legacy, [&SPIRV_MAGIC[..], &[0; 16]].concat()).unwrap();
        let stale = dir.path().join(format!(".{}.spv.123.0.tmp", key("d").hex()));
        std::fs::write(&stale, b"half").unwrap();
        let foreign = [dir.path().join("notes.txt"), dir.path().join(format!("{}.spv", key("e").hex()))];
        std::fs::write(&foreign[0], b"mine").unwrap();
        std::fs::write(&foreign[1], b"not ours either").unwrap();
        let entries = store.entries().unwrap();
        assert_eq!(entries.len(), 4, "{entries:?}");
        assert!(entries.iter().any(|e| e.legacy) && entries.iter().any(|e| e.kind == "tmp"));
        assert!(entries.iter().all(|e| e.damaged.is_none()));
        assert_eq!(store.clear().unwrap().0, 4);
        assert!(foreign.iter().all(|f| f.exists()), "other files stay");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 2);
    }
}
