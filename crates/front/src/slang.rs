//! Slang's compiler (slangc), the front end of Slang models and the second HLSL front end: what DXC-era engine
//! HLSL holds and glslang's HLSL front end refuses or crashes on (static member functions returning their own
//! struct, struct inheritance, `select`, a member function calling a static member unqualified). `make setup`
//! installs slangc from the pinned slangtorch wheel (scripts/slang-wheel.txt) into the tools folder; brdfprof
//! runs it on the include-expanded text with a stub of its own (for HLSL: the text glslang refused), and
//! spirv-cross writes its SPIR-V back as GLSL as it does glslang's (`cross`). slangc's own preprocessor reads
//! the text (variadic macros and all); `import`ed modules are found in the model's folder and the include
//! directories. Its SPIR-V is cached (in memory and on disk, `crate::cache`) under everything that reaches it,
//! the modules it read checked by content on every use.

use super::includes::Expanded;
use anyhow::{Context, Result};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::{Mutex, OnceLock};

/// How slangc reads the text: as DXC-era HLSL (`half` and the minimum-precision types as float, `.hlsl`), or
/// as Slang (its own fp16 `half`, modules, interfaces and generics, `.slang`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Dialect {
    Hlsl,
    Slang,
}

impl Dialect {
    fn extension(self) -> &'static str {
        match self {
            Dialect::Hlsl => "hlsl",
            Dialect::Slang => "slang",
        }
    }
}

/// The name the expanded text is compiled under (a `#line` directive gives it): the SPIR-V's line table and
/// slangc's messages name the text by it, apart from the modules it imports, which keep their own paths.
pub const MAIN_NAME: &str = "brdfprof-shader";

/// The variable that names another folder holding the wheel's files (`slangtorch/bin/slangc`).
pub const DIR_VAR: &str = "BRDFPROF_SLANG_DIR";

/// Where the stub stores what it computes: Slang removes code whose result nothing reads, so its stub writes to
/// a buffer, which `cross::view` drops with the stub (a model's own buffers are still refused).
pub const OUT_BUFFER: &str = "brdfprof_out";

/// slangc's flags: SPIR-V emitted directly (no GLSL on the way), no optimisation (spirv-cross and the kernels'
/// compilers see the shader as written), line tables (`-g1`: an `OpLine` per statement, which per-line cost
/// reads as it reads glslang's `-g`; the same code as without, where `-g` adds a copy of every variable), the
/// stub as the compute entry.
pub const FLAGS: [&str; 9] =
    ["-target", "spirv", "-emit-spirv-directly", "-O0", "-g1", "-entry", super::STUB, "-stage", "compute"];

/// `half` and the minimum-precision types as 32-bit floats (`-Dhalf=float`, ...): DXC's default without
/// `-enable-16bit-types`, as glslang's HLSL front end reads them; Slang's own `half` is always fp16.
pub fn float_defines() -> Vec<String> {
    let mut out = Vec::new();
    for ty in ["half", "min16float", "min10float"] {
        out.push(format!("-D{ty}=float"));
        for n in 1..=4 {
            out.push(format!("-D{ty}{n}=float{n}"));
            for m in 1..=4 {
                out.push(format!("-D{ty}{n}x{m}=float{n}x{m}"));
            }
        }
    }
    out
}

/// The folder of the wheel's files (`tools::locate`: `$BRDFPROF_SLANG_DIR`, beside the binary, the data
/// directory, the build checkout).
pub fn install_dir() -> PathBuf {
    crate::tools::dir("slang")
}

/// slangc, where `make setup` installed it.
pub fn slangc() -> Option<PathBuf> {
    Some(install_dir().join("slangtorch/bin/slangc")).filter(|p| p.is_file())
}

/// slangc's version (`slangc -v`), once per process.
pub fn version() -> String {
    static VERSION: OnceLock<String> = OnceLock::new();
    VERSION
        .get_or_init(|| {
            let Some(slangc) = slangc() else { return "not installed".into() };
            let mut cmd = crate::cleanup::command(&slangc.to_string_lossy());
            cmd.arg("-v");
            crate::launch::output_quick(&mut cmd, "slangc -v")
                .map(|o| {
                    let text = String::from_utf8_lossy(&o.stdout).to_string() + &String::from_utf8_lossy(&o.stderr);
                    text.trim().to_string()
                })
                .unwrap_or_else(|_| "(version unknown)".into())
        })
        .clone()
}

/// The compute entry that calls each of `calls` and stores the sum where Slang cannot drop it, on one line.
pub fn stub(calls: &[String]) -> String {
    let body: String = calls.iter().map(|c| format!(" v += {c}(v, v, v, v, v);")).collect();
    format!(
        "RWStructuredBuffer<float3> {OUT_BUFFER}; [numthreads(1, 1, 1)] void {}() {{ float3 v = {OUT_BUFFER}[0];{body} {OUT_BUFFER}[0] = v; }}",
        super::STUB
    )
}

/// The attributes that make slangc inline a function at every call even at -O0 (`[ForceInline]`), blanked
/// column for column: the stub's call would take `BRDF` and the entries' functions out of the SPIR-V, where
/// spirv-cross and the composition look for them. Inlining changes no value; the kernels' compilers inline as
/// they choose.
pub fn without_forced_inlining(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let mut rest = text;
    while let Some(open) = rest.find('[') {
        let (before, from) = rest.split_at(open);
        out.push_str(before);
        let close = from.find(']').map(|c| c + 1).unwrap_or(from.len());
        let inner = from[1..close.saturating_sub(1).max(1)].trim();
        if close > 1 && FORCED_INLINING.contains(&inner) {
            out.extend(std::iter::repeat_n(' ', from[..close].chars().count()));
        } else {
            out.push('[');
            rest = &from[1..];
            continue;
        }
        rest = &from[close..];
    }
    out.push_str(rest);
    out
}

/// Slang's attributes that force inlining.
const FORCED_INLINING: [&str; 2] = ["ForceInline", "__unsafeForceInlineEarly"];

/// What one compilation gives: the SPIR-V, or slangc's messages at the user's files' lines.
pub type Compiled = std::result::Result<Vec<u32>, String>;

/// The shader compiled by slangc as `dialect`, modules searched for in `search`: None where slangc is not
/// installed, Some(Err(its messages at the user's files' lines)) where it refuses the shader (or crashes),
/// else the SPIR-V (from the cache where everything that reaches slangc is unchanged).
pub fn compile(
    x: &Expanded,
    defines: &[(String, String)],
    model: &Path,
    dialect: Dialect,
    search: &[PathBuf],
) -> Result<Option<Compiled>> {
    let Some(slangc) = slangc() else { return Ok(None) };
    let text = format!("#line 1 \"{MAIN_NAME}.{}\"\n{}", dialect.extension(), without_forced_inlining(&x.text()));
    let mut args: Vec<String> = FLAGS.iter().map(|f| f.to_string()).collect();
    if dialect == Dialect::Hlsl {
        args.extend(float_defines());
    }
    args.extend(defines.iter().map(|(n, v)| if v.is_empty() { format!("-D{n}") } else { format!("-D{n}={v}") }));
    for dir in search {
        args.push("-I".into());
        args.push(if dir.as_os_str().is_empty() { ".".into() } else { dir.display().to_string() });
    }
    let key = crate::cache::KeyBuilder::new(CACHE_KIND)
        .part("brdfprof", env!("CARGO_PKG_VERSION"))
        .part("slangc", version())
        .part("args", args.join("\0"))
        .part("dialect", dialect.extension())
        .part("text", &text);
    // A relative folder (`-I .`) is another folder from another working directory.
    let key = search
        .iter()
        .fold(key, |k, d| {
            let d = if d.as_os_str().is_empty() { Path::new(".") } else { d.as_path() };
            k.part("folder", std::fs::canonicalize(d).unwrap_or_else(|_| d.to_path_buf()).to_string_lossy().as_bytes())
        })
        .finish();
    if let Some(words) = cached(&key) {
        return Ok(Some(Ok(words)));
    }
    let dir = crate::cleanup::TempDir::new().context("cannot create a temporary directory for slangc")?;
    let source = dir.path().join(format!("shader.{}", dialect.extension()));
    std::fs::write(&source, &text).with_context(|| format!("cannot write {}", source.display()))?;
    let (out, depfile) = (dir.path().join("shader.spv"), dir.path().join("shader.d"));
    let mut cmd = crate::cleanup::command(&slangc.to_string_lossy());
    crate::launch::bound_memory(&mut cmd)?;
    cmd.arg(&source).args(&args).arg("-o").arg(&out).arg("-depfile").arg(&depfile);
    let what = format!("{} (Slang's slangc)", model.display());
    let result = crate::launch::output(&mut cmd, &what)?;
    let log = String::from_utf8_lossy(&result.stdout).to_string() + &String::from_utf8_lossy(&result.stderr);
    if let Some(signal) = std::os::unix::process::ExitStatusExt::signal(&result.status) {
        return Ok(Some(Err(format!(
            "slangc crashed (signal {signal}) on the shader {}",
            crate::launch::memory_note()
        ))));
    }
    if !result.status.success() || !out.is_file() {
        let mut text = messages(&log, x, &source);
        // slangc says "internal error" where an allocation failed under the bound.
        if ["bad_alloc", "out of memory", "Out of memory", "internal error"].iter().any(|m| log.contains(m)) {
            text += &format!(" {}", crate::launch::memory_note());
        }
        return Ok(Some(Err(text)));
    }
    let bytes = crate::io::read_bounded(&out, crate::launch::MAX_OUTPUT_BYTES as u64).context("slangc's SPIR-V")?;
    let words = crate::glslang::Spirv::from_bytes(&what, &bytes)?.words.to_vec();
    let deps = std::fs::read_to_string(&depfile).map(|d| depfile_paths(&d)).unwrap_or_default();
    let deps: Vec<PathBuf> = deps.into_iter().filter(|p| p != &source).collect();
    store(&key, &deps, &bytes);
    Ok(Some(Ok(words)))
}

/// The cache's kind for slangc's SPIR-V.
const CACHE_KIND: &str = "slang_spv";

/// A cached compilation: the files it read besides its text (the imported modules) with their contents' hash.
type Entry = (Vec<(PathBuf, String)>, Vec<u8>);

fn memory() -> &'static Mutex<HashMap<crate::cache::Key, Entry>> {
    static CACHE: OnceLock<Mutex<HashMap<crate::cache::Key, Entry>>> = OnceLock::new();
    CACHE.get_or_init(Mutex::default)
}

/// The hash of a module's content, None where it cannot be read.
fn content_hash(path: &Path) -> Option<String> {
    let bytes = crate::io::read_bounded(path, crate::io::MAX_INPUT_BYTES).ok()?;
    Some(crate::cache::KeyBuilder::new("module").part("content", bytes).finish().hex().to_string())
}

/// The cached SPIR-V of `key`, where every module it read still has the content it had.
fn cached(key: &crate::cache::Key) -> Option<Vec<u32>> {
    let fresh = |e: &Entry| e.0.iter().all(|(p, h)| content_hash(p).as_deref() == Some(h.as_str()));
    let in_memory = memory().lock().unwrap().get(key).cloned();
    let entry = match in_memory {
        Some(e) => e,
        None => {
            let store = crate::cache::Store::open_default()?;
            let crate::cache::Lookup::Hit(payload) = store.get(CACHE_KIND, key) else { return None };
            let entry = decode(&payload)?;
            memory().lock().unwrap().insert(key.clone(), entry.clone());
            entry
        }
    };
    if !fresh(&entry) {
        return None;
    }
    crate::glslang::Spirv::from_bytes("cached slangc SPIR-V", &entry.1).ok().map(|s| s.words.to_vec())
}

/// Records a compilation in memory and on disk (a store that cannot be written costs a compilation next time).
fn store(key: &crate::cache::Key, deps: &[PathBuf], spirv: &[u8]) {
    let Some(hashed) = deps.iter().map(|p| content_hash(p).map(|h| (p.clone(), h))).collect::<Option<Vec<_>>>() else {
        return;
    };
    let entry = (hashed, spirv.to_vec());
    if let Some(store) = crate::cache::Store::open_default() {
        let _ = store.put(CACHE_KIND, key, &encode(&entry));
    }
    memory().lock().unwrap().insert(key.clone(), entry);
}

/// An entry as stored: one JSON line of [path, hash] pairs, then the SPIR-V's bytes.
fn encode(entry: &Entry) -> Vec<u8> {
    let deps: Vec<(String, &String)> = entry.0.iter().map(|(p, h)| (p.display().to_string(), h)).collect();
    let mut out = serde_json::to_vec(&deps).unwrap_or_default();
    out.push(b'\n');
    out.extend_from_slice(&entry.1);
    out
}

fn decode(payload: &[u8]) -> Option<Entry> {
    let split = payload.iter().position(|&b| b == b'\n')?;
    let deps: Vec<(String, String)> = serde_json::from_slice(&payload[..split]).ok()?;
    Some((deps.into_iter().map(|(p, h)| (PathBuf::from(p), h)).collect(), payload[split + 1..].to_vec()))
}

/// The prerequisites of a Make-style depfile (`out: a b\ c`), a backslash escaping a space.
fn depfile_paths(text: &str) -> Vec<PathBuf> {
    let text = text.replace("\\\n", " ");
    let Some((_, deps)) = text.split_once(": ") else { return Vec::new() };
    let mut out = Vec::new();
    let mut current = String::new();
    let mut chars = deps.chars();
    while let Some(c) = chars.next() {
        match c {
            '\\' => current.extend(chars.next()),
            c if c.is_whitespace() => {
                if !current.is_empty() {
                    out.push(PathBuf::from(std::mem::take(&mut current)));
                }
            }
            c => current.push(c),
        }
    }
    if !current.is_empty() {
        out.push(PathBuf::from(current));
    }
    out
}

/// The most errors of one shader said; the rest are counted.
const MAX_MESSAGES: usize = 20;

/// slangc's errors (`error[E30015]: undefined identifier` or `fatal error[...]`, then ` --> shader.hlsl:2:12`
/// and a caret line's detail: a line of blanks, `|` and carets, then the detail) at the user's files' lines; a
/// line brdfprof wrote is named by what it stands for. The first `MAX_MESSAGES`, the rest counted. Where none
/// is located, the log, with the temporary file's name (`source`, gone by the time anyone reads it) replaced by
/// "the expanded shader".
pub fn messages(log: &str, x: &Expanded, source: &Path) -> String {
    let lines: Vec<&str> = log.lines().collect();
    let mut out: Vec<String> = Vec::new();
    let error = |l: &str| {
        let l = l.strip_prefix("fatal ").unwrap_or(l);
        l.strip_prefix("error").and_then(|r| r.split_once("]: ").map(|(_, m)| m.to_string()))
    };
    for (i, l) in lines.iter().enumerate() {
        let Some(message) = error(l) else { continue };
        let at = lines.get(i + 1).and_then(|a| a.trim().strip_prefix("--> "));
        // A caret line is blanks and `|` then carets; a source line slangc quotes starts with its number.
        fn caret(d: &str) -> Option<&str> {
            let lead = d.trim_start_matches([' ', '\t', '|']);
            lead.starts_with('^').then(|| lead.trim_start_matches('^').trim())
        }
        let detail = lines[i + 1..]
            .iter()
            .take_while(|d| error(d).is_none() && !d.starts_with("warning"))
            .find_map(|d| caret(d))
            .filter(|d| !d.is_empty());
        let tail = detail.map_or_else(String::new, |d| format!(" ({d})"));
        let located = at.and_then(|a| {
            let mut parts = a.rsplitn(3, ':');
            let (col, line) = (parts.next()?.parse::<usize>().ok()?, parts.next()?.parse::<usize>().ok()?);
            let file = parts.next()?;
            // A module slangc imported keeps its own path; the text brdfprof wrote is numbered as expanded.
            if !file.starts_with(MAIN_NAME) && !file.ends_with(&*source.to_string_lossy()) {
                return Some(format!("{file}:{line}:{col}: {message}{tail}"));
            }
            let origin = *x.origins.get(line.checked_sub(1)?)?;
            Some(match x.generated.get(&(line - 1)) {
                Some(what) => format!("{}:{}:1: {what}: {message}{tail}", x.files[origin.0], origin.1),
                None => format!("{}:{}:{col}: {message}{tail}", x.files[origin.0], origin.1),
            })
        });
        out.push(located.unwrap_or_else(|| format!("{message}{tail}")));
    }
    if out.is_empty() {
        return log.trim().replace(&source.display().to_string(), "the expanded shader");
    }
    let more = out.len().saturating_sub(MAX_MESSAGES);
    out.truncate(MAX_MESSAGES);
    if more > 0 {
        out.push(format!("... and {more} more errors"));
    }
    out.join("\n")
}

/// The front end of Slang models, with slangc's version, as reports state it.
pub fn describe_slang() -> String {
    format!("Slang's slangc {} ({}; the slangtorch wheel of `make setup`)", version(), FLAGS.join(" "))
}

/// The front end of HLSL glslang refused, with slangc's version, as reports state it.
pub fn describe() -> String {
    format!(
        "Slang's slangc {} ({}; `half` and min16float as float, -Dhalf=float ...; the slangtorch wheel of `make setup`)",
        version(),
        FLAGS.join(" ")
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn messages_are_located_counted_and_never_a_source_line() {
        let x = Expanded::default();
        let log = "error[E1]: undefined identifier\n --> /tmp/brdfprof-1/shader.hlsl:2:3\n2 | float y = a ^ b;\n  |   ^ here\n"
            .to_string()
            + &"fatal error[E2]: too many errors\n".repeat(30);
        let m = messages(&log, &x, Path::new("/tmp/brdfprof-1/shader.hlsl"));
        assert!(m.starts_with("undefined identifier (here)"), "{m}");
        assert!(m.contains("too many errors") && m.ends_with("... and 11 more errors"), "{m}");
        let raw =
            messages("slangc: cannot open /tmp/brdfprof-1/shader.hlsl", &x, Path::new("/tmp/brdfprof-1/shader.hlsl"));
        assert_eq!(raw, "slangc: cannot open the expanded shader");
        let module = messages(
            "error[E30015]: undefined identifier\n --> /src/common.slang:4:9\n",
            &x,
            Path::new("/tmp/brdfprof-1/shader.slang"),
        );
        assert_eq!(module, "/src/common.slang:4:9: undefined identifier");
    }

    #[test]
    fn forced_inlining_is_blanked_column_for_column() {
        let text = "[ForceInline]\nfloat3 f() { return a[0]; }\n[ForceInline ] [numthreads(1, 1, 1)]";
        let out = without_forced_inlining(text);
        assert_eq!(out, "             \nfloat3 f() { return a[0]; }\n               [numthreads(1, 1, 1)]");
    }

    #[test]
    fn a_depfile_names_each_prerequisite_once_with_escaped_spaces() {
        let deps = depfile_paths("out.spv: /a/shader.slang /b/my\\ module.slang \\\n  /c/x.slang\n");
        let deps: Vec<String> = deps.iter().map(|p| p.display().to_string()).collect();
        assert_eq!(deps, ["/a/shader.slang", "/b/my module.slang", "/c/x.slang"]);
    }

    #[test]
    fn a_cache_entry_reads_back_as_written() {
        let entry = (vec![(PathBuf::from("/a b/c.slang"), "00ff".to_string())], vec![3, 2, 0x23, 7]);
        assert_eq!(decode(&encode(&entry)), Some(entry));
        assert_eq!(decode(b"not json"), None);
    }

    #[test]
    fn the_stub_stores_what_it_computes_in_one_line() {
        let s = stub(&["BRDF".into(), "brdfprof_entry0".into()]);
        assert!(!s.contains('\n') && s.contains("v += BRDF(v, v, v, v, v);") && s.contains("brdfprof_out[0] = v;"));
    }
}
