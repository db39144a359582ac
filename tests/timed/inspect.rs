//! `brdfprof inspect` end to end on lavapipe, validation layer on (in brdfprof and in its callgrind child):
//! the executed-instruction count of a kernel is the same on every run, the report has every section, and
//! bad input exits 2 with the reason.

use crate::common;
use serde_json::Value;
use std::path::Path;

fn inspect(dir: &Path, name: &str, extra: &[&str]) -> Value {
    let json = dir.join(format!("{name}.json"));
    let md = dir.join(format!("{name}.md"));
    let out = common::brdfprof()
        .args(["inspect", "--validate", "--model", "ggx", "--lights", "8"])
        .args(extra)
        .arg("--json")
        .arg(&json)
        .arg("--markdown")
        .arg(&md)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "inspect failed: {stderr}");
    assert!(!stderr.contains("validation ["), "validation messages: {stderr}");
    for title in
        ["SPIR-V instructions, glslang", "spirv-opt -O", "naga", "Driver statistics", "Executed CPU instructions"]
    {
        assert!(stdout.contains(title), "no `{title}` section on stdout:\n{stdout}");
    }
    assert_eq!(
        std::fs::read_to_string(&md).unwrap(),
        stdout[..stdout.find("JSON: ").unwrap()],
        "Markdown file differs from stdout"
    );
    serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap()
}

fn row<'a>(report: &'a Value, model: &str) -> &'a Value {
    report["rows"].as_array().unwrap().iter().find(|r| r["model"] == model).unwrap_or_else(|| panic!("no row {model}"))
}

#[test]
fn executed_instruction_counts_are_identical_across_runs() {
    let _serial = crate::serial();
    let dir = tempfile::tempdir().unwrap();
    let profile = common::repo_root().join("results/profile-llvmpipe.json");
    let a = inspect(dir.path(), "a", &["--profile", profile.to_str().unwrap()]);
    let b = inspect(dir.path(), "b", &[]);
    let kernels = |r: &Value| r["callgrind"]["kernels"].clone();
    assert_eq!(kernels(&a), kernels(&b), "callgrind counts differ between two runs of the same build");
    let labels: Vec<&str> =
        a["callgrind"]["kernels"].as_array().unwrap().iter().map(|k| k["label"].as_str().unwrap()).collect();
    assert_eq!(labels, ["ggx", "baseline"]);
    let ir = |r: &Value, m: &str| row(r, m)["stats"]["callgrind/ir-per-eval"].as_f64().unwrap();
    // The BRDF costs instructions on top of the memory-only kernel; net = gross - baseline.
    assert!(ir(&a, "ggx") > ir(&a, "baseline") && ir(&a, "baseline") > 0.0);
    let net = row(&a, "ggx")["stats"]["callgrind/net-ir-per-eval"].as_f64().unwrap();
    assert!((net - (ir(&a, "ggx") - ir(&a, "baseline"))).abs() < 1e-9);
    // Every statistic, not only callgrind's, is deterministic.
    assert_eq!(a["rows"], b["rows"]);
    // SPIR-V: the baseline kernel has no BRDF, so fewer instructions; naga parses glslang's vulkan1.1 output.
    let spirv = |m: &str| row(&a, m)["stats"]["spirv/total"].as_f64().unwrap();
    assert!(spirv("ggx") > spirv("baseline"));
    assert_eq!(row(&a, "ggx")["notes"]["naga"], "valid");
    assert!(a["section_notes"]["driver/"].as_str().unwrap().contains("not available on this device"));
    // --profile puts the timings of the profile next to the counts.
    let vs = &a["vs_profile"]["rows"];
    assert_eq!(vs.as_array().unwrap().len(), 2, "{vs}");
    assert!(vs[0]["ns_per_eval"].as_f64().unwrap() > 0.0);
}

#[test]
fn bad_input_exits_2_with_the_reason() {
    let _serial = crate::serial();
    let dir = tempfile::tempdir().unwrap();
    let run = |args: &[&str]| {
        let out = common::brdfprof().args(args).current_dir(dir.path()).output().unwrap();
        (out.status.code(), String::from_utf8_lossy(&out.stderr).into_owned())
    };
    let (code, err) = run(&["inspect", "--model", "phong", "--no-callgrind"]);
    assert_eq!(code, Some(2));
    assert!(err.contains("unknown model `phong`"), "{err}");
    let (code, err) = run(&["inspect", "--glsl", "no-such-dir", "--no-callgrind"]);
    assert_eq!(code, Some(2));
    assert!(err.contains("no-such-dir") && err.contains("kernels.txt"), "{err}");
    let (code, err) = run(&["inspect", "--lights", "0", "--no-callgrind"]);
    assert_eq!(code, Some(2));
    assert!(err.contains("--lights"), "{err}");
    let (code, err) = run(&["inspect", "--no-callgrind", "--profile", "missing.json"]);
    assert_eq!(code, Some(2));
    assert!(err.contains("missing.json"), "{err}");
    assert!(std::fs::read_dir(dir.path()).unwrap().next().is_none(), "nothing written on errors");
}
