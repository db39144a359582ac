//! Slang's compiler (slangc) as the second HLSL front end: what DXC-era engine HLSL holds and glslang's HLSL front
//! end refuses or crashes on (static member functions returning their own struct, struct inheritance, `select`,
//! a member function calling a static member unqualified). `make setup` installs slangc from the pinned
//! slangtorch wheel (scripts/slang-wheel.txt) into .tools/slang; brdfprof runs it on the same expanded text as
//! glslang, with a stub of its own, when glslang refuses the shader, and spirv-cross writes its SPIR-V back as
//! GLSL as it does glslang's (`cross`).

use super::includes::Expanded;
use anyhow::{Context, Result};
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

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

/// The shader compiled by slangc: None where slangc is not installed, Some(Err(its messages at the user's files'
/// lines)) where it refuses the shader (or crashes), else the SPIR-V.
pub fn compile(
    x: &Expanded,
    defines: &[(String, String)],
    model: &Path,
) -> Result<Option<std::result::Result<Vec<u32>, String>>> {
    let Some(slangc) = slangc() else { return Ok(None) };
    let dir = crate::cleanup::TempDir::new().context("cannot create a temporary directory for slangc")?;
    let source = dir.path().join("shader.hlsl");
    std::fs::write(&source, x.text()).with_context(|| format!("cannot write {}", source.display()))?;
    let out = dir.path().join("shader.spv");
    let mut cmd = crate::cleanup::command(&slangc.to_string_lossy());
    crate::launch::bound_memory(&mut cmd)?;
    cmd.arg(&source).args(FLAGS).args(float_defines()).arg("-o").arg(&out);
    cmd.args(defines.iter().map(|(n, v)| if v.is_empty() { format!("-D{n}") } else { format!("-D{n}={v}") }));
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
    Ok(Some(Ok(crate::shaders::Spirv::from_bytes(&what, &bytes)?.words.to_vec())))
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

/// The front end, with slangc's version, as reports state it.
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
    }

    #[test]
    fn the_stub_stores_what_it_computes_in_one_line() {
        let s = stub(&["BRDF".into(), "brdfprof_entry0".into()]);
        assert!(!s.contains('\n') && s.contains("v += BRDF(v, v, v, v, v);") && s.contains("brdfprof_out[0] = v;"));
    }
}
