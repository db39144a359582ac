//! Front ends for a model written in HLSL, Slang or WGSL (docs/hlsl.md, docs/slang.md, docs/wgsl.md), or in GLSL
//! that includes files: the user's shader, its includes or imports resolved, compiled to SPIR-V by its
//! language's own front end (glslang's GLSL and HLSL front ends; Slang's slangc; naga_oil and naga for WGSL),
//! and brought back as GLSL by spirv-cross, so that it composes into brdfprof's kernels as
//! a GLSL shader does (src/model/brdf_file/foreign.rs orchestrates; this module knows nothing of `.brdf` files).
//!
//! - `includes`: C `#include` for HLSL, Slang and GLSL, with `#pragma once`, include guards, virtual paths and
//!   cycles.
//! - `hlsl`: glslang's HLSL (and GLSL) preprocessor and compiler, their messages at FILE:LINE:COLUMN.
//! - `slang`: slangc, for Slang code and for HLSL glslang refuses, its SPIR-V cached by its sources.
//! - `wgsl`: naga_oil's `#import`/`#ifdef` composition over the include directories, naga's validation and
//!   SPIR-V, their messages at FILE:LINE:COLUMN.
//! - `cross`: spirv-cross, and the GLSL it writes cut down to the shader's own declarations and functions.

pub mod cross;
pub mod glsl;
pub mod glslang;
pub mod hlsl;
pub mod includes;
pub mod overloads;
pub mod slang;
pub mod wgsl;
pub mod wgsl_lines;

use brdfprof_files::{cache, io};
use brdfprof_process::{cleanup, launch, messages, tools};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Mutex;

/// The language of a model's shader.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Language {
    Glsl,
    Hlsl,
    Slang,
    Wgsl,
}

impl Language {
    pub fn name(self) -> &'static str {
        match self {
            Language::Glsl => "GLSL",
            Language::Hlsl => "HLSL",
            Language::Slang => "Slang",
            Language::Wgsl => "WGSL",
        }
    }

    /// The word after `::begin shader` (none: GLSL, as BRDF Explorer's files are).
    pub fn of_section(word: Option<&str>) -> Option<Language> {
        match word.map(str::to_ascii_lowercase).as_deref() {
            None | Some("glsl") => Some(Language::Glsl),
            Some("hlsl") => Some(Language::Hlsl),
            Some("slang") => Some(Language::Slang),
            Some("wgsl") => Some(Language::Wgsl),
            Some(_) => None,
        }
    }

    /// The language of a plain shader file, by its extension (`.hlsl`, `.hlsli`, `.ush`, `.usf`, `.slang`,
    /// `.wgsl`).
    pub fn of_extension(ext: &str) -> Option<Language> {
        match ext.to_ascii_lowercase().as_str() {
            "hlsl" | "hlsli" | "ush" | "usf" => Some(Language::Hlsl),
            "slang" => Some(Language::Slang),
            "wgsl" => Some(Language::Wgsl),
            _ => None,
        }
    }
}

/// Which front end compiles an HLSL shader (`hlsl-front-end=` in a model spec, `--hlsl-front-end`): glslang,
/// and Slang's slangc where glslang refuses or crashes (`Auto`, the default), or one of them alone.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum HlslFrontEnd {
    #[default]
    Auto,
    Glslang,
    Slang,
}

impl HlslFrontEnd {
    pub const NAMES: [&str; 3] = ["auto", "glslang", "slang"];
    /// The model-spec key that chooses it.
    pub const KEY: &str = "hlsl-front-end";

    pub fn parse(text: &str) -> Option<HlslFrontEnd> {
        match text {
            "auto" => Some(HlslFrontEnd::Auto),
            "glslang" => Some(HlslFrontEnd::Glslang),
            "slang" => Some(HlslFrontEnd::Slang),
            _ => None,
        }
    }
}

/// The extensions a model text may name a shader file by: `.brdf`, then plain shader files.
pub const FILE_EXTENSIONS: [&str; 7] = ["brdf", "hlsl", "hlsli", "ush", "usf", "slang", "wgsl"];

/// Where `#include` (HLSL) and `#import` (WGSL) look: `--include-override NAME=FILE` first (FILE wherever NAME
/// would be included, beside the includer or through the search path: a stub for an engine's header), then
/// `--include-map VIRTUAL=DIR` (a name under the virtual prefix VIRTUAL is found under DIR), then beside the
/// including file (quoted includes) and `--include-dir DIR` in order.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Includes {
    pub dirs: Vec<PathBuf>,
    pub maps: Vec<(String, PathBuf)>,
    pub overrides: Vec<(String, PathBuf)>,
}

impl Includes {
    pub fn is_empty(&self) -> bool {
        self.dirs.is_empty() && self.maps.is_empty() && self.overrides.is_empty()
    }

    /// The file that replaces `name` (`--include-override`): given as written (`Common/Globals.ush`), or by its
    /// file name alone where the override names no folder (`globals.hlsli` replaces `../globals.hlsli` too).
    pub fn overridden(&self, name: &str) -> Option<&PathBuf> {
        let file_name = name.rsplit(['/', '\\']).next().unwrap_or(name);
        self.overrides.iter().find(|(n, _)| n == name || (!n.contains(['/', '\\']) && n == file_name)).map(|(_, f)| f)
    }

    /// The longest mapped prefix `name` lies under (`/Engine` for `/Engine/Private/BRDF.ush`), with the rest of
    /// the name after it.
    pub fn mapped<'a>(&self, name: &'a str) -> Option<(&(String, PathBuf), &'a str)> {
        let under =
            |v: &str| name == v || (name.starts_with(v) && (v.ends_with('/') || name[v.len()..].starts_with('/')));
        let map = self.maps.iter().filter(|(v, _)| under(v)).max_by_key(|(v, _)| v.len())?;
        Some((map, name[map.0.len()..].trim_start_matches('/')))
    }
}

impl Includes {
    /// The one lookup of a file a shader names, for HLSL's `#include` and WGSL's quoted `#import`: a name under
    /// a mapped virtual prefix under its DIR alone; any other in `beside` (the including file's directory, for
    /// `#include "NAME"` and a quoted import; None for `#include <NAME>`), then in each include directory in
    /// order. The first that exists and is not a directory is the one: a FIFO or device there is refused
    /// by name when it is read, not passed over for another file.
    pub fn find(&self, name: &str, beside: Option<&Path>) -> Option<PathBuf> {
        let found = |p: &PathBuf| p.metadata().is_ok_and(|m| !m.is_dir());
        if let Some(file) = self.overridden(name) {
            return Some(file.clone()).filter(found);
        }
        if let Some(((_, dir), rest)) = self.mapped(name) {
            return Some(dir.join(rest)).filter(|p| stays_under(rest) && found(p));
        }
        beside.map(|d| d.join(name)).into_iter().chain(self.dirs.iter().map(|d| d.join(name))).find(found)
    }

    /// Where `find` looked for `name`, as a message goes on after the name: `: --include-map V=DIR maps it to
    /// P, which does not exist`, or ` (searched: DIR, ...)`.
    pub fn searched(&self, name: &str, beside: Option<&Path>) -> String {
        if let Some(((v, dir), _)) = self.mapped(name).filter(|(_, rest)| !stays_under(rest)) {
            return format!(": its `..` leaves the directory --include-map {v}={} maps it under", dir.display());
        }
        if let Some(((v, dir), rest)) = self.mapped(name) {
            return format!(
                ": --include-map {v}={} maps it to {}, which does not exist",
                dir.display(),
                dir.join(rest).display()
            );
        }
        let dirs: Vec<String> =
            beside.map(shown_dir).into_iter().chain(self.dirs.iter().map(|d| shown_dir(d))).collect();
        format!(" (searched: {})", if dirs.is_empty() { "no directory".to_string() } else { dirs.join(", ") })
    }
}

/// Whether a path under a mapped prefix stays under its directory (its `..` never climbs above the start), as
/// the map promises "under DIR alone".
fn stays_under(rest: &str) -> bool {
    let mut depth = 0i32;
    for part in rest.split(['/', '\\']) {
        match part {
            ".." => depth -= 1,
            "" | "." => {}
            _ => depth += 1,
        }
        if depth < 0 {
            return false;
        }
    }
    true
}

/// The directory a shader file's own includes and imports are found beside: its parent, empty for a bare file
/// name (the working directory, which paths then do not spell out).
pub fn dir_of(path: &Path) -> PathBuf {
    path.parent().map_or_else(PathBuf::new, Path::to_path_buf)
}

/// A directory as messages name it (`.` for the empty one, the working directory).
pub fn shown_dir(dir: &Path) -> String {
    if dir.as_os_str().is_empty() { ".".to_string() } else { dir.display().to_string() }
}

/// A call the front end writes in the shader's language around a declared entry (`entry NAME(ARG, ...)`):
/// a function `name(L, V, N, X, Y)` returning what `callee(args)` returns (or the `@out` argument's value).
#[derive(Clone, Debug, PartialEq)]
pub struct Glue {
    pub name: String,
    pub callee: String,
    pub args: Vec<GlueArg>,
}

/// An argument of a glue call: an expression of the shader's language over L, V, N, X, Y and the parameters,
/// or a local of the parameter's type (starting at zero) whose value is returned (`@out`) or discarded
/// (`@scratch`).
#[derive(Clone, Debug, PartialEq)]
pub enum GlueArg {
    Expr(String),
    Out(String),
    Scratch(String),
}

impl Glue {
    /// The glue on one line in a language: `signature { return CALLEE(ARGS); }`, a local declared by
    /// `local(type, name)` for each `@out`/`@scratch` argument and passed as `pass(name)`, the `@out` one
    /// returned.
    pub fn write(
        &self,
        signature: &str,
        local: impl Fn(&str, &str) -> String,
        pass: impl Fn(&str) -> String,
    ) -> String {
        let mut locals = String::new();
        let mut out = None;
        let mut args = Vec::new();
        for (k, a) in self.args.iter().enumerate() {
            let name = format!("{GENERATED_PREFIX}arg{k}");
            match a {
                GlueArg::Expr(e) => args.push(e.clone()),
                GlueArg::Out(ty) | GlueArg::Scratch(ty) => {
                    locals += &local(ty, &name);
                    args.push(pass(&name));
                    if matches!(a, GlueArg::Out(_)) {
                        out = Some(name);
                    }
                }
            }
        }
        let call = format!("{}({})", self.callee, args.join(", "));
        let body = match out {
            Some(o) => format!("{locals}{call}; return {o};"),
            None => format!("{locals}return {call};"),
        };
        format!("{signature} {{ {body} }}")
    }
}

/// The names a front end generates: none of the shader's own may start with this.
pub const GENERATED_PREFIX: &str = "brdfprof_";

/// The compute entry point the front ends compile the shader with (it calls `BRDF` and every glue function,
/// so that each reaches the SPIR-V); spirv-cross's output drops it.
pub const STUB: &str = "brdfprof_stub";

/// Front ends used by this process, model path -> what translated it (`describe`), for reports' provenance.
static USED: Mutex<BTreeMap<String, String>> = Mutex::new(BTreeMap::new());

/// Records that `path`'s shader went through `language`'s front end (`front_end`: which, where the file says).
pub fn record(path: &str, language: Language, front_end: Option<&str>) {
    if language != Language::Glsl || front_end.is_some() {
        let described = front_end.map_or_else(|| describe(language), str::to_string);
        USED.lock().unwrap().insert(path.to_string(), described);
    }
}

/// The front ends of the HLSL and WGSL models this process read, by model path (empty when there were none).
pub fn used() -> BTreeMap<String, String> {
    USED.lock().unwrap().clone()
}

/// What translates a language, with versions: what reports state.
pub fn describe(language: Language) -> String {
    match language {
        Language::Glsl => format!("GLSL, {}", crate::glslang::glslang_version().unwrap_or_else(|| "glslang".into())),
        Language::Hlsl => format!("HLSL: {}; {}", hlsl::describe(), cross::describe()),
        Language::Slang => format!("Slang: {}; {}", slang::describe_slang(), cross::describe()),
        Language::Wgsl => format!("WGSL: {}; {}", wgsl::describe(), cross::describe()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn languages_by_section_and_extension() {
        assert_eq!(Language::of_section(None), Some(Language::Glsl));
        assert_eq!(Language::of_section(Some("HLSL")), Some(Language::Hlsl));
        assert_eq!(Language::of_section(Some("wgsl")), Some(Language::Wgsl));
        assert_eq!(Language::of_section(Some("metal")), None);
        assert_eq!(Language::of_extension("ush"), Some(Language::Hlsl));
        assert_eq!(Language::of_section(Some("Slang")), Some(Language::Slang));
        assert_eq!(Language::of_extension("slang"), Some(Language::Slang));
        assert_eq!(Language::of_extension("brdf"), None);
    }

    #[test]
    fn the_longest_virtual_prefix_maps_a_name() {
        let inc = Includes {
            dirs: vec![],
            overrides: vec![],
            maps: vec![
                ("/Engine".into(), "a".into()),
                ("/Engine/Private".into(), "b".into()),
                ("/Eng".into(), "c".into()),
            ],
        };
        let ((v, d), rest) = inc.mapped("/Engine/Private/BRDF.ush").unwrap();
        assert_eq!((v.as_str(), d.to_str().unwrap(), rest), ("/Engine/Private", "b", "BRDF.ush"));
        assert_eq!(inc.mapped("/Engine/Public/X.ush").unwrap().1, "Public/X.ush");
        assert!(inc.mapped("/EngineX/a.ush").is_none() && inc.mapped("Engine/a.ush").is_none());
    }
}
