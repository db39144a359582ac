//! A user's `.brdf` file as a model: its parameters bound to values or to the kernels' inputs, and its shader
//! composed into brdfprof's own kernels (eval, shade, albedo, scene) and compiled with glslang at run time.
//!
//! Composition: the composed source is the kernel's own GLSL (`glsl/<kind>.comp`, unchanged) with, before it,
//! `#define BRDF_FILE`, the file's parameters as GLSL globals and the file's renamed shader (`brdf_file`).
//! Under `BRDF_FILE`, `specular_brdf_unit` (glsl/brdf.glsl), which every kernel calls for f_s, sets the bound
//! parameters from its inputs and returns the file's `BRDF(L, V, N, X, Y)` as is; the kernels set the tangent
//! and the material the binding reads. A parameter bound to a value is a `const`, which the compiler folds as
//! it folds a built-in model's specialisation constants, so the timed loop holds the file's code and nothing
//! else. The SPIR-V is cached in memory and on disk (`crate::cache`), keyed by everything that reaches glslang:
//! the composed source (so the file's content), every file of the GLSL tree it includes, defines, flags,
//! glslang's and brdfprof's versions.

use super::KernelKind;
use super::brdf_file::{self, BrdfFile, FileParam, FileParamKind, HlslFrontEnd, Includes, Returns, glsl_float};
use crate::shaders::{self, Shaders, Spirv};
use anyhow::{Context, Result, anyhow, bail};
use glam::DVec3;
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex, OnceLock};

/// The inputs a parameter can be bound to (`--param NAME=@INPUT`), per pixel or per sample.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Input {
    /// Perceptual roughness r, as the G-buffer, the sample set and scene materials hold it.
    Roughness,
    /// r^2, the microfacet alpha of the built-in models.
    Alpha,
    /// The specular reflectance at normal incidence.
    F0,
    /// The base colour (where only F0 is known, as in `eval` and the albedo grid: F0).
    BaseColor,
    /// Metalness (where only F0 is known: 1, so that base colour = F0 is consistent).
    Metallic,
}

impl Input {
    pub const ALL: [Input; 5] = [Input::Roughness, Input::Alpha, Input::F0, Input::BaseColor, Input::Metallic];

    pub fn name(self) -> &'static str {
        match self {
            Input::Roughness => "roughness",
            Input::Alpha => "alpha",
            Input::F0 => "f0",
            Input::BaseColor => "basecolor",
            Input::Metallic => "metallic",
        }
    }

    fn is_colour(self) -> bool {
        matches!(self, Input::F0 | Input::BaseColor)
    }

    /// The input as a GLSL expression in `specular_brdf_unit`'s scope (`roughness`, `f0`) and the globals the
    /// kernels set (`file_basecolor`, `file_metallic`).
    fn glsl(self) -> &'static str {
        match self {
            Input::Roughness => "roughness",
            Input::Alpha => "(roughness * roughness)",
            Input::F0 => "f0",
            Input::BaseColor => "file_basecolor",
            Input::Metallic => "file_metallic",
        }
    }

    /// The input converted to a parameter of type `kind`: a colour to a float is the mean of its channels, a
    /// float to a colour is grey. Bools cannot be bound.
    fn glsl_as(self, kind: &FileParamKind) -> Option<String> {
        let e = self.glsl();
        match (kind, self.is_colour()) {
            (FileParamKind::Float { .. }, false) | (FileParamKind::Color { .. }, true) => Some(e.to_string()),
            (FileParamKind::Float { .. }, true) => Some(format!("dot({e}, vec3(1.0 / 3.0))")),
            (FileParamKind::Color { .. }, false) => Some(format!("vec3({e})")),
            (FileParamKind::Bool { .. }, _) => None,
        }
    }
}

/// A parameter's value.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Value {
    Float(f64),
    Bool(bool),
    Color([f64; 3]),
}

impl Value {
    fn glsl(&self) -> String {
        match *self {
            Value::Float(x) => glsl_float(x),
            Value::Bool(b) => b.to_string(),
            Value::Color([r, g, b]) => format!("vec3({}, {}, {})", glsl_float(r), glsl_float(g), glsl_float(b)),
        }
    }

    /// As `--param` takes it: `0.5`, `1`, `0.9,0.6,0.3`.
    pub fn text(&self) -> String {
        match *self {
            Value::Float(x) => format!("{x}"),
            Value::Bool(b) => (b as u8).to_string(),
            Value::Color([r, g, b]) => format!("{r},{g},{b}"),
        }
    }

    /// The value as floats, as a per-row column holds it (a bool as 0 or 1).
    pub fn floats(&self) -> Vec<f32> {
        match *self {
            Value::Float(x) => vec![x as f32],
            Value::Bool(b) => vec![b as u8 as f32],
            Value::Color(c) => c.iter().map(|&x| x as f32).collect(),
        }
    }
}

/// Where a parameter's value comes from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Binding {
    /// A constant: the file's default or a `--param` value.
    Value(Value),
    /// A kernel input, per pixel or per sample.
    Input(Input),
    /// Per eval row, from the CSV column(s) named like the parameter: the float at this offset of the row's
    /// extra values.
    Row(usize),
}

/// A `.brdf` file with a binding for each of its parameters.
#[derive(Clone, Debug, PartialEq)]
pub struct FileModel {
    pub file: BrdfFile,
    /// The path as the user wrote it (names and messages use it).
    pub path: String,
    /// One per `file.params`, in order.
    pub bindings: Vec<Binding>,
    /// Its `name=` label (`Model::label`), when one was given.
    pub label: Option<String>,
    /// `entry=NAME`: a declared entry other than the file's default (`FileModel::entry`).
    pub entry: Option<String>,
    /// `returns=f|f_nol`: overrides what the entry's declaration says it returns.
    pub returns: Option<Returns>,
    /// Each parameter's default binding (`bind` in the file, else its value): what names leave out.
    pub defaults: Vec<Binding>,
    /// `loop-passes=N` (`LOOP_PASSES`).
    pub loop_passes: Option<u32>,
}

/// The function the kernels call for f_s: `BRDF`, or a declared entry (`entry NAME(ARG, ...)` in the file).
#[derive(Clone, Debug, PartialEq)]
pub struct ChosenEntry<'a> {
    /// None: BRDF Explorer's `BRDF(L, V, N, X, Y)`.
    pub declared: Option<&'a brdf_file::Entry>,
    pub returns: Returns,
}

impl FileParam {
    /// Parses a `--param` value for this parameter: a number, 0/1, `r,g,b`, or `@INPUT`.
    fn parse_binding(&self, file: &str, text: &str) -> Result<Binding> {
        let text = text.trim();
        let fail = |why: String| {
            anyhow!("{file}: parameter `{}` ({} at line {}): {why}", self.name, self.kind_name(), self.line)
        };
        if let Some(input) = text.strip_prefix('@') {
            let i = Input::ALL.iter().copied().find(|i| i.name() == input).ok_or_else(|| {
                fail(format!(
                    "unknown input `@{input}`; inputs are {}",
                    Input::ALL.iter().map(|i| format!("@{}", i.name())).collect::<Vec<_>>().join(", ")
                ))
            })?;
            if i.glsl_as(&self.kind).is_none() {
                return Err(fail(format!("a bool cannot be bound to `@{input}`")));
            }
            return Ok(Binding::Input(i));
        }
        let number = |t: &str| -> Result<f64> {
            let x: f64 = t.trim().parse().map_err(|_| fail(format!("`{t}` is not a number")))?;
            if !x.is_finite() {
                return Err(fail(format!("`{t}` is not finite")));
            }
            if x.abs() > f64::from(f32::MAX) {
                return Err(fail(format!(
                    "`{t}` is beyond fp32's range (at most {:e} in magnitude), in which the kernels compute",
                    f32::MAX
                )));
            }
            Ok(x)
        };
        let value = match self.kind {
            FileParamKind::Float { .. } => Value::Float(number(text)?),
            FileParamKind::Bool { .. } => match text {
                "0" | "false" => Value::Bool(false),
                "1" | "true" => Value::Bool(true),
                _ => return Err(fail(format!("`{text}`: a bool is 0 or 1"))),
            },
            FileParamKind::Color { .. } => {
                let parts: Vec<&str> = text.split(',').collect();
                let [r, g, b] = parts.as_slice() else {
                    return Err(fail(format!("`{text}`: a colour is r,g,b")));
                };
                Value::Color([number(r)?, number(g)?, number(b)?])
            }
        };
        if let (FileParamKind::Float { min, max, .. }, Value::Float(x)) = (self.kind, value) {
            if !(min..=max).contains(&x) {
                crate::messages::input_warning(format!(
                    "{file}: {} = {x} is outside the file's range [{min}, {max}] (BRDF Explorer's slider bounds); used as given",
                    self.name
                ));
            }
        }
        Ok(Binding::Value(value))
    }

    fn kind_name(&self) -> &'static str {
        match self.kind {
            FileParamKind::Float { .. } => "float",
            FileParamKind::Bool { .. } => "bool",
            FileParamKind::Color { .. } => "color",
        }
    }

    pub fn default_value(&self) -> Value {
        match self.kind {
            FileParamKind::Float { default, .. } => Value::Float(default),
            FileParamKind::Bool { default } => Value::Bool(default),
            FileParamKind::Color { default } => Value::Color(default),
        }
    }

    /// The eval CSV columns that set it per row: its name, or NAMEr, NAMEg, NAMEb for a colour (as f0r,f0g,f0b).
    pub fn columns(&self) -> Vec<String> {
        match self.kind {
            FileParamKind::Color { .. } => ["r", "g", "b"].iter().map(|c| format!("{}{c}", self.name)).collect(),
            _ => vec![self.name.clone()],
        }
    }
}

/// Each parameter's default: its `bind NAME=@INPUT` in the file's `brdfprof` section, else its value.
fn default_bindings(file: &BrdfFile, path: &str) -> Result<Vec<Binding>> {
    file.params
        .iter()
        .map(|p| match file.binds.iter().find(|(name, _, _)| name == &p.name) {
            Some((_, input, line)) => {
                p.parse_binding(path, input).map_err(|e| anyhow!("{}:{line}: `bind`: {e:#}", file.path.display()))
            }
            None => Ok(Binding::Value(p.default_value())),
        })
        .collect()
}

/// A model text's shader file path (`.brdf`, or a plain HLSL or WGSL file: `front::FILE_EXTENSIONS`) and the
/// `NAME=VALUE` fields after it. The path ends at such an extension followed by a comma or the end (so a path
/// may hold commas: `a,b/m.brdf,k=1`): the first such whose file exists (relative to `base`), else the first
/// such. None when the text names no shader file (a spec never does).
pub fn split_path<'a>(text: &'a str, base: &Path) -> Option<(&'a str, Vec<&'a str>)> {
    let lower = text.to_ascii_lowercase();
    let mut ends: Vec<usize> = crate::model::front::FILE_EXTENSIONS
        .iter()
        .flat_map(|ext| lower.match_indices(&format!(".{ext}")).map(|(i, m)| i + m.len()).collect::<Vec<_>>())
        .filter(|&e| e == text.len() || text.as_bytes()[e] == b',')
        .collect();
    ends.sort_unstable();
    let end =
        ends.iter().copied().find(|&e| base.join(text[..e].trim()).is_file()).or_else(|| ends.first().copied())?;
    let fields = text[end..].strip_prefix(',').map(|r| r.split(',').collect()).unwrap_or_default();
    Some((text[..end].trim(), fields))
}

/// Whether a model text names a `.brdf` file (`split_path`).
pub fn names_a_file(text: &str) -> bool {
    split_path(text, Path::new("")).is_some()
}

/// What a loop of a file means on lavapipe, which ends every loop after `LAVAPIPE_LOOP_LIMIT` iterations
/// without a word: within it, beyond it, or not known from the source.
fn loop_warning(path: &str, l: &brdf_file::Loop) -> String {
    let limit = brdf_file::LAVAPIPE_LOOP_LIMIT;
    let head = format!("{}:{}: a `{}` loop", l.file.as_deref().unwrap_or(path), l.line, l.keyword);
    match l.trip_count {
        Some(n) if n <= limit => {
            format!("{head} of {n} iterations: within the {limit} iterations after which lavapipe ends every loop")
        }
        Some(n) => format!(
            "{head} of {n} iterations: lavapipe ends every loop after {limit} iterations, so its results there are wrong (other drivers run it to the end)"
        ),
        None => format!(
            "{head} whose iterations brdfprof cannot bound from the source: lavapipe ends every loop after {limit} iterations without a word, so a longer loop gives wrong results there"
        ),
    }
}

/// The key of a macro for the file's shader in a model text (`my.brdf,define=QUALITY=1`), as `--define`
/// gives one to every file and a scene material's `define` does.
pub const DEFINE: &str = "define";

/// The keys of a model text that choose the entry (`entry=NAME`) and say what it returns (`returns=f|f_nol`).
pub const ENTRY: &str = "entry";
pub const RETURNS: &str = "returns";

/// The keys of a model text that add an include directory (`include=DIR`, as `--include-dir`) and map a
/// virtual include prefix to a directory (`include-map=VIRTUAL=DIR`, as `--include-map`), for an HLSL shader's
/// `#include` and a WGSL shader's `#import`.
pub const INCLUDE: &str = "include";
pub const INCLUDE_MAP: &str = "include-map";
/// `include-override=NAME=FILE` (as `--include-override`): FILE wherever NAME would be included.
pub const INCLUDE_OVERRIDE: &str = "include-override";

/// The key of a model text that chooses an HLSL shader's front end (`hlsl-front-end=auto|glslang|slang`, as
/// `--hlsl-front-end`).
pub const HLSL_FRONT_END: &str = HlslFrontEnd::KEY;

/// `loop-passes=N`: every loop of the file's shader runs N header passes per entry, a pass counter in place of its
/// exit tests (`spirv::loops`): the kernel compiled for its cost at that trip count, its results not the file's.
/// `targets::trips` prices a model's loops from two such compiles.
pub const LOOP_PASSES: &str = "loop-passes";
/// spirv-opt's `--loop-unroll` writes out no loop of a single pass (none of a `for` loop's iterations).
const MIN_LOOP_PASSES: u32 = 2;
/// Every pass is a copy of the loop's body in the compiled kernel.
const MAX_LOOP_PASSES: u32 = 256;

/// The keys of a model text brdfprof reads itself (no parameter may take one's name).
const KEYS: [&str; 8] = [DEFINE, ENTRY, RETURNS, INCLUDE, INCLUDE_MAP, INCLUDE_OVERRIDE, HLSL_FRONT_END, LOOP_PASSES];

/// The entry and its parameters as BRDF Explorer's files name them: no macro may take these names.
const ENTRY_NAMES: [&str; 6] = ["BRDF", "L", "V", "N", "X", "Y"];

fn is_define(item: &str) -> bool {
    item.split_once('=').is_some_and(|(k, _)| k.trim() == DEFINE)
}

/// A `define=`, `include=`, `include-map=` or `hlsl-front-end=` item: what prepares the shader.
fn is_shader_option(item: &str) -> bool {
    item.split_once('=')
        .is_some_and(|(k, _)| [DEFINE, INCLUDE, INCLUDE_MAP, INCLUDE_OVERRIDE, HLSL_FRONT_END].contains(&k.trim()))
}

/// The HLSL front end `hlsl-front-end=` items choose over `old`: one choice given twice is one, two different
/// ones are refused, naming both.
fn front_end_option(path: &str, old: HlslFrontEnd, items: &[String]) -> Result<HlslFrontEnd> {
    let mut chosen: Option<(HlslFrontEnd, &String)> = None;
    for item in items {
        let value = item.split_once('=').map_or("", |(_, v)| v.trim());
        let front = HlslFrontEnd::parse(value)
            .ok_or_else(|| anyhow!("{path}: `{item}`: expected {HLSL_FRONT_END}={}", HlslFrontEnd::NAMES.join("|")))?;
        if let Some((first, first_item)) = chosen
            && first != front
        {
            bail!("{path}: `{first_item}` and `{item}` choose two HLSL front ends; give one");
        }
        chosen = Some((front, item));
    }
    Ok(chosen.map_or(old, |(f, _)| f))
}

/// `include=DIR` and `include-map=VIRTUAL=DIR` items over `old`: a directory given again is not repeated, a
/// virtual prefix of `old` mapped again takes the new directory, and one prefix mapped to two directories by
/// `items` themselves is refused, naming both (neither would be chosen silently). Each directory must exist.
fn merge_includes(path: &str, old: &Includes, items: &[String]) -> Result<Includes> {
    let mut out = old.clone();
    let mut mapped: Vec<(&str, &str, &String)> = Vec::new();
    for item in items {
        let (key, value) = item.split_once('=').map(|(k, v)| (k.trim(), v.trim())).unwrap_or((item, ""));
        if key == INCLUDE_OVERRIDE {
            let Some((name, file)) = value
                .split_once('=')
                .map(|(n, f)| (n.trim(), f.trim()))
                .filter(|(n, f)| !n.is_empty() && !f.is_empty())
            else {
                bail!("{path}: `{item}`: expected {INCLUDE_OVERRIDE}=NAME=FILE");
            };
            if !Path::new(file).is_file() {
                bail!("{path}: `{item}`: {file} is not a file");
            }
            match out.overrides.iter_mut().find(|(n, _)| n == name) {
                Some(slot) => slot.1 = PathBuf::from(file),
                None => out.overrides.push((name.to_string(), PathBuf::from(file))),
            }
            continue;
        }
        let (virtual_prefix, dir) = match key {
            INCLUDE_MAP => value.split_once('=').map(|(v, d)| (Some(v.trim()), d.trim())).unwrap_or((None, "")),
            _ => (None, value),
        };
        if dir.is_empty() || (key == INCLUDE_MAP && virtual_prefix.is_none_or(str::is_empty)) {
            bail!("{path}: `{item}`: expected {INCLUDE}=DIR or {INCLUDE_MAP}=VIRTUAL=DIR");
        }
        if !Path::new(dir).is_dir() {
            bail!("{path}: `{item}`: {dir} is not a directory");
        }
        if let Some(v) = virtual_prefix {
            let same = |p: &str| p.trim_end_matches('/') == v.trim_end_matches('/');
            if let Some((_, first_dir, first)) = mapped.iter().find(|(p, d, _)| same(p) && *d != dir) {
                bail!(
                    "{path}: `{first}` and `{item}` map one prefix to two directories ({first_dir}, {dir}); give it once"
                );
            }
            mapped.push((v, dir, item));
        }
        match virtual_prefix {
            Some(v) => match out.maps.iter_mut().find(|(m, _)| m == v) {
                Some(slot) => slot.1 = PathBuf::from(dir),
                None => out.maps.push((v.to_string(), PathBuf::from(dir))),
            },
            None if !out.dirs.iter().any(|d| d == Path::new(dir)) => out.dirs.push(PathBuf::from(dir)),
            None => {}
        }
    }
    Ok(out)
}

/// The file's shader options under `items` (`define=`, `include=`, `include-map=`, `hlsl-front-end=`) over the
/// file's own.
fn shader_options(
    path: &str,
    (defines, includes, front): (&[(String, String)], &Includes, HlslFrontEnd),
    items: &[String],
) -> Result<(Vec<(String, String)>, Includes, HlslFrontEnd)> {
    let is_front = |i: &String| i.split_once('=').is_some_and(|(k, _)| k.trim() == HLSL_FRONT_END);
    let (fronts, items): (Vec<String>, Vec<String>) = items.iter().cloned().partition(is_front);
    let (defs, incs): (Vec<String>, Vec<String>) = items.into_iter().partition(|i| is_define(i));
    Ok((
        merge_defines(path, defines, &defs)?,
        merge_includes(path, includes, &incs)?,
        front_end_option(path, front, &fronts)?,
    ))
}

/// `defines` (`define=NAME[=VALUE]` items) over `old`: a name given again replaces its value; a name given
/// twice in `defines` is an error, as a parameter is.
fn merge_defines(path: &str, old: &[(String, String)], defines: &[String]) -> Result<Vec<(String, String)>> {
    let mut out = old.to_vec();
    let mut given: Vec<String> = Vec::new();
    for item in defines {
        let macro_text = item.split_once('=').map_or("", |(_, v)| v.trim());
        let (name, value) = macro_text.split_once('=').map_or((macro_text, ""), |(n, v)| (n.trim(), v.trim()));
        if !brdf_file::is_identifier(name) || name.starts_with("GL_") || name.contains("__") {
            bail!(
                "{path}: `{item}`: expected define=NAME or define=NAME=VALUE with NAME an identifier (not GL_... and without `__`, which GLSL reserves)"
            );
        }
        if value.contains(['\n', '\r']) {
            bail!("{path}: `{item}`: a define's value is one line");
        }
        if value.ends_with('\\') {
            bail!(
                "{path}: `{item}`: the value ends with a backslash, which would continue the macro onto the shader's next line; drop it"
            );
        }
        if ENTRY_NAMES.contains(&name) {
            bail!(
                "{path}: `{item}`: `{name}` is a name of the entry `vec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y)`, which a macro of that name would rewrite; choose another macro name"
            );
        }
        if given.iter().any(|g| g == name) {
            bail!("{path}: `define={name}` is given twice; give each macro once");
        }
        given.push(name.to_string());
        match out.iter_mut().find(|(n, _)| n == name) {
            Some(slot) => slot.1 = value.to_string(),
            None => out.push((name.to_string(), value.to_string())),
        }
    }
    Ok(out)
}

/// `k=v` items of a model text after its path; a field without `=` continues the previous value (a colour's
/// `r,g,b`).
fn split_params(rest: &[&str]) -> Result<Vec<String>> {
    let mut out: Vec<String> = Vec::new();
    for field in rest {
        match (field.contains('='), out.last_mut()) {
            (true, _) => out.push(field.trim().to_string()),
            (false, Some(last)) => *last += &format!(",{}", field.trim()),
            (false, None) => bail!("`{field}`: expected NAME=VALUE after the file"),
        }
    }
    Ok(out)
}

impl FileModel {
    /// `PATH.brdf[,NAME=VALUE...]`: the file with its defaults, then the overrides.
    pub fn parse(text: &str) -> Result<Self> {
        let (path, fields) = split_path(text, Path::new("")).ok_or_else(|| {
            anyhow!("`{text}` names no model file (.{})", crate::model::front::FILE_EXTENSIONS.join(", ."))
        })?;
        let items = split_params(&fields)?;
        let (options, params): (Vec<String>, Vec<String>) = items.into_iter().partition(|i| is_shader_option(i));
        let (defines, includes, front) =
            shader_options(path, (&[], &Includes::default(), HlslFrontEnd::Auto), &options)?;
        let file = brdf_file::load_shader(Path::new(path), &defines, &includes, front)?;
        crate::model::front::record(path, file.language, file.front_end.as_deref());
        if file.has_is_func {
            crate::messages::input_note(format!(
                "{path}: its isFunc section (importance sampling) is ignored: brdfprof integrates with its own estimator"
            ));
        }
        if let Some(p) = file.params.iter().find(|p| KEYS.contains(&p.name.as_str())) {
            bail!(
                "{}:{}: a parameter cannot be called `{}`: `{}=` in a model spec is brdfprof's own key",
                file.path.display(),
                p.line,
                p.name,
                p.name
            );
        }
        let defaults = default_bindings(&file, path)?;
        let model = FileModel {
            file,
            path: path.to_string(),
            bindings: defaults.clone(),
            label: None,
            entry: None,
            returns: None,
            defaults,
            loop_passes: None,
        };
        model.warn_new(None);
        model.with_params(&params)
    }

    /// The entry the kernels call: `entry=NAME`'s, else the first declared, else `BRDF`; what it returns, as
    /// `returns=` or its declaration says.
    pub fn entry(&self) -> ChosenEntry<'_> {
        let declared = match &self.entry {
            Some(name) => self.file.entries.iter().find(|e| &e.name == name),
            None => self.file.entries.first(),
        };
        ChosenEntry { declared, returns: self.returns.or(declared.map(|e| e.returns)).unwrap_or(Returns::F) }
    }

    /// Whether the entry returns f_s N.L (`returns f_nol`): the kernels then take its value as f_s N.L, and
    /// `eval` divides it by N.L on the host.
    pub fn returns_f_nol(&self) -> bool {
        self.entry().returns == Returns::FNoL
    }

    /// Prints the file's warnings and loop warnings that `before` (the model it was made from) did not have.
    fn warn_new(&self, before: Option<&FileModel>) {
        // A loop within lavapipe's limit needs nothing done: said with --verbose only.
        let loops = |m: &FileModel| {
            m.file
                .loops
                .iter()
                .filter(|l| {
                    crate::messages::verbose() || l.trip_count.is_none_or(|n| n > brdf_file::LAVAPIPE_LOOP_LIMIT)
                })
                .map(|l| loop_warning(&m.path, l))
                .collect::<Vec<_>>()
        };
        let old: Vec<String> =
            before.map(|b| b.file.warnings.iter().cloned().chain(loops(b)).collect()).unwrap_or_default();
        let new: Vec<String> =
            self.file.warnings.iter().cloned().chain(loops(self)).filter(|w| !old.contains(w)).collect();
        for w in crate::messages::grouped(&new) {
            crate::messages::input_warning(w);
        }
    }

    pub fn takes_param(&self, name: &str) -> bool {
        KEYS.contains(&name) || self.file.params.iter().any(|p| p.name == name)
    }

    /// Applies `NAME=VALUE` overrides and `define=NAME[=VALUE]` macros (the shader then preprocessed again); an
    /// unknown name is an error naming the file and its parameters.
    pub fn with_params(&self, params: &[String]) -> Result<Self> {
        let mut m = self.clone();
        let (options, params): (Vec<&String>, Vec<&String>) = params.iter().partition(|i| is_shader_option(i));
        if !options.is_empty() {
            let options: Vec<String> = options.into_iter().cloned().collect();
            let old = (self.file.defines.as_slice(), &self.file.includes, self.file.hlsl_front_end);
            let (defines, includes, front) = shader_options(&self.path, old, &options)?;
            m.file = self.file.with_options(&defines, &includes, front)?;
            m.warn_new(Some(self));
        }
        let mut given: Vec<&str> = Vec::new();
        for p in &params {
            let (name, value) =
                p.split_once('=').ok_or_else(|| anyhow!("{}: `{p}`: expected NAME=VALUE", self.path))?;
            let name = name.trim();
            if given.contains(&name) {
                bail!(
                    "{}: `{name}` is given twice ({}); give each parameter once",
                    self.path,
                    params.iter().map(|p| p.as_str()).collect::<Vec<_>>().join(", ")
                );
            }
            given.push(name);
            if name == ENTRY {
                m.entry = Some(m.parse_entry(value.trim())?);
                continue;
            }
            if name == RETURNS {
                m.returns = Some(Returns::parse(value.trim()).ok_or_else(|| {
                    anyhow!("{}: `returns={}`: expected returns=f or returns=f_nol", self.path, value.trim())
                })?);
                continue;
            }
            if name == LOOP_PASSES {
                let n = value.trim().parse().ok().filter(|n| (MIN_LOOP_PASSES..=MAX_LOOP_PASSES).contains(n));
                m.loop_passes = Some(n.ok_or_else(|| {
                    anyhow!(
                        "{}: `{LOOP_PASSES}={}`: expected a whole number of passes, {MIN_LOOP_PASSES} to {MAX_LOOP_PASSES}",
                        self.path,
                        crate::messages::escape_line(value.trim())
                    )
                })?);
                continue;
            }
            let k = self.file.params.iter().position(|q| q.name == name).ok_or_else(|| {
                let known = self.file.params.iter().map(|q| q.name.as_str()).collect::<Vec<_>>();
                anyhow!(
                    "{}: no parameter `{name}` (the file's parameters: {})",
                    self.path,
                    if known.is_empty() { "none".to_string() } else { known.join(", ") }
                )
            })?;
            m.bindings[k] = self.file.params[k].parse_binding(&self.path, value)?;
        }
        Ok(m)
    }

    /// The same model with each parameter in `names` read per eval row (`Binding::Row`), at consecutive
    /// offsets in `names`' order; returns the model and the number of floats per row.
    pub fn with_rows(&self, names: &[&str]) -> (Self, usize) {
        let mut m = self.clone();
        let mut offset = 0;
        for name in names {
            if let Some(k) = self.file.params.iter().position(|p| p.name == *name) {
                m.bindings[k] = Binding::Row(offset);
                offset += self.file.params[k].columns().len();
            }
        }
        (m, offset)
    }

    /// `entry=NAME`: a declared entry, or `BRDF` where the file defines it; anything else is an error naming
    /// the declared ones.
    fn parse_entry(&self, name: &str) -> Result<String> {
        let declared: Vec<&str> = self.file.entries.iter().map(|e| e.name.as_str()).collect();
        if declared.contains(&name) || (name == "BRDF" && self.file.defines_brdf) {
            return Ok(name.to_string());
        }
        let known = declared
            .iter()
            .map(|d| d.to_string())
            .chain(self.file.defines_brdf.then(|| "BRDF".to_string()))
            .collect::<Vec<_>>();
        bail!(
            "{}: `entry={name}`: the file declares no such entry (its entries: {}; declare one as `entry NAME(ARG, ...) returns f|f_nol` in a `::begin brdfprof` section)",
            self.path,
            known.join(", ")
        )
    }

    /// The model text: the path, the shader options (`options`: the defines, the include directories and maps),
    /// the entry and what it returns, then the parameters (`all`: every one; else those that differ from the
    /// defaults).
    fn text_with(&self, all: bool, options: bool) -> String {
        let mut s = self.path.clone();
        if options {
            s += &self.define_items().iter().map(|d| format!(",{DEFINE}={d}")).collect::<String>();
            s += &self.file.includes.dirs.iter().map(|d| format!(",{INCLUDE}={}", d.display())).collect::<String>();
            s += &self
                .file
                .includes
                .maps
                .iter()
                .map(|(v, d)| format!(",{INCLUDE_MAP}={v}={}", d.display()))
                .collect::<String>();
            s += &self
                .file
                .includes
                .overrides
                .iter()
                .map(|(n, f)| format!(",{INCLUDE_OVERRIDE}={n}={}", f.display()))
                .collect::<String>();
        }
        let default_entry = self.file.entries.first().map_or("BRDF", |e| e.name.as_str());
        if let Some(e) = self.entry.as_ref().filter(|e| all || e.as_str() != default_entry) {
            s += &format!(",{ENTRY}={e}");
        }
        let declared = self.entry().declared.map_or(Returns::F, |e| e.returns);
        if let Some(r) = self.returns.filter(|r| all || *r != declared) {
            s += &format!(",{RETURNS}={}", r.text());
        }
        if let Some(n) = self.loop_passes {
            s += &format!(",{LOOP_PASSES}={n}");
        }
        for ((p, b), d) in self.file.params.iter().zip(&self.bindings).zip(&self.defaults) {
            let text = match b {
                Binding::Value(v) if all || b != d => v.text(),
                Binding::Input(i) if all || b != d => format!("@{}", i.name()),
                _ => continue,
            };
            s += &format!(",{}={text}", p.name);
        }
        s
    }

    /// The path with the overrides that differ from the file's defaults.
    pub fn name(&self) -> String {
        self.text_with(false, true)
    }

    /// `name` without the defines and the include directories and maps: what a default label adds after the
    /// file's stem (`labels::distinguish` adds the defines that tell models given together apart).
    pub fn name_for_label(&self) -> String {
        self.text_with(false, false)
    }

    /// Each define as `NAME` or `NAME=VALUE`.
    pub fn define_items(&self) -> Vec<String> {
        let item = |(n, v): &(String, String)| if v.is_empty() { n.clone() } else { format!("{n}={v}") };
        self.file.defines.iter().map(item).collect()
    }

    /// The path with every parameter.
    pub fn canonical(&self) -> String {
        self.text_with(true, true)
    }

    /// The parameters compiled in as constants (bound to a value, not to an input), as `NAME=VALUE`: a kernel
    /// costed with them is costed for those values, which its compiler may fold away.
    pub fn folded(&self) -> Vec<String> {
        self.file
            .params
            .iter()
            .zip(&self.bindings)
            .filter_map(
                |(p, b)| if let Binding::Value(v) = b { Some(format!("{}={}", p.name, v.text())) } else { None },
            )
            .collect()
    }

    /// The binding of parameter `name`.
    pub fn binding(&self, name: &str) -> Option<Binding> {
        self.file.params.iter().position(|p| p.name == name).map(|k| self.bindings[k])
    }

    /// The file's loops whose trip count brdfprof cannot read from the source (`for` with a bound that is not a
    /// literal, `while`, `do`): a compiler may keep them, and no cost rule counts a kept loop's iterations.
    pub fn uncounted_loops(&self) -> impl Iterator<Item = &crate::model::brdf_file::Loop> {
        self.file.loops.iter().filter(|l| l.trip_count.is_none())
    }

    /// The kernels' switches for the entry's form and the file's loops.
    fn shape_defines(&self, returns: Returns) -> String {
        let mut s = String::new();
        if returns == Returns::FNoL {
            s += "#define BRDF_FILE_RETURNS_F_NOL 1\n";
        }
        // A loop of unknown trip count: shade.glsl writes the light block out (a kept inner loop keeps the
        // light loop around it, which the cost rules would read as every light's work).
        if self.uncounted_loops().next().is_some() {
            s += "#define BRDF_FILE_KEEPS_LOOPS 1\n";
        }
        s
    }

    /// The source composed for `kind`: the preamble, the file, then the kernel's own source (from `glsl/`).
    fn compose(&self, kind: KernelKind, kernel_source: &str) -> Result<String> {
        let renamed = self.file.renamed_shader();
        let mut s =
            String::from("#version 450\n#extension GL_GOOGLE_include_directive : require\n#define BRDF_FILE 1\n");
        let mut bind = Vec::new();
        let mut rows = Vec::new();
        let mut row_floats = 0;
        for (p, b) in self.file.params.iter().zip(&self.bindings) {
            let g = self.file.glsl_name(&p.name);
            match b {
                Binding::Value(v) => s += &format!("const {} {g} = {};\n", p.glsl_type(), v.glsl()),
                Binding::Input(i) => {
                    s += &format!("{} {g};\n", p.glsl_type());
                    bind.push(format!("{g} = {};", i.glsl_as(&p.kind).expect("checked when bound")));
                }
                Binding::Row(offset) => {
                    if kind != KernelKind::Eval {
                        bail!("{}: `{}` is set per CSV row, which only eval reads", self.path, p.name);
                    }
                    s += &format!("{} {g};\n", p.glsl_type());
                    rows.push(row_assignment(&g, &p.kind, *offset));
                    row_floats = row_floats.max(offset + p.columns().len());
                }
            }
        }
        // A global initialiser that reads a parameter set per call or per row runs again once it is set
        // (brdf_file::inits): GLSL ran it at the start of `main`, before.
        let bound: Vec<&str> = self
            .file
            .params
            .iter()
            .zip(&self.bindings)
            .filter(|(_, b)| !matches!(b, Binding::Value(_)))
            .map(|(p, _)| p.name.as_str())
            .collect();
        bind.extend(
            renamed
                .initialisers
                .iter()
                .filter(|i| bound.iter().any(|b| i.reads.contains(*b)))
                .map(|i| i.assignment.clone()),
        );
        s += &format!("#define BRDF_FILE_BIND {}\n", bind.join(" "));
        s += &format!(
            "#define EVAL_STRIDE {}\n#define BRDF_FILE_ROWS(base) {}\n",
            4 + row_floats.div_ceil(4),
            rows.join(" ")
        );
        let entry = self.entry();
        let glue = entry.declared.map(|e| self.file.entry_glue(e));
        let function = glue.as_ref().map_or_else(|| self.file.glsl_name("BRDF"), |(name, _)| name.clone());
        s += &format!("#define BRDF_FILE_FUNCTION {function}\n");
        s += &self.shape_defines(entry.returns);
        s += &format!("{}\n{}", self.file.line_directive(), renamed.text());
        if let Some((_, text)) = &glue {
            s += text;
        }
        // The kernel's own text, numbered as in its file (its `#version` line dropped).
        let (first, body) = kernel_source.split_once('\n').unwrap_or(("", kernel_source));
        if !first.starts_with("#version") {
            bail!("{}.comp does not start with #version", kind.base());
        }
        s += &format!("#line 2 \"{}.comp\"\n{body}", kind.base());
        Ok(s)
    }

    /// The file's kernel of `kind`, composed with `shaders`' GLSL (the embedded tree or `--glsl DIR`) and
    /// compiled, or taken from the cache (in memory, then on disk: `crate::cache`), keyed by everything that
    /// reaches glslang (`cache_key`).
    pub fn kernel(&self, kind: KernelKind, shaders: &Shaders) -> Result<Spirv> {
        if matches!(kind, KernelKind::Terms | KernelKind::SceneTerms) {
            bail!("{}: a .brdf model is one function; it has no separate D, Vis and F terms", self.path);
        }
        let kernel_name = format!("{}_f32", kind.base());
        let tree = GlslTree::of(shaders);
        let (source_file, defines) = tree.entry(&kernel_name)?;
        let kernel_source = tree.read(Path::new(&source_file)).with_context(|| format!("cannot read {source_file}"))?;
        let composed = self.compose(kind, &kernel_source)?;
        let key = cache_key(&composed, &defines, &tree);
        let name = format!("{}:{}", self.path, kernel_name);
        if let Some(words) = memory_cache().lock().unwrap().get(&key).cloned() {
            return Ok(Spirv { name, words: self.with_loop_passes(kind, &words)?.into() });
        }
        let store = crate::cache::Store::open_default();
        let valid = |bytes: &[u8]| Spirv::from_bytes(&name, bytes).map(|_| ());
        let compile = || Ok(words_to_bytes(&self.compile(&tree, kind, &composed, &defines, &[])?));
        let bytes = crate::cache::get_or_build(store.as_ref(), SPIRV_KIND, &key, &name, valid, compile)?;
        let words: Arc<[u32]> = Spirv::from_bytes(&name, &bytes)?.words;
        memory_cache().lock().unwrap().insert(key, words.clone());
        Ok(Spirv { name, words: self.with_loop_passes(kind, &words)?.into() })
    }

    /// `words` with the loops at `loop-passes=`' count, where given, and but in the eval kernel (whose loop
    /// passes `targets::trips` counts as the model's) written out by spirv-opt's `--loop-unroll` (Mesa 22.3's
    /// Bifrost compiler keeps even a loop of 2 passes): every loop of the module is the file's (a file with such
    /// a loop has the light block written out), which the count of loops set checks.
    fn with_loop_passes(&self, kind: KernelKind, words: &[u32]) -> Result<Vec<u32>> {
        let Some(passes) = self.loop_passes else { return Ok(words.to_vec()) };
        let unroll = kind != KernelKind::Eval;
        let (words, set) = crate::spirv::loops::at_passes(words, passes, unroll)
            .with_context(|| format!("{}: {LOOP_PASSES}={passes}", self.path))?;
        if set != self.file.loops.len() {
            bail!(
                "{}: {LOOP_PASSES}={passes}: the kernel has {set} loops where the file has {}: only the file's own loops can be set",
                self.path,
                self.file.loops.len()
            );
        }
        if !unroll {
            return Ok(words);
        }
        let words = crate::spirv::spirv_opt(&words, &["--loop-unroll".to_string()])?;
        if crate::spirv::loops::count(&words)? > 0 {
            bail!(
                "{}: {LOOP_PASSES}={passes}: spirv-opt cannot write out the file's loops (it writes out a loop whose one exit is a test before its body: a `for` or `while` without `break`, `continue` or `return` in it, not a `do`)",
                self.path
            );
        }
        Ok(words)
    }

    /// The file's kernel of `kind` compiled again with glslang's line information (`-g`), never cached: what
    /// the C translation reads to name the file's line of a construct it cannot express.
    pub fn kernel_with_lines(&self, kind: KernelKind, shaders: &Shaders) -> Result<Spirv> {
        let kernel_name = format!("{}_f32", kind.base());
        let tree = GlslTree::of(shaders);
        let (source_file, defines) = tree.entry(&kernel_name)?;
        let kernel_source = tree.read(Path::new(&source_file)).with_context(|| format!("cannot read {source_file}"))?;
        let composed = self.compose(kind, &kernel_source)?;
        let words = crate::shaders::without_source_text(&self.compile(&tree, kind, &composed, &defines, &["-g"])?);
        Ok(Spirv { name: format!("{}:{kernel_name}", self.path), words: self.with_loop_passes(kind, &words)?.into() })
    }

    /// glslang on the composed source: written beside a copy of the embedded tree (or with `--glsl DIR` on the
    /// include path), so that the kernel's `#include "brdf.glsl"` resolves as in glsl/. Errors name the file's
    /// lines and its own identifiers.
    fn compile(
        &self,
        tree: &GlslTree,
        kind: KernelKind,
        composed: &str,
        defines: &[String],
        extra: &[&str],
    ) -> Result<Vec<u32>> {
        let dir =
            crate::cleanup::TempDir::new().context("cannot create a temporary directory for the composed kernel")?;
        let root = tree.materialise(&dir.path().join("glsl"))?;
        let src = dir.path().join("composed");
        std::fs::create_dir_all(&src).with_context(|| format!("cannot create {}", src.display()))?;
        let path = src.join(format!("{}.comp", kind.base()));
        std::fs::write(&path, composed).with_context(|| format!("cannot write {}", path.display()))?;
        let what = format!("{} ({} kernel, glslang)", self.path, kind.base());
        match shaders::glslang_with(&path, defines, &[&root], &what, extra) {
            Ok(words) => Ok(words),
            Err(e) => match e.downcast_ref::<shaders::GlslangError>() {
                Some(g) => {
                    let renamed = self.file.renamed_shader();
                    let log = self.file.remap_log(renamed, &g.log, |_| None);
                    let log = if log.trim().is_empty() { self.file.unlocated_log(renamed, &g.log) } else { log };
                    // The temporary directory means nothing to the user: the kernel's file and glsl/'s names do.
                    let mut log = log.replace(&format!("{}/", src.display()), "");
                    if root.starts_with(dir.path()) {
                        log = log.replace(&format!("{}/", root.display()), "glsl/");
                    }
                    bail!(
                        "{}: glslang cannot compile the file's shader into the {} kernel:\n{}",
                        self.path,
                        kind.base(),
                        log.trim_end()
                    )
                }
                None => Err(e),
            },
        }
    }
}

/// The cache's kind for SPIR-V entries (`<key>.spv`).
const SPIRV_KIND: &str = "spv";

fn words_to_bytes(words: &[u32]) -> Vec<u8> {
    words.iter().flat_map(|w| w.to_le_bytes()).collect()
}

/// The GLSL the kernels are composed with: the embedded tree (glsl/ as brdfprof was built) or `--glsl DIR`.
enum GlslTree {
    Embedded,
    Dir(PathBuf),
}

impl GlslTree {
    fn of(shaders: &Shaders) -> Self {
        match shaders.glsl_dir() {
            Some(dir) => GlslTree::Dir(dir.to_path_buf()),
            None => GlslTree::Embedded,
        }
    }

    /// The kernel's source file and defines, as kernels.txt lists them.
    fn entry(&self, name: &str) -> Result<(String, Vec<String>)> {
        match self {
            GlslTree::Embedded => {
                let k = shaders::embedded(name)?;
                Ok((k.source.to_string(), k.defines.iter().map(|d| d.to_string()).collect()))
            }
            GlslTree::Dir(root) => shaders::kernel_entry(root, name),
        }
    }

    /// The text of `rel` (a path relative to the tree's root, `..` resolved).
    fn read(&self, rel: &Path) -> Result<String> {
        match self {
            GlslTree::Embedded => {
                let rel = rel.to_string_lossy();
                shaders::GLSL_FILES
                    .iter()
                    .find(|(p, _)| *p == rel)
                    .map(|(_, t)| t.to_string())
                    .ok_or_else(|| anyhow!("the embedded glsl/ has no {rel}"))
            }
            GlslTree::Dir(root) => {
                let path = root.join(rel);
                String::from_utf8(crate::io::read_input(&path)?)
                    .map_err(|_| anyhow!("cannot read {}: not UTF-8 text", path.display()))
            }
        }
    }

    fn exists(&self, rel: &Path) -> bool {
        match self {
            GlslTree::Embedded => shaders::GLSL_FILES.iter().any(|(p, _)| Path::new(p) == rel),
            GlslTree::Dir(root) => root.join(rel).is_file(),
        }
    }

    /// A directory glslang can include from: the embedded tree written into `dir`, or `--glsl DIR` itself.
    fn materialise(&self, dir: &Path) -> Result<PathBuf> {
        match self {
            GlslTree::Embedded => {
                shaders::write_glsl_tree(dir)?;
                Ok(dir.to_path_buf())
            }
            GlslTree::Dir(root) => Ok(root.clone()),
        }
    }

    /// Every file the composed source includes, directly or not, with its content, as glslang resolves them
    /// (`#include "x"`: beside the including file, then the tree's root; `<x>`: the root), found by following
    /// every `#include` line whatever the conditionals around it (a superset of what one compilation reads).
    /// A name that resolves nowhere is recorded as missing.
    fn included(&self, composed: &str) -> Vec<(String, Option<String>)> {
        let mut out: Vec<(String, Option<String>)> = Vec::new();
        // The composed source sits outside the tree: its includes resolve from the root.
        let mut pending: Vec<(Option<PathBuf>, String)> =
            include_names(composed).into_iter().map(|n| (None, n)).collect();
        while let Some((from, name)) = pending.pop() {
            let beside = from.as_ref().and_then(|f| f.parent()).map(|d| normalise(&d.join(&name)));
            let found = beside
                .filter(|p| self.exists(p))
                .or_else(|| Some(normalise(Path::new(&name))).filter(|p| self.exists(p)));
            let shown = found.as_ref().map_or(format!("missing: {name}"), |p| p.display().to_string());
            if out.iter().any(|(s, _)| *s == shown) {
                continue;
            }
            let text = found.as_ref().and_then(|p| self.read(p).ok());
            if let (Some(p), Some(t)) = (&found, &text) {
                pending.extend(include_names(t).into_iter().map(|n| (Some(p.clone()), n)));
            }
            out.push((shown, text));
        }
        out.sort();
        out
    }
}

/// The names of a source's `#include "x"` and `#include <x>` lines.
fn include_names(source: &str) -> Vec<String> {
    source
        .lines()
        .filter_map(|l| l.trim_start().strip_prefix('#'))
        .filter_map(|l| l.trim_start().strip_prefix("include"))
        .filter_map(|l| {
            let l = l.trim();
            let (open, close) = match l.chars().next()? {
                '"' => ('"', '"'),
                '<' => ('<', '>'),
                _ => return None,
            };
            l.strip_prefix(open)?.split(close).next().map(str::to_string)
        })
        .collect()
}

/// `a/./b/../c` as `a/c` (lexically; the tree has no links that matter to its includes).
fn normalise(p: &Path) -> PathBuf {
    let mut out = PathBuf::new();
    for c in p.components() {
        match c {
            std::path::Component::CurDir => {}
            std::path::Component::ParentDir => {
                if !out.pop() {
                    out.push("..");
                }
            }
            other => out.push(other),
        }
    }
    out
}

fn glslang_version() -> String {
    static V: OnceLock<String> = OnceLock::new();
    V.get_or_init(|| shaders::glslang_version().unwrap_or_default()).clone()
}

/// Everything that reaches glslang for one kernel: brdfprof's version, glslang's version and flags, the
/// defines, the composed source (the file's renamed shader, its parameters and the kernel's own text) and
/// the content of every file it includes from the tree.
fn cache_key(composed: &str, defines: &[String], tree: &GlslTree) -> crate::cache::Key {
    let mut key = crate::cache::KeyBuilder::new(SPIRV_KIND)
        .part("brdfprof", env!("CARGO_PKG_VERSION"))
        .part("glslang", glslang_version())
        .part("flags", shaders::GLSLANG_FLAGS.join(" "))
        .part("defines", defines.join(" "))
        .part("composed", composed);
    for (file, text) in tree.included(composed) {
        key = key.part("include", file).part("content", text.as_deref().unwrap_or("\0missing"));
    }
    key.finish()
}

fn memory_cache() -> &'static Mutex<HashMap<crate::cache::Key, Arc<[u32]>>> {
    static CACHE: OnceLock<Mutex<HashMap<crate::cache::Key, Arc<[u32]>>>> = OnceLock::new();
    CACHE.get_or_init(Mutex::default)
}

/// X of the tangent frame, as the kernels compute it (`file_tangent_frame` in glsl/brdf.glsl): `t` made
/// orthogonal to the unit normal `n`, or, when `t` is zero or parallel to `n`, the first vector of the
/// branchless orthonormal basis of Duff et al. 2017 ("Building an Orthonormal Basis, Revisited", JCGT 6(1),
/// Listing 3). Y = N x X.
pub fn tangent_frame(n: DVec3, t: DVec3) -> DVec3 {
    let x = t - n * n.dot(t);
    if t.length_squared() > 0.0 && x.length_squared() > TANGENT_PARALLEL * t.length_squared() {
        return x.normalize();
    }
    let sign = if n.z >= 0.0 { 1.0 } else { -1.0 };
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    DVec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x)
}

/// |t - n (n.t)|^2 / |t|^2 below which a given tangent counts as parallel to N (sin^2 of 1e-3 rad): the
/// documented basis is used instead. The same constant is in glsl/brdf.glsl (a test reads both).
pub const TANGENT_PARALLEL: f64 = 1e-6;

/// The GLSL statement setting parameter `g` (of `kind`) from its columns of a CSV row, at float `offset` in the
/// row's `inputs[(base) + ..]` vec4s.
fn row_assignment(g: &str, kind: &FileParamKind, offset: usize) -> String {
    let at = |k: usize| format!("inputs[(base) + {}][{}]", (offset + k) / 4, (offset + k) % 4);
    match kind {
        FileParamKind::Float { .. } => format!("{g} = {};", at(0)),
        FileParamKind::Bool { .. } => format!("{g} = {} != 0.0;", at(0)),
        FileParamKind::Color { .. } => format!("{g} = vec3({}, {}, {});", at(0), at(1), at(2)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn file(dir: &Path) -> String {
        let path = dir.join("m.brdf");
        std::fs::write(&path, "analytic\n::begin parameters\nfloat r 0 1 0.5\ncolor c 0.1 0.2 0.3\nbool b 1\n::end parameters\n::begin shader\nvec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y) { return b ? c * r : vec3(0.0); }\n::end shader\n").unwrap();
        path.display().to_string()
    }

    #[test]
    fn model_text_round_trips_with_colours_and_bindings() {
        let dir = tempfile::tempdir().unwrap();
        let path = file(dir.path());
        let m = FileModel::parse(&format!("{path},c=0.9,0.6,0.3,r=@alpha")).unwrap();
        assert_eq!(m.binding("c"), Some(Binding::Value(Value::Color([0.9, 0.6, 0.3]))));
        assert_eq!(m.binding("r"), Some(Binding::Input(Input::Alpha)));
        assert_eq!(m.name(), format!("{path},r=@alpha,c=0.9,0.6,0.3"));
        assert_eq!(FileModel::parse(&m.canonical()).unwrap(), m);
        assert_eq!(FileModel::parse(&m.name()).unwrap(), m);
        assert_eq!(FileModel::parse(&path).unwrap().name(), path, "defaults are not repeated in the name");
        let e = format!("{:#}", FileModel::parse("m.txt,r=1").unwrap_err());
        assert!(e.contains("names no model file (.brdf, .hlsl, .hlsli, .ush, .usf, .slang, .wgsl)"), "{e}");
    }

    #[test]
    fn bad_bindings_are_refused_naming_the_parameter() {
        let dir = tempfile::tempdir().unwrap();
        let m = FileModel::parse(&file(dir.path())).unwrap();
        for (p, needle) in [
            ("b=@roughness", "a bool cannot be bound"),
            ("b=2", "a bool is 0 or 1"),
            ("c=1,2", "a colour is r,g,b"),
            ("r=nan", "is not finite"),
            ("r=x", "is not a number"),
            ("q=1", "no parameter `q`"),
            ("r", "expected NAME=VALUE"),
        ] {
            let e = format!("{:#}", m.with_params(&[p.to_string()]).unwrap_err());
            assert!(e.contains(needle) && e.contains("m.brdf"), "{p}: {e}");
        }
        assert_eq!(m.with_params(&["b=0".into()]).unwrap().binding("b"), Some(Binding::Value(Value::Bool(false))));
    }

    #[test]
    fn an_input_converts_to_the_parameter_type() {
        let float = FileParamKind::Float { min: 0.0, max: 1.0, default: 0.5 };
        let colour = FileParamKind::Color { default: [0.0; 3] };
        assert_eq!(Input::F0.glsl_as(&float).unwrap(), "dot(f0, vec3(1.0 / 3.0))");
        assert_eq!(Input::Roughness.glsl_as(&colour).unwrap(), "vec3(roughness)");
        assert_eq!(Input::Alpha.glsl_as(&float).unwrap(), "(roughness * roughness)");
    }

    #[test]
    fn the_tangent_rule_gives_an_orthonormal_frame() {
        for n in [DVec3::Z, -DVec3::Z, DVec3::new(0.6, 0.0, 0.8), DVec3::new(0.0, -0.6, -0.8)] {
            for t in [DVec3::ZERO, DVec3::X, n] {
                let x = tangent_frame(n, t);
                assert!(n.dot(x).abs() < 1e-12 && (x.length() - 1.0).abs() < 1e-12, "n {n:?} t {t:?}: x {x:?}");
            }
        }
        assert_eq!(tangent_frame(DVec3::Z, DVec3::ZERO), DVec3::X, "Duff et al.'s basis at the pole");
    }

    #[test]
    fn a_key_given_twice_and_values_beyond_fp32_are_refused() {
        let dir = tempfile::tempdir().unwrap();
        let path = file(dir.path());
        let e = format!("{:#}", FileModel::parse(&format!("{path},r=0.1,r=0.2")).unwrap_err());
        assert!(e.contains("`r` is given twice (r=0.1, r=0.2)"), "{e}");
        let m = FileModel::parse(&format!("{path},r=0.1")).unwrap();
        assert_eq!(
            m.with_params(&["r=0.3".into()]).unwrap().binding("r"),
            Some(Binding::Value(Value::Float(0.3))),
            "--param overrides the text"
        );
        for bad in ["r=1e39", "r=-3.5e38", "c=0,1e39,0"] {
            let e = format!("{:#}", m.with_params(&[bad.into()]).unwrap_err());
            assert!(e.contains("is beyond fp32's range"), "{bad}: {e}");
        }
    }

    #[test]
    fn a_path_may_hold_commas() {
        let dir = tempfile::tempdir().unwrap();
        let sub = dir.path().join("a,b.brdf,c");
        std::fs::create_dir(&sub).unwrap();
        let path = file(&sub);
        assert!(names_a_file(&path) && names_a_file(&format!("{path},r=0.25")) && !names_a_file("ggx,gamma=2"));
        let m = FileModel::parse(&format!("{path},r=0.25,c=1,0,0")).unwrap();
        assert_eq!((m.path.as_str(), m.binding("r")), (path.as_str(), Some(Binding::Value(Value::Float(0.25)))));
        assert_eq!(FileModel::parse(&m.name()).unwrap(), m, "its name reads back");
    }

    /// The key covers every file of the tree the kernel includes, and only those: an edit of brdf.glsl or of
    /// generated/ changes it, an edit of a file no kernel includes does not.
    #[test]
    fn the_cache_key_covers_every_included_file() {
        let dir = tempfile::tempdir().unwrap();
        let glsl = dir.path().join("glsl");
        shaders::write_glsl_tree(&glsl).unwrap();
        let m = FileModel::parse(&file(dir.path())).unwrap();
        let tree = GlslTree::Dir(glsl.clone());
        let key = || {
            let (source, defines) = tree.entry("eval_f32").unwrap();
            let composed = m.compose(KernelKind::Eval, &tree.read(Path::new(&source)).unwrap()).unwrap();
            cache_key(&composed, &defines, &tree)
        };
        let embedded = {
            let (source, defines) = GlslTree::Embedded.entry("eval_f32").unwrap();
            let composed = m.compose(KernelKind::Eval, &GlslTree::Embedded.read(Path::new(&source)).unwrap()).unwrap();
            cache_key(&composed, &defines, &GlslTree::Embedded)
        };
        let original = key();
        assert_eq!(original, embedded, "a copy of the tree keys as the embedded tree does");
        let included: Vec<String> = tree
            .included(&m.compose(KernelKind::Eval, &tree.read(Path::new("eval.comp")).unwrap()).unwrap())
            .into_iter()
            .map(|(f, _)| f)
            .collect();
        assert!(
            included.iter().any(|f| f == "brdf.glsl") && included.iter().any(|f| f.starts_with("generated/")),
            "{included:?}"
        );
        let edit = |rel: &str| {
            let p = glsl.join(rel);
            let text = std::fs::read_to_string(&p).unwrap();
            std::fs::write(&p, format!("{text}\n// edited\n")).unwrap();
            let k = key();
            std::fs::write(&p, text).unwrap();
            k
        };
        assert_ne!(edit("brdf.glsl"), original);
        let generated = included.iter().find(|f| f.starts_with("generated/")).unwrap().clone();
        assert_ne!(edit(&generated), original, "{generated}");
        assert_eq!(edit("shade.comp"), original, "the eval kernel does not include shade.comp");
        assert_eq!(key(), original);
    }
}
