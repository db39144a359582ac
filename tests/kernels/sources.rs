//! spv/ must be what glslang makes of glsl/ today: recompiles every kernel of glsl/kernels.txt with the
//! flags of glsl/build-spv.sh and compares bytes with the embedded SPIR-V.

use crate::common;
use brdfprof::shaders::KERNELS;
use std::process::Command;

#[test]
fn spv_matches_glsl() {
    let root = common::repo_root();
    let dir = tempfile::tempdir().unwrap();
    let mut stale = Vec::new();
    for k in KERNELS {
        let out = dir.path().join(format!("{}.spv", k.name));
        let mut cmd = Command::new("glslangValidator");
        cmd.args(["-V", "--target-env", "vulkan1.1"]);
        for d in k.defines {
            cmd.arg(format!("-D{d}"));
        }
        cmd.arg("-o").arg(&out).arg(root.join("glsl").join(k.source));
        let status = cmd.output().expect("glslangValidator (install glslang-tools, or run `make setup`)");
        assert!(status.status.success(), "{} does not compile:\n{}", k.source, String::from_utf8_lossy(&status.stdout));
        if std::fs::read(&out).unwrap() != k.spirv {
            stale.push(k.name);
        }
    }
    assert!(stale.is_empty(), "spv/ is stale against glsl/ for {stale:?}: run `make spv` and commit spv/");
}

#[test]
fn kernel_list_covers_every_spv_file() {
    let listed: Vec<String> = KERNELS.iter().map(|k| format!("{}.spv", k.name)).collect();
    for entry in std::fs::read_dir(common::repo_root().join("spv")).unwrap() {
        let name = entry.unwrap().file_name().to_string_lossy().into_owned();
        assert!(listed.contains(&name), "spv/{name} is not in glsl/kernels.txt");
    }
}

#[test]
fn generated_glsl_is_what_the_rust_tables_generate() {
    let dir = common::repo_root().join("glsl/generated");
    for (name, text) in brdfprof::kernels::generated_glsl() {
        let committed = std::fs::read_to_string(dir.join(name)).unwrap_or_default();
        assert!(
            committed == text,
            "glsl/generated/{name} is stale against the Rust tables: run `make spv` and commit glsl/ and spv/"
        );
    }
}

/// The comment right above a GLSL function definition `NAME(`, as one string.
fn comment_above(glsl: &str, name: &str) -> Option<String> {
    let lines: Vec<&str> = glsl.lines().collect();
    let at = lines.iter().position(|l| l.starts_with("real") && l.contains(&format!(" {name}(")))?;
    let mut comment: Vec<&str> = lines[..at].iter().rev().take_while(|l| l.starts_with("//")).copied().collect();
    comment.reverse();
    Some(comment.join(" "))
}

/// Every row of the term tables has its GLSL function in glsl/brdf.glsl, and the citation above it is the
/// table's (the bracketed reference of the Rust citation).
#[test]
fn every_term_has_its_glsl_function_with_the_tables_citation() {
    use brdfprof::brdf::{D, F, Vis};
    let glsl = std::fs::read_to_string(common::repo_root().join("glsl/brdf.glsl")).unwrap();
    let rows: Vec<(&str, &str)> = D::ALL
        .iter()
        .map(|t| (t.glsl_name(), t.citation()))
        .chain(Vis::ALL.iter().map(|t| (t.glsl_name(), t.citation())))
        .chain(F::ALL.iter().map(|t| (t.glsl_name(), t.citation())))
        .collect();
    let mut problems = Vec::new();
    for (name, citation) in rows {
        let reference = citation
            .split('[')
            .nth(1)
            .and_then(|r| r.split(']').next())
            .unwrap_or_else(|| panic!("{name}: citation without [reference]: {citation}"));
        match comment_above(&glsl, name) {
            None => problems.push(format!("{name}: no GLSL function `{name}(` in glsl/brdf.glsl")),
            Some(c) if !c.contains(reference) => {
                problems.push(format!("{name}: the comment above it does not cite [{reference}]: {c}"))
            }
            Some(_) => {}
        }
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}
