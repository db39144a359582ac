//! The regression gate on Mesa's GPU compilers: `brdfprof check --device TARGET` compares the compiler's
//! statistics of this build's kernels (RADV's ACO for navi21 and vangogh, Turnip's ir3 for adreno:a660,
//! PanVK's Bifrost for mali:g52, ANV's brw for anv:tgl, each run without the GPU) with the committed baselines
//! results/baseline-<target>.json, under the validation layer (PanVK: without it, its report says why). They
//! depend on the Mesa version alone: on any machine with the same Mesa the driver statistics gate at 1%; a
//! baseline from another Mesa is "not comparable". After a deliberate kernel change: `make baseline` re-saves
//! them with the lavapipe one.

use crate::check_gate::glsl_with_extra_pow;
use crate::common;
use std::path::{Path, PathBuf};
use std::process::Output;

/// Every target with a committed baseline whose compiler is a Mesa driver (`make baseline`'s list).
const TARGETS: [&str; 5] = ["radv:navi21", "radv:vangogh", "adreno:a660", "mali:g52", "anv:tgl"];

fn baseline(target: &str) -> PathBuf {
    common::repo_root().join(format!("results/baseline-{}.json", target.replace(':', "-")))
}

fn check(target: &str, baseline: &Path, glsl: Option<&Path>) -> (Option<i32>, String, String) {
    let mut cmd = common::brdfprof();
    cmd.args(["check", "--validate", "--device", target, "--baseline"]).arg(baseline);
    if let Some(dir) = glsl {
        cmd.arg("--glsl").arg(dir);
    }
    let out: Output = cmd.output().unwrap();
    let (stdout, stderr) =
        (String::from_utf8_lossy(&out.stdout).into_owned(), String::from_utf8_lossy(&out.stderr).into_owned());
    assert!(!stderr.contains("validation ["), "validation messages: {stderr}");
    (out.status.code(), stdout, stderr)
}

fn group_line<'a>(stdout: &'a str, group: &str) -> &'a str {
    stdout
        .lines()
        .find(|l| l.starts_with(&format!("| {group} ")))
        .unwrap_or_else(|| panic!("no {group} row:\n{stdout}"))
}

/// The Mesa version this machine's RADV reports, from the committed baseline's device if it matches.
fn baseline_mesa(b: &serde_json::Value) -> String {
    b["environment"]["driver"]["mesa"]
        .as_str()
        .expect("a compile-only baseline keys its driver group on Mesa")
        .to_string()
}

#[test]
fn this_build_passes_the_committed_mesa_compiler_baselines() {
    let _serial = crate::serial();
    let makefile = std::fs::read_to_string(common::repo_root().join("Makefile")).unwrap();
    for target in TARGETS {
        assert!(
            makefile.lines().any(|l| l.starts_with("TARGET_BASELINES :=") && l.split_whitespace().any(|w| w == target)),
            "make baseline does not re-save {target}"
        );
        let (code, stdout, stderr) = check(target, &baseline(target), None);
        eprintln!("{stdout}");
        let b: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(baseline(target)).unwrap()).unwrap();
        if let Some(family) = target.strip_prefix("radv:") {
            assert_eq!(
                b["inspect"]["provenance"]["device"]["name"],
                format!("Null hardware (RADV {})", family.to_uppercase())
            );
        } else {
            assert_eq!(b["inspect"]["provenance"]["target"], target);
        }
        assert_eq!(
            code,
            Some(0),
            "{target} regressed against {} (after a deliberate change: `make baseline`):\n{stdout}\n{stderr}",
            baseline(target).display()
        );
        let driver = group_line(&stdout, "driver");
        // On this Mesa the ACO statistics gate; on another one they are not comparable, which says so.
        if driver.contains("| compared") {
            assert!(stdout.contains("0 changed."), "{stdout}");
        } else {
            assert!(driver.contains(&format!("not comparable: Mesa {} vs", baseline_mesa(&b))), "{driver}");
        }
    }
}

#[test]
fn an_extra_pow_in_d_ggx_fails_the_aco_gate_naming_ggx_and_the_statistics_that_grew() {
    let _serial = crate::serial();
    let dir = tempfile::tempdir().unwrap();
    let glsl = glsl_with_extra_pow(dir.path());
    let (code, stdout, stderr) = check("radv:navi21", &baseline("radv:navi21"), Some(&glsl));
    eprintln!("{stdout}");
    assert_eq!(code, Some(1), "expected a regression:\n{stdout}\n{stderr}");
    let regressions: Vec<&str> =
        stdout.split("## Verdict").nth(1).unwrap().lines().filter(|l| l.starts_with("- ")).collect();
    assert!(regressions.iter().all(|l| l.starts_with("- ggx ")), "only ggx runs D_Ggx: {regressions:?}");
    if group_line(&stdout, "driver").contains("| compared") {
        // pow(x, y) is exp2(y log2(x)) on RDNA 2: two transcendental instructions and a multiply per light.
        for stat in ["driver/instructions", "driver/latency", "driver/inverse-throughput"] {
            assert!(
                regressions.iter().any(|l| l.starts_with(&format!("- ggx {stat}: "))),
                "{stat} did not regress: {regressions:?}"
            );
        }
    }
}

#[test]
fn a_baseline_from_another_mesa_is_not_comparable() {
    let _serial = crate::serial();
    let dir = tempfile::tempdir().unwrap();
    let mut b: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(baseline("radv:navi21")).unwrap()).unwrap();
    b["environment"]["driver"]["mesa"] = "19.0.0-imaginary".into();
    // ...and figures that would fail the gate if they were compared.
    for row in b["inspect"]["rows"].as_array_mut().unwrap() {
        row["stats"]["driver/instructions"] = 1.0.into();
    }
    let path = dir.path().join("other-mesa.json");
    std::fs::write(&path, serde_json::to_string(&b).unwrap()).unwrap();
    let (code, stdout, stderr) = check("radv:navi21", &path, None);
    assert_eq!(code, Some(0), "{stdout}\n{stderr}");
    assert!(group_line(&stdout, "driver").contains("not comparable: Mesa 19.0.0-imaginary vs "), "{stdout}");
    assert!(group_line(&stdout, "spirv").contains("| compared"), "{stdout}");
}

#[test]
fn an_extra_pow_in_d_ggx_fails_the_ir3_bifrost_and_brw_gates_on_ggx_alone() {
    let _serial = crate::serial();
    let dir = tempfile::tempdir().unwrap();
    let glsl = glsl_with_extra_pow(dir.path());
    for target in TARGETS.iter().filter(|t| !t.starts_with("radv:")) {
        let (code, stdout, stderr) = check(target, &baseline(target), Some(&glsl));
        assert_eq!(code, Some(1), "{target}: expected a regression:\n{stdout}\n{stderr}");
        let regressions: Vec<&str> =
            stdout.split("## Verdict").nth(1).unwrap().lines().filter(|l| l.starts_with("- ")).collect();
        assert!(regressions.iter().all(|l| l.starts_with("- ggx ")), "{target}: only ggx runs D_Ggx: {regressions:?}");
        if group_line(&stdout, "driver").contains("| compared") {
            // Some statistic of the compiler's own grew past the gate's 1% (ir3: its code size, instructions +<1%).
            assert!(
                regressions.iter().any(|l| l.starts_with("- ggx driver/")),
                "{target}: no driver statistic regressed: {regressions:?}"
            );
        }
    }
}
