//! GLSL that includes files (`#include`, as glslang's GL_GOOGLE_include_directive reads it): the includes
//! expanded as for HLSL (`includes`: `--include-dir`, `--include-map`, `--include-override`, `#pragma once`,
//! guards), glslang's GLSL front end over the text with a `main` of its own that calls `BRDF` and each glue
//! function, and spirv-cross back to GLSL, so that messages and per-line cost name the included files' lines.
//! A GLSL shader without an `#include` is composed as written (src/model/brdf_file).

use super::Glue;
use super::includes::Expanded;
use anyhow::{Result, bail};
use std::path::Path;

/// glslang's flags: GLSL, a compute stage, no SPIR-V optimisation, line information.
pub const FLAGS: [&str; 5] = ["-V", "-Od", "-g", "-S", "comp"];

/// The version line the text starts with, as the kernels' own.
pub const VERSION: &str = "#version 450";

/// A parameter as a GLSL global (private to the invocation in a compute shader).
pub fn param_decl(name: &str, glsl_type: &str) -> String {
    format!("{glsl_type} {name};")
}

/// A glue function on one line: `vec3 NAME(vec3 L, ...) { return CALLEE(ARGS); }`, with a local for each
/// `@out`/`@scratch` argument (zero-initialised where its type has a one-argument constructor) and the `@out`
/// one returned.
pub fn glue(g: &Glue) -> String {
    let local =
        |ty: &str, l: &str| if is_numeric(ty) { format!("{ty} {l} = {ty}(0); ") } else { format!("{ty} {l}; ") };
    g.write(&format!("vec3 {}(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y)", g.name), local, str::to_string)
}

/// Whether `T(0)` makes a zero of GLSL type `ty`.
fn is_numeric(ty: &str) -> bool {
    let base = ty.trim_end_matches(|c: char| c.is_ascii_digit() || c == 'x');
    ["float", "double", "int", "uint", "bool", "vec", "dvec", "ivec", "uvec", "bvec", "mat", "dmat"].contains(&base)
}

/// The compute entry: `main`, calling each of `calls`, on one line (spirv-cross's `main` is dropped).
pub fn stub(calls: &[String]) -> String {
    let body: String = calls.iter().map(|c| format!(" v += {c}(v, v, v, v, v);")).collect();
    format!("layout(local_size_x = 1) in; void main() {{ vec3 v = vec3(0.0);{body} }}")
}

/// glslang's GLSL preprocessor on the expanded text: Ok(the text, line for line with `x` but for its `#line`
/// directives) or Err(the messages at the user's files' lines).
pub fn preprocess(
    x: &Expanded,
    defines: &[(String, String)],
    model: &Path,
) -> Result<std::result::Result<String, String>> {
    let what = format!("{} (glslang's GLSL preprocessor)", model.display());
    Ok(super::hlsl::run(x, defines, &["-E", "-S", "comp"], &what)?
        .map(|(out, _)| out)
        .map_err(|log| super::hlsl::messages(&log, x)))
}

/// The shader compiled to SPIR-V, or Err(glslang's messages at the user's files' lines).
pub fn compile(
    x: &Expanded,
    defines: &[(String, String)],
    model: &Path,
) -> Result<std::result::Result<Vec<u32>, String>> {
    let what = format!("{} (glslang's GLSL front end)", model.display());
    Ok(match super::hlsl::run(x, defines, &FLAGS, &what)? {
        Ok((_, Some(bytes))) => Ok(crate::glslang::Spirv::from_bytes(&what, &bytes)?.words.to_vec()),
        Ok((_, None)) => bail!("{what}: glslang wrote no SPIR-V"),
        Err(log) => Err(super::hlsl::messages(&log, x)),
    })
}

/// The front end as reports state it.
pub fn describe() -> String {
    let v = crate::glslang::glslang_version()
        .map_or_else(|| "(version unknown)".into(), |v| v.trim_start_matches("Glslang Version:").trim().to_string());
    format!("GLSL with includes: glslang {v} (glslangValidator {}; includes expanded by brdfprof)", FLAGS.join(" "))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::GlueArg;

    #[test]
    fn glue_and_stub_are_one_line_of_glsl() {
        let g = Glue {
            name: "brdfprof_entry0".into(),
            callee: "shade".into(),
            args: vec![GlueArg::Expr("N".into()), GlueArg::Out("vec3".into()), GlueArg::Scratch("Surface".into())],
        };
        assert_eq!(
            glue(&g),
            "vec3 brdfprof_entry0(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y) { vec3 brdfprof_arg1 = vec3(0); Surface brdfprof_arg2; shade(N, brdfprof_arg1, brdfprof_arg2); return brdfprof_arg1; }"
        );
        let s = stub(&["BRDF".into()]);
        assert!(!s.contains('\n') && s.contains("void main()") && s.contains("v += BRDF(v, v, v, v, v);"));
    }
}
