//! Slang as a language (`.slang` files, `::begin shader slang`), GLSL that includes files, and engine headers
//! replaced by stubs: the same GGX distribution written four ways (tests/fixtures/slang) evaluates alike and
//! equals the formula; messages and the cache follow the files.

use crate::common;
use std::path::Path;

fn fixtures() -> std::path::PathBuf {
    common::repo_root().join("tests/fixtures/slang")
}

/// `n` rows of normals, views and lights with N.L > 0 and N.V > 0 mostly.
fn write_rows(path: &Path, n: usize) {
    let mut s = String::from("nx,ny,nz,vx,vy,vz,lx,ly,lz,roughness,f0r,f0g,f0b\n");
    let mut next = common::uniform(0x9e37_79b9_7f4a_7c15);
    for _ in 0..n {
        let v: Vec<f64> = (0..9).map(|_| next()).collect();
        let d = |k: usize| [2.0 * v[k] - 1.0, 2.0 * v[k + 1] - 1.0, 2.0 * v[k + 2] + 0.2];
        let (nn, vv, ll) = (d(0), d(3), d(6));
        s += &format!(
            "{},{},{},{},{},{},{},{},{},0.5,0.04,0.04,0.04\n",
            nn[0], nn[1], nn[2], vv[0], vv[1], vv[2], ll[0], ll[1], ll[2]
        );
    }
    std::fs::write(path, s).unwrap();
}

/// GGX's D (Walter et al. 2007, alpha = 0.25) at each row of `input`, in f64.
fn ggx_d(input: &Path) -> Vec<f64> {
    let text = std::fs::read_to_string(input).unwrap();
    text.lines()
        .skip(1)
        .map(|row| {
            let v: Vec<f64> = row.split(',').map(|x| x.parse().unwrap()).collect();
            let at = |k: usize| glam::DVec3::new(v[k], v[k + 1], v[k + 2]).normalize();
            let noh = at(0).dot((at(3) + at(6)).normalize()).clamp(0.0, 1.0);
            let a2 = 0.25f64 * 0.25;
            let d = (noh * a2 - noh) * noh + 1.0;
            if noh > 0.0 { a2 / (std::f64::consts::PI * d * d) } else { 0.0 }
        })
        .collect()
}

fn eval(dir: &Path, model: &str, extra: &[&str], out: &str) -> Vec<[f64; 3]> {
    let mut args = vec!["eval", "--model", model, "--input", "in.csv", "--output", out];
    args.extend(extra);
    common::run_in(dir, &args).ok();
    common::csv_values(&dir.join(out))
}

#[test]
fn a_slang_model_with_a_module_an_interface_a_generic_and_a_variadic_macro_evaluates_as_its_glsl_and_hlsl_twins() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    write_rows(&d.join("in.csv"), 400);
    let f = fixtures();
    let file = |name: &str| f.join(name).display().to_string();
    let include = f.display().to_string();
    let expected = ggx_d(&d.join("in.csv"));
    let runs = [
        ("slang", eval(d, &file("ggx-d.slang"), &["--include-dir", &include], "slang.csv")),
        ("slang section", eval(d, &file("ggx-d-slang.brdf"), &["--include-dir", &include], "section.csv")),
        ("glsl with #include", eval(d, &file("ggx-d-glsl.brdf"), &[], "glsl.csv")),
        (
            "hlsl, header replaced",
            eval(
                d,
                &file("ggx-d.hlsl"),
                &["--include-override", &format!("globals.hlsli={}", file("stub.hlsli"))],
                "hlsl.csv",
            ),
        ),
    ];
    assert!(expected.iter().filter(|&&x| x > 0.1).count() > 100, "most rows are lit");
    for (what, got) in &runs {
        assert_eq!(got.len(), expected.len(), "{what}");
        for (g, e) in got.iter().zip(&expected) {
            assert!((g[0] - e).abs() <= 1e-5 * e.max(1.0), "{what}: {} against GGX's D {e}", g[0]);
        }
        for (g, s) in got.iter().zip(&runs[0].1) {
            assert!(
                (g[0] - s[0]).abs() <= 1e-5 * s[0].abs().max(1.0),
                "{what}: {} against the Slang file's {}",
                g[0],
                s[0]
            );
        }
    }
}

#[test]
fn the_front_ends_are_named_with_the_headers_replaced() {
    let f = fixtures();
    let r = common::run_in(
        &f,
        &[
            "diff",
            "--model",
            "ggx-d.slang,include=.",
            "--model",
            "ggx-d.hlsl,include-override=globals.hlsli=stub.hlsli",
            "--model",
            "ggx-d-glsl.brdf",
            "--reference",
            "ggx",
            "--samples",
            "500",
            "--json",
            "-",
        ],
    );
    assert_eq!(r.code, Some(0), "{}", r.stderr);
    assert!(r.stdout.contains("Slang: Slang's slangc"), "{}", r.stdout);
    assert!(r.stdout.contains("GLSL with includes: glslang"), "{}", r.stdout);
    assert!(r.stdout.contains("headers replaced: `globals.hlsli` by stub.hlsli"), "{}", r.stdout);
}

/// A copy of the fixtures in a folder of the test's own, to edit.
fn copy_fixtures(to: &Path) {
    for e in walk(&fixtures()) {
        let rel = e.strip_prefix(fixtures()).unwrap();
        std::fs::create_dir_all(to.join(rel).parent().unwrap()).unwrap();
        std::fs::copy(&e, to.join(rel)).unwrap();
    }
}

fn walk(dir: &Path) -> Vec<std::path::PathBuf> {
    let mut out = Vec::new();
    for e in std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().path()) {
        if e.is_dir() { out.extend(walk(&e)) } else { out.push(e) }
    }
    out
}

#[test]
fn a_slang_compile_is_cached_until_a_module_it_imports_changes() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    copy_fixtures(d);
    write_rows(&d.join("in.csv"), 50);
    let cache = d.join("cache");
    let run = |out: &str| {
        let args = ["eval", "--model", "ggx-d.slang", "--include-dir", ".", "--input", "in.csv", "--output", out];
        let o = common::brdfprof().args(args).current_dir(d).env("BRDFPROF_CACHE_DIR", &cache).output().unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        common::csv_values(&d.join(out))
    };
    let first = run("a.csv");
    let entries = || {
        std::fs::read_dir(&cache)
            .unwrap()
            .filter(|e| e.as_ref().unwrap().path().to_string_lossy().ends_with(".slang_spv"))
            .count()
    };
    assert_eq!(entries(), 1, "slangc's SPIR-V is cached");
    assert_eq!(run("b.csv"), first, "the cached compile gives the same values");
    assert_eq!(entries(), 1, "the same text and modules: no new entry");
    let module = d.join("Rendering/Microfacet.slang");
    let text = std::fs::read_to_string(&module).unwrap();
    std::fs::write(&module, text.replace("return a2 / (kPi * d * d);", "return 2.0 * a2 / (kPi * d * d);")).unwrap();
    let changed = run("c.csv");
    for (c, f) in changed.iter().zip(&first) {
        assert!(
            (c[0] - 2.0 * f[0]).abs() <= 1e-5 * f[0].max(1.0),
            "the edited module is compiled: {} against 2 x {}",
            c[0],
            f[0]
        );
    }
}

#[test]
fn slang_and_included_glsl_errors_are_named_at_their_own_files_lines() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    copy_fixtures(d);
    let module = d.join("Rendering/Microfacet.slang");
    let text = std::fs::read_to_string(&module).unwrap();
    std::fs::write(&module, text.replace("float a2 = alpha * alpha;", "float a2 = alpha * alhpa;")).unwrap();
    let r = common::run_in(d, &["diff", "--model", "ggx-d.slang,include=.", "--reference", "ggx", "--samples", "10"]);
    r.fails(2, "Rendering/Microfacet.slang:20:");
    std::fs::write(&module, text).unwrap();
    std::fs::write(d.join("bad.slang"), "import Rendering.Microfacet;\nfloat3 BRDF(float3 L, float3 V, float3 N, float3 X, float3 Y)\n{\n    return float3(undefined_name);\n}\n").unwrap();
    let r = common::run_in(d, &["diff", "--model", "bad.slang,include=.", "--reference", "ggx", "--samples", "10"]);
    r.fails(2, "bad.slang:4:19: undefined identifier");
    // GLSL: a missing header at the include's line; an error in a header at the header's line.
    std::fs::write(d.join("missing.brdf"), "analytic\n::begin shader\n#include \"nowhere.glsl\"\nvec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y) { return L; }\n::end shader\n").unwrap();
    let r = common::run_in(d, &["diff", "--model", "missing.brdf", "--reference", "ggx", "--samples", "10"]);
    r.fails(2, "missing.brdf:3");
    let common_glsl = std::fs::read_to_string(d.join("common.glsl")).unwrap();
    std::fs::write(
        d.join("common.glsl"),
        common_glsl.replace("return a2 / (M_PI * d * d);", "return a2 / (M_PI * d * e);"),
    )
    .unwrap();
    let r = common::run_in(d, &["diff", "--model", "ggx-d-glsl.brdf", "--reference", "ggx", "--samples", "10"]);
    r.fails(2, "common.glsl:10:");
}

#[test]
fn a_fragment_shaders_interface_in_an_included_glsl_header_is_dropped_and_said_there() {
    let tmp = tempfile::tempdir().unwrap();
    let d = tmp.path();
    std::fs::write(
        d.join("io.glsl"),
        "in vec3 WorldPos;\nlayout(location = 0) out vec4 FragColor;\nuniform float exposure;\n",
    )
    .unwrap();
    std::fs::write(
        d.join("pasted.brdf"),
        "analytic\n::begin shader\n#include \"io.glsl\"\nvec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y)\n{\n    return vec3(max(dot(N, L), 0.0));\n}\n::end shader\n",
    )
    .unwrap();
    write_rows(&d.join("in.csv"), 20);
    let r =
        common::run_in(d, &["eval", "--model", "pasted.brdf", "--input", "in.csv", "--output", "out.csv", "--verbose"])
            .ok();
    assert!(r.stderr.contains("io.glsl:1: `in` dropped from `WorldPos`"), "{}", r.stderr);
    assert!(r.stderr.contains("io.glsl:2: `layout(location=0) out` dropped from `FragColor`"), "{}", r.stderr);
    assert!(r.stderr.contains("io.glsl:3: `uniform` dropped from `exposure`"), "{}", r.stderr);
    assert!(common::csv_values(&d.join("out.csv")).iter().any(|v| v[0] > 0.1));
}
