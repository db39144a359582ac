//! WGSL alone: naga_oil's imports and shader defs, loops in imported modules, the BRDF signature, `enable f16`.

use super::*;

#[test]
fn wgsl_loops_are_warned_about_in_imported_modules_and_nested_comments_hide_theirs() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    write_lights(&d.join("in.csv"), &[[0.0, 0.6, 0.8]]);
    let sum = "#define_import_path loopy::sum\nfn total() -> f32 {\n    var s = 0.0;\n    for (var i: i32 = 0; i < 100000; i++) { s += 1e-5; }\n    return s;\n}\nfn unused() -> f32 {\n    var s = 0.0;\n    loop { s += 1.0; if s > 3.0 { break; } }\n    return s;\n}\n";
    let lexed = format!(
        "/* outer /* inner */ for (;;) {{}} */\nconst K = 0x1.8p1f;\n{WGSL_BRDF} {{ return vec3<f32>(K) * dot(N, L); }}\n"
    );
    write(
        d,
        &[
            ("mods/sum.wgsl", sum),
            ("m.wgsl", &format!("#import loopy::sum::total\n{WGSL_BRDF} {{ return vec3<f32>(total()); }}\n")),
            ("lex.wgsl", &lexed),
        ],
    );
    let out =
        run_in(d, &["eval", "--model", "m.wgsl", "--include-dir", "mods", "--input", "in.csv", "--output", "o.csv"])
            .ok();
    assert!(
        out.stderr.contains(
            "mods/sum.wgsl:4: a `for` loop of 100000 iterations: lavapipe ends every loop after 65535 iterations"
        ),
        "{}",
        out.stderr
    );
    assert!(!out.stderr.contains("sum.wgsl:9"), "a function the composition leaves out: {}", out.stderr);
    let out = run_in(d, &["eval", "--model", "lex.wgsl", "--input", "in.csv", "--output", "o.csv"]).ok();
    assert!(!out.stderr.contains("loop"), "a `for` in a nested comment: {}", out.stderr);
}

#[test]
fn a_wgsl_brdf_of_another_signature_is_refused_at_its_fn_in_wgsl() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    write_lights(&d.join("in.csv"), &[[0.0, 0.6, 0.8]]);
    write(
        d,
        &[(
            "n3.wgsl",
            "// the BRDF\n  fn BRDF(L: vec3<f32>, V: vec3<f32>, N: vec3<f32>, X: vec3<f32>, Y: vec3<f32>) -> f32 { return 1.0; }\n",
        )],
    );
    run_in(d, &["eval", "--model", "n3.wgsl", "--input", "in.csv", "--output", "x.csv"])
        .fails(2, &format!("n3.wgsl:2:3: `BRDF` must be defined as `{WGSL_BRDF}`"))
        .fails(2, "-> f32`");
}

#[test]
fn a_quoted_wgsl_import_is_found_beside_the_importing_module() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    write_lights(&d.join("in.csv"), &[[0.0, 0.6, 0.8]]);
    // m.wgsl imports "mods/a.wgsl" (beside it), which imports "b.wgsl" beside itself, as an HLSL include is found;
    // n.wgsl, named bare, finds the module `named::c` declared beside it.
    write(
        d,
        &[
            ("m.wgsl", &format!("#import \"mods/a.wgsl\"::a\n{WGSL_BRDF} {{ return vec3<f32>(a()); }}\n")),
            ("mods/a.wgsl", "#import \"b.wgsl\"::b\nfn a() -> f32 { return b() + 1.0; }\n"),
            ("mods/b.wgsl", "fn b() -> f32 { return 2.0; }\n"),
            ("n.wgsl", &format!("#import named::c::c\n{WGSL_BRDF} {{ return vec3<f32>(c()); }}\n")),
            ("c.wgsl", "#define_import_path named::c\nfn c() -> f32 { return 5.0; }\n"),
        ],
    );
    run_in(d, &["eval", "--model", "m.wgsl", "--input", "in.csv", "--output", "o.csv"]).ok();
    assert!(
        common::csv_values(&d.join("o.csv")).iter().all(|v| *v == [3.0; 3]),
        "{:?}",
        common::csv_values(&d.join("o.csv"))
    );
    run_in(d, &["eval", "--model", "n.wgsl", "--input", "in.csv", "--output", "o.csv"]).ok();
    assert!(common::csv_values(&d.join("o.csv")).iter().all(|v| *v == [5.0; 3]));
}

/// `enable f16` (naga's front end takes it): a WGSL GGX distribution in half precision evaluates within
/// f16's error of its f32 twin, and not bit-identically (the halves are really computed in half precision). The
/// bound: f16 rounds N.H by up to 2^-11; D's denominator 1 - (1 - a^2) N.H^2 at N.H near 1 and a = 0.25 is then
/// off by about 1.9 x 2^-11 of its 0.0625, about 1.5%, squared about 3%; 5% allowed.
#[test]
fn wgsl_enable_f16_computes_in_half_precision_within_its_rounding() {
    let dir = tempfile::tempdir().unwrap();
    let half = |n: &str| root().join("tests/fixtures/wgsl/half").join(n).display().to_string();
    run_in(
        dir.path(),
        &[
            "diff",
            "--model",
            &half("d-ggx-f32.wgsl"),
            "--model",
            &half("d-ggx-f16.wgsl"),
            "--samples",
            "2000",
            "--json",
            "d.json",
            "--tolerance",
            "0.05",
        ],
    )
    .ok();
    let d: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("d.json")).unwrap()).unwrap();
    for c in d["difference"]["channels"].as_array().unwrap() {
        let max = c["max_rel"].as_f64().unwrap();
        assert!(max > 1e-4 && max <= 0.05, "channel {}: max relative difference {max}", c["channel"]);
        assert_eq!(c["mismatched_nonfinite"], 0);
    }
    // A GPU without shaderFloat16 (GCN 1 in Mesa 22.3) leaves the half model out with the reason, as it does a
    // built-in precision=f16 spec, instead of crashing its compiler.
    let out = run_in(
        dir.path(),
        &[
            "inspect",
            "--no-callgrind",
            "--device",
            "radv:tahiti",
            "--model",
            &half("d-ggx-f16.wgsl"),
            "--json",
            "t.json",
            "--markdown",
            "t.md",
        ],
    )
    .ok();
    let md = std::fs::read_to_string(dir.path().join("t.md")).unwrap();
    assert!(md.contains("d-ggx-f16.wgsl") && md.contains("has no shaderFloat16"), "{}\n{md}", out.stderr);
}

/// A Bevy-style module that needs shader defs: without them the error lists each def by name at its file,
/// line and column with the --define to pass; with them the model evaluates to the branch they select.
#[test]
fn shader_defs_an_import_graph_needs_are_listed_by_name_where_missing() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    write_rows(&d.join("in.csv"), 2);
    std::fs::create_dir_all(d.join("mods")).unwrap();
    std::fs::write(
        d.join("mods/lights.wgsl"),
        "#define_import_path test::lights\n\nconst MAX_LIGHTS: i32 = #{MAX_LIGHTS};\n\nfn gain() -> f32 {\n#if CASCADES == 4\n    return 0.5 * f32(MAX_LIGHTS) / 8.0;\n#else\n    return 1.0;\n#endif\n}\n",
    )
    .unwrap();
    std::fs::write(
        d.join("m.wgsl"),
        "#import test::lights::gain\nfn BRDF(L: vec3<f32>, V: vec3<f32>, N: vec3<f32>, X: vec3<f32>, Y: vec3<f32>) -> vec3<f32> {\n    return vec3<f32>(gain());\n}\n",
    )
    .unwrap();
    let eval = |defines: &[&str]| {
        let mut args =
            vec!["eval", "--model", "m.wgsl", "--include-dir", "mods", "--input", "in.csv", "--output", "x.csv"];
        args.extend(defines.iter().flat_map(|v| ["--define", *v]));
        run_in(d, &args)
    };
    let out = eval(&[]).fails(2, "shader defs the shader and its imports use that no define gives: ");
    for needle in [
        "MAX_LIGHTS (mods/lights.wgsl:3:27 `const MAX_LIGHTS",
        "CASCADES (mods/lights.wgsl:6:5 `#if CASCADES == 4`)",
        "--define MAX_LIGHTS=VALUE --define CASCADES=VALUE",
    ] {
        assert!(out.stderr.contains(needle), "{needle}: {}", out.stderr);
    }
    eval(&["MAX_LIGHTS=8"]).fails(2, "CASCADES (mods/lights.wgsl:6:5");
    eval(&["MAX_LIGHTS=8", "CASCADES=4"]).ok();
    let text = std::fs::read_to_string(d.join("x.csv")).unwrap();
    assert!(text.lines().skip(1).all(|l| l.rsplit(',').next().unwrap().trim() == "0.5"), "{text}");
}
