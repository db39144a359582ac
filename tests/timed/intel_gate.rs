//! The regression gate on Intel's compiler: `brdfprof check --device intel:gen12lp` compares IGC's statistics
//! of this build's kernels (ocloc on their OpenCL C translation, checked against the Vulkan kernels first) with
//! the committed baseline results/baseline-intel-gen12lp.json. They depend on the compiler's version and
//! options alone: another ocloc is "not comparable". After a deliberate kernel change: `make baseline`.

use crate::check_gate::glsl_with_extra_pow;
use crate::common;
use std::path::{Path, PathBuf};

fn baseline() -> PathBuf {
    common::repo_root().join("results/baseline-intel-gen12lp.json")
}

fn check(baseline: &Path, glsl: Option<&Path>) -> (Option<i32>, String, String) {
    let mut cmd = common::brdfprof();
    cmd.args(["check", "--validate", "--device", "intel:gen12lp", "--baseline"]).arg(baseline);
    if let Some(dir) = glsl {
        cmd.arg("--glsl").arg(dir);
    }
    let out = cmd.output().unwrap();
    let (stdout, stderr) = (String::from_utf8_lossy(&out.stdout).into_owned(), String::from_utf8_lossy(&out.stderr).into_owned());
    assert!(!stderr.contains("validation ["), "validation messages: {stderr}");
    (out.status.code(), stdout, stderr)
}

fn group_line<'a>(stdout: &'a str, group: &str) -> &'a str {
    stdout.lines().find(|l| l.starts_with(&format!("| {group} "))).unwrap_or_else(|| panic!("no {group} row:\n{stdout}"))
}

#[test]
fn this_build_passes_the_committed_intel_baseline() {
    let _serial = crate::serial();
    let (code, stdout, stderr) = check(&baseline(), None);
    eprintln!("{stdout}");
    assert_eq!(code, Some(0), "intel:gen12lp regressed against {} (after a deliberate change: `make baseline`):\n{stdout}\n{stderr}", baseline().display());
    let b: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(baseline()).unwrap()).unwrap();
    assert_eq!(b["inspect"]["provenance"]["target"], "intel:gen12lp");
    let driver = group_line(&stdout, "driver");
    assert!(driver.contains("| compared"), "the same ocloc gives comparable figures: {driver}");
    assert!(stdout.contains("0 changed."), "{stdout}");
}

#[test]
fn an_extra_pow_in_d_ggx_fails_the_intel_gate_naming_only_ggx() {
    let _serial = crate::serial();
    let dir = tempfile::tempdir().unwrap();
    let glsl = glsl_with_extra_pow(dir.path());
    let (code, stdout, stderr) = check(&baseline(), Some(&glsl));
    eprintln!("{stdout}");
    assert_eq!(code, Some(1), "expected a regression:\n{stdout}\n{stderr}");
    let regressions: Vec<&str> = stdout.split("## Verdict").nth(1).unwrap().lines().filter(|l| l.starts_with("- ")).collect();
    assert!(!regressions.is_empty() && regressions.iter().all(|l| l.starts_with("- ggx ")), "only ggx runs D_Ggx: {regressions:?}");
    // native_powr(x, y) is math.log, a multiply and math.exp per light.
    for stat in ["driver/instructions", "driver/issue-cycles"] {
        assert!(regressions.iter().any(|l| l.starts_with(&format!("- ggx {stat}: "))), "{stat} did not regress: {regressions:?}");
    }
}

#[test]
fn a_baseline_from_another_ocloc_is_not_comparable() {
    let _serial = crate::serial();
    let dir = tempfile::tempdir().unwrap();
    let mut b: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(baseline()).unwrap()).unwrap();
    b["environment"]["driver"]["compiler"] = "ocloc 0.0".into();
    for row in b["inspect"]["rows"].as_array_mut().unwrap() {
        row["stats"]["driver/instructions"] = 1.0.into();
    }
    let path = dir.path().join("other-ocloc.json");
    std::fs::write(&path, serde_json::to_string(&b).unwrap()).unwrap();
    let (code, stdout, stderr) = check(&path, None);
    assert_eq!(code, Some(0), "{stdout}\n{stderr}");
    assert!(group_line(&stdout, "driver").contains("not comparable: compiler: baseline `ocloc 0.0`"), "{stdout}");
    assert!(group_line(&stdout, "spirv").contains("| compared"), "{stdout}");
}
