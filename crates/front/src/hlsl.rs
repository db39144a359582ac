//! HLSL through glslang's HLSL front end (`glslangValidator -D`), the one brdfprof already runs for GLSL: its
//! preprocessor over the include-expanded text (`includes`), then a compute compilation of the shader with a
//! stub entry that calls `BRDF` and each glue function. `half` is 32-bit float (glslang without
//! `--hlsl-enable-16bit-types`, as DXC without `-enable-16bit-types`). Messages come back at FILE:LINE:COLUMN
//! of the user's files: the line through `Expanded::origin`, the column from glslang's parse-failure column,
//! else from the token its message names on that line.

use super::includes::Expanded;
use super::{Glue, STUB};
use anyhow::{Context, Result, bail};
use std::collections::HashMap;
use std::path::Path;

/// glslang's flags for the compilation: HLSL, a compute stage with the stub as its entry, no SPIR-V
/// optimisation (whose HLSL legalisation would inline every function into the stub).
pub const FLAGS: [&str; 6] = ["-D", "-V", "-Od", "-g", "-S", "comp"];

/// A parameter as an HLSL global: `static` (a private global, as a GLSL global is), of its type.
pub fn param_decl(name: &str, glsl_type: &str) -> String {
    let ty = match glsl_type {
        "vec3" => "float3",
        other => other,
    };
    format!("static {ty} {name};")
}

/// The words glslang's HLSL front end reads as keywords or reserves (its scanner's keyword map and reserved
/// set, glslang/HLSL/hlslScanContext.cpp), besides the numeric vector and matrix types (`is_keyword`): no
/// variable can take one of these names.
const KEYWORDS: &[&str] = &[
    "static",
    "const",
    "unorm",
    "snorm",
    "extern",
    "uniform",
    "volatile",
    "precise",
    "shared",
    "groupshared",
    "linear",
    "centroid",
    "nointerpolation",
    "noperspective",
    "sample",
    "row_major",
    "column_major",
    "packoffset",
    "in",
    "out",
    "inout",
    "layout",
    "globallycoherent",
    "inline",
    "point",
    "line",
    "triangle",
    "lineadj",
    "triangleadj",
    "PointStream",
    "LineStream",
    "TriangleStream",
    "InputPatch",
    "OutputPatch",
    "Buffer",
    "vector",
    "matrix",
    "void",
    "string",
    "uint64_t",
    "dword",
    "sampler",
    "sampler1D",
    "sampler2D",
    "sampler3D",
    "samplerCUBE",
    "sampler_state",
    "SamplerState",
    "SamplerComparisonState",
    "texture",
    "Texture1D",
    "Texture1DArray",
    "Texture2D",
    "Texture2DArray",
    "Texture3D",
    "TextureCube",
    "TextureCubeArray",
    "Texture2DMS",
    "Texture2DMSArray",
    "RWTexture1D",
    "RWTexture1DArray",
    "RWTexture2D",
    "RWTexture2DArray",
    "RWTexture3D",
    "RWBuffer",
    "SubpassInput",
    "SubpassInputMS",
    "AppendStructuredBuffer",
    "ByteAddressBuffer",
    "ConsumeStructuredBuffer",
    "RWByteAddressBuffer",
    "RWStructuredBuffer",
    "StructuredBuffer",
    "TextureBuffer",
    "class",
    "struct",
    "cbuffer",
    "ConstantBuffer",
    "tbuffer",
    "typedef",
    "this",
    "namespace",
    "true",
    "false",
    "for",
    "do",
    "while",
    "break",
    "continue",
    "if",
    "else",
    "discard",
    "return",
    "switch",
    "case",
    "default",
    "auto",
    "catch",
    "char",
    "const_cast",
    "enum",
    "explicit",
    "friend",
    "goto",
    "long",
    "mutable",
    "new",
    "operator",
    "private",
    "protected",
    "public",
    "reinterpret_cast",
    "short",
    "signed",
    "sizeof",
    "static_cast",
    "template",
    "throw",
    "try",
    "typename",
    "union",
    "unsigned",
    "using",
    "virtual",
];

/// The scalar types whose vectors (`float3`) and matrices (`half2x4`) are keywords too.
const NUMERIC: [&str; 11] =
    ["bool", "int", "uint", "half", "float", "double", "min16float", "min10float", "min16int", "min12int", "min16uint"];

/// Whether glslang's HLSL front end reads `name` as a keyword (or reserves it): `texture`, `sample`, `float3`.
pub fn is_keyword(name: &str) -> bool {
    let dims = |d: &str| matches!(d.as_bytes(), [b'1'..=b'4'] | [b'1'..=b'4', b'x', b'1'..=b'4']);
    KEYWORDS.contains(&name) || NUMERIC.iter().any(|t| name.strip_prefix(t).is_some_and(|d| d.is_empty() || dims(d)))
}

/// Whether `(T)0` makes a zero of HLSL type `ty` (a scalar, vector or matrix of a numeric type).
fn is_numeric(ty: &str) -> bool {
    let base = ty.trim_end_matches(|c: char| c.is_ascii_digit() || c == 'x');
    ["float", "half", "double", "int", "uint", "bool", "min16float", "min10float", "min16int", "min12int", "min16uint"]
        .contains(&base)
}

/// A glue function, on one line: `float3 NAME(float3 L, ...) { return CALLEE(ARGS); }`, with a local for each
/// `@out`/`@scratch` argument (zero where its type is numeric) and the `@out` one returned.
pub fn glue(g: &Glue) -> String {
    let local =
        |ty: &str, l: &str| if is_numeric(ty) { format!("{ty} {l} = ({ty})0; ") } else { format!("{ty} {l}; ") };
    g.write(&format!("float3 {}(float3 L, float3 V, float3 N, float3 X, float3 Y)", g.name), local, str::to_string)
}

/// The compute entry that calls each of `calls` (functions of (L, V, N, X, Y) returning float3), on one line.
pub fn stub(calls: &[String]) -> String {
    let body: String = calls.iter().map(|c| format!(" v += {c}(v, v, v, v, v);")).collect();
    format!("[numthreads(1, 1, 1)] void {STUB}() {{ float3 v = (float3)0;{body} }}")
}

/// glslang's `-D` flags for `defines` (NAME, or NAME=VALUE).
fn define_flags(defines: &[(String, String)]) -> Vec<String> {
    defines.iter().map(|(n, v)| if v.is_empty() { format!("-D{n}") } else { format!("-D{n}={v}") }).collect()
}

/// Runs glslangValidator on `x`'s text written to a temporary `shader.hlsl`, with `args` then the defines:
/// Ok(Ok(stdout, the output file's bytes)) or Ok(Err(its log)) when it refuses the shader.
pub(super) fn run(
    x: &Expanded,
    defines: &[(String, String)],
    args: &[&str],
    what: &str,
) -> Result<std::result::Result<(String, Option<Vec<u8>>), String>> {
    let dir = crate::cleanup::TempDir::new().context("cannot create a temporary directory for glslang")?;
    let source = dir.path().join("shader.hlsl");
    std::fs::write(&source, x.text()).with_context(|| format!("cannot write {}", source.display()))?;
    let out = dir.path().join("shader.spv");
    let mut cmd = crate::cleanup::command("glslangValidator");
    crate::launch::bound_memory(&mut cmd)?;
    cmd.args(args).args(define_flags(defines)).arg(&source);
    // HLSL's entry is the stub; GLSL's is always `main` (which the GLSL stub is).
    if args.contains(&"-D") {
        cmd.args(["-e", STUB]);
    }
    if args.contains(&"-V") {
        cmd.arg("-o").arg(&out);
    }
    let result = match crate::launch::output(&mut cmd, what) {
        Ok(r) => r,
        Err(e) if e.downcast_ref::<std::io::Error>().is_some() => {
            bail!("cannot run glslangValidator ({e}): install glslang-tools, or run `make setup`")
        }
        Err(e) => return Err(e),
    };
    let stdout = String::from_utf8_lossy(&result.stdout).into_owned();
    if let Some(signal) = std::os::unix::process::ExitStatusExt::signal(&result.status) {
        let name = match signal {
            6 => " SIGABRT",
            11 => " SIGSEGV",
            _ => "",
        };
        return Ok(Err(format!(
            "{}: glslang's HLSL front end crashed (signal {signal}{name}) on the shader",
            x.files.first().map_or("?", String::as_str)
        )));
    }
    if !result.status.success() {
        return Ok(Err(stdout + &String::from_utf8_lossy(&result.stderr)));
    }
    let spirv = if args.contains(&"-V") {
        Some(crate::io::read_bounded(&out, crate::launch::MAX_OUTPUT_BYTES as u64).context("glslang's SPIR-V")?)
    } else {
        None
    };
    Ok(Ok((stdout, spirv)))
}

/// glslang's preprocessor (`-E`) on the expanded text under `defines`: Ok(the preprocessed text, line for line
/// with `x` but for its `#line` directives) or Err(the messages at the user's files' lines).
pub fn preprocess(
    x: &Expanded,
    defines: &[(String, String)],
    model: &Path,
) -> Result<std::result::Result<String, String>> {
    let what = format!("{} (glslang's HLSL preprocessor)", model.display());
    Ok(run(x, defines, &["-D", "-E", "-S", "comp"], &what)?.map(|(out, _)| out).map_err(|log| messages(&log, x)))
}

/// The shader compiled to SPIR-V (`FLAGS`, the stub as entry), or Err(the messages at the user's files' lines).
pub fn compile(
    x: &Expanded,
    defines: &[(String, String)],
    model: &Path,
) -> Result<std::result::Result<Vec<u32>, String>> {
    let what = format!("{} (glslang's HLSL front end)", model.display());
    Ok(match run(x, defines, &FLAGS, &what)? {
        Ok((_, Some(bytes))) => {
            let mut words = crate::glslang::Spirv::from_bytes(&what, &bytes)?.words.to_vec();
            c_remainders(&mut words);
            Ok(words)
        }
        Ok((_, None)) => bail!("{what}: glslang wrote no SPIR-V"),
        Err(log) => Err(messages(&log, x)),
    })
}

/// HLSL's `%` and `fmod` are C's remainder, with the sign of the dividend (`x - y * trunc(x / y)`: SPIR-V's
/// OpFRem, and OpSRem for signed integers, as DXC's DXIL `frem`/`srem`), but glslang's HLSL front end emits
/// GLSL's `mod`, with the sign of the divisor (OpFMod, OpSMod): `fmod(-0.5, 1.0)` would be 0.5 and `-6 % 4`
/// 2, where HLSL gives -0.5 and -2. DXC's SPIR-V back end made the same mistake for `fmod` and fixed it
/// (DirectXShaderCompiler PR #2990, "[spirv] Fix incorrect opcode generation for fmod() function"). HLSL has no
/// GLSL `mod`, so no OpFMod or OpSMod of glslang's HLSL is meant: each is rewritten to OpFRem or OpSRem (same
/// operands). Unsigned `%` (OpUMod) is right as it is. Returns how many were rewritten.
pub fn c_remainders(words: &mut [u32]) -> usize {
    use rspirv::spirv::Op;
    let (mut i, mut rewritten) = (5, 0);
    while i < words.len() {
        let to = match words[i] & 0xffff {
            op if op == Op::FMod as u32 => Some(Op::FRem),
            op if op == Op::SMod as u32 => Some(Op::SRem),
            _ => None,
        };
        if let Some(op) = to {
            words[i] = (words[i] & 0xffff_0000) | op as u32;
            rewritten += 1;
        }
        i += ((words[i] >> 16) as usize).max(1);
    }
    rewritten
}

/// `SOURCE:LINE: message` -> (LINE, message), at the first `:digits: `.
fn located(rest: &str) -> Option<(usize, &str)> {
    let b = rest.as_bytes();
    rest.match_indices(':')
        .find_map(|(i, _)| {
            let digits = b[i + 1..].iter().take_while(|c| c.is_ascii_digit()).count();
            (digits > 0 && b.get(i + 1 + digits) == Some(&b':'))
                .then(|| (rest[i + 1..i + 1 + digits].parse().ok(), rest[i + 2 + digits..].trim()))
        })
        .and_then(|(n, m)| Some((n?, m)))
}

/// glslang's `FILE(LINE): error at column C, HLSL parsing failed.` lines: LINE -> C.
fn parse_columns(log: &str) -> HashMap<usize, usize> {
    let mut out = HashMap::new();
    for l in log.lines() {
        let Some((head, tail)) = l.split_once("): error at column ") else { continue };
        let line = head.rsplit('(').next().and_then(|n| n.parse().ok());
        let column = tail.split(',').next().and_then(|c| c.trim().parse().ok());
        if let (Some(line), Some(column)) = (line, column) {
            out.insert(line, column);
        }
    }
    out
}

/// The 1-based column (in characters) of the token a glslang message quotes (`'foo' : unknown variable`) on
/// `line`, if it is there.
pub fn token_column(line: &str, message: &str) -> Option<usize> {
    let quoted = message.strip_prefix('\'').and_then(|m| m.split('\'').next()).filter(|t| !t.is_empty())?;
    let ident = |c: char| c.is_ascii_alphanumeric() || c == '_';
    let whole = |i: usize| {
        !(quoted.starts_with(ident) && (line[..i].ends_with(ident) || line[i + quoted.len()..].starts_with(ident)))
    };
    let i = line.match_indices(quoted).map(|(i, _)| i).find(|&i| whole(i))?;
    Some(line[..i].chars().count() + 1)
}

/// The column of a message at `line`: its quoted token's, else glslang's parse-failure column, else the line's
/// first non-blank character's.
fn column(line: &str, message: &str, parse_failure: Option<usize>) -> usize {
    let first = || line.find(|c: char| !c.is_whitespace()).map_or(1, |i| line[..i].chars().count() + 1);
    token_column(line, message).or(parse_failure).unwrap_or_else(first)
}

/// glslang's log as `FILE:LINE:COLUMN: message` lines at the user's files (`x`'s origins), the first message
/// of each line only (glslang's next ones at a line follow from it); brdfprof's own `#error` lines (a missing
/// include, a cycle) as their messages, and nothing after the first (glslang stops there); a line brdfprof wrote (a parameter, an entry's glue) at its model
/// file line's column 1, saying what it stands for (`FILE:15:1: entry \`Light\`: 'x' : unknown variable`), as
/// WGSL's are. Lines located nowhere are dropped; a log with no located error is
/// returned as it is.
pub fn messages(log: &str, x: &Expanded) -> String {
    let columns = parse_columns(log);
    let mut seen: Vec<(usize, usize)> = Vec::new();
    let mut out: Vec<String> = Vec::new();
    for rest in log.lines().filter_map(|l| l.trim().strip_prefix("ERROR: ")) {
        let Some((n, message)) = located(rest) else { continue };
        let Some(&origin) = n.checked_sub(1).and_then(|i| x.origins.get(i)) else { continue };
        if seen.contains(&origin) {
            continue;
        }
        seen.push(origin);
        let text = x.lines.get(n - 1).map_or("", String::as_str);
        let (column, message) = match (x.notes.get(&(n - 1)), x.generated.get(&(n - 1))) {
            (Some((c, m)), _) => (*c, m.clone()),
            // A line brdfprof wrote: named by what it stands for, at the start of the model file's line.
            (None, Some(what)) => (1, format!("{what}: {message}")),
            (None, None) => {
                let column = column(text, message, columns.get(&n).copied());
                (column, non_ascii(text, column, message))
            }
        };
        out.push(format!("{}:{}:{column}: {message}", x.files[origin.0], origin.1));
        if x.notes.contains_key(&(n - 1)) {
            break; // glslang stops at brdfprof's `#error`: what it says after (`missing #endif`) follows from it
        }
    }
    if out.is_empty() {
        return unlocated(log, x);
    }
    out.join("\n")
}

/// A message at a non-ASCII character (glslang reads bytes: `'<bad token>'`) says which character and why.
fn non_ascii(line: &str, column: usize, message: &str) -> String {
    match line.chars().nth(column.saturating_sub(1)).filter(|c| !c.is_ascii()) {
        Some(c) => format!(
            "{} (`{c}`, U+{:04X}: glslang reads HLSL identifiers and tokens as ASCII letters, digits and _ only; non-ASCII text belongs in comments)",
            message.replace('\u{FFFD}', &c.to_string()),
            u32::from(c)
        ),
        None => message.to_string(),
    }
}

/// glslang's log when it located no message (a link-stage error): recursion named at the user's function that
/// recurses, else the log without the temporary file's name glslang prints first and its closing banner.
fn unlocated(log: &str, x: &Expanded) -> String {
    let call = log.lines().skip_while(|l| !l.contains("Recursion detected")).nth(1);
    // "    f(f1; calling g(f1;": the caller's and the callee's mangled names.
    let name = |s: &str| s.trim().split('(').next().unwrap_or_default().to_string();
    if let Some((caller, callee)) = call.and_then(|c| c.split_once(" calling ")).map(|(a, b)| (name(a), name(b))) {
        let message = format!(
            "recursion: `{caller}` calls `{callee}`, which leads back to it (HLSL shaders, as SPIR-V for Vulkan, cannot recurse)"
        );
        return match definition(x, &caller) {
            Some((file, line, column)) => format!("{file}:{line}:{column}: {message}"),
            None => message,
        };
    }
    let banner = |l: &str| l.trim_end().ends_with("shader.hlsl") || l.starts_with("SPIR-V is not generated");
    log.lines().filter(|l| !banner(l)).collect::<Vec<_>>().join("\n").trim().to_string()
}

/// Where the user's text first names `function(`: (file, 1-based line, 1-based column), lines brdfprof wrote
/// left out.
fn definition(x: &Expanded, function: &str) -> Option<(String, usize, usize)> {
    let ident = |c: char| c.is_ascii_alphanumeric() || c == '_';
    x.lines.iter().enumerate().filter(|(i, _)| !x.generated.contains_key(i)).find_map(|(i, line)| {
        let at = line
            .match_indices(function)
            .map(|(k, _)| k)
            .find(|&k| !line[..k].ends_with(ident) && line[k + function.len()..].trim_start().starts_with('('))?;
        let (file, n) = *x.origins.get(i)?;
        Some((x.files[file].clone(), n, line[..at].chars().count() + 1))
    })
}

/// The front end, with glslang's version, as reports state it.
pub fn describe() -> String {
    let v = crate::glslang::glslang_version()
        .map_or_else(|| "(version unknown)".into(), |v| v.trim_start_matches("Glslang Version:").trim().to_string());
    format!(
        "glslang {v}'s HLSL front end (glslangValidator {}; `half` is 32-bit float, as DXC without -enable-16bit-types)",
        FLAGS.join(" ")
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::GlueArg;

    #[test]
    fn glue_and_stub_text() {
        let g = Glue {
            name: "brdfprof_entry0".into(),
            callee: "Light".into(),
            args: vec![GlueArg::Expr("N".into()), GlueArg::Scratch("Surface".into()), GlueArg::Out("float3".into())],
        };
        assert_eq!(
            glue(&g),
            "float3 brdfprof_entry0(float3 L, float3 V, float3 N, float3 X, float3 Y) { Surface brdfprof_arg1; float3 brdfprof_arg2 = (float3)0; Light(N, brdfprof_arg1, brdfprof_arg2); return brdfprof_arg2; }"
        );
        assert_eq!(
            stub(&["BRDF".into()]),
            "[numthreads(1, 1, 1)] void brdfprof_stub() { float3 v = (float3)0; v += BRDF(v, v, v, v, v); }"
        );
        assert_eq!(param_decl("f0", "vec3"), "static float3 f0;");
    }

    #[test]
    fn glslangs_gl_remainders_become_cs_and_hlsl_keywords_are_known() {
        use rspirv::spirv::Op;
        let inst = |op: Op| [(5 << 16) | op as u32, 1, 2, 3, 4];
        let mut words: Vec<u32> = vec![0x0723_0203, 0x0001_0000, 0, 10, 0];
        for op in [Op::FMod, Op::SMod, Op::UMod, Op::FAdd] {
            words.extend(inst(op));
        }
        assert_eq!(c_remainders(&mut words), 2);
        let ops: Vec<u32> = words[5..].chunks(5).map(|c| c[0] & 0xffff).collect();
        assert_eq!(ops, [Op::FRem, Op::SRem, Op::UMod, Op::FAdd].map(|o| o as u32));
        assert!(
            is_keyword("texture")
                && is_keyword("sample")
                && is_keyword("half3x4")
                && is_keyword("min16float2")
                && is_keyword("template")
        );
        assert!(!is_keyword("Roughness") && !is_keyword("float5") && !is_keyword("half3x5") && !is_keyword("floatx"));
    }

    #[test]
    fn columns_come_from_the_parse_failure_or_the_quoted_token() {
        assert_eq!(token_column("  return x + foo;", "'foo' : unknown variable"), Some(14));
        assert_eq!(token_column("  return food + foo;", "'foo' : unknown variable"), Some(17));
        assert_eq!(
            column("\treturn x * Gloss;", "'Gloss' : unknown variable", Some(19)),
            13,
            "the token, not where parsing stopped"
        );
        assert_eq!(column("   }", "';' : Expected", None), 4);
        assert_eq!(column("  x +* 2;", "'expression' : Expected", Some(6)), 6);
        assert_eq!(parse_columns("x.hlsl(2): error at column 13, HLSL parsing failed."), HashMap::from([(2, 13)]));
        assert_eq!(located("/tmp/a b/shader.hlsl:12: 'x' : y"), Some((12, "'x' : y")));
    }
}
