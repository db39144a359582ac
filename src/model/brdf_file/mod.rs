//! BRDF Explorer `.brdf` files (wdas/brdf, `BRDFBase::loadBRDF`), read as BRDF Explorer reads them, and their
//! GLSL prepared for composition into brdfprof's Vulkan kernels.
//!
//! The format: line 1 names the kind (`analytic`; brdfprof reads no other). After it, blank lines and lines
//! whose trimmed text starts with `#` are skipped, as BRDF Explorer skips them; but in the shader a
//! preprocessor directive (`#define`, `#if`, ...) is kept and the shader goes through glslang's preprocessor
//! (`preprocess`, under the model's defines), because engine code relies on it; any other `#` line
//! there is dropped with a warning. `::begin NAME` / `::end NAME` enclose sections: `parameters` (`float NAME MIN
//! MAX DEFAULT`, `bool NAME 0|1`, `color NAME R G B`), `shader` (GLSL defining
//! `vec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y)`; BRDF Explorer declares each parameter before it as
//! `uniform float/bool/vec3 NAME;`), `isFunc` (importance sampling, ignored here) and brdfprof's own `brdfprof`
//! (`entry NAME(ARG, ...) returns f|f_nol`: an engine's function to call instead of `BRDF`; `bind NAME=@INPUT`:
//! default bindings; docs/engine-brdf.md).
//!
//! Composition (`renamed_shader`): every global name the shader declares and every parameter name is renamed,
//! at each of its occurrences, with a prefix (`brdf_f_`, or a variant when the file already uses identifiers
//! starting with `brdf_f`), so that the file's functions win over GLSL built-ins of the same name (a file's own
//! `reflect`, which glslang refuses to redefine in Vulkan mode) and cannot collide with the host kernels'
//! identifiers (`PI`, `pow5`, `D_Ggx`, ...). Renaming every occurrence is alpha-equivalent: a function parameter
//! or local named like a global is renamed with it. The host must declare no identifier that starts with
//! `brdf_f`. Lines keep their number and order, so errors map back to the file:
//!
//! ```text
//! #version 450
//! #extension GL_GOOGLE_cpp_style_line_directive : require   // implied by GL_GOOGLE_include_directive
//! const float brdf_f_roughness = 0.5;                       // default_constants(); or `float brdf_f_f0;`,
//!                                                           // a private global main sets per sample
//! #line 12 "my.brdf"                                        // line_directive()
//! ...the renamed shader lines...
//! #line 40 "kernel.comp"                                     // back to the composed source's own numbering
//! #include "brdf.glsl"                                       // host code after the file: its macros
//! void main() { ... brdf_f_BRDF(L, V, N, X, Y) ... }         // (`real`, ...) cannot touch the file's text
//! ```
//!
//! glslang then names the file and its own line in every message about it; `remap_log` turns those messages
//! (or, without the directive, messages located through a line map) into `my.brdf:57: ...` with the original
//! identifiers.
//!
//! An HLSL or WGSL shader (`::begin shader hlsl|wgsl`, or a plain `.hlsl`/`.ush`/`.wgsl` file read by
//! `load_shader`) is first translated into GLSL by its front end (`foreign`, `crate::model::front`): every step
//! above then reads that GLSL, while the checks of its entries, its loops and its messages are the source's.

mod foreign;
mod format;
mod globals;
mod inits;
mod loops;
mod preprocess;
mod rename;
#[cfg(test)]
mod tests;
mod tokens;

use format::*;
use globals::*;
use loops::*;
use preprocess::*;
use rename::*;
use tokens::*;

pub use format::is_identifier;
pub use inits::Initialiser;
pub use loops::LAVAPIPE_LOOP_LIMIT;

pub use crate::model::front::{HlslFrontEnd, Includes, Language};

use anyhow::{Result, anyhow, bail};
use sha2::{Digest, Sha256};
use std::collections::HashSet;
use std::fmt::Display;
use std::path::{Path, PathBuf};

/// A parsed `.brdf` file.
#[derive(Clone, Debug, PartialEq)]
pub struct BrdfFile {
    /// The path as the user gave it (every message names it so).
    pub path: PathBuf,
    /// The file stem.
    pub name: String,
    pub params: Vec<FileParam>,
    /// Every line of the shader section as written, with its 1-based file line: preprocessor directives kept,
    /// blank lines and dropped `#` lines (`dropped_hash_line`) empty, so that the lines are consecutive.
    pub source: Vec<(usize, String)>,
    /// The defines the shader is preprocessed with (`define=NAME=VALUE` in the model spec, `--define`).
    pub defines: Vec<(String, String)>,
    /// The shader's language (`::begin shader hlsl|wgsl`, or a plain `.hlsl`/`.ush`/`.wgsl` file's).
    pub language: Language,
    /// Where an HLSL shader's `#include` and a WGSL shader's `#import` look (`include=`, `include-map=`).
    pub includes: Includes,
    /// Which front end compiles an HLSL shader (`hlsl-front-end=`).
    pub hlsl_front_end: HlslFrontEnd,
    /// What translated an HLSL or WGSL shader into the GLSL the kernels compose (`front::describe`).
    pub front_end: Option<String>,
    /// `source` after glslang's preprocessor (`preprocess`), line for line: what every later step reads. The
    /// same as `source` when it has no directive and no define is given.
    pub shader: Vec<(usize, String)>,
    /// For an HLSL shader: the user's file, line and text each line of `shader` (by index) came from, where the
    /// front end's line information names one (`foreign::origins`); empty otherwise.
    /// One place shared by every line that came from it (a 20,000-term WGSL statement is one line of the user's
    /// and 20,000 of the front end's: copies of its text took 4.8 GB and a minute).
    pub front_end_origins: Vec<Option<std::sync::Arc<(String, usize, String)>>>,
    /// The line of `::begin shader`.
    shader_begin: usize,
    /// Functions declared in the `brdfprof` section to call instead of `BRDF` (`entry ...`), in order.
    pub entries: Vec<Entry>,
    /// The shader defines `BRDF` with BRDF Explorer's signature (it may not when it declares entries).
    pub defines_brdf: bool,
    /// The roughness the file's engine admits (`domain roughness MIN MAX`): (min, max, line).
    pub roughness_domain: Option<(f64, f64, usize)>,
    /// The N.V and N.L its engine calls it with (`domain nov MIN MAX`, `domain nol MIN MAX`): (min, max, line).
    pub nov_domain: Option<(f64, f64, usize)>,
    pub nol_domain: Option<(f64, f64, usize)>,
    /// The built-in spec it is measured against where a command takes a reference and none is given
    /// (`reference SPEC`): (spec text, line).
    pub reference: Option<(String, usize)>,
    /// Default bindings of parameters to inputs (`bind NAME=@INPUT`): (name, `@INPUT`, line).
    pub binds: Vec<(String, String, usize)>,
    /// The file has an `isFunc` section with code in it (brdfprof ignores it; BRDF Explorer samples with it).
    pub has_is_func: bool,
    /// `FILE:LINE: ...` for what the file does that BRDF Explorer tolerates but is likely a mistake: those of
    /// its format, then those of its preprocessed shader.
    pub warnings: Vec<String>,
    /// The warnings of the format alone (the shader's depend on the defines).
    format_warnings: Vec<String>,
    /// SHA-256 of the file's bytes, lowercase hex.
    pub hash: String,
    /// What every renamed name starts with (`BrdfFile::prefix`), computed once.
    pub prefix: String,
    /// The shader's loops (`for`, `while`, `do`), with the trip count where the source bounds it (an HLSL
    /// or WGSL shader's as its own source has them, includes too).
    pub loops: Vec<Loop>,
    /// The preprocessed shader with its globals and parameters renamed, computed once.
    renamed: RenamedShader,
}

/// A loop of the shader: lavapipe stops every loop at `LAVAPIPE_LOOP_LIMIT` iterations.
#[derive(Clone, Debug, PartialEq)]
pub struct Loop {
    /// The file it is in, where not the model's own (an included HLSL file).
    pub file: Option<String>,
    /// The 1-based file line of its keyword.
    pub line: usize,
    pub keyword: &'static str,
    /// Iterations, where the loop is `for (T i = A; i OP B; i STEP)` with literal A, B and step.
    pub trip_count: Option<u64>,
}

/// An engine's function the file names as its entry (`entry NAME(ARG, ...) returns ...`).
#[derive(Clone, Debug, PartialEq)]
pub struct Entry {
    pub name: String,
    /// GLSL expressions over L, V, N, X, Y and the file's parameters, one per argument of the function; or
    /// `@out` (an `out`/`inout vec3` the function writes its value to, starting at zero: an engine's
    /// accumulator) or `@scratch` (an `out`/`inout` argument whose value is discarded: a diffuse accumulator).
    pub args: Vec<String>,
    /// Each parameter's type as the shader declares it (filled by the shader's checks; `@scratch` needs it).
    pub param_types: Vec<String>,
    pub returns: Returns,
    /// The 1-based file line that declares it.
    pub line: usize,
    /// For an HLSL or WGSL shader: the function its front end wrote around the call, `NAME(L, V, N, X, Y)`
    /// in the GLSL it translated the shader into, which the kernels call instead.
    pub glue: Option<String>,
}

/// What an entry returns.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Returns {
    /// f_s itself, as BRDF Explorer's `BRDF`.
    F,
    /// f_s times N.L with the function's own cosine, as an engine's light loop returns it.
    FNoL,
}

impl Returns {
    pub fn parse(text: &str) -> Option<Returns> {
        match text {
            "f" => Some(Returns::F),
            "f_nol" => Some(Returns::FNoL),
            _ => None,
        }
    }

    pub fn text(self) -> &'static str {
        match self {
            Returns::F => "f",
            Returns::FNoL => "f_nol",
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct FileParam {
    pub name: String,
    pub kind: FileParamKind,
    /// The 1-based file line that declares it.
    pub line: usize,
}

/// A parameter's type and default. MIN and MAX are BRDF Explorer's slider bounds, not physical limits.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FileParamKind {
    Float { min: f64, max: f64, default: f64 },
    Bool { default: bool },
    Color { default: [f64; 3] },
}

/// The shader section with the file's global names and parameters renamed (`BrdfFile::renamed_shader`).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct RenamedShader {
    /// The shader's lines, one for one with `BrdfFile::shader` (same file line numbers).
    pub lines: Vec<(usize, String)>,
    /// What every renamed name starts with.
    pub prefix: String,
    /// The original names that were renamed: the parameters, then the shader's globals, in declaration order.
    pub renamed: Vec<String>,
    /// `renamed` as a set, for `original_names`.
    lookup: HashSet<String>,
    /// The non-`const` globals' initialisers, as assignments in the renamed names, with the parameters each
    /// reads (`inits`): the composition runs those that read a bound parameter again after the bindings.
    pub initialisers: Vec<Initialiser>,
}

/// Reads and parses `path`.
pub fn load(path: &Path) -> Result<BrdfFile> {
    load_with(path, &[])
}

/// Reads and parses `path`, its shader preprocessed under `defines` (as `BrdfFile::with_defines`), in one pass:
/// a file whose own defaults do not preprocess (an `#error` unless a macro is given) is read with its macros.
pub fn load_with(path: &Path, defines: &[(String, String)]) -> Result<BrdfFile> {
    load_shader(path, defines, &Includes::default(), HlslFrontEnd::Auto)
}

/// Reads and parses `path`: a `.brdf` file, or a plain HLSL or WGSL shader file (`.hlsl`, `.hlsli`, `.ush`,
/// `.usf`, `.wgsl`: a shader section without parameters), its includes or imports found through `includes`.
/// `front` chooses the front end of an HLSL shader.
pub fn load_shader(
    path: &Path,
    defines: &[(String, String)],
    includes: &Includes,
    front: HlslFrontEnd,
) -> Result<BrdfFile> {
    let bytes = crate::io::read_input(path)?;
    let plain = path.extension().and_then(|e| Language::of_extension(&e.to_string_lossy()));
    let mut file = match plain {
        Some(language) => empty(path, &bytes, language),
        None => read_brdf(path, &bytes)?,
    };
    if plain.is_some() {
        file.source = split_lines(text_of(path, &bytes)?).enumerate().map(|(i, l)| (i + 1, l.to_string())).collect();
        file.shader_begin = 1;
    }
    file.includes = includes.clone();
    file.hlsl_front_end = front;
    file.set_defines(defines)?;
    file.prepare_shader()?;
    Ok(file)
}

/// Parses a `.brdf` file's bytes; `path` is how messages name it.
pub fn parse(path: &Path, bytes: &[u8]) -> Result<BrdfFile> {
    parse_with(path, bytes, &[])
}

/// `parse`, the shader preprocessed under `defines`.
pub fn parse_with(path: &Path, bytes: &[u8], defines: &[(String, String)]) -> Result<BrdfFile> {
    let mut file = read_brdf(path, bytes)?;
    file.set_defines(defines)?;
    file.prepare_shader()?;
    Ok(file)
}

/// A `.brdf` file's sections, its shader not yet prepared.
fn read_brdf(path: &Path, bytes: &[u8]) -> Result<BrdfFile> {
    let text = text_of(path, bytes)?;
    let mut lines = split_lines(text);
    check_kind(path, lines.next().unwrap_or(""))?;
    let mut file = empty(path, bytes, Language::Glsl);
    let shader_begin = read_sections(&mut file, lines)?;
    file.shader_begin =
        shader_begin.ok_or_else(|| anyhow!(at(path, 1, "no shader section (`::begin shader` ... `::end shader`)")))?;
    file.format_warnings = std::mem::take(&mut file.warnings);
    Ok(file)
}

/// A file of `language` with nothing read yet.
fn empty(path: &Path, bytes: &[u8], language: Language) -> BrdfFile {
    BrdfFile {
        path: path.to_path_buf(),
        name: path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_default(),
        params: Vec::new(),
        source: Vec::new(),
        defines: Vec::new(),
        language,
        includes: Includes::default(),
        hlsl_front_end: HlslFrontEnd::Auto,
        front_end: None,
        shader: Vec::new(),
        front_end_origins: Vec::new(),
        shader_begin: 0,
        entries: Vec::new(),
        defines_brdf: false,
        roughness_domain: None,
        nov_domain: None,
        nol_domain: None,
        reference: None,
        binds: Vec::new(),
        has_is_func: false,
        warnings: Vec::new(),
        format_warnings: Vec::new(),
        hash: hex(&Sha256::digest(bytes)),
        prefix: String::new(),
        loops: Vec::new(),
        renamed: RenamedShader::default(),
    }
}

impl BrdfFile {
    /// Whether the shader reaches the kernels through a front end's translation (HLSL, Slang, WGSL, and GLSL
    /// that includes files), not as written.
    pub fn translated(&self) -> bool {
        self.language != Language::Glsl || includes_files(&self.source)
    }

    /// The text of line `line` of the GLSL an HLSL or WGSL shader's front end wrote (`shader`, numbered as the
    /// composed kernel's `#line` directive names it: `directive_name`), where `file` is that name as a compiler
    /// reported it (perhaps made absolute or relative to the working directory); None for a GLSL shader, whose
    /// file can be read.
    /// The user's file, line and text line `line` of the front end's GLSL (named `file` by a compiler) came from,
    /// where the front end's line information says (HLSL through glslang).
    pub fn front_end_origin(&self, file: &str, line: u32) -> Option<&(String, usize, String)> {
        self.front_end_line(file, line)?;
        self.front_end_origins.get((line as usize).checked_sub(1)?)?.as_deref()
    }

    pub fn front_end_line(&self, file: &str, line: u32) -> Option<&str> {
        // Named as the directive gave it, or read back from it (`io::from_directive_name`).
        let same = [self.directive_name(), crate::io::from_directive_name(&self.directive_name())]
            .iter()
            .any(|name| file == name || name.ends_with(file) || file.ends_with(name.as_str()));
        if !self.translated() || !same {
            return None;
        }
        self.shader.iter().find(|(n, _)| *n == line as usize).map(|(_, text)| text.trim())
    }

    /// Whether the shader, as the kernels compose it (an HLSL or WGSL one after its front end), computes in half
    /// precision (`float16_t`, `f16vec*`, `f16mat*`: WGSL's `enable f16`, GLSL's explicit 16-bit types), which a
    /// device without shaderFloat16 cannot run.
    pub fn uses_float16(&self) -> bool {
        self.uses_word(|w| w == "float16_t" || w.starts_with("f16vec") || w.starts_with("f16mat"))
    }

    /// Whether the shader, as the kernels compose it, computes in double precision (`double`, `dvec*`,
    /// `dmat*`, `float64_t`, `f64vec*`, `f64mat*`), which a device without shaderFloat64 cannot run (Mesa's
    /// Turnip and PanVK crash compiling it rather than refuse it).
    pub fn uses_float64(&self) -> bool {
        self.uses_word(|w| {
            w == "double"
                || w == "float64_t"
                || ["dvec", "dmat", "f64vec", "f64mat"]
                    .iter()
                    .any(|p| w.strip_prefix(p).is_some_and(|d| d.starts_with(['2', '3', '4'])))
        })
    }

    fn uses_word(&self, is: impl Fn(&str) -> bool) -> bool {
        self.shader.iter().any(|(_, line)| line.split(|c: char| !(c.is_ascii_alphanumeric() || c == '_')).any(&is))
    }

    /// The same file with its shader preprocessed under `defines` (`NAME`, `VALUE`; an empty value defines
    /// NAME as glslang's `-DNAME` does).
    pub fn with_defines(&self, defines: &[(String, String)]) -> Result<BrdfFile> {
        self.with_options(defines, &self.includes, self.hlsl_front_end)
    }

    /// The same file with its shader prepared again under `defines`, `includes` and HLSL front end `front`.
    pub fn with_options(
        &self,
        defines: &[(String, String)],
        includes: &Includes,
        front: HlslFrontEnd,
    ) -> Result<BrdfFile> {
        let mut file = self.clone();
        file.includes = includes.clone();
        file.hlsl_front_end = front;
        file.set_defines(defines)?;
        file.prepare_shader()?;
        Ok(file)
    }

    /// `defines`, refused where one is named like a parameter or takes a name of brdfprof's own (`brdfprof_`,
    /// in any case: the front ends' stub, glue and arguments, the includes' `BRDFPROF_ONCE_` guards).
    fn set_defines(&mut self, defines: &[(String, String)]) -> Result<()> {
        for (name, _) in defines {
            if name.to_ascii_lowercase().starts_with(crate::model::front::GENERATED_PREFIX) {
                bail!(
                    "{}: `define={name}`: names starting with `{}` (in any case) are brdfprof's own (the functions and guards it writes into the shader); give the macro another name",
                    self.path.display(),
                    crate::model::front::GENERATED_PREFIX
                );
            }
            if let Some(p) = self.params.iter().find(|p| &p.name == name) {
                bail!(
                    "{}: `define={name}`: `{name}` is the file's parameter (line {}); a macro of that name would replace it in the shader",
                    self.path.display(),
                    p.line
                );
            }
        }
        self.defines = defines.to_vec();
        Ok(())
    }

    /// Preprocesses `source` into `shader` and reads what the shader declares; the warnings are the format's,
    /// then the shader's.
    fn prepare_shader(&mut self) -> Result<()> {
        self.warnings = self.format_warnings.clone();
        self.shader = match self.language {
            Language::Glsl if !includes_files(&self.source) => preprocess(&self.path, &self.source, &self.defines)?,
            // The translation's GLSL through the same preprocessor (spirv-cross writes macros for control-flow
            // attributes); the user's defines were the front end's.
            _ => {
                let glsl = foreign::translate(self)?;
                preprocess(&self.path, &glsl, &[])?
            }
        };
        // Tokens and globals once: the checks, the loops and the renaming all read them.
        let tokens = tokenize(&self.path, &self.shader)?;
        let scan = scan_globals(&self.path, &self.shader, &tokens)?;
        check_shader(self, self.shader_begin, &tokens, &scan)?;
        self.prefix = self.choose_prefix();
        self.renamed = self.rename(&tokens, &scan);
        self.renamed.initialisers = inits::initialisers(self, &tokens)?;
        Ok(())
    }
}

/// `FILE:LINE: message`, the form of every error and warning.
fn at(path: &Path, line: usize, message: impl Display) -> String {
    format!("{}:{line}: {message}", path.display())
}

fn hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

impl FileParam {
    /// The GLSL type BRDF Explorer declares it with.
    pub fn glsl_type(&self) -> &'static str {
        match self.kind {
            FileParamKind::Float { .. } => "float",
            FileParamKind::Bool { .. } => "bool",
            FileParamKind::Color { .. } => "vec3",
        }
    }

    /// Its default as a GLSL constant expression (`0.5`, `true`, `vec3(0.04, 0.04, 0.04)`).
    pub fn default_glsl(&self) -> String {
        match self.kind {
            FileParamKind::Float { default, .. } => glsl_float(default),
            FileParamKind::Bool { default } => default.to_string(),
            FileParamKind::Color { default: [r, g, b] } => {
                format!("vec3({}, {}, {})", glsl_float(r), glsl_float(g), glsl_float(b))
            }
        }
    }
}

/// A finite f64 as a GLSL float literal (Rust's shortest round-trip form has a `.` or an exponent).
pub fn glsl_float(x: f64) -> String {
    format!("{x:?}")
}
