//! Where the kernels' SPIR-V comes from: the modules embedded from `spv/`, or a GLSL directory compiled at
//! run time with glslang, so that `inspect --glsl DIR` and `check --glsl DIR` measure an edited copy of the
//! shaders exactly as `make spv` would have compiled it.

use crate::brdf::Precision;
use crate::shaders::KernelSource;
use anyhow::{anyhow, bail, Context, Result};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::Mutex;

/// glslang's flags for every kernel, as in glsl/build-spv.sh (`-D<define>` and `-o` follow).
pub const GLSLANG_FLAGS: [&str; 3] = ["-V", "--target-env", "vulkan1.1"];

/// The kernels a command measures.
pub struct KernelSet {
    glsl: Option<PathBuf>,
    /// Kernels compiled so far, by name. Leaked: `KernelSource` holds `&'static` data and a command compiles
    /// at most a handful of kernels once each.
    compiled: Mutex<HashMap<String, &'static KernelSource>>,
}

impl KernelSet {
    /// The SPIR-V embedded in the binary (`spv/`).
    pub fn embedded() -> Self {
        KernelSet { glsl: None, compiled: Mutex::default() }
    }

    /// Kernels compiled on demand from `dir` (a copy of `glsl/` with its own `kernels.txt`).
    pub fn from_glsl(dir: &Path) -> Result<Self> {
        if !dir.join("kernels.txt").is_file() {
            bail!("--glsl {}: no kernels.txt there (expected a directory like glsl/)", dir.display());
        }
        Ok(KernelSet { glsl: Some(dir.to_path_buf()), compiled: Mutex::default() })
    }

    pub fn glsl_dir(&self) -> Option<&Path> {
        self.glsl.as_deref()
    }

    /// Where the SPIR-V came from, for reports.
    pub fn describe(&self) -> String {
        match &self.glsl {
            None => "embedded spv/".into(),
            Some(dir) => format!("compiled at run time from {} ({})", dir.display(), glslang_version().unwrap_or_else(|| "glslang".into())),
        }
    }

    /// The profiling kernel (`shade_<precision>`).
    pub fn shade(&self, precision: Precision) -> Result<&'static KernelSource> {
        self.get(&format!("shade_{}", precision.name()))
    }

    /// The kernel `name` of kernels.txt.
    pub fn get(&self, name: &str) -> Result<&'static KernelSource> {
        let Some(dir) = &self.glsl else {
            return Ok(crate::shaders::kernel(name));
        };
        let mut compiled = self.compiled.lock().unwrap();
        if let Some(k) = compiled.get(name) {
            return Ok(k);
        }
        let k: &'static KernelSource = Box::leak(Box::new(compile(dir, name)?));
        compiled.insert(name.to_string(), k);
        Ok(k)
    }
}

/// `name`'s line in `dir/kernels.txt`: (source file, defines).
fn kernel_entry(dir: &Path, name: &str) -> Result<(String, Vec<String>)> {
    let list = dir.join("kernels.txt");
    let text = std::fs::read_to_string(&list).with_context(|| format!("cannot read {}", list.display()))?;
    for line in text.lines().map(str::trim).filter(|l| !l.is_empty() && !l.starts_with('#')) {
        let mut fields = line.split_whitespace();
        if fields.next() == Some(name) {
            let source = fields.next().ok_or_else(|| anyhow!("{}: `{line}` names no source file", list.display()))?;
            return Ok((source.to_string(), fields.map(str::to_string).collect()));
        }
    }
    bail!("{} lists no kernel `{name}`", list.display())
}

fn leak(s: String) -> &'static str {
    Box::leak(s.into_boxed_str())
}

/// Compiles kernel `name` of `dir` with glslang into a `KernelSource`.
fn compile(dir: &Path, name: &str) -> Result<KernelSource> {
    let (source, defines) = kernel_entry(dir, name)?;
    let out_dir = tempfile::tempdir().context("cannot create a temporary directory for glslang's output")?;
    let out = out_dir.path().join(format!("{name}.spv"));
    let mut cmd = Command::new("glslangValidator");
    cmd.args(GLSLANG_FLAGS);
    for d in &defines {
        cmd.arg(format!("-D{d}"));
    }
    cmd.arg("-o").arg(&out).arg(dir.join(&source));
    let result = cmd
        .output()
        .map_err(|e| anyhow!("cannot run glslangValidator ({e}): install glslang-tools, or run `make setup`"))?;
    if !result.status.success() {
        bail!(
            "glslangValidator failed on {}:\n{}{}",
            dir.join(&source).display(),
            String::from_utf8_lossy(&result.stdout),
            String::from_utf8_lossy(&result.stderr)
        );
    }
    let spirv = std::fs::read(&out).with_context(|| format!("cannot read glslang's output {}", out.display()))?;
    let defines: Vec<&'static str> = defines.into_iter().map(leak).collect();
    Ok(KernelSource { name: leak(name.to_string()), source: leak(source), defines: Box::leak(defines.into_boxed_slice()), spirv: Box::leak(spirv.into_boxed_slice()) })
}

/// `glslangValidator --version`'s first line, e.g. "Glslang Version: 11:12.0.0".
pub fn glslang_version() -> Option<String> {
    first_line_of(Command::new("glslangValidator").arg("--version"))
}

/// The first non-empty line a tool prints, or None when it cannot run.
pub(crate) fn first_line_of(cmd: &mut Command) -> Option<String> {
    let out = cmd.output().ok()?;
    let text = String::from_utf8_lossy(&out.stdout).into_owned() + &String::from_utf8_lossy(&out.stderr);
    text.lines().map(str::trim).find(|l| !l.is_empty()).map(str::to_string)
}
