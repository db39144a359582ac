//! Names a pull request controls cannot start a line of brdfprof's output (a GitHub workflow command such as
//! `::stop-commands::`), and no command writes over one of its own inputs.

use crate::common::{self, run_in};
use std::path::Path;

const TOKEN: &str = "::stop-commands::TOKEN";

/// A GLSL model whose file name holds a newline, a CR and an escape before a workflow command.
const MODEL: &str = "analytic\n::begin shader\nvec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y)\n{\n    return vec3(0.25 * max(dot(N, L), 0.0));\n}\n::end shader\n";

/// Every line of `text` (split as GitHub's runner splits a step's output, at LF and CR) that its runner would
/// take for the planted workflow command.
fn injected(text: &str) -> Vec<String> {
    text.split(['\n', '\r']).filter(|l| l.trim_start().starts_with(TOKEN)).map(str::to_string).collect()
}

fn assert_clean(what: &str, r: &common::Run, extra: &[&Path]) {
    let mut found = injected(&r.stdout);
    found.extend(injected(&r.stderr));
    for p in extra {
        found.extend(injected(&String::from_utf8_lossy(&std::fs::read(p).unwrap_or_default())));
    }
    assert!(found.is_empty(), "{what}: injected lines {found:?}\nstdout:\n{}\nstderr:\n{}", r.stdout, r.stderr);
}

#[test]
fn planted_names_never_start_a_line() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let name = format!("x\n{TOKEN}\ry\u{1b}[2K\n{TOKEN}.brdf");
    std::fs::write(d.join(&name), MODEL).unwrap();
    // A WGSL module in an include folder, and an HLSL include, named the same way.
    let shaders = d.join("shaders");
    std::fs::create_dir(&shaders).unwrap();
    let bevy = common::repo_root().join("tests/fixtures/wgsl/bevy");
    for m in ["pbr_lighting.wgsl", "utils.wgsl"] {
        std::fs::copy(bevy.join("shaders").join(m), shaders.join(m)).unwrap();
    }
    std::fs::write(shaders.join(format!("z\n{TOKEN}\n.wgsl")), "fn unused() -> f32 { return 1.0 }\n").unwrap();
    let bevy_model = bevy.join("bevy-ggx.brdf");
    let runs: Vec<(&str, Vec<String>)> = vec![
        (
            "eval",
            vec![
                "diff".into(),
                "--model".into(),
                name.clone(),
                "--reference".into(),
                "ggx".into(),
                "--samples".into(),
                "200".into(),
            ],
        ),
        (
            "stability",
            vec!["stability".into(), "--no-energy".into(), "--model".into(), name.clone(), "--out".into(), "st".into()],
        ),
        (
            "inspect",
            vec![
                "inspect".into(),
                "--device".into(),
                "radv:navi21".into(),
                "--model".into(),
                name.clone(),
                "--json".into(),
                "i.json".into(),
                "--markdown".into(),
                "i.md".into(),
            ],
        ),
        (
            "wgsl module",
            vec![
                "inspect".into(),
                "--device".into(),
                "radv:navi21".into(),
                "--model".into(),
                bevy_model.display().to_string(),
                "--include-dir".into(),
                shaders.display().to_string(),
                "--json".into(),
                "w.json".into(),
                "--markdown".into(),
                "w.md".into(),
            ],
        ),
        (
            "baseline",
            vec![
                "check".into(),
                "--device".into(),
                "radv:navi21".into(),
                "--model".into(),
                name.clone(),
                "--save-baseline".into(),
                "b.json".into(),
            ],
        ),
    ];
    for (what, args) in &runs {
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let r = run_in(d, &args).no_validation();
        assert!(matches!(r.code, Some(0 | 1)), "{what}: exit {:?}\n{}", r.code, r.stderr);
        assert_clean(what, &r, &[&d.join("i.md"), &d.join("w.md")]);
    }
    // A baseline entry renamed to a planted name, then checked with every CI output on.
    let text = std::fs::read_to_string(d.join("b.json")).unwrap();
    let mut baseline: serde_json::Value = serde_json::from_str(&text).unwrap();
    let planted = format!("planted\n{TOKEN}\nname");
    let rows = baseline.pointer_mut("/inspect/rows").and_then(|r| r.as_array_mut()).expect("the baseline's rows");
    let row = rows.iter_mut().find(|r| r["model"] != "ggx" && r["model"] != "baseline").expect("the model's row");
    row["model"] = serde_json::Value::String(planted);
    std::fs::write(d.join("b.json"), serde_json::to_string(&baseline).unwrap()).unwrap();
    let args = [
        "check",
        "--device",
        "radv:navi21",
        "--model",
        &name,
        "--baseline",
        "b.json",
        "--annotations",
        "github",
        "--summary",
        "summary.md",
        "--sarif",
        "s.sarif",
    ];
    let r = run_in(d, &args).no_validation();
    assert!(matches!(r.code, Some(0..=2)), "check: exit {:?}\n{}", r.code, r.stderr);
    assert_clean("check against a planted baseline", &r, &[&d.join("summary.md")]);
}

/// A command never writes over one of its inputs (the same file after links, hard links too) or gives two
/// outputs one path: exit 2 before measuring, the input unchanged.
#[test]
fn no_command_writes_over_its_inputs() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("m.brdf"), MODEL).unwrap();
    std::fs::hard_link(d.join("m.brdf"), d.join("hard.brdf")).unwrap();
    let baseline = common::repo_root().join("results/baseline-radv-navi21.json");
    std::fs::copy(&baseline, d.join("b.json")).unwrap();
    let before = |p: &str| std::fs::read(d.join(p)).unwrap();
    let (model, base) = (before("m.brdf"), before("b.json"));
    let target = ["--device", "radv:navi21"];
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (
            vec!["check", target[0], target[1], "--baseline", "b.json", "--sarif", "b.json"],
            "--sarif b.json: is the same file as --baseline b.json",
        ),
        (
            vec!["check", target[0], target[1], "--model", "m.brdf", "--summary", "m.brdf"],
            "--summary m.brdf: is the same file as --model m.brdf",
        ),
        (
            vec!["check", target[0], target[1], "--model", "m.brdf", "--save-baseline", "hard.brdf"],
            "--save-baseline hard.brdf: is the same file as --model m.brdf",
        ),
        (
            vec!["inspect", target[0], target[1], "--model", "m.brdf", "--json", "m.brdf"],
            "--json m.brdf: is the same file as --model m.brdf",
        ),
        (
            vec!["check", target[0], target[1], "--baseline", "b.json", "--summary", "s.md", "--sarif", "s.md"],
            "--summary s.md: is also given to --sarif",
        ),
        (
            vec!["stability", "--model", "m.brdf", "--markdown", "hard.brdf"],
            "--markdown hard.brdf: is the same file as --model m.brdf",
        ),
    ];
    for (args, message) in cases {
        run_in(d, &args).fails(2, message);
        assert_eq!((before("m.brdf"), before("b.json")), (model.clone(), base.clone()), "{args:?} changed an input");
        assert!(!d.join("s.md").exists());
    }
    // The documented refresh still replaces the baseline it compared with.
    run_in(d, &["check", "--device", "radv:navi21", "--baseline", "b.json", "--save-baseline", "b.json"])
        .no_validation();
}

/// A baseline naming a shader renamed since is no corrupt baseline: the shader is named as gone, the others are
/// compared, and the documented refresh writes a baseline without it.
#[test]
fn a_baseline_naming_a_renamed_shader_names_it_and_compares_the_rest() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("a.brdf"), MODEL).unwrap();
    std::fs::write(d.join("b.brdf"), MODEL.replace("0.25", "0.5")).unwrap();
    let save =
        ["check", "--device", "radv:navi21", "--model", "a.brdf", "--model", "b.brdf", "--save-baseline", "base.json"];
    run_in(d, &save).ok();
    std::fs::rename(d.join("b.brdf"), d.join("renamed.brdf")).unwrap();
    let r = run_in(d, &["check", "--device", "radv:navi21", "--baseline", "base.json"]).ok();
    assert!(r.stderr.contains("shader files that are gone") && r.stderr.contains("b.brdf)"), "{}", r.stderr);
    assert!(r.stdout.contains("## Shader files the baseline names that are gone"), "{}", r.stdout);
    run_in(d, &["check", "--device", "radv:navi21", "--baseline", "base.json", "--save-baseline", "base.json"]).ok();
    let text = std::fs::read_to_string(d.join("base.json")).unwrap();
    assert!(!text.contains("b.brdf") && text.contains("a.brdf"), "the refreshed baseline drops the gone shader");
    let r = run_in(d, &["check", "--device", "radv:navi21", "--baseline", "base.json"]).ok();
    assert!(!r.stderr.contains("gone"), "{}", r.stderr);
}

/// The smaller ones: `compare` given a diff report says so, and a tiny `--f0` bound does not write 300 digits.
#[test]
fn a_diff_report_given_to_compare_is_named_and_tiny_bounds_are_short() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    run_in(d, &["diff", "--model", "ggx", "--model", "blinn", "--samples", "100", "--json", "d.json"]).no_validation();
    let profile = common::repo_root().join("results/profile-llvmpipe.json");
    run_in(d, &["compare", "d.json", profile.to_str().unwrap()])
        .fails(2, "d.json: a `diff` report, which holds no cost per evaluation");
    let r = run_in(d, &["diff", "--model", "ggx", "--model", "blinn", "--samples", "50", "--f0", "1e-400..1e-300"]);
    assert!(r.stdout.contains("F0 in [0, 1e-300]^3"), "{}", r.stdout);
}

/// A compiler running away is bounded in memory: nested `[ForceUnroll]` loops made slangc take 8 GB; under a
/// 512 MiB bound it fails within seconds, and the message names the bound and how to raise it.
#[test]
fn a_runaway_compiler_stops_at_its_memory_bound() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let body = "    [ForceUnroll] for (int i = 0; i < 400; i++)\n        [ForceUnroll] for (int j = 0; j < 400; j++)\n            [ForceUnroll] for (int k = 0; k < 400; k++)\n                s = select(s > 0.5, s * 0.5, s + 0.25);\n";
    let text = format!(
        "float3 BRDF(float3 L, float3 V, float3 N, float3 X, float3 Y)\n{{\n    float s = dot(N, L);\n{body}    return float3(s, s, s);\n}}\n"
    );
    std::fs::write(d.join("runaway.hlsl"), text).unwrap();
    let start = std::time::Instant::now();
    let out = common::brdfprof()
        .args(["diff", "--model", "runaway.hlsl", "--hlsl-front-end", "slang", "--reference", "ggx", "--samples", "10"])
        .env("BRDFPROF_CHILD_MEMORY_MB", "512")
        .current_dir(d)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("bounded at 512 MiB") && stderr.contains("BRDFPROF_CHILD_MEMORY_MB"), "{stderr}");
    assert!(start.elapsed() < std::time::Duration::from_secs(55), "stopped by the bound, not the time limit");
}
