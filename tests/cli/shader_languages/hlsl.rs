//! HLSL alone: DXC's and glslang's readings of engines' HLSL (defines, `#pragma once`, include guards, `#line`,
//! `fmod`, minimum precision, DXC-era code through Slang's slangc, the front-end choice, include overrides).

use super::*;

#[test]
fn an_hlsl_define_selects_its_branch() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    write_rows(&d.join("in.csv"), 4);
    std::fs::write(d.join("q.hlsl"), "#ifndef QUALITY\n#define QUALITY 0\n#endif\nfloat3 BRDF(float3 L, float3 V, float3 N, float3 X, float3 Y)\n{\n#if QUALITY >= 2\n\treturn 2;\n#else\n\treturn 1;\n#endif\n}\n").unwrap();
    run_in(d, &["eval", "--model", "q.hlsl", "--input", "in.csv", "--output", "a.csv"]).ok();
    run_in(d, &["eval", "--model", "q.hlsl", "--define", "QUALITY=2", "--input", "in.csv", "--output", "b.csv"]).ok();
    run_in(d, &["eval", "--model", "q.hlsl,define=QUALITY=3", "--input", "in.csv", "--output", "c.csv"]).ok();
    assert!(common::csv_values(&d.join("a.csv")).iter().all(|v| *v == [1.0; 3]));
    assert!(
        common::csv_values(&d.join("b.csv"))
            .iter()
            .chain(&common::csv_values(&d.join("c.csv")))
            .all(|v| *v == [2.0; 3])
    );
}

#[test]
fn a_loop_in_an_included_header_is_warned_about_at_its_own_line() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    write_rows(&d.join("in.csv"), 2);
    std::fs::create_dir(d.join("inc")).unwrap();
    std::fs::write(d.join("inc/sum.ush"), "#pragma once\nfloat Sum()\n{\n\tfloat s = 0;\n\t[loop] for (int i = 0; i < 100000; i++) { s += 1e-5; }\n\treturn s;\n}\n").unwrap();
    std::fs::write(
        d.join("m.usf"),
        "#include \"sum.ush\"\nfloat3 BRDF(float3 L, float3 V, float3 N, float3 X, float3 Y) { return Sum(); }\n",
    )
    .unwrap();
    let out =
        run_in(d, &["eval", "--model", "m.usf", "--include-dir", "inc", "--input", "in.csv", "--output", "o.csv"]).ok();
    assert!(
        out.stderr.contains(
            "inc/sum.ush:5: a `for` loop of 100000 iterations: lavapipe ends every loop after 65535 iterations"
        ),
        "{}",
        out.stderr
    );
}

#[test]
fn hlsl_fmod_and_float_remainder_keep_the_sign_of_the_dividend() {
    // HLSL's fmod and float % are C's (DXC's OpFRem), not GLSL's mod; integer % truncates.
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    write_lights(&d.join("in.csv"), &[[-0.6, 0.0, 0.8], [0.6, 0.0, 0.8]]);
    let hlsl = format!(
        "{HLSL_BRDF}\n{{\n\tfloat a = L.x * 3.0;\n\tint i = (int)round(L.x * 10.0);\n\treturn float3(fmod(a, 1.0), a % 1.0, (float)(i % 4));\n}}\n"
    );
    let wgsl = format!(
        "{WGSL_BRDF} {{\n    let a = L.x * 3.0;\n    let i = i32(round(L.x * 10.0));\n    return vec3<f32>(a % 1.0, a % 1.0, f32(i % 4));\n}}\n"
    );
    write(d, &[("m.hlsl", &hlsl), ("m.wgsl", &wgsl)]);
    for m in ["m.hlsl", "m.wgsl"] {
        run_in(d, &["eval", "--model", m, "--input", "in.csv", "--output", "o.csv"]).ok();
        let v = common::csv_values(&d.join("o.csv"));
        for (row, want) in v.iter().zip([[-0.8, -0.8, -2.0], [0.8, 0.8, 2.0]]) {
            assert!((0..3).all(|c| (row[c] - want[c]).abs() < 1e-5), "{m}: {row:?}, expected {want:?}");
        }
    }
}

#[test]
fn pragma_once_holds_across_spellings_of_one_path_and_angle_includes_search_the_include_dirs_alone() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    write_lights(&d.join("in.csv"), &[[0.0, 0.6, 0.8]]);
    let includes =
        ["a.ush", "./a.ush", "sub/../a.ush", "<b.ush>", "b.ush", "/Eng/Private/c.ush", "/Eng/Private/../Private/c.ush"];
    let lines: String = includes
        .iter()
        .map(|i| if i.starts_with('<') { format!("#include {i}\n") } else { format!("#include \"{i}\"\n") })
        .collect();
    let model =
        format!("analytic\n::begin shader hlsl\n{lines}{HLSL_BRDF} {{ return A() + B() + C(); }}\n::end shader\n");
    let angle =
        format!("analytic\n::begin shader hlsl\n#include <a.ush>\n{HLSL_BRDF} {{ return A(); }}\n::end shader\n");
    write(
        d,
        &[
            ("m.brdf", &model),
            ("n.brdf", &angle),
            ("a.ush", "#pragma once\nfloat A() { return 1; }\n"),
            ("sub/x.ush", ""),
            ("inc/b.ush", "#pragma once\nfloat B() { return 2; }\n"),
            ("eng/Private/c.ush", "#pragma once\nfloat C() { return 4; }\n"),
        ],
    );
    let flags = ["--include-dir", "inc", "--include-map", "/Eng=eng", "--input", "in.csv"];
    let args =
        |m: &'static str| ["eval", "--model", m, "--output", "o.csv"].into_iter().chain(flags).collect::<Vec<_>>();
    run_in(d, &args("m.brdf")).ok();
    assert!(
        common::csv_values(&d.join("o.csv")).iter().all(|v| *v == [7.0; 3]),
        "{:?}",
        common::csv_values(&d.join("o.csv"))
    );
    // `<a.ush>` is not looked for beside the model.
    run_in(d, &args("n.brdf")).fails(2, "n.brdf:3:10: cannot find include `a.ush` (searched: inc)");
}

#[test]
fn an_include_guard_with_an_else_of_its_own_is_no_guard() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    write_lights(&d.join("in.csv"), &[[0.0, 0.6, 0.8]]);
    let model = format!(
        "analytic\n::begin shader hlsl\n#include \"g.ush\"\n#include \"g.ush\"\n{HLSL_BRDF} {{ return A() + A2(); }}\n::end shader\n"
    );
    write(
        d,
        &[
            ("m.brdf", &model),
            ("g.ush", "#ifndef A_H\n#define A_H\nfloat A() { return 1; }\n#else\nfloat A2() { return 2; }\n#endif\n"),
        ],
    );
    run_in(d, &["eval", "--model", "m.brdf", "--input", "in.csv", "--output", "o.csv"]).ok();
    assert!(common::csv_values(&d.join("o.csv")).iter().all(|v| *v == [3.0; 3]));
}

#[test]
fn a_line_directive_in_an_hlsl_header_is_dropped_with_a_warning() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    write_lights(&d.join("in.csv"), &[[0.0, 0.6, 0.8]]);
    let model =
        format!("analytic\n::begin shader hlsl\n#include \"lined.ush\"\n{HLSL_BRDF} {{ return H(); }}\n::end shader\n");
    write(
        d,
        &[
            ("m.brdf", &model),
            ("lined.ush", "#pragma once\n#line 500\nfloat H() { return 1; }\n"),
            ("bad.ush", "#pragma once\n#line 500\nfloat H() { return nope; }\n"),
        ],
    );
    let out = run_in(d, &["eval", "--model", "m.brdf", "--input", "in.csv", "--output", "o.csv"]).ok();
    assert!(
        out.stderr.contains("lined.ush:2: `#line 500` is dropped: brdfprof numbers the file's lines itself"),
        "{}",
        out.stderr
    );
    // An error after it is at the header's own line.
    std::fs::write(d.join("m.brdf"), model.replace("lined.ush", "bad.ush")).unwrap();
    run_in(d, &["eval", "--model", "m.brdf", "--input", "in.csv", "--output", "x.csv"])
        .fails(2, "bad.ush:3:20: 'nope' : unknown variable");
}

#[test]
fn generated_hlsl_lines_are_named_and_resources_and_keywords_are_refused_at_their_lines() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    write_lights(&d.join("in.csv"), &[[0.0, 0.6, 0.8]]);
    // An unknown name in an entry's argument: the `entry` line, named, not a column of the generated glue.
    let light = std::fs::read_to_string(ue("ue-light.brdf")).unwrap();
    let line = light.lines().position(|l| l.starts_with("entry SpecularLight(")).unwrap() + 1;
    std::fs::write(
        d.join("light.brdf"),
        light.replace("entry SpecularLight(N, V, L, Roughness,", "entry SpecularLight(N, V, L, Rough,"),
    )
    .unwrap();
    run_with_includes(d, &["eval", "--model", "light.brdf", "--input", "in.csv", "--output", "x.csv"])
        .fails(2, &format!("light.brdf:{line}:1: entry `SpecularLight`: 'Rough' : unknown variable"));
    let param = |name: &str| {
        format!(
            "analytic\n::begin parameters\nfloat {name} 0 1 0.5\n::end parameters\n::begin shader hlsl\n{HLSL_BRDF} {{ return {name} * dot(N, L); }}\n::end shader\n"
        )
    };
    write(
        d,
        &[
            ("kw.brdf", &param("texture")),
            (
                "g.hlsl",
                &format!("/* Gloss: how glossy */\nfloat Gloss;\n{HLSL_BRDF} {{ return Gloss * dot(N, L); }}\n"),
            ),
        ],
    );
    run_in(d, &["eval", "--model", "kw.brdf", "--input", "in.csv", "--output", "x.csv"])
        .fails(2, "kw.brdf:3: parameter `texture`: a keyword of HLSL");
    // A global without `static` is a uniform of HLSL's $Global constant buffer: its declaration, not a comment.
    run_in(d, &["eval", "--model", "g.hlsl", "--input", "in.csv", "--output", "x.csv"])
        .fails(2, "g.hlsl:2:7: `Gloss` is a global without `static`")
        .fails(2, "declare it `static`");
    assert!(!d.join("x.csv").exists());
}

/// HLSL as engines write it, read as a compiler would: a return semantic on BRDF, a main file that includes
/// itself after `#pragma once`, a shader global `_x` beside parameter `x`, a chain of 120 `#pragma once`
/// headers (past glslang's `#ifdef` nesting limit had each been wrapped); and a NUL byte or an error after
/// lone-CR line ends named at its own file, line and column.
#[test]
fn hlsl_read_as_a_compiler_reads_it() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    write_rows(&d.join("in.csv"), 2);
    let entry = |body: &str| {
        format!("float3 BRDF(float3 L, float3 V, float3 N, float3 X, float3 Y){body}\n{{\n\treturn Gain().xxx;\n}}\n")
    };
    std::fs::write(d.join("gain.ush"), "#pragma once\nfloat Gain() { return 0.5; }\n").unwrap();
    std::fs::write(d.join("sv.hlsl"), format!("#include \"gain.ush\"\n{}", entry(" : SV_Target"))).unwrap();
    std::fs::write(
        d.join("self.hlsl"),
        format!("#pragma once\n#include \"self.hlsl\"\n#include \"gain.ush\"\n{}", entry("")),
    )
    .unwrap();
    std::fs::write(
        d.join("global.brdf"),
        "analytic\n::begin parameters\nfloat x 0 1 0.5\n::end parameters\n::begin shader hlsl\nstatic float _x = 2.0;\nfloat Gain() { return x * _x * 0.5; }\nfloat3 BRDF(float3 L, float3 V, float3 N, float3 X, float3 Y)\n{\n\treturn Gain().xxx;\n}\n::end shader\n",
    )
    .unwrap();
    for k in 0..120 {
        let next =
            if k + 1 < 120 { format!("#include \"h{}.ush\"\n", k + 1) } else { "#include \"gain.ush\"\n".into() };
        std::fs::write(d.join(format!("h{k}.ush")), format!("#pragma once\n{next}float H{k}() {{ return 1.0; }}\n"))
            .unwrap();
    }
    std::fs::write(d.join("deep.hlsl"), format!("#include \"h0.ush\"\n#include \"h1.ush\"\n{}", entry(""))).unwrap();
    for model in ["sv.hlsl", "self.hlsl", "global.brdf,x=0.5", "deep.hlsl"] {
        run_in(d, &["eval", "--model", model, "--input", "in.csv", "--output", "v.csv"]).ok();
        let text = std::fs::read_to_string(d.join("v.csv")).unwrap();
        assert!(text.lines().skip(1).all(|l| l.split(',').all(|v| v.trim() == "0.5")), "{model}: {text}");
    }
    std::fs::write(d.join("nul.ush"), b"float Gain() { return 0.5; }\n  \x00\n").unwrap();
    std::fs::write(d.join("nul.hlsl"), format!("#include \"nul.ush\"\n{}", entry(""))).unwrap();
    run_in(d, &["eval", "--model", "nul.hlsl", "--input", "in.csv", "--output", "x.csv"])
        .fails(2, "nul.ush:2:3: a NUL byte (U+0000)");
    std::fs::write(
        d.join("cr.ush"),
        "// old Mac line ends\rfloat Gain() { return 0.5; }\rfloat Bad() { return nowhere; }\r",
    )
    .unwrap();
    std::fs::write(d.join("cr.hlsl"), format!("#include \"cr.ush\"\n{}", entry(""))).unwrap();
    run_in(d, &["eval", "--model", "cr.hlsl", "--input", "in.csv", "--output", "x.csv"]).fails(2, "cr.ush:3:");
}

/// DXC-era HLSL (static factories returning their own struct, inheritance, select(), a member calling a static
/// member unqualified) goes through Slang's slangc where glslang refuses it or crashes: the same values as its
/// GLSL twin, the front end named in the report; without slangc, glslang's refusal (a crash named with its
/// signal) and `make setup`, exit 2.
#[test]
fn dxc_era_hlsl_goes_through_slang_where_glslang_refuses_or_crashes() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    write_rows(&d.join("in.csv"), 400);
    let slang = |f: &str| root().join("tests/fixtures/hlsl/slang").join(f).display().to_string();
    let out = run_in(d, &["eval", "--model", &slang("dxc-era.hlsl"), "--input", "in.csv", "--output", "h.csv"]).ok();
    assert!(
        out.stderr.contains("refused the shader") && out.stderr.contains("Slang's slangc compiled it"),
        "{}",
        out.stderr
    );
    run_in(d, &["eval", "--model", &slang("dxc-era-twin.brdf"), "--input", "in.csv", "--output", "g.csv"]).ok();
    let (h, g) = (common::csv_values(&d.join("h.csv")), common::csv_values(&d.join("g.csv")));
    assert!(g.iter().filter(|v| v[0] > 0.0).count() > 20, "lit rows");
    for (x, y) in h.iter().zip(&g) {
        for c in 0..3 {
            assert!(common::rel_err(x[c], y[c]) <= 1e-6, "{x:?} against the twin's {y:?}");
        }
    }
    // The report names the front end that compiled it.
    run_in(
        d,
        &[
            "inspect",
            "--no-callgrind",
            "--device",
            "nvidia:sm_89",
            "--model",
            &slang("dxc-era.hlsl"),
            "--json",
            "i.json",
            "--markdown",
            "i.md",
        ],
    )
    .ok();
    let md = std::fs::read_to_string(d.join("i.md")).unwrap();
    assert!(md.contains("HLSL: Slang's slangc") && md.contains("glslang refused the shader"), "{md}");
    // glslang crashes on a member calling a static member unqualified: named as a crash, and Slang takes it.
    write(
        d,
        &[(
            "crash.hlsl",
            "struct Ndf {\n    float a2;\n    static float square(float x) { return x * x; }\n    float eval(float c) { return a2 / square(c); }\n};\nfloat3 BRDF(float3 L, float3 V, float3 N, float3 X, float3 Y) {\n    Ndf n; n.a2 = 0.25;\n    return n.eval(max(dot(N, L), 0.5)).xxx;\n}\n",
        )],
    );
    run_in(d, &["eval", "--model", "crash.hlsl", "--input", "in.csv", "--output", "c.csv"]).ok();
    for (model, needle) in
        [("crash.hlsl", "crashed (signal 11 SIGSEGV)"), (&slang("dxc-era.hlsl"), "'member type' : Expected")]
    {
        let stderr = eval_without_slang(d, &["--model", model]);
        assert!(stderr.contains(needle) && stderr.contains("run `make setup`"), "{stderr}");
    }
}

/// `--hlsl-front-end` / `hlsl-front-end=` chooses one HLSL front end alone: Slang's slangc for a shader glslang
/// takes gives the same values and is named in the report; glslang alone reports its own refusal of DXC-era
/// HLSL without trying Slang; two different choices, an unknown one, and slangc chosen but not installed are
/// refused (exit 2), naming the spec item or `make setup`.
#[test]
fn the_hlsl_front_end_can_be_chosen() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    write_rows(&d.join("in.csv"), 200);
    write(
        d,
        &[(
            "plain.hlsl",
            "static const float PI = 3.14159265;\nfloat3 BRDF(float3 L, float3 V, float3 N, float3 X, float3 Y) {\n    float3 H = normalize(L + V);\n    float NoH = saturate(dot(N, H));\n    return (pow(NoH, 32.0) * 34.0 / (8.0 * PI)).xxx;\n}\n",
        )],
    );
    let eval = |args: &[&str], out: &str| {
        let mut all = vec!["eval", "--input", "in.csv", "--output", out];
        all.extend(args);
        run_in(d, &all)
    };
    eval(&["--model", "plain.hlsl"], "g.csv").ok();
    eval(&["--model", "plain.hlsl", "--hlsl-front-end", "slang"], "s.csv").ok();
    let (g, s) = (common::csv_values(&d.join("g.csv")), common::csv_values(&d.join("s.csv")));
    assert!(g.iter().filter(|v| v[0] > 0.0).count() > 20, "lit rows");
    for (x, y) in s.iter().zip(&g) {
        assert!(common::rel_err(x[0], y[0]) <= 1e-6, "slangc's {x:?} against glslang's {y:?}");
    }
    let inspect = ["inspect", "--no-callgrind", "--device", "nvidia:sm_89", "--json", "i.json", "--markdown", "i.md"];
    run_in(d, &[&inspect[..], &["--model", "plain.hlsl,hlsl-front-end=slang"]].concat()).ok();
    let md = std::fs::read_to_string(d.join("i.md")).unwrap();
    assert!(md.contains("HLSL: Slang's slangc") && md.contains("chosen: hlsl-front-end=slang"), "{md}");
    let dxc = root().join("tests/fixtures/hlsl/slang/dxc-era.hlsl").display().to_string();
    let refused =
        eval(&["--model", &format!("{dxc},hlsl-front-end=glslang")], "x.csv").fails(2, "'member type' : Expected");
    assert!(!refused.stderr.contains("Slang"), "glslang alone: {}", refused.stderr);
    eval(&["--model", "plain.hlsl,hlsl-front-end=glslang", "--hlsl-front-end", "slang"], "x.csv")
        .fails(2, "`hlsl-front-end=glslang` and `hlsl-front-end=slang` choose two HLSL front ends");
    eval(&["--model", "plain.hlsl,hlsl-front-end=dxc"], "x.csv").fails(2, "expected hlsl-front-end=auto|glslang|slang");
    let stderr = eval_without_slang(d, &["--model", "plain.hlsl", "--hlsl-front-end", "slang"]);
    assert!(stderr.contains("hlsl-front-end=slang: Slang's slangc is not installed: run `make setup`"), "{stderr}");
}

/// DXC's minimum-precision overloads (distinct types for overloading, 32-bit with 16-bit types off): a
/// `min16float` overload beside its `float` twin, written directly or made by a macro as engines' headers do,
/// evaluates in both front ends, the 32-bit one taken, the dropped one said once at its line.
#[test]
fn min16float_overloads_beside_their_float_twins_evaluate_in_both_front_ends() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let seven = "float Sq(float x) { return x * x; }\nmin16float Sq(min16float x) { return x * x; }\nfloat3 BRDF(float3 L, float3 V, float3 N, float3 X, float3 Y)\n{\n    float nl = max(dot(N, L), 0.0);\n    return float3(Sq(nl), Sq(nl), Sq(nl));\n}\n";
    std::fs::write(d.join("seven.hlsl"), seven).unwrap();
    let macro_made = "#define TWIN(NAME, BODY) float NAME(float x) { BODY } min16float NAME(min16float x) { BODY }\nTWIN(Sq, return x * x;)\nfloat3 BRDF(float3 L, float3 V, float3 N, float3 X, float3 Y)\n{\n    float nl = max(dot(N, L), 0.0);\n    return float3(Sq(nl), Sq(nl), Sq(nl));\n}\n";
    std::fs::write(d.join("macro.hlsl"), macro_made).unwrap();
    write_rows(&d.join("in.csv"), 50);
    let rows: Vec<[f64; 3]> = {
        let text = std::fs::read_to_string(d.join("in.csv")).unwrap();
        text.lines()
            .skip(1)
            .map(|l| {
                let v: Vec<f64> = l.split(',').map(|x| x.parse().unwrap()).collect();
                let n = glam::DVec3::new(v[0], v[1], v[2]).normalize();
                let l = glam::DVec3::new(v[6], v[7], v[8]).normalize();
                let nl = n.dot(l).max(0.0);
                [nl * nl; 3]
            })
            .collect()
    };
    for (file, front) in [("seven.hlsl", "glslang"), ("seven.hlsl", "slang"), ("macro.hlsl", "glslang")] {
        let out = format!("{file}-{front}.csv");
        let r = common::run_in(
            d,
            &["eval", "--model", file, "--hlsl-front-end", front, "--input", "in.csv", "--output", &out],
        )
        .ok();
        assert!(
            r.stderr.contains(":2: `Sq(float)` is defined again once minimum-precision types are 32-bit"),
            "{}",
            r.stderr
        );
        for (got, want) in common::csv_values(&d.join(&out)).iter().zip(&rows) {
            assert!((got[0] - want[0]).abs() <= 1e-5 * want[0].max(1e-3), "{file} {front}: {got:?} against {want:?}");
        }
    }
}

/// An engine's header beside the including file is replaced by a stub (`--include-override NAME=FILE`): the
/// stub is used although the header is found first beside the file, the front-end line names it, and the model
/// evaluates; without it the header's engine-only code is refused.
#[test]
fn a_header_beside_the_file_is_replaced_by_a_stub() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::create_dir(d.join("shaders")).unwrap();
    std::fs::write(
        d.join("shaders/globals.hlsli"),
        "#pragma once\nTexture2D<float4> gBindless[] : register(t0, space1);\ntemplate<typename T> T engine_only(T x) { return gBindless[0].Load(int3(0, 0, 0)).x * x; }\nstatic const float SPECULAR_SCALE = 7.0;\n",
    )
    .unwrap();
    std::fs::write(d.join("stub.hlsli"), "#pragma once\nstatic const float SPECULAR_SCALE = 0.5;\n").unwrap();
    std::fs::write(
        d.join("shaders/lobe.hlsl"),
        "#include \"globals.hlsli\"\nfloat3 BRDF(float3 L, float3 V, float3 N, float3 X, float3 Y)\n{\n    float nl = max(dot(N, L), 0.0);\n    return float3(nl, nl, nl) * SPECULAR_SCALE;\n}\n",
    )
    .unwrap();
    write_rows(&d.join("in.csv"), 20);
    let r = common::run_in(
        d,
        &[
            "diff",
            "--model",
            "shaders/lobe.hlsl",
            "--include-override",
            "globals.hlsli=stub.hlsli",
            "--reference",
            "ggx",
            "--input",
            "in.csv",
        ],
    );
    assert!(matches!(r.code, Some(0 | 1)), "{}", r.stderr);
    assert!(r.stdout.contains("headers replaced: `globals.hlsli` by stub.hlsli"), "{}", r.stdout);
    let out = "out.csv";
    common::run_in(
        d,
        &[
            "eval",
            "--model",
            "shaders/lobe.hlsl",
            "--include-override",
            "globals.hlsli=stub.hlsli",
            "--input",
            "in.csv",
            "--output",
            out,
        ],
    )
    .ok();
    let text = std::fs::read_to_string(d.join("in.csv")).unwrap();
    for (row, got) in text.lines().skip(1).zip(common::csv_values(&d.join(out))) {
        let v: Vec<f64> = row.split(',').map(|x| x.parse().unwrap()).collect();
        let nl =
            glam::DVec3::new(v[0], v[1], v[2]).normalize().dot(glam::DVec3::new(v[6], v[7], v[8]).normalize()).max(0.0);
        assert!((got[0] - 0.5 * nl).abs() <= 1e-6, "{got:?} against {}", 0.5 * nl);
    }
}
