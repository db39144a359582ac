//! brdfprof where CI results are read (docs/ci.md): a regression located at the source line that caused it in
//! SARIF (validated by Microsoft's SARIF Multitool, which `make setup` installs into .tools/sarif), in GitHub's
//! workflow commands and in the step summary; trend data for benchmark dashboards; and the documented
//! workflow's commands, run in order on a fixture repository.

use crate::common::{self, Run};
use std::path::{Path, PathBuf};

/// Microsoft's SARIF Multitool as `make setup` installs it.
fn multitool() -> PathBuf {
    let tool = common::repo_root().join(".tools/sarif/node_modules/@microsoft/sarif-multitool-linux/Sarif.Multitool");
    assert!(tool.exists(), "{} is missing: run `make setup`", tool.display());
    tool
}

/// Validates `sarif` with the Multitool: no error-level message (warnings allowed).
fn assert_valid_sarif(sarif: &Path) {
    let out = std::process::Command::new(multitool()).arg("validate").arg(sarif).output().unwrap();
    let text = format!("{}{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    assert!(text.contains("Analysis completed successfully"), "{text}");
    assert!(!text.lines().any(|l| l.contains(": error ")), "SARIF Multitool errors:\n{text}");
}

/// A fixture repository: `shaders/lobe.brdf` (the example GGX file) and an empty `ci/`.
fn fixture() -> tempfile::TempDir {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir_all(dir.path().join("shaders")).unwrap();
    std::fs::create_dir_all(dir.path().join("ci")).unwrap();
    std::fs::copy(common::repo_root().join("examples/brdf/ggx.brdf"), dir.path().join("shaders/lobe.brdf")).unwrap();
    dir
}

/// The fixture's shader with a loop of `pow()` added after `marker`'s line; returns the new line's number.
fn add_pow_loop(path: &Path, marker: &str) -> usize {
    let text = std::fs::read_to_string(path).unwrap();
    let at = text.lines().position(|l| l.trim() == marker).expect("the marker line") + 1;
    let mut lines: Vec<&str> = text.lines().collect();
    lines.insert(at, "    for (int i = 0; i < 16; i++) NoV = pow(NoV, 1.001);");
    std::fs::write(path, lines.join("\n") + "\n").unwrap();
    at + 1
}

#[test]
fn a_regressed_line_is_named_in_sarif_annotations_and_the_step_summary() {
    let repo = fixture();
    let d = repo.path();
    let check = |extra: &[&str]| -> Run {
        common::run_in(d, &[&["check", "--device", "nvidia:sm_89", "--model", "shaders/lobe.brdf"], extra].concat())
    };
    check(&["--save-baseline", "ci/base.json"]).ok();
    let baseline: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(d.join("ci/base.json")).unwrap()).unwrap();
    assert!(baseline["inspect"]["lines"].as_array().is_some_and(|l| !l.is_empty()), "the baseline keeps per-line cost");
    // Lines below the new one move down: matched by their text, they are not blamed.
    let line = add_pow_loop(&d.join("shaders/lobe.brdf"), "NoV = guard_cosine(NoV);");
    std::fs::write(d.join("summary.md"), "# earlier step\n").unwrap();
    let args =
        ["--baseline", "ci/base.json", "--sarif", "s.sarif", "--annotations", "github", "--summary", "summary.md"];
    let r = check(&args);
    assert_eq!(r.code, Some(1), "a regression: {}", r.stderr);

    let sarif_path = d.join("s.sarif");
    assert_valid_sarif(&sarif_path);
    let sarif: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&sarif_path).unwrap()).unwrap();
    let results = sarif["runs"][0]["results"].as_array().unwrap();
    let lobe = results.iter().find(|r| r["properties"]["model"] == "lobe").expect("a result for the model");
    assert_eq!(lobe["ruleId"], "brdfprof/count-regression");
    assert_eq!(lobe["properties"]["target"], "nvidia:sm_89");
    let at = &lobe["locations"][0]["physicalLocation"];
    assert_eq!(at["artifactLocation"]["uri"], "shaders/lobe.brdf");
    assert_eq!(at["region"]["startLine"], line as u64, "{lobe}");
    assert!(!lobe["partialFingerprints"].as_object().unwrap().is_empty());

    let command =
        format!("::error file=shaders/lobe.brdf,line={line},title=Shader cost regression::lobe on nvidia:sm_89");
    assert!(r.stdout.lines().any(|l| l.starts_with(&command)), "{}", r.stdout);
    assert!(r.stdout.contains("lobe: the lines whose cost rose most"), "{}", r.stdout);
    let summary = std::fs::read_to_string(d.join("summary.md")).unwrap();
    assert!(summary.starts_with("# earlier step\n"), "the step summary is appended to");
    assert!(summary.contains(&format!("shaders/lobe.brdf:{line}")), "{summary}");

    // The same source again: no regression, and a SARIF log with no results (which closes the alert).
    let saved = check(&["--baseline", "ci/base.json", "--save-baseline", "ci/base.json"]);
    assert_eq!(saved.code, Some(1), "{}", saved.stderr);
    let r = check(&["--baseline", "ci/base.json", "--sarif", "s.sarif", "--annotations", "github"]).ok();
    assert!(!r.stdout.contains("::error"), "{}", r.stdout);
    assert_valid_sarif(&sarif_path);
    let sarif: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&sarif_path).unwrap()).unwrap();
    assert_eq!(sarif["runs"][0]["results"].as_array().map(Vec::len), Some(0));
}

#[test]
fn inspect_bench_json_lists_each_model_on_each_target() {
    let repo = fixture();
    let d = repo.path();
    std::fs::copy(common::repo_root().join("examples/brdf/blinn.brdf"), d.join("shaders/blinn.brdf")).unwrap();
    let targets = ["nvidia:sm_89", "radv:navi21"];
    common::run_in(
        d,
        &[
            "inspect",
            "--no-callgrind",
            "--model",
            "shaders/lobe.brdf",
            "--model",
            "shaders/blinn.brdf",
            "--device",
            targets[0],
            "--device",
            targets[1],
            "--json",
            "i.json",
            "--markdown",
            "i.md",
            "--bench-json",
            "b.json",
        ],
    )
    .ok();
    let list: Vec<serde_json::Value> =
        serde_json::from_str(&std::fs::read_to_string(d.join("b.json")).unwrap()).unwrap();
    let report: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(d.join("i.json")).unwrap()).unwrap();
    for (k, target) in targets.iter().enumerate() {
        let cost = &report["reports"][k]["cost"];
        for row in cost["rows"].as_array().unwrap().iter().filter(|r| r["model"] != "baseline") {
            let name = format!("inspect/{target}/{}", row["model"].as_str().unwrap());
            let entries: Vec<&serde_json::Value> = list.iter().filter(|e| e["name"] == name.as_str()).collect();
            assert_eq!(entries.len(), 1, "{name}: {list:?}");
            assert_eq!(entries[0]["value"], row["cycles_per_eval"], "{name}");
            assert_eq!(entries[0]["unit"], format!("{}/eval", cost["unit"].as_str().unwrap()));
        }
    }
    // Two models, the reference ggx and (a model being a file) ggx without its guards, on each of the two targets.
    assert_eq!(list.len(), 8, "{list:?}");
}

/// Every `brdfprof` command of docs/ci.md (the first baseline, the GitHub workflow's steps, the GitLab job), in
/// order, on a fixture repository, with the runner's variables set: each one succeeds, and the files the
/// workflow uploads are written (a SARIF log the Multitool validates, the trend data, the summary).
#[test]
fn the_ci_docs_commands_run_in_order_on_a_fixture_repository() {
    let docs = std::fs::read_to_string(common::repo_root().join("docs/ci.md")).unwrap();
    // The lines of the fenced code blocks that run brdfprof (a YAML list item or a `run: |` line).
    let mut fenced = false;
    let mut commands: Vec<String> = Vec::new();
    for l in docs.lines().map(str::trim) {
        if l.starts_with("```") {
            fenced = !fenced;
        } else if let Some(command) = l.trim_start_matches("- ").strip_prefix("brdfprof ").filter(|_| fenced) {
            commands.push(format!("brdfprof {}", command.trim_end_matches(" || test $? -eq 1")));
        }
    }
    assert!(commands.len() >= 6, "{commands:?}");
    let repo = fixture();
    let d = repo.path();
    let bin = d.join(".bin");
    std::fs::create_dir(&bin).unwrap();
    std::os::unix::fs::symlink(env!("CARGO_BIN_EXE_brdfprof"), bin.join("brdfprof")).unwrap();
    let path = format!("{}:{}", bin.display(), std::env::var("PATH").unwrap_or_default());
    let summary = d.join("step-summary.md");
    for command in &commands {
        let out = std::process::Command::new("sh")
            .args(["-c", command])
            .current_dir(d)
            .env("PATH", &path)
            .env("GITHUB_STEP_SUMMARY", &summary)
            .env("BRDFPROF_VALIDATION", "1")
            .output()
            .unwrap();
        assert!(out.status.success(), "`{command}` failed:\n{}", String::from_utf8_lossy(&out.stderr));
    }
    assert_valid_sarif(&d.join("brdfprof.sarif"));
    assert_valid_sarif(&d.join("gl-brdfprof.sarif"));
    for file in ["brdfprof-bench.json", "brdfprof-summary.md", "ci/brdfprof-baseline.json"] {
        assert!(d.join(file).is_file(), "{file} not written");
    }
    assert!(std::fs::read_to_string(&summary).unwrap().contains("no regression"));
}

/// `profile --bench-json`: one entry per model (and the memory-only kernel) with the median ns/eval and the
/// half-width of its interval as `range`; sweep writes its profile's entries the same way.
#[test]
fn profile_bench_json_gives_each_models_median_and_interval() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let args = ["profile", "--model", "ggx", "--model", "blinn", "--size", "64x64", "--budget", "4"];
    common::run_in(d, &[&args[..], &["--json", "p.json", "--bench-json", "b.json"]].concat()).ok();
    let list: Vec<serde_json::Value> =
        serde_json::from_str(&std::fs::read_to_string(d.join("b.json")).unwrap()).unwrap();
    let report: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(d.join("p.json")).unwrap()).unwrap();
    let rows = report["rows"].as_array().unwrap();
    assert_eq!(list.len(), rows.len(), "{list:?}");
    for (entry, row) in list.iter().zip(rows) {
        let name = entry["name"].as_str().unwrap();
        assert!(
            name.starts_with("profile/") && name.ends_with(&format!("/{}", row["model"].as_str().unwrap())),
            "{name}"
        );
        assert_eq!(entry["unit"], "ns/eval");
        let e = &row["ns_per_eval"];
        assert_eq!(entry["value"], e["median"]);
        let half = (e["hi"].as_f64().unwrap() - e["median"].as_f64().unwrap())
            .max(e["median"].as_f64().unwrap() - e["lo"].as_f64().unwrap());
        let range: f64 = entry["range"].as_str().unwrap().trim_start_matches("± ").parse().unwrap();
        assert!((range - half).abs() <= 0.01 * half, "{range} against {half}");
    }
}

/// `--bench-format bmf`: Bencher's Metric Format, an object keyed by benchmark name, each figure under its
/// measure (the unit), with its interval as lower and upper values where it has one.
#[test]
fn bench_json_in_bencher_metric_format() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let args = ["profile", "--model", "ggx", "--size", "64x64", "--budget", "3", "--json", "p.json"];
    common::run_in(d, &[&args[..], &["--bench-json", "b.json", "--bench-format", "bmf"]].concat()).ok();
    let bmf: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(d.join("b.json")).unwrap()).unwrap();
    let entries = bmf.as_object().expect("an object keyed by benchmark");
    let ggx = entries.iter().find(|(k, _)| k.ends_with("/ggx")).expect("ggx's entry").1;
    let m = &ggx["ns-eval"];
    let (v, lo, hi) =
        (m["value"].as_f64().unwrap(), m["lower_value"].as_f64().unwrap(), m["upper_value"].as_f64().unwrap());
    assert!(lo <= v && v <= hi, "{m}");
}
