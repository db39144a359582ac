//! The regression gates on the compilers that take the kernels' C translation (checked against the Vulkan
//! kernels first): `brdfprof check --device nvidia:sm_89` (ptxas' statistics of NVRTC's build of the CUDA C++)
//! and `--device intel:gen12lp` (IGC's, through ocloc, of the OpenCL C) against the committed
//! results/baseline-nvidia-sm_89.json and results/baseline-intel-gen12lp.json. They depend on the compiler's
//! version and options alone: another compiler is "not comparable". After a deliberate kernel change:
//! `make baseline`. An extra pow costs on both: under -use_fast_math `pow` is exp2(y log2(x)), two MUFU and a
//! multiply per light; OpenCL's native_powr is math.log, a multiply and math.exp.

use crate::check_gate::glsl_with_extra_pow;
use crate::common;
use std::path::{Path, PathBuf};

/// A gated target: its device, its committed baseline, and a compiler name that is not its own.
struct Gate {
    device: &'static str,
    baseline: &'static str,
    other_compiler: &'static str,
}

const GATES: [Gate; 2] = [
    Gate { device: "nvidia:sm_89", baseline: "results/baseline-nvidia-sm_89.json", other_compiler: "NVRTC 9.9" },
    Gate { device: "intel:gen12lp", baseline: "results/baseline-intel-gen12lp.json", other_compiler: "ocloc 0.0" },
];

impl Gate {
    fn baseline(&self) -> PathBuf {
        common::repo_root().join(self.baseline)
    }

    fn check(&self, baseline: &Path, glsl: Option<&Path>) -> (Option<i32>, String, String) {
        let mut cmd = common::brdfprof();
        cmd.args(["check", "--validate", "--device", self.device, "--baseline"]).arg(baseline);
        if let Some(dir) = glsl {
            cmd.arg("--glsl").arg(dir);
        }
        let out = cmd.output().unwrap();
        let (stdout, stderr) =
            (String::from_utf8_lossy(&out.stdout).into_owned(), String::from_utf8_lossy(&out.stderr).into_owned());
        assert!(!stderr.contains("validation ["), "{}: validation messages: {stderr}", self.device);
        (out.status.code(), stdout, stderr)
    }
}

fn group_line<'a>(stdout: &'a str, group: &str) -> &'a str {
    stdout
        .lines()
        .find(|l| l.starts_with(&format!("| {group} ")))
        .unwrap_or_else(|| panic!("no {group} row:\n{stdout}"))
}

#[test]
fn this_build_passes_the_committed_translated_baselines() {
    let _serial = crate::serial();
    for g in &GATES {
        let (code, stdout, stderr) = g.check(&g.baseline(), None);
        eprintln!("{stdout}");
        assert_eq!(
            code,
            Some(0),
            "{} regressed against {} (after a deliberate change: `make baseline`):\n{stdout}\n{stderr}",
            g.device,
            g.baseline().display()
        );
        let b: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(g.baseline()).unwrap()).unwrap();
        assert_eq!(b["inspect"]["provenance"]["target"], g.device);
        let driver = group_line(&stdout, "driver");
        assert!(driver.contains("| compared"), "{}: the same compiler gives comparable figures: {driver}", g.device);
        assert!(stdout.contains("0 changed."), "{stdout}");
    }
}

#[test]
fn an_extra_pow_in_d_ggx_fails_each_translated_gate_naming_only_ggx() {
    let _serial = crate::serial();
    let dir = tempfile::tempdir().unwrap();
    let glsl = glsl_with_extra_pow(dir.path());
    for g in &GATES {
        let (code, stdout, stderr) = g.check(&g.baseline(), Some(&glsl));
        eprintln!("{stdout}");
        assert_eq!(code, Some(1), "{}: expected a regression:\n{stdout}\n{stderr}", g.device);
        let regressions: Vec<&str> =
            stdout.split("## Verdict").nth(1).unwrap().lines().filter(|l| l.starts_with("- ")).collect();
        assert!(
            !regressions.is_empty() && regressions.iter().all(|l| l.starts_with("- ggx ")),
            "{}: only ggx runs D_Ggx: {regressions:?}",
            g.device
        );
        for stat in ["driver/instructions", "driver/issue-cycles"] {
            assert!(
                regressions.iter().any(|l| l.starts_with(&format!("- ggx {stat}: "))),
                "{}: {stat} did not regress: {regressions:?}",
                g.device
            );
        }
    }
}

#[test]
fn a_baseline_from_another_compiler_is_not_comparable() {
    let _serial = crate::serial();
    let dir = tempfile::tempdir().unwrap();
    for g in &GATES {
        let mut b: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(g.baseline()).unwrap()).unwrap();
        b["environment"]["driver"]["compiler"] = g.other_compiler.into();
        for row in b["inspect"]["rows"].as_array_mut().unwrap() {
            row["stats"]["driver/instructions"] = 1.0.into();
        }
        let path = dir.path().join(format!("other-{}.json", g.device.replace(':', "-")));
        std::fs::write(&path, serde_json::to_string(&b).unwrap()).unwrap();
        let (code, stdout, stderr) = g.check(&path, None);
        assert_eq!(code, Some(0), "{stdout}\n{stderr}");
        assert!(
            group_line(&stdout, "driver")
                .contains(&format!("not comparable: compiler: baseline `{}`", g.other_compiler)),
            "{stdout}"
        );
        assert!(group_line(&stdout, "spirv").contains("| compared"), "{stdout}");
    }
}
