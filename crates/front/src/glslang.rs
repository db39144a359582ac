//! glslang, the one GLSL (and HLSL) compiler brdfprof runs: a source compiled to SPIR-V under the compile limit,
//! its preprocessor alone, its version; SPIR-V words as a module (`Spirv`).

use anyhow::{Context, Result, bail};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::Arc;

/// A SPIR-V module ready for `gpu::Kernel::new`.
#[derive(Clone, Debug, PartialEq)]
pub struct Spirv {
    pub name: String,
    pub words: Arc<[u32]>,
}

impl Spirv {
    /// SPIR-V from its bytes (little-endian words, as glslang writes them).
    pub fn from_bytes(name: &str, bytes: &[u8]) -> Result<Self> {
        const MAGIC: u32 = 0x0723_0203;
        if bytes.len() % 4 != 0 || bytes.len() < 20 {
            bail!("{name}: not a SPIR-V module ({} bytes, not whole words of a header and more)", bytes.len());
        }
        let words: Vec<u32> = bytes.chunks_exact(4).map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]])).collect();
        if words[0] != MAGIC {
            bail!("{name}: not a SPIR-V module (magic number {:#010x})", words[0]);
        }
        Ok(Spirv { name: name.to_string(), words: words.into() })
    }

    pub fn bytes(&self) -> Vec<u8> {
        self.words.iter().flat_map(|w| w.to_le_bytes()).collect()
    }
}

/// glslang's flags for every kernel, as in glsl/build-spv.sh (`-D<define>` and `-o` follow).
pub const GLSLANG_FLAGS: [&str; 3] = ["-V", "--target-env", "vulkan1.1"];

/// Compiles `source` with glslang (`GLSLANG_FLAGS`, `-D` for each define, `-I` for each include directory)
/// under the compile limit (`launch`; `what` names the compilation in its messages) and returns the
/// SPIR-V words; a failure carries glslang's own messages.
pub fn glslang(source: &Path, defines: &[String], includes: &[&Path], what: &str) -> Result<Vec<u32>> {
    glslang_with(source, defines, includes, what, &[])
}

/// `glslang` with `extra` flags after brdfprof's own (`-g`: line information for the translation's messages).
pub fn glslang_with(
    source: &Path,
    defines: &[String],
    includes: &[&Path],
    what: &str,
    extra: &[&str],
) -> Result<Vec<u32>> {
    let out_dir = crate::cleanup::TempDir::new().context("cannot create a temporary directory for glslang's output")?;
    let out = out_dir.path().join("out.spv");
    let mut cmd = crate::cleanup::command("glslangValidator");
    crate::launch::bound_memory(&mut cmd)?;
    cmd.args(GLSLANG_FLAGS).args(extra);
    for d in defines {
        cmd.arg(format!("-D{d}"));
    }
    for i in includes {
        cmd.arg(format!("-I{}", i.display()));
    }
    cmd.arg("-o").arg(&out).arg(source);
    let result = match crate::launch::output(&mut cmd, what) {
        Ok(r) => r,
        Err(e) if e.downcast_ref::<std::io::Error>().is_some() => {
            bail!("cannot run glslangValidator ({e}): install glslang-tools, or run `make setup`")
        }
        Err(e) => return Err(e),
    };
    if !result.status.success() {
        bail!(GlslangError {
            source: source.to_path_buf(),
            log: format!("{}{}", String::from_utf8_lossy(&result.stdout), String::from_utf8_lossy(&result.stderr))
        });
    }
    let bytes = crate::io::read_bounded(&out, crate::launch::MAX_OUTPUT_BYTES as u64)
        .with_context(|| format!("glslang's output {}", out.display()))?;
    Ok(Spirv::from_bytes(&source.display().to_string(), &bytes)?.words.to_vec())
}

/// glslang's preprocessor alone (`-E`) on `text` (a whole source, `#version` first) as a compute shader, with
/// `-D` for each define, under the compile limit: Ok(the preprocessed text) or Err(glslang's log).
/// `-E` cannot be combined with `-V`, so `VULKAN=100`, which glslang defines when it compiles for Vulkan, is
/// given here as a define: a `#ifdef VULKAN` selects what the kernel compilation will see.
pub fn glslang_preprocess(text: &str, defines: &[String], what: &str) -> Result<std::result::Result<String, String>> {
    let dir =
        crate::cleanup::TempDir::new().context("cannot create a temporary directory for glslang's preprocessor")?;
    let source = dir.path().join("shader.comp");
    std::fs::write(&source, text).with_context(|| format!("cannot write {}", source.display()))?;
    let mut cmd = crate::cleanup::command("glslangValidator");
    crate::launch::bound_memory(&mut cmd)?;
    cmd.arg("-E").arg("-DVULKAN=100");
    for d in defines {
        cmd.arg(format!("-D{d}"));
    }
    cmd.arg(&source);
    let result = match crate::launch::output(&mut cmd, what) {
        Ok(r) => r,
        Err(e) if e.downcast_ref::<std::io::Error>().is_some() => {
            bail!("cannot run glslangValidator ({e}): install glslang-tools, or run `make setup`")
        }
        Err(e) => return Err(e),
    };
    let stdout = String::from_utf8_lossy(&result.stdout).into_owned();
    if result.status.success() {
        return Ok(Ok(stdout));
    }
    let log = stdout + &String::from_utf8_lossy(&result.stderr);
    Ok(Err(log.replace(&source.display().to_string(), "shader")))
}

/// glslang refused a source: its log, as it printed it.
#[derive(Debug)]
pub struct GlslangError {
    pub source: PathBuf,
    pub log: String,
}

impl std::fmt::Display for GlslangError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "glslangValidator failed on {}:\n{}", self.source.display(), self.log.trim_end())
    }
}

impl std::error::Error for GlslangError {}

/// `glslangValidator --version`'s first line, e.g. "Glslang Version: 11:12.0.0".
pub fn glslang_version() -> Option<String> {
    first_line_of(crate::cleanup::command("glslangValidator").arg("--version"))
}

/// The first non-empty line a tool prints, or None when it cannot run.
pub fn first_line_of(cmd: &mut Command) -> Option<String> {
    let what = format!("{:?} --version", cmd.get_program());
    let out = crate::launch::output_quick(cmd, &what).ok()?;
    let text = String::from_utf8_lossy(&out.stdout).into_owned() + &String::from_utf8_lossy(&out.stderr);
    text.lines().map(str::trim).find(|l| !l.is_empty()).map(str::to_string)
}

/// `words` without the source text a `-g` build embeds (OpSource's source operand, OpSourceContinued): glslang
/// cuts that text into instructions by bytes, so a non-ASCII character (in a comment, say) can straddle two and
/// neither string is UTF-8 any more, which SPIR-V requires and rspirv checks. OpString and OpLine keep every
/// file and line.
pub fn without_source_text(words: &[u32]) -> Vec<u32> {
    const SOURCE_CONTINUED: u32 = 2;
    const SOURCE: u32 = 3;
    let mut out = words[..words.len().min(5)].to_vec();
    let mut i = 5;
    while i < words.len() {
        let (op, len) = (words[i] & 0xffff, (words[i] >> 16) as usize);
        let len = len.max(1).min(words.len() - i);
        match op {
            SOURCE_CONTINUED => {}
            // Language, version and the file's id; the text after them dropped.
            SOURCE if len > 4 => {
                out.push((4 << 16) | SOURCE);
                out.extend_from_slice(&words[i + 1..i + 4]);
            }
            _ => out.extend_from_slice(&words[i..i + len]),
        }
        i += len;
    }
    out
}
