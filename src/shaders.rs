//! The SPIR-V kernels: embedded at build time from `spv/` as listed in `glsl/kernels.txt`, or compiled at run
//! time with glslang (from another GLSL directory, `--glsl DIR`, or composed for a `.brdf` model), and the
//! GLSL sources themselves, embedded so that kernels can be composed without a checkout.

use anyhow::{Context, Result, anyhow, bail};
use std::collections::HashMap;
use std::path::{Path, PathBuf};

use std::sync::Mutex;

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

pub use brdfprof_front::glslang::{
    GLSLANG_FLAGS, GlslangError, Spirv, first_line_of, glslang, glslang_preprocess, glslang_version, glslang_with,
    without_source_text,
};

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
