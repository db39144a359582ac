//! Files in and out: inputs read with a bound on their size, output paths checked before a command measures
//! anything, and atomic writes so that a failed run never leaves a half-written result behind.

use anyhow::{Context, Result, anyhow, bail};
use std::io::Write;
use std::os::unix::ffi::OsStrExt;
use std::path::{Path, PathBuf};

/// Reading back a report's figures: JSON writes a NaN or Inf as null, which would fail an f64 field, so a
/// figure read with `#[serde(default = "crate::io::nan", deserialize_with = "crate::io::nan_if_null")]` is NaN
/// where the report wrote null or (an older report) nothing, and `finite` tells the two kinds apart again.
pub fn nan_if_null<'de, D: serde::Deserializer<'de>>(d: D) -> std::result::Result<f64, D::Error> {
    Ok(<Option<f64> as serde::Deserialize>::deserialize(d)?.unwrap_or(f64::NAN))
}

/// What a figure missing from a report reads as (see `nan_if_null`).
pub fn nan() -> f64 {
    f64::NAN
}

/// A figure as read back: None where the report wrote null (NaN or Inf) or nothing.
pub fn finite(x: f64) -> Option<f64> {
    x.is_finite().then_some(x)
}

/// The `eval` output: header `r,g,b`, one row per sample (shortest text that reads back to the same f32).
pub fn format_rgb_csv(rows: &[[f32; 3]]) -> String {
    let mut out = String::with_capacity(rows.len() * 32 + 8);
    out.push_str("r,g,b\n");
    for [r, g, b] in rows {
        out.push_str(&format!("{r},{g},{b}\n"));
    }
    out
}

/// Reads an input file; the error names the file and the reason the system gives (a directory, a loop of
/// symbolic links), and for a dangling symbolic link the missing file it points to.
pub fn read_input(path: &Path) -> Result<Vec<u8>> {
    if let Err(e) = std::fs::metadata(path) {
        let dangling = std::fs::symlink_metadata(path).is_ok_and(|m| m.file_type().is_symlink())
            && e.kind() == std::io::ErrorKind::NotFound;
        return Err(match std::fs::read_link(path).ok().filter(|_| dangling) {
            Some(to) => anyhow!(
                "cannot read {}: it is a symbolic link to {}, which does not exist ({e})",
                path.display(),
                to.display()
            ),
            None => anyhow!("cannot read {}: {e}", path.display()),
        });
    }
    read_bounded(path, MAX_INPUT_BYTES)
}

/// The largest input file (a CSV, a `.brdf` file, a scene) read: 1 GiB, some 15 million CSV rows
/// (docs/limits.md).
pub const MAX_INPUT_BYTES: u64 = 1 << 30;

/// The largest saved report read (`report`, `compare`, `check --baseline`, `inspect --profile`): the biggest
/// default report, a sweep's, is under 1 MB.
pub const MAX_REPORT_BYTES: u64 = 256 << 20;

/// Reads a file that must be a regular one (after symbolic links) of at most `max` bytes: a device, FIFO or
/// directory is refused before anything is read, and the read itself stops past `max`, so a file that grows
/// while it is read (or lies about its size) cannot exhaust memory.
pub fn read_bounded(path: &Path, max: u64) -> Result<Vec<u8>> {
    use std::io::Read;
    let (file, meta) = open_regular(path)?;
    if meta.len() > max {
        bail!(
            "cannot read {}: {} bytes, more than the {max} bytes brdfprof reads from such a file",
            path.display(),
            meta.len()
        );
    }
    let mut bytes = Vec::with_capacity(meta.len() as usize);
    file.take(max + 1).read_to_end(&mut bytes).map_err(|e| anyhow!("cannot read {}: {e}", path.display()))?;
    if bytes.len() as u64 > max {
        bail!("cannot read {}: it grew past the {max} bytes brdfprof reads from such a file", path.display());
    }
    Ok(bytes)
}

/// Opens a file for reading that must be a regular one (after symbolic links). The open itself does not
/// block: a FIFO with no writer would hold a plain open forever, so the file is opened with O_NONBLOCK (which
/// changes nothing for a regular file's reads) and its type checked on the open descriptor, before anything is
/// read; a device, FIFO, socket or directory is refused naming the path.
pub fn open_regular(path: &Path) -> Result<(std::fs::File, std::fs::Metadata)> {
    use std::os::unix::fs::{FileTypeExt, OpenOptionsExt};
    let file = std::fs::OpenOptions::new()
        .read(true)
        .custom_flags(libc::O_NONBLOCK | libc::O_NOCTTY)
        .open(path)
        .map_err(|e| anyhow!("cannot read {}: {e}", path.display()))?;
    let meta = file.metadata().map_err(|e| anyhow!("cannot read {}: {e}", path.display()))?;
    let kind = meta.file_type();
    let what = if kind.is_dir() {
        "a directory"
    } else if kind.is_fifo() {
        "a FIFO"
    } else if kind.is_socket() {
        "a socket"
    } else if kind.is_char_device() || kind.is_block_device() {
        "a device"
    } else {
        return Ok((file, meta));
    };
    bail!("cannot read {}: not a regular file ({what})", path.display())
}

/// Symbolic links followed at most this many times (Linux's own limit, MAXSYMLINKS).
const MAX_LINKS: usize = 40;

/// Where writing `path` writes: `path` itself, or the file its chain of symbolic links ends at, which need
/// not exist yet (as a shell's `>` creates a dangling link's target).
fn link_target(path: &Path) -> Result<PathBuf> {
    let mut target = path.to_path_buf();
    for _ in 0..MAX_LINKS {
        match std::fs::symlink_metadata(&target) {
            Ok(m) if m.file_type().is_symlink() => {
                let next = std::fs::read_link(&target)
                    .with_context(|| format!("cannot read the symbolic link {}", target.display()))?;
                target = target.parent().map_or_else(|| next.clone(), |dir| dir.join(&next));
            }
            _ => return Ok(target),
        }
    }
    bail!("{}: more than {MAX_LINKS} symbolic links in a row (a loop?)", path.display())
}

/// Writes a command's named output. A regular file, or a path that does not exist yet, is written atomically:
/// a temporary file in the same directory (with the old file's permissions), synced, then renamed over it, so
/// a failure leaves any existing file untouched and no temporary behind. A symbolic link is followed, and its
/// target written the same way, so the link stays a link. Any other existing file (a device such as
/// /dev/null, a FIFO) is opened and written in place, never replaced. While outputs are staged
/// (`stage_outputs`), the rename waits for `commit_outputs`.
pub fn write_output(path: &Path, bytes: &[u8]) -> Result<()> {
    crate::cleanup::park_if_interrupted();
    if is_stdout(path) {
        use std::io::Write as _;
        let mut out = std::io::stdout().lock();
        return out.write_all(bytes).and_then(|_| out.flush()).context("cannot write the JSON to stdout");
    }
    let target = link_target(path)?;
    match std::fs::metadata(&target) {
        Ok(m) if m.is_dir() => bail!("cannot write {}: it is a directory", path.display()),
        Ok(m) if !m.is_file() => {
            let mut f = std::fs::OpenOptions::new()
                .write(true)
                .open(&target)
                .with_context(|| format!("cannot open {}", path.display()))?;
            f.write_all(bytes).and_then(|_| f.flush()).with_context(|| format!("cannot write {}", path.display()))
        }
        Ok(m) => write_atomic(&target, bytes, Some(m.permissions())),
        Err(_) => write_atomic(&target, bytes, None),
    }
}

/// `-` as an output path: stdout, which then carries that output alone (`claim_stdout`).
pub fn is_stdout(path: &Path) -> bool {
    path.as_os_str() == "-"
}

static STDOUT_CLAIMED: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);

/// An output goes to stdout (`--json -`): from now on what a command reports for people goes to stderr, so that
/// stdout carries the JSON alone.
pub fn claim_stdout() {
    STDOUT_CLAIMED.store(true, std::sync::atomic::Ordering::SeqCst);
}

/// Whether an output took stdout (`claim_stdout`).
pub fn stdout_claimed() -> bool {
    STDOUT_CLAIMED.load(std::sync::atomic::Ordering::SeqCst)
}

/// Writes a Markdown report (`write_output`) through `messages::safe_text`: no name from an input starts a line
/// of its own in it, as on stdout.
pub fn write_markdown(path: &Path, text: &str) -> Result<()> {
    write_output(path, crate::messages::safe_text(text).as_bytes())
}

/// A written temporary waiting for `commit_outputs` to be renamed over its target.
struct Staged {
    tmp: PathBuf,
    target: PathBuf,
    _guard: crate::cleanup::PathGuard,
}

static STAGING: std::sync::atomic::AtomicBool = std::sync::atomic::AtomicBool::new(false);
static STAGED: std::sync::Mutex<Vec<Staged>> = std::sync::Mutex::new(Vec::new());

fn staged() -> std::sync::MutexGuard<'static, Vec<Staged>> {
    STAGED.lock().unwrap_or_else(|e| e.into_inner())
}

/// From now on, `write_output` stages: every output of the command is written beside its target and renamed
/// into place only by `commit_outputs`, so that a command that fails or is stopped leaves none of them
/// (`discard_outputs`, or the signal handler, removes the temporaries and the directories created for them).
/// `main` turns it on for every command.
pub fn stage_outputs() {
    STAGING.store(true, std::sync::atomic::Ordering::SeqCst);
}

/// Renames every staged output into place (all of them, even if a signal arrives meanwhile: `stop` waits).
pub fn commit_outputs() -> Result<()> {
    crate::cleanup::committing(|| {
        let all = std::mem::take(&mut *staged());
        let mut result = Ok(());
        for s in &all {
            if result.is_ok() {
                result =
                    std::fs::rename(&s.tmp, &s.target).with_context(|| format!("cannot write {}", s.target.display()));
            }
            if result.is_err() {
                let _ = std::fs::remove_file(&s.tmp);
            }
        }
        crate::cleanup::forget_created_dirs();
        result
    })
}

/// Removes every staged output, and the directories created for them where empty: a failed command leaves
/// none of its outputs.
pub fn discard_outputs() {
    for s in std::mem::take(&mut *staged()) {
        let _ = std::fs::remove_file(&s.tmp);
    }
    for d in crate::cleanup::forget_created_dirs().iter().rev() {
        let _ = std::fs::remove_dir(d);
    }
}

/// Creates `dir` and its missing ancestors; while staging, the created ones are registered so that a failed
/// command removes them again.
fn create_dirs(dir: &Path) -> Result<()> {
    let mut missing = Vec::new();
    let mut d = dir.to_path_buf();
    while std::fs::symlink_metadata(&d).is_err() {
        missing.push(d.clone());
        match d.parent() {
            Some(p) if !p.as_os_str().is_empty() => d = p.to_path_buf(),
            _ => break,
        }
    }
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create directory {}", dir.display()))?;
    if STAGING.load(std::sync::atomic::Ordering::SeqCst) {
        missing.reverse();
        crate::cleanup::register_created_dirs(&missing);
    }
    Ok(())
}

/// Temp-then-rename in `path`'s directory (regular files only; `write_output` decides); the rename waits for
/// `commit_outputs` while staging.
fn write_atomic(path: &Path, bytes: &[u8], permissions: Option<std::fs::Permissions>) -> Result<()> {
    let dir = parent_dir(path);
    create_dirs(&dir)?;
    let file_name = path.file_name().ok_or_else(|| anyhow!("{} is not a file path", path.display()))?;
    static NEXT: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
    let n = NEXT.fetch_add(1, std::sync::atomic::Ordering::SeqCst);
    let tmp = dir.join(format!(".{}.{}.{n}.tmp", file_name.to_string_lossy(), std::process::id()));
    // Registered before it exists, so that an interrupted write leaves no temporary behind either.
    let (guard, mut f) = crate::cleanup::PathGuard::create(&tmp, || std::fs::File::create(&tmp))
        .with_context(|| format!("cannot write {}", path.display()))?;
    let staging = STAGING.load(std::sync::atomic::Ordering::SeqCst);
    let result = (|| -> Result<()> {
        f.write_all(bytes)?;
        if let Some(p) = permissions {
            f.set_permissions(p)?;
        }
        f.sync_all()?;
        if !staging {
            std::fs::rename(&tmp, path)?;
        }
        Ok(())
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    } else if staging {
        let mut all = staged();
        // The same output written twice: the later content wins.
        if let Some(i) = all.iter().position(|s| s.target == path) {
            let _ = std::fs::remove_file(&all.remove(i).tmp);
        }
        all.push(Staged { tmp, target: path.to_path_buf(), _guard: guard });
    }
    result.with_context(|| format!("cannot write {}", path.display()))
}

/// The directory a relative or absolute file path is in (`.` for a bare name).
fn parent_dir(path: &Path) -> PathBuf {
    match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

/// The files git tracks in `dir` whose names match `pattern` (a git pathspec: `*` matches any text), as paths
/// under `dir`; none where `dir` does not exist, is in no repository, or git is not installed (then nothing a
/// checkout committed can be there to overwrite).
pub fn tracked_by_git(dir: &Path, pattern: &str) -> Vec<PathBuf> {
    if !dir.is_dir() {
        return Vec::new();
    }
    let out = crate::launch::output_quick(
        crate::cleanup::command("git").arg("-C").arg(dir).args(["ls-files", "-z", "--"]).arg(pattern),
        "git ls-files",
    );
    match out {
        Ok(o) if o.status.success() => o
            .stdout
            .split(|&b| b == 0)
            .filter(|n| !n.is_empty())
            .map(|n| dir.join(std::ffi::OsStr::from_bytes(n)))
            .collect(),
        _ => Vec::new(),
    }
}

/// Refuses a default output (one the user did not name) that would overwrite a file git tracks: run inside a
/// checkout, a default path must not replace the committed results. `files` are the names the command writes in
/// `dir` (patterns, as `tracked_by_git`); `flag` is the option that names the output instead.
pub fn refuse_tracked_default(flag: &str, dir: &Path, files: &[String]) -> Result<()> {
    for f in files {
        if let Some(t) = tracked_by_git(dir, f).first() {
            bail!(
                "{flag} not given: the default output {} would overwrite {}, a file git tracks; name the output with {flag} PATH",
                dir.join(f).display(),
                t.display()
            );
        }
    }
    Ok(())
}

/// Checks, before a command measures anything, that it will be able to write the file output `path` given
/// by `flag`: not a directory, and in a directory that exists or can be created. Errors name the flag and
/// the path.
pub fn check_output_path(flag: &str, path: &Path) -> Result<()> {
    let shown = path.display();
    if path.as_os_str().is_empty() {
        bail!("{flag}: empty path; give a file name");
    }
    if path.as_os_str().as_bytes().ends_with(b"/") || path.file_name().is_none() {
        bail!("{flag} {shown}: names a directory; give a file path");
    }
    let target = link_target(path).map_err(|e| anyhow!("{flag} {shown}: {e:#}"))?;
    match std::fs::metadata(&target) {
        Ok(m) if m.is_dir() => bail!("{flag} {shown}: is a directory; give a file path"),
        Ok(_) => Ok(()),
        Err(e) if missing(&e) => creatable(flag, path, &parent_dir(&target)),
        Err(e) => bail!("{flag} {shown}: {e}"),
    }
}

/// Checks, before a command measures anything, that the output directory `dir` given by `flag` is a
/// directory or can be created. Errors name the flag and the path.
pub fn check_output_dir(flag: &str, dir: &Path) -> Result<()> {
    if dir.as_os_str().is_empty() {
        bail!("{flag}: empty path; give a directory");
    }
    match std::fs::metadata(dir) {
        Ok(m) if m.is_dir() => writable(flag, dir, dir),
        Ok(_) => bail!("{flag} {}: exists and is not a directory", dir.display()),
        Err(e) if missing(&e) => creatable(flag, dir, dir),
        Err(e) => bail!("{flag} {}: {e}", dir.display()),
    }
}

/// Refuses an output that is one of the command's inputs (the same file, by whatever path or link): writing
/// it would replace what the command reads. `inputs` are (flag, path) pairs; errors name both flags.
pub fn check_not_input(flag: &str, output: &Path, inputs: &[(&str, &Path)]) -> Result<()> {
    use std::os::unix::fs::MetadataExt;
    let Ok(out) = std::fs::metadata(output) else { return Ok(()) };
    for (input_flag, input) in inputs {
        if std::fs::metadata(input).is_ok_and(|m| (m.dev(), m.ino()) == (out.dev(), out.ino())) {
            bail!(
                "{flag} {}: is the same file as {input_flag} {}; writing it would replace the input. Give another output path",
                output.display(),
                input.display()
            );
        }
    }
    Ok(())
}

/// A file name as a `#line` directive's string gives it to glslang, which garbles any byte above 0x7f there (it
/// wrote `caf\xc3\xa9\xff\xff\xff` for `café.brdf`, which is not UTF-8, so no SPIR-V reader took the module):
/// non-ASCII bytes, `%`, `"` and control characters percent-encoded (`caf%C3%A9.brdf`), the rest as it is.
/// `from_directive_name` reads it back exactly.
pub fn directive_name(name: &str) -> String {
    let mut out = String::with_capacity(name.len());
    for b in name.bytes() {
        if b.is_ascii() && !b.is_ascii_control() && b != b'%' && b != b'"' {
            out.push(b as char);
        } else {
            out += &format!("%{b:02X}");
        }
    }
    out
}

/// The file name `directive_name` encoded (a name it did not encode, with no `%`, comes back as it is).
pub fn from_directive_name(name: &str) -> String {
    let b = name.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        let hex = |k: usize| b.get(k).and_then(|c| (*c as char).to_digit(16));
        match (b[i], hex(i + 1), hex(i + 2)) {
            (b'%', Some(h), Some(l)) => {
                out.push((h * 16 + l) as u8);
                i += 3;
            }
            (c, _, _) => {
                out.push(c);
                i += 1;
            }
        }
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// Whether two paths name one existing file (after links; hard links included).
pub fn same_file(a: &Path, b: &Path) -> bool {
    use std::os::unix::fs::MetadataExt;
    match (std::fs::metadata(a), std::fs::metadata(b)) {
        (Ok(x), Ok(y)) => (x.dev(), x.ino()) == (y.dev(), y.ino()),
        _ => false,
    }
}

/// No such path (ENOENT), or a file where a directory should be on the way (ENOTDIR: found by `creatable`).
fn missing(e: &std::io::Error) -> bool {
    matches!(e.kind(), std::io::ErrorKind::NotFound | std::io::ErrorKind::NotADirectory)
}

/// `dir` exists, or its nearest existing ancestor is a directory brdfprof may write in.
fn creatable(flag: &str, output: &Path, dir: &Path) -> Result<()> {
    let mut d = dir.to_path_buf();
    loop {
        match std::fs::metadata(&d) {
            Ok(m) if m.is_dir() => return writable(flag, output, &d),
            Ok(_) => bail!("{flag} {}: {} is not a directory", output.display(), d.display()),
            Err(e) if missing(&e) => d = parent_dir(&d),
            Err(e) => bail!("{flag} {}: cannot use {}: {e}", output.display(), d.display()),
        }
    }
}

/// `dir` admits new entries (permissions, read-only file systems).
fn writable(flag: &str, output: &Path, dir: &Path) -> Result<()> {
    let c = std::ffi::CString::new(dir.as_os_str().as_bytes())
        .map_err(|_| anyhow!("{flag} {}: the path contains a NUL byte", output.display()))?;
    // SAFETY: `c` is a NUL-terminated path that outlives the call.
    if unsafe { libc::access(c.as_ptr(), libc::W_OK | libc::X_OK) } != 0 {
        bail!("{flag} {}: cannot write in {} ({})", output.display(), dir.display(), std::io::Error::last_os_error());
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::os::unix::fs::{FileTypeExt, MetadataExt};

    #[test]
    fn directive_names_are_ascii_and_read_back() {
        for name in ["café.brdf", "shäders/lobe.brdf", "a\"b%c\nd.brdf", "plain/x.brdf"] {
            let d = directive_name(name);
            assert!(d.is_ascii() && !d.contains('"') && !d.chars().any(|c| c.is_control()), "{d}");
            assert_eq!(from_directive_name(&d), name);
        }
        assert_eq!(directive_name("café.brdf"), "caf%C3%A9.brdf");
    }

    #[test]
    fn a_regular_file_is_replaced_atomically() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("out.csv");
        write_output(&p, b"first").unwrap();
        // A hard link keeps the old file: the new content went to a new file renamed over the path, not
        // into the old one (a reader of the old file never sees half of the new).
        let old = dir.path().join("old-link");
        std::fs::hard_link(&p, &old).unwrap();
        let inode = std::fs::metadata(&p).unwrap().ino();
        write_output(&p, b"second").unwrap();
        assert_eq!(std::fs::read(&p).unwrap(), b"second");
        assert_eq!(std::fs::read(&old).unwrap(), b"first");
        assert_ne!(std::fs::metadata(&p).unwrap().ino(), inode);
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 2, "no temporary left behind");
    }

    #[test]
    fn permissions_of_the_replaced_file_are_kept() {
        use std::os::unix::fs::PermissionsExt;
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("out.csv");
        std::fs::write(&p, "x").unwrap();
        std::fs::set_permissions(&p, std::fs::Permissions::from_mode(0o640)).unwrap();
        write_output(&p, b"y").unwrap();
        assert_eq!(std::fs::metadata(&p).unwrap().permissions().mode() & 0o777, 0o640);
    }

    #[test]
    fn a_symlink_output_writes_its_target_and_stays_a_link() {
        let dir = tempfile::tempdir().unwrap();
        let target = dir.path().join("target.csv");
        std::fs::write(&target, "old").unwrap();
        let link = dir.path().join("link.csv");
        std::os::unix::fs::symlink("target.csv", &link).unwrap();
        write_output(&link, b"r,g,b\n").unwrap();
        assert!(std::fs::symlink_metadata(&link).unwrap().file_type().is_symlink());
        assert_eq!(std::fs::read(&target).unwrap(), b"r,g,b\n");
        // A dangling link's target is created, as a shell's `>` does.
        let dangling = dir.path().join("dangling.csv");
        std::os::unix::fs::symlink(dir.path().join("sub/new.csv"), &dangling).unwrap();
        write_output(&dangling, b"x").unwrap();
        assert!(std::fs::symlink_metadata(&dangling).unwrap().file_type().is_symlink());
        assert_eq!(std::fs::read(dir.path().join("sub/new.csv")).unwrap(), b"x");
    }

    #[test]
    fn a_fifo_output_receives_the_bytes_and_stays_a_fifo() {
        let dir = tempfile::tempdir().unwrap();
        let fifo = dir.path().join("out.fifo");
        let made = std::process::Command::new("mkfifo").arg(&fifo).status().unwrap();
        assert!(made.success());
        let reader = {
            let fifo = fifo.clone();
            std::thread::spawn(move || std::fs::read(fifo).unwrap())
        };
        let csv = format_rgb_csv(&[[0.5, 0.25, 1.0]]);
        write_output(&fifo, csv.as_bytes()).unwrap();
        assert_eq!(reader.join().unwrap(), csv.as_bytes());
        assert!(std::fs::symlink_metadata(&fifo).unwrap().file_type().is_fifo());
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1, "no temporary beside the FIFO");
    }

    #[test]
    fn a_directory_is_refused_by_name() {
        let dir = tempfile::tempdir().unwrap();
        let e = write_output(dir.path(), b"x").unwrap_err().to_string();
        assert!(e.contains(&format!("cannot write {}: it is a directory", dir.path().display())), "{e}");
    }

    #[test]
    fn output_paths_are_checked_before_any_work() {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        let file = d.join("file");
        std::fs::write(&file, "x").unwrap();
        assert!(check_output_path("--json", &d.join("new.json")).is_ok());
        assert!(
            check_output_path("--json", &d.join("a/b/new.json")).is_ok(),
            "missing directories are created on writing"
        );
        assert!(check_output_path("--json", &file).is_ok());
        let e = check_output_path("--json", d).unwrap_err().to_string();
        assert_eq!(e, format!("--json {}: is a directory; give a file path", d.display()));
        let e = check_output_path("--out", &file.join("x.json")).unwrap_err().to_string();
        assert_eq!(e, format!("--out {}: {} is not a directory", file.join("x.json").display(), file.display()));
        let e = check_output_path("--json", Path::new("results/")).unwrap_err().to_string();
        assert!(e.contains("--json results/: names a directory"), "{e}");
        assert!(check_output_path("--json", Path::new("")).unwrap_err().to_string().contains("--json: empty path"));
        assert!(check_output_dir("--out", d).is_ok());
        assert!(check_output_dir("--out", &d.join("new/dir")).is_ok());
        let e = check_output_dir("--out", &file).unwrap_err().to_string();
        assert_eq!(e, format!("--out {}: exists and is not a directory", file.display()));
        let e = check_output_dir("--out", &file.join("sub")).unwrap_err().to_string();
        assert!(e.contains(&format!("{} is not a directory", file.display())), "{e}");
    }
}
