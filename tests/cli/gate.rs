//! `check` gates on the figure the cost tables headline: a compile-only target's modelled cycles per evaluation,
//! before -> after in the report, the largest regression first in the annotations, the verdict first in the
//! step summary.

use crate::common::run_in;
use std::path::Path;

/// A model of `pows` dependent `pow` calls after a Lambert-like lobe, written for the tests.
fn model(dir: &Path, name: &str, pows: usize) {
    let chain: String = (0..pows).map(|k| format!("    x = pow(x + 0.5, 1.0{});\n", k % 7 + 1)).collect();
    let text = format!(
        "analytic\n::begin shader\nvec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y)\n{{\n    float x = max(dot(N, L), 0.0);\n{chain}    return vec3(x * 0.25);\n}}\n::end shader\n"
    );
    std::fs::write(dir.join(name), text).unwrap();
}

#[test]
fn the_gate_ranks_regressions_by_their_cycles_per_evaluation() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let names = ["two.brdf", "eight.brdf", "thirty-two.brdf"];
    for n in names {
        model(d, n, 1);
    }
    let mut save = vec!["check", "--device", "nvidia:sm_89", "--save-baseline", "base.json"];
    for n in &names {
        save.extend(["--model", n]);
    }
    run_in(d, &save).ok();
    for (n, extra) in names.iter().zip([2, 8, 32]) {
        model(d, n, 1 + extra);
    }
    let r = run_in(
        d,
        &[
            "check",
            "--device",
            "nvidia:sm_89",
            "--baseline",
            "base.json",
            "--annotations",
            "github",
            "--summary",
            "s.md",
        ],
    );
    assert_eq!(r.code, Some(1), "{}\n{}", r.stdout, r.stderr);
    let annotated: Vec<&str> = r.stdout.lines().filter(|l| l.starts_with("::error")).collect();
    assert_eq!(annotated.len(), 3, "{}", r.stdout);
    assert!(annotated[0].contains("thirty-two.brdf") && annotated[2].contains("two.brdf"), "{annotated:#?}");
    assert!(r.stdout.contains("## Modelled cycles per evaluation"), "{}", r.stdout);
    let row = r.stdout.lines().find(|l| l.starts_with("| thirty-two ")).expect("its cycles before and after");
    assert!(row.contains(" -> ") && row.contains("REGRESSION"), "{row}");
    let summary = std::fs::read_to_string(d.join("s.md")).unwrap();
    let head: Vec<&str> = summary.lines().take(5).collect();
    assert!(head.iter().any(|l| l.contains("Verdict: REGRESSED") && l.contains("thirty-two")), "{head:#?}");
}

/// A baseline keeps its shader files' paths relative to its own folder: `check` run from a subdirectory (or
/// the repository checked out elsewhere) finds them, where paths relative to the folder it was saved from were
/// called corrupt or gone.
#[test]
fn a_baseline_finds_its_shaders_from_another_folder() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    for sub in ["shaders", "ci", "sub"] {
        std::fs::create_dir(d.join(sub)).unwrap();
    }
    model(&d.join("shaders"), "lobe.brdf", 1);
    run_in(d, &["check", "--device", "radv:navi21", "--model", "shaders/lobe.brdf", "--save-baseline", "ci/b.json"])
        .ok();
    let saved = std::fs::read_to_string(d.join("ci/b.json")).unwrap();
    assert!(saved.contains("../shaders/lobe.brdf"), "the path relative to the baseline's folder");
    let r = run_in(&d.join("sub"), &["check", "--device", "radv:navi21", "--baseline", "../ci/b.json"]).ok();
    assert!(!r.stderr.contains("gone") && r.stdout.contains("lobe"), "{}\n{}", r.stdout, r.stderr);
}
