//! The `.brdf` format as BRDF Explorer reads it: line ends, the kind line, sections, parameters, and which
//! `#` lines of the shader stay for the preprocessor.

use super::*;
use anyhow::{Result, anyhow, bail};
use std::path::Path;

/// The lines of `text`, ended by `\n`, `\r\n` or a lone `\r` (classic Mac OS line ends, which some editors
/// still write): each counts as one line, as editors number them.
pub(super) fn split_lines(text: &str) -> impl Iterator<Item = &str> {
    let mut rest = Some(text);
    std::iter::from_fn(move || {
        let t = rest?;
        match t.find(['\n', '\r']) {
            Some(i) => {
                let next = if t[i..].starts_with("\r\n") { i + 2 } else { i + 1 };
                rest = Some(&t[next..]).filter(|r| !r.is_empty());
                Some(&t[..i])
            }
            None => {
                rest = None;
                Some(t)
            }
        }
    })
}

/// The file as text: not empty, no NUL byte, UTF-8 (a UTF-8 byte order mark is skipped).
pub(super) fn text_of<'a>(path: &Path, bytes: &'a [u8]) -> Result<&'a str> {
    let line_of = |offset: usize| bytes[..offset].iter().filter(|&&b| b == b'\n').count() + 1;
    if let Some(p) = bytes.iter().position(|&b| b == 0) {
        bail!(at(path, line_of(p), format!("binary content: NUL byte at byte {p} of the file, not a .brdf text file")));
    }
    let text = std::str::from_utf8(bytes).map_err(|e| {
        let p = e.valid_up_to();
        anyhow!(at(path, line_of(p), format!("not UTF-8 text: byte {p} of the file is {:#04x}", bytes[p])))
    })?;
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    if text.trim().is_empty() {
        bail!(at(path, 1, "empty file: a .brdf file starts with `analytic`"));
    }
    Ok(text)
}

/// Line 1 names the kind of BRDF, up to its first space.
pub(super) fn check_kind(path: &Path, first: &str) -> Result<()> {
    match first.split_whitespace().next().unwrap_or("") {
        "analytic" => Ok(()),
        "bparam" => bail!(at(path, 1, "`bparam` files are not supported: brdfprof reads only `analytic` .brdf files")),
        other => bail!(at(path, 1, format!("expected `analytic` as the first line, found `{other}`"))),
    }
}

/// An open section and the line of its `::begin`.
pub(super) struct Open {
    pub(super) name: String,
    pub(super) line: usize,
}

/// The directives of a `.brdf` shader that glslang's preprocessor runs, as in any GLSL (engine code selects its
/// branches with `#if` and names its constants with `#define`).
/// `#pragma` is not among them: glslang's preprocessor passes pragmas through into the text brdfprof reads for
/// the file's globals, and none changes the SPIR-V of a compute kernel (`dropped_hash_line`).
pub(super) const PREPROCESSOR_DIRECTIVES: [&str; 10] =
    ["define", "undef", "if", "ifdef", "ifndef", "elif", "else", "endif", "error", "extension"];

/// The directive name of a `#` line (`#  if X` -> `if`).
pub(super) fn directive_of(line: &str) -> &str {
    line[1..].trim_start().split(|c: char| !c.is_ascii_alphanumeric() && c != '_').next().unwrap_or("")
}

/// Whether a `#` line of the shader section stays for the preprocessor (`#include` too: a shader that includes
/// files goes through glslang's GLSL front end, `foreign` and `front::glsl`); any other line is dropped
/// (`dropped_hash_line`).
pub(super) fn keeps_directive(line: &str) -> bool {
    directive_of(line) == "include" || PREPROCESSOR_DIRECTIVES.contains(&directive_of(line))
}

/// Whether a GLSL shader includes files.
pub(super) fn includes_files(source: &[(usize, String)]) -> bool {
    source.iter().any(|(_, l)| l.trim_start().starts_with('#') && directive_of(l.trim_start()) == "include")
}

/// A `#` line of the shader that is no directive brdfprof keeps is dropped, as BRDF Explorer drops every `#`
/// line; never silently.
pub(super) fn dropped_hash_line(path: &Path, n: usize, line: &str) -> String {
    let why = match directive_of(line) {
        "version" => "the kernel the file is composed into sets `#version 450`",
        "line" => "brdfprof numbers the file's lines itself, so messages name the file's own lines",
        "pragma" => {
            "no pragma changes the compute kernel brdfprof compiles (glslang ignores `optimize` and `debug` for SPIR-V, `STDGL invariant` applies to vertex outputs, and a .brdf shader is one file, so `once` guards nothing)"
        }
        _ => "a `#` line that is no preprocessor directive is a BRDF Explorer comment",
    };
    at(path, n, format!("`{line}` is dropped: {why}"))
}

/// A blank or `#` line of the shader section: a kept directive as written, anything else empty (with a
/// warning for a dropped `#` line). An HLSL or WGSL shader keeps every line for its own preprocessor.
fn push_blank_or_hash_line(file: &mut BrdfFile, n: usize, raw: &str) -> Result<()> {
    if file.language != Language::Glsl {
        file.source.push((n, raw.to_string()));
        return Ok(());
    }
    let trimmed = raw.trim();
    let kept = trimmed.starts_with('#') && keeps_directive(trimmed);
    file.source.push((n, if kept { raw.to_string() } else { String::new() }));
    if trimmed.starts_with('#') && !kept {
        let warning = dropped_hash_line(&file.path, n, trimmed);
        file.warnings.push(warning);
    }
    Ok(())
}

/// Reads every line after the first into `file`; returns the line of `::begin shader`, if any.
pub(super) fn read_sections<'a>(file: &mut BrdfFile, lines: impl Iterator<Item = &'a str>) -> Result<Option<usize>> {
    let path = file.path.clone();
    let mut open: Option<Open> = None;
    let mut shader_begin = None;
    let mut declared: std::collections::HashMap<String, usize> = std::collections::HashMap::new();
    for (i, raw) in lines.enumerate() {
        let n = i + 2;
        let raw = raw.strip_suffix('\r').unwrap_or(raw);
        let trimmed = raw.trim();
        let in_shader = open.as_ref().is_some_and(|o| o.name == "shader");
        // BRDF Explorer skips these everywhere; in the shader a preprocessor directive stays for glslang's
        // preprocessor and any other stays as an empty line, to keep the numbering.
        if trimmed.is_empty() || trimmed.starts_with('#') {
            if in_shader {
                push_blank_or_hash_line(file, n, raw)?;
            }
            continue;
        }
        let mut tokens = trimmed.split_whitespace();
        match tokens.next().unwrap_or("") {
            "::begin" => open = Some(begin_section(file, n, &mut tokens, open.as_ref(), &mut shader_begin)?),
            "::end" => {
                let name = tokens.next().unwrap_or("");
                match &open {
                    None => bail!(at(&path, n, format!("`::end {name}` outside any section"))),
                    Some(o) if o.name != name => {
                        bail!(at(
                            &path,
                            n,
                            format!("`::end {name}` does not close section `{}` (begun at line {})", o.name, o.line)
                        ))
                    }
                    Some(_) => open = None,
                }
            }
            _ => match open.as_ref().map(|o| o.name.as_str()) {
                None => file.warnings.push(at(&path, n, "text outside any section is ignored")),
                Some("parameters") => {
                    let param = parse_param(&path, n, trimmed, &mut file.warnings)?;
                    if let Some(first) = declared.insert(param.name.clone(), param.line) {
                        bail!(at(
                            &path,
                            n,
                            format!("parameter `{}` is declared twice (first at line {first})", param.name)
                        ));
                    }
                    file.params.push(param);
                }
                Some("shader") => file.source.push((n, raw.to_string())),
                Some("isFunc") => file.has_is_func = true,
                Some(DIRECTIVES_SECTION) => parse_directive(file, n, trimmed)?,
                Some(_) => {}
            },
        }
    }
    if let Some(o) = open {
        bail!(at(&path, o.line, format!("section `{}` has no `::end {}`", o.name, o.name)));
    }
    Ok(shader_begin)
}

/// The section a `::begin` line opens (`tokens` after `::begin`), with the shader's language where it is the
/// shader; an error where a section is open (`open`) or the shader section is a second one.
fn begin_section<'t>(
    file: &mut BrdfFile,
    n: usize,
    tokens: &mut impl Iterator<Item = &'t str>,
    open: Option<&Open>,
    shader_begin: &mut Option<usize>,
) -> Result<Open> {
    let path = file.path.clone();
    let name = tokens.next().ok_or_else(|| anyhow!(at(&path, n, "`::begin` names no section")))?;
    if let Some(o) = open {
        bail!(at(
            &path,
            n,
            format!("`::begin {name}` inside section `{}` (begun at line {}): sections do not nest", o.name, o.line)
        ));
    }
    match name {
        "shader" => {
            if let Some(first) = *shader_begin {
                bail!(at(&path, n, format!("a second shader section (the first begins at line {first})")));
            }
            let word = tokens.next();
            file.language = Language::of_section(word).ok_or_else(|| {
                anyhow!(at(
                    &path,
                    n,
                    format!(
                        "`::begin shader {}`: the shader's language is glsl (the default), hlsl or wgsl",
                        word.unwrap_or("")
                    )
                ))
            })?;
            *shader_begin = Some(n);
        }
        "parameters" | "isFunc" | DIRECTIVES_SECTION => {}
        other => file.warnings.push(at(
            &path,
            n,
            format!("don't know what to do with section `{other}`: its content is ignored"),
        )),
    }
    Ok(Open { name: name.to_string(), line: n })
}

/// One line of the parameters section.
pub(super) fn parse_param(path: &Path, n: usize, line: &str, warnings: &mut Vec<String>) -> Result<FileParam> {
    let tokens: Vec<&str> = line.split_whitespace().collect();
    let (form, needed) = match tokens[0] {
        "float" => ("float NAME MIN MAX DEFAULT", 4),
        "bool" => ("bool NAME DEFAULT", 2),
        "color" => ("color NAME R G B", 4),
        other => {
            bail!(at(path, n, format!("unknown parameter type `{other}`: BRDF Explorer knows float, bool and color")))
        }
    };
    if tokens.len() < needed + 1 {
        bail!(at(path, n, format!("`{line}`: too few values, expected `{form}`")));
    }
    let name = tokens[1];
    check_identifier(path, n, name, warnings)?;
    let number = |what: &str, s: &str| -> Result<f64> {
        let x = s
            .parse::<f64>()
            .ok()
            .filter(|x| x.is_finite())
            .ok_or_else(|| anyhow!(at(path, n, format!("{what} of `{name}`: `{s}` is not a finite number"))))?;
        if x.abs() > f64::from(f32::MAX) && what != "MIN" && what != "MAX" {
            bail!(at(
                path,
                n,
                format!(
                    "{what} of `{name}`: `{s}` is beyond fp32's range (at most {:e} in magnitude), in which the kernels compute",
                    f32::MAX
                )
            ));
        }
        Ok(x)
    };
    let kind = match tokens[0] {
        "float" => {
            let (min, max, default) =
                (number("MIN", tokens[2])?, number("MAX", tokens[3])?, number("DEFAULT", tokens[4])?);
            if !(min <= default && default <= max) {
                warnings.push(at(
                    path,
                    n,
                    format!("`{name}`'s default {default} is outside its slider range [{min}, {max}]"),
                ));
            }
            FileParamKind::Float { min, max, default }
        }
        // BRDF Explorer reads a bool with `>> bool`: a number, 0 or 1.
        "bool" => match tokens[2] {
            "0" => FileParamKind::Bool { default: false },
            "1" => FileParamKind::Bool { default: true },
            other => bail!(at(path, n, format!("DEFAULT of bool `{name}`: `{other}` is not 0 or 1"))),
        },
        _ => FileParamKind::Color {
            default: [number("R", tokens[2])?, number("G", tokens[3])?, number("B", tokens[4])?],
        },
    };
    let rest = &tokens[needed + 1..];
    if rest.first().is_some_and(|t| !t.starts_with('#')) {
        warnings.push(at(
            path,
            n,
            format!("`{}` after `{name}` is ignored (BRDF Explorer ignores it too)", rest.join(" ")),
        ));
    }
    Ok(FileParam { name: name.to_string(), kind, line: n })
}

/// GLSL keywords and reserved words (GLSL 4.60, with Vulkan's), which cannot name a parameter.
pub(super) const GLSL_KEYWORDS: &[&str] = &[
    "active",
    "asm",
    "atomic_uint",
    "attribute",
    "bool",
    "break",
    "buffer",
    "bvec2",
    "bvec3",
    "bvec4",
    "case",
    "cast",
    "centroid",
    "class",
    "coherent",
    "common",
    "const",
    "continue",
    "default",
    "discard",
    "dmat2",
    "dmat2x2",
    "dmat2x3",
    "dmat2x4",
    "dmat3",
    "dmat3x2",
    "dmat3x3",
    "dmat3x4",
    "dmat4",
    "dmat4x2",
    "dmat4x3",
    "dmat4x4",
    "do",
    "double",
    "dvec2",
    "dvec3",
    "dvec4",
    "else",
    "enum",
    "extern",
    "external",
    "false",
    "filter",
    "fixed",
    "flat",
    "float",
    "for",
    "fvec2",
    "fvec3",
    "fvec4",
    "goto",
    "half",
    "highp",
    "hvec2",
    "hvec3",
    "hvec4",
    "if",
    "in",
    "inline",
    "inout",
    "input",
    "int",
    "interface",
    "invariant",
    "isampler2D",
    "isampler3D",
    "ivec2",
    "ivec3",
    "ivec4",
    "layout",
    "long",
    "lowp",
    "mat2",
    "mat2x2",
    "mat2x3",
    "mat2x4",
    "mat3",
    "mat3x2",
    "mat3x3",
    "mat3x4",
    "mat4",
    "mat4x2",
    "mat4x3",
    "mat4x4",
    "mediump",
    "namespace",
    "noinline",
    "noperspective",
    "out",
    "output",
    "partition",
    "patch",
    "precise",
    "precision",
    "public",
    "readonly",
    "resource",
    "restrict",
    "return",
    "sample",
    "sampler",
    "sampler1D",
    "sampler2D",
    "sampler3D",
    "samplerCube",
    "sampler2DShadow",
    "shared",
    "short",
    "sizeof",
    "smooth",
    "static",
    "struct",
    "subpassInput",
    "subroutine",
    "superp",
    "switch",
    "template",
    "texture2D",
    "texture3D",
    "textureCube",
    "this",
    "true",
    "typedef",
    "uint",
    "uniform",
    "union",
    "unsigned",
    "usampler2D",
    "using",
    "uvec2",
    "uvec3",
    "uvec4",
    "varying",
    "vec2",
    "vec3",
    "vec4",
    "void",
    "volatile",
    "while",
    "writeonly",
];

pub fn is_identifier(s: &str) -> bool {
    let mut chars = s.chars();
    chars.next().is_some_and(|c| c == '_' || c.is_ascii_alphabetic())
        && chars.all(|c| c == '_' || c.is_ascii_alphanumeric())
}

/// A parameter name must be a GLSL identifier that GLSL does not reserve.
pub(super) fn check_identifier(path: &Path, n: usize, name: &str, warnings: &mut Vec<String>) -> Result<()> {
    if !is_identifier(name) || GLSL_KEYWORDS.contains(&name) || name.starts_with("gl_") {
        bail!(at(path, n, format!("parameter name `{name}` is not a valid GLSL identifier")));
    }
    if name.contains("__") {
        warnings.push(at(path, n, format!("`{name}`: GLSL reserves identifiers containing `__`")));
    }
    Ok(())
}

/// The section of brdfprof's own directives (BRDF Explorer warns about it and reads on): `entry`, `bind`, `domain`.
pub(super) const DIRECTIVES_SECTION: &str = "brdfprof";

/// One line of the `brdfprof` section:
/// - `entry NAME(ARG, ...) [returns f|f_nol]`: the shader's function to call instead of `BRDF`, with each
///   argument a GLSL expression over `L V N X Y` (BRDF Explorer's entry's arguments) and the file's
///   parameters; `returns f_nol` when it returns f_s times N.L (an engine's light loop body).
/// - `bind NAME=@INPUT ...`: a parameter's default binding to a kernel input, as `NAME=@INPUT` in the model spec.
/// - `domain roughness MIN MAX`: the perceptual roughness the file's engine admits (`diff` samples within it).
pub(super) fn parse_directive(file: &mut BrdfFile, n: usize, line: &str) -> Result<()> {
    let path = file.path.clone();
    let (word, rest) = line.split_once(char::is_whitespace).map_or((line, ""), |(w, r)| (w, r.trim()));
    match word {
        "entry" => {
            let entry = parse_entry(&path, n, rest)?;
            if let Some(first) = file.entries.iter().find(|e| e.name == entry.name) {
                bail!(at(&path, n, format!("entry `{}` is declared twice (first at line {})", entry.name, first.line)));
            }
            file.entries.push(entry);
        }
        "bind" => parse_bind(file, n, rest)?,
        "domain" => parse_domain(file, n, rest)?,
        "reference" => {
            if let Some((_, first)) = &file.reference {
                bail!(at(&path, n, format!("the reference is declared twice (first at line {first})")));
            }
            crate::brdf::ModelSpec::parse(rest).map_err(|e| {
                anyhow!(at(
                    &path,
                    n,
                    format!("`reference {rest}`: {e} (a reference is a built-in spec: a preset or d=..,vis=..,f=..)")
                ))
            })?;
            file.reference = Some((rest.trim().to_string(), n));
        }
        other => bail!(at(
            &path,
            n,
            format!(
                "unknown directive `{other}` in the `{DIRECTIVES_SECTION}` section (known: entry, bind, domain, reference)"
            )
        )),
    }
    Ok(())
}

/// `bind NAME=@INPUT ...`.
fn parse_bind(file: &mut BrdfFile, n: usize, rest: &str) -> Result<()> {
    let path = file.path.clone();
    for item in rest.split_whitespace() {
        let (name, value) =
            item.split_once('=').ok_or_else(|| anyhow!(at(&path, n, format!("`{item}`: expected NAME=@INPUT"))))?;
        if !value.starts_with('@') {
            bail!(at(
                &path,
                n,
                format!(
                    "`{item}`: `bind` binds a parameter to an input (NAME=@roughness, ...); a value belongs in the parameters section"
                )
            ));
        }
        if let Some((_, _, first)) = file.binds.iter().find(|(b, _, _)| b == name) {
            bail!(at(&path, n, format!("`{name}` is bound twice (first at line {first})")));
        }
        file.binds.push((name.to_string(), value.to_string(), n));
    }
    if rest.is_empty() {
        bail!(at(&path, n, "`bind` names no parameter: `bind NAME=@INPUT ...`"));
    }
    Ok(())
}

/// `domain roughness|nov|nol MIN MAX`.
fn parse_domain(file: &mut BrdfFile, n: usize, rest: &str) -> Result<()> {
    let path = file.path.clone();
    let form = "`domain roughness|nov|nol MIN MAX`";
    let words: Vec<&str> = rest.split_whitespace().collect();
    let [input, min, max] = words.as_slice() else { bail!(at(&path, n, format!("`domain {rest}`: expected {form}"))) };
    // Perceptual roughness and the cosines all lie in [0, 1]: a domain outside it holds no input brdfprof makes.
    let slot = match *input {
        "roughness" => &mut file.roughness_domain,
        "nov" => &mut file.nov_domain,
        "nol" => &mut file.nol_domain,
        _ => bail!(at(&path, n, format!("`domain {input}`: the domains declared are roughness, nov and nol ({form})"))),
    };
    let number = |t: &str| t.parse::<f64>().ok().filter(|x| (0.0..=1.0).contains(x));
    let (Some(lo), Some(hi)) = (number(min), number(max)) else {
        bail!(at(&path, n, format!("`domain {rest}`: MIN and MAX are numbers within [0, 1] (the range of {input})")))
    };
    if lo > hi {
        bail!(at(&path, n, format!("`domain {rest}`: MIN {lo} is above MAX {hi}")));
    }
    if let Some((_, _, first)) = slot {
        bail!(at(&path, n, format!("the {input} domain is declared twice (first at line {first})")));
    }
    *slot = Some((lo, hi, n));
    Ok(())
}

/// `NAME(ARG, ...) [returns f|f_nol]`.
fn parse_entry(path: &Path, n: usize, text: &str) -> Result<Entry> {
    let form = "`entry NAME(ARG, ...) [returns f|f_nol]`";
    let open = text.find('(').ok_or_else(|| anyhow!(at(path, n, format!("`entry {text}`: expected {form}"))))?;
    let name = text[..open].trim();
    // A WGSL shader may name an imported module's function by its path (`lighting::direct`).
    if !name.split("::").all(is_identifier) || GLSL_KEYWORDS.contains(&name) {
        bail!(at(path, n, format!("`entry {text}`: `{name}` is not a function name")));
    }
    let mut depth = 0usize;
    let mut args = Vec::new();
    let mut start = open + 1;
    let mut close = None;
    for (i, c) in text.char_indices().skip(open) {
        match c {
            '(' => depth += 1,
            ')' => {
                depth -= 1;
                if depth == 0 {
                    close = Some(i);
                    break;
                }
            }
            ',' if depth == 1 => {
                args.push(text[start..i].trim().to_string());
                start = i + 1;
            }
            _ => {}
        }
    }
    // A line comment inside the arguments would reach the composed kernel's call and hide the rest of it.
    if text.find("//").is_some_and(|p| close.is_none_or(|c| p < c)) {
        bail!(at(
            path,
            n,
            format!("`entry {text}`: a `//` comment inside the argument list; put it after the closing `)`")
        ));
    }
    let close =
        close.ok_or_else(|| anyhow!(at(path, n, format!("`entry {text}`: the argument list has no closing `)`"))))?;
    let last = text[start..close].trim();
    if !(args.is_empty() && last.is_empty()) {
        args.push(last.to_string());
    }
    if let Some(empty) = args.iter().position(|a| a.is_empty()) {
        bail!(at(path, n, format!("`entry {text}`: argument {} is empty", empty + 1)));
    }
    let tail = text[close + 1..].split("//").next().unwrap_or_default();
    let returns = match tail.split_whitespace().collect::<Vec<_>>().as_slice() {
        [] => Returns::F,
        ["returns", r] => {
            Returns::parse(r).ok_or_else(|| anyhow!(at(path, n, format!("`returns {r}`: expected f or f_nol"))))?
        }
        _ => bail!(at(path, n, format!("`entry {text}`: expected {form}"))),
    };
    Ok(Entry { name: name.to_string(), args, param_types: Vec::new(), returns, line: n, glue: None })
}
