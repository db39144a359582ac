//! The SPIR-V kernels: embedded at build time from `spv/` as listed in `glsl/kernels.txt`, or compiled at run
//! time with glslang (from another GLSL directory, `--glsl DIR`, or composed for a `.brdf` model), and the
//! GLSL sources themselves, embedded so that kernels can be composed without a checkout.

use anyhow::{Context, Result, anyhow, bail};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::{Arc, Mutex};

/// One compiled kernel as the build embedded it: its GLSL source (under `glsl/`), the preprocessor defines it
/// was compiled with, and the SPIR-V that glslang produced.
#[derive(Debug)]
pub struct KernelSource {
    pub name: &'static str,
    pub source: &'static str,
    pub defines: &'static [&'static str],
    pub spirv: &'static [u8],
}

include!(concat!(env!("OUT_DIR"), "/kernels.rs"));

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

/// The embedded kernel `name` (a name from `glsl/kernels.txt`).
pub fn embedded(name: &str) -> Result<&'static KernelSource> {
    let k = KERNELS.iter().find(|k| k.name == name).ok_or_else(|| anyhow!("no kernel `{name}` in glsl/kernels.txt"))?;
    if k.spirv.is_empty() {
        bail!("spv/{name}.spv was missing when brdfprof was built: run `make spv` and rebuild");
    }
    Ok(k)
}

impl KernelSource {
    pub fn spirv(&self) -> Spirv {
        Spirv::from_bytes(self.name, self.spirv).expect("embedded SPIR-V is well formed")
    }
}

/// glslang's flags for every kernel, as in glsl/build-spv.sh (`-D<define>` and `-o` follow).
pub const GLSLANG_FLAGS: [&str; 3] = ["-V", "--target-env", "vulkan1.1"];

/// Where the built-in kernels' SPIR-V comes from: the modules embedded from `spv/`, or a GLSL directory (a
/// copy of glsl/ with its kernels.txt) compiled on demand, so that `inspect --glsl DIR` and `check --glsl DIR`
/// measure an edited copy of the shaders exactly as `make spv` would have compiled it.
pub struct Shaders {
    glsl: Option<PathBuf>,
    compiled: Mutex<HashMap<String, Spirv>>,
}

impl Shaders {
    pub fn embedded() -> Self {
        Shaders { glsl: None, compiled: Mutex::default() }
    }

    pub fn from_glsl(dir: &Path) -> Result<Self> {
        if !dir.join("kernels.txt").is_file() {
            bail!("--glsl {}: no kernels.txt there (expected a directory like glsl/)", dir.display());
        }
        Ok(Shaders { glsl: Some(dir.to_path_buf()), compiled: Mutex::default() })
    }

    pub fn glsl_dir(&self) -> Option<&Path> {
        self.glsl.as_deref()
    }

    /// Where the SPIR-V came from, for reports.
    pub fn describe(&self) -> String {
        match &self.glsl {
            None => "embedded spv/".into(),
            Some(dir) => format!(
                "compiled at run time from {} ({})",
                dir.display(),
                glslang_version().unwrap_or_else(|| "glslang".into())
            ),
        }
    }

    /// The kernel `name` of kernels.txt.
    pub fn get(&self, name: &str) -> Result<Spirv> {
        let Some(dir) = &self.glsl else {
            return Ok(embedded(name)?.spirv());
        };
        let mut compiled = self.compiled.lock().unwrap();
        if let Some(k) = compiled.get(name) {
            return Ok(k.clone());
        }
        let (source, defines) = kernel_entry(dir, name)?;
        let words = glslang(&dir.join(&source), &defines, &[], &format!("{name} from {} (glslang)", dir.display()))?;
        let spirv = Spirv { name: name.to_string(), words: words.into() };
        compiled.insert(name.to_string(), spirv.clone());
        Ok(spirv)
    }
}

impl Shaders {
    /// The kernel `name` compiled again with glslang's `-g`: the same code with OpLine and OpString, so that
    /// each instruction names its file and line (`inspect --lines`). From `--glsl DIR`, or from the embedded
    /// glsl/ tree written into a temporary directory named `glsl` (file names then read `.../glsl/brdf.glsl`).
    pub fn with_lines(&self, name: &str) -> Result<Spirv> {
        let what = format!("{name} with line information (glslang -g)");
        let words = match &self.glsl {
            Some(dir) => {
                let (source, defines) = kernel_entry(dir, name)?;
                glslang_with(&dir.join(&source), &defines, &[], &what, &["-g"])?
            }
            None => {
                let k = embedded(name)?;
                let tmp =
                    crate::cleanup::TempDir::new().context("cannot create a temporary directory for glslang -g")?;
                let root = tmp.path().join("glsl");
                write_glsl_tree(&root)?;
                let defines: Vec<String> = k.defines.iter().map(|d| d.to_string()).collect();
                glslang_with(&root.join(k.source), &defines, &[], &what, &["-g"])?
            }
        };
        Ok(Spirv { name: format!("{name} (-g)"), words: words.into() })
    }
}

/// `name`'s line in `dir/kernels.txt`: (source file, defines).
pub fn kernel_entry(dir: &Path, name: &str) -> Result<(String, Vec<String>)> {
    let list = dir.join("kernels.txt");
    let text = String::from_utf8(crate::io::read_input(&list)?)
        .map_err(|_| anyhow::anyhow!("cannot read {}: not UTF-8 text", list.display()))?;
    for line in text.lines().map(str::trim).filter(|l| !l.is_empty() && !l.starts_with('#')) {
        let mut fields = line.split_whitespace();
        if fields.next() == Some(name) {
            let source = fields.next().ok_or_else(|| anyhow!("{}: `{line}` names no source file", list.display()))?;
            return Ok((source.to_string(), fields.map(str::to_string).collect()));
        }
    }
    bail!("{} lists no kernel `{name}`", list.display())
}

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

/// Writes the embedded glsl/ tree into `dir` (for kernels composed at run time).
pub fn write_glsl_tree(dir: &Path) -> Result<()> {
    for (rel, text) in GLSL_FILES {
        let path = dir.join(rel);
        if let Some(parent) = path.parent() {
            std::fs::create_dir_all(parent).with_context(|| format!("cannot create {}", parent.display()))?;
        }
        std::fs::write(&path, text).with_context(|| format!("cannot write {}", path.display()))?;
    }
    Ok(())
}

/// The text of an embedded glsl/ file by its path within glsl/ (`brdf.glsl`, `generated/terms.glsl`).
pub fn embedded_glsl(rel: &str) -> Option<&'static str> {
    GLSL_FILES.iter().find(|(r, _)| *r == rel).map(|(_, t)| *t)
}

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
