//! The regression gate: `brdfprof check` against the committed lavapipe baseline (results/baseline-
//! llvmpipe.json), under the validation layer. This build must pass it; a copy of glsl/ with an extra `pow`
//! in D_GGX must fail it, naming ggx and the statistics; a missing or corrupt baseline exits 2 with the
//! reason. The tests of this binary run one at a time: a check's timing rounds must not share the two cores
//! with another test's callgrind run.

use crate::common;
use std::path::{Path, PathBuf};
use std::process::Output;

fn baseline() -> PathBuf {
    common::repo_root().join("results/baseline-llvmpipe.json")
}

fn check(args: &[&str], glsl: Option<&Path>) -> Output {
    let mut cmd = common::brdfprof();
    cmd.args(["check", "--validate"]).args(args);
    if let Some(dir) = glsl {
        cmd.arg("--glsl").arg(dir);
    }
    cmd.output().unwrap()
}

fn text(out: &Output) -> (String, String) {
    (String::from_utf8_lossy(&out.stdout).into_owned(), String::from_utf8_lossy(&out.stderr).into_owned())
}

/// The verdict's lines, after "## Verdict".
fn verdict(stdout: &str) -> Vec<&str> {
    stdout.split("## Verdict").nth(1).unwrap_or_default().lines().filter(|l| !l.trim().is_empty()).collect()
}

/// The status of a statistic group in the report's table.
fn group_compared(stdout: &str, group: &str) -> bool {
    stdout.lines().any(|l| l.starts_with(&format!("| {group} ")) && l.contains("| compared"))
}

/// Timing threshold of the CI self-gate: CI shares machines, so there timing gates only a large, significant
/// slowdown (15%); the deterministic counts (1%) are what catch a kernel that grew. `brdfprof check` run by
/// hand keeps its 5% default.
const CI_TIMING_THRESHOLD: &str = "timing=0.15";

#[test]
fn this_build_passes_the_committed_baseline() {
    let _serial = crate::serial();
    let dir = tempfile::tempdir().unwrap();
    let saved = dir.path().join("saved.json");
    let out = check(
        &[
            "--baseline",
            baseline().to_str().unwrap(),
            "--save-baseline",
            saved.to_str().unwrap(),
            "--threshold",
            CI_TIMING_THRESHOLD,
        ],
        None,
    );
    let (stdout, stderr) = text(&out);
    eprintln!("{stdout}");
    assert_eq!(
        out.status.code(),
        Some(0),
        "the build regressed against results/baseline-llvmpipe.json (after a deliberate change: `make baseline`):\n{stdout}\n{stderr}"
    );
    assert!(!stderr.contains("validation ["), "validation messages: {stderr}");
    assert_eq!(verdict(&stdout), ["no regression"]);
    // SPIR-V counts are machine-independent: always compared, and unchanged.
    assert!(group_compared(&stdout, "spirv") && group_compared(&stdout, "spirv-O"), "{stdout}");
    assert!(stdout.contains("changed.") && !stdout.contains("| REGRESSION"), "{stdout}");
    // The saved baseline reads back and compares equal on every count.
    let saved_json: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&saved).unwrap()).unwrap();
    let committed: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(baseline()).unwrap()).unwrap();
    assert_eq!(saved_json["format"], committed["format"]);
    for (new, old) in
        saved_json["inspect"]["rows"].as_array().unwrap().iter().zip(committed["inspect"]["rows"].as_array().unwrap())
    {
        for (key, value) in old["stats"].as_object().unwrap().iter().filter(|(k, _)| k.starts_with("spirv")) {
            assert_eq!(&new["stats"][key], value, "{} {key}", old["model"]);
        }
    }
}

/// A copy of glsl/ whose D_Ggx multiplies its result by pow(NoH, 0.01): one more pow, same shape.
pub(crate) fn glsl_with_extra_pow(dir: &Path) -> PathBuf {
    let copy = dir.join("glsl");
    brdfprof::shaders::write_glsl_tree(&copy).unwrap();
    let brdf = copy.join("brdf.glsl");
    let source = std::fs::read_to_string(&brdf).unwrap();
    let start = source.find("real D_Ggx(").expect("D_Ggx in glsl/brdf.glsl");
    let ret = start + source[start..].find("return ").unwrap();
    let end = ret + source[ret..].find(';').unwrap();
    let expr = &source[ret + "return ".len()..end];
    let edited = format!("{}return ({expr}) * pow(NoH, real(0.01)){}", &source[..ret], &source[end..]);
    std::fs::write(&brdf, edited).unwrap();
    copy
}

#[test]
fn an_extra_pow_in_d_ggx_fails_the_check_naming_ggx() {
    let _serial = crate::serial();
    let dir = tempfile::tempdir().unwrap();
    let glsl = glsl_with_extra_pow(dir.path());
    let out = check(&["--baseline", baseline().to_str().unwrap()], Some(&glsl));
    let (stdout, stderr) = text(&out);
    eprintln!("{stdout}");
    assert_eq!(out.status.code(), Some(1), "expected a regression:\n{stdout}\n{stderr}");
    assert!(!stderr.contains("validation ["), "validation messages: {stderr}");
    let lines = verdict(&stdout);
    assert!(lines[0].starts_with("REGRESSION"), "{lines:?}");
    let regressions: Vec<&str> = lines.iter().filter(|l| l.starts_with("- ")).copied().collect();
    // Only ggx runs D_Ggx among the thesis models (the memory-only kernel runs no BRDF).
    assert!(regressions.iter().all(|l| l.starts_with("- ggx ")), "{regressions:?}");
    assert!(regressions.iter().any(|l| l.starts_with("- ggx spirv/glsl.Pow: 0 -> 1")), "{regressions:?}");
    assert!(regressions.iter().any(|l| l.starts_with("- ggx spirv-O/glsl.Pow")), "{regressions:?}");
    if group_compared(&stdout, "callgrind") {
        assert!(regressions.iter().any(|l| l.starts_with("- ggx callgrind/ir-per-eval")), "{regressions:?}");
    }
}

#[test]
fn a_missing_or_corrupt_baseline_exits_2_with_the_reason() {
    let _serial = crate::serial();
    let dir = tempfile::tempdir().unwrap();
    let missing = dir.path().join("missing.json");
    let out = check(&["--baseline", missing.to_str().unwrap()], None);
    let (_, stderr) = text(&out);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("missing.json: cannot read it") && stderr.contains("No such file"), "{stderr}");

    let committed = std::fs::read_to_string(baseline()).unwrap();
    let cases = [
        ("truncated.json", committed[..committed.len() / 2].to_string(), "corrupt, not valid JSON"),
        ("foreign.json", "{\"rows\": []}".to_string(), "not a brdfprof check baseline"),
        ("mangled.json", committed.replacen("\"rows\": [", "\"rows\": 7, \"x\": [", 1), "corrupt"),
    ];
    for (name, text_of_file, reason) in cases {
        let path = dir.path().join(name);
        std::fs::write(&path, text_of_file).unwrap();
        let saved = dir.path().join(format!("saved-{name}"));
        let out = check(&["--baseline", path.to_str().unwrap(), "--save-baseline", saved.to_str().unwrap()], None);
        let (_, stderr) = text(&out);
        assert_eq!(out.status.code(), Some(2), "{name}: {stderr}");
        assert!(stderr.contains(name) && stderr.contains(reason), "{name}: expected `{reason}` in: {stderr}");
        assert!(!saved.exists(), "{name}: nothing may be saved when the baseline cannot be read");
    }
    let out = check(&["--baseline", baseline().to_str().unwrap(), "--threshold", "spirv/total"], None);
    assert_eq!(out.status.code(), Some(2));
    assert!(text(&out).1.contains("expected STAT=FRACTION"));
}
