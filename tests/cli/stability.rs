//! `stability` on the code users bring: a model without a twin is judged against its reference's formula exactly
//! (no floor), every shape of failure writes its report and exits as it should (never a panic), an entry
//! returning f_s N.L is judged on its own value below the horizon, a declared domain is checked at its own bounds
//! with the loss there said, and `--json`/`--markdown` write where asked.

use crate::common::{self, run_in};
use serde_json::Value;
use std::path::{Path, PathBuf};

fn fixture(name: &str) -> String {
    common::repo_root().join("tests/fixtures/brdf/stability").join(name).display().to_string()
}

/// Runs `stability` on `model` with `extra` flags into `dir/NAME`, its exit status checked; returns the JSON
/// report's one spec, the Markdown and the directory.
fn stability(dir: &Path, name: &str, model: &str, extra: &[&str], code: i32) -> (Value, String, PathBuf) {
    let out = dir.join(name);
    let json = dir.join(format!("{name}.json"));
    let md = dir.join(format!("{name}.md"));
    let mut args = vec!["stability", "--no-energy", "--model", model, "--out", out.to_str().unwrap()];
    args.extend(["--json", json.to_str().unwrap(), "--markdown", md.to_str().unwrap()]);
    args.extend_from_slice(extra);
    let r = run_in(dir, &args).no_validation();
    assert_eq!(r.code, Some(code), "{name}: exit {:?}\n{}", r.code, r.stderr);
    assert!(!r.stderr.contains("panicked"), "{}", r.stderr);
    let report: Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let markdown = std::fs::read_to_string(&md).unwrap();
    assert_eq!(markdown, r.stdout.split("\nwritten: ").next().unwrap(), "--markdown holds what stdout shows");
    let saved = common::device_file(&out, "stability-", ".json");
    assert_eq!(std::fs::read(&saved).unwrap(), std::fs::read(&json).unwrap(), "--json is the report --out holds");
    (report["specs"][0].clone(), markdown, out)
}

/// The hard cases out of tolerance that had a value to be within (not the invalid inputs, which only must not
/// come out poisoned).
fn valid_cases_out(spec: &Value) -> Vec<String> {
    spec["cases_out_of_tolerance"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|c| !c["expected"].is_null())
        .map(|c| format!("{} at {}", c["case"], c["inputs"]))
        .collect()
}

/// The exact GGX / height-correlated Smith / Schlick formula in fp32 with only a lit mask and a half-vector guard
/// is within tolerance of that formula: judged against the guarded twin (cosines floored at 1e-4) it had a hard
/// case and thousands of grid points out, worst 1e6 tolerances, where its values were the exact ones.
#[test]
fn the_exact_formula_is_within_tolerance_of_its_reference() {
    let dir = tempfile::tempdir().unwrap();
    let (spec, md, _) = stability(dir.path(), "exact", &fixture("exact-ggx.brdf"), &[], 0);
    assert!(spec["expected_from"].as_str().unwrap().contains("its formula exactly, no floor"), "{spec}");
    assert_eq!(valid_cases_out(&spec), Vec::<String>::new());
    let counted =
        132_300 - spec["grid_outside_domain"].as_u64().unwrap() - spec["grid_without_value"].as_u64().unwrap();
    let out = spec["grid_out_of_tolerance"].as_u64().unwrap();
    assert!(counted > 50_000 && out as f64 <= 1e-3 * counted as f64, "{out} of {counted} grid points out of tolerance");
    assert_eq!(spec["discontinuities"], 0);
    // The case at N.V = N.L = 1e-7 is judged against the formula there (about 8e3), not at the 1e-4 floor.
    let at =
        spec["cases_out_of_tolerance"].as_array().unwrap().iter().any(|c| c["case"].as_str().unwrap().contains("1e-7"));
    assert!(!at);
    // The worst value is named with its inputs.
    if out > 0 {
        assert!(md.contains("## Out of tolerance: where") && md.contains("the worst") && md.contains("NoV "), "{md}");
    }
}

/// No combination of failing hard cases and grid points panics: each shape exits as it should (1 where a valid
/// input gives NaN, Inf or a negative value) with every output written.
#[test]
fn every_shape_of_failure_writes_its_report() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // NaN only where L + V = 0: a hard case, no grid point (the heat map had no panel and divided by zero).
    let (spec, md, out) = stability(d, "cases", &fixture("nan-at-no-half-vector.brdf"), &[], 1);
    assert!(spec["nan"].as_u64().unwrap() > 0 && spec["failures"]["grid_points"] == 0, "{spec}");
    assert!(md.contains("L = -V"), "{md}");
    assert!(!common::device_file(&out, "stability-", ".md").with_extension("png").exists());
    // Negative on one grid row only: the heat map is drawn.
    let (spec, _, out) = stability(d, "grid", &fixture("negative-on-a-grid-row.brdf"), &[], 1);
    assert!(spec["negative"].as_u64().unwrap() > 0 && spec["failures"]["cases"].as_array().unwrap().is_empty());
    assert!(std::fs::read_dir(&out).unwrap().any(|e| e.unwrap().path().to_string_lossy().ends_with("-failures.png")));
    // Poisoned only by invalid input: reported, not failing.
    let (spec, _, _) = stability(d, "invalid", &fixture("poisoned-by-invalid-input.brdf"), &[], 0);
    assert!(spec["invalid_input_poisoned"].as_u64().unwrap() > 0 && spec["nan"] == 0, "{spec}");
    // Nothing to find.
    let (spec, _, _) = stability(d, "clean", &fixture("clean.brdf"), &[], 0);
    assert_eq!((spec["nan"].as_u64(), spec["inf"].as_u64(), spec["negative"].as_u64()), (Some(0), Some(0), Some(0)));
}

/// An entry returning f_s N.L with N.L floored at 1e-8 returns a tiny positive value below the horizon: judged
/// as it is (finite, non-negative, about 0), not divided by the negative N.L into a negative f_s.
#[test]
fn an_epsilon_floored_f_nol_entry_is_not_negative_below_the_horizon() {
    let dir = tempfile::tempdir().unwrap();
    let reference = "d=ggx,vis=smith-ggx-correlated,f=schlick";
    let (spec, _, _) =
        stability(dir.path(), "nol", &fixture("epsilon-floored-nol.brdf"), &["--reference", reference], 0);
    assert_eq!((spec["negative"].as_u64(), spec["nan"].as_u64()), (Some(0), Some(0)), "{spec}");
    let below: Vec<String> = valid_cases_out(&spec)
        .into_iter()
        .filter(|c| c.contains("light, NoL = -") || c.contains("back-facing"))
        .collect();
    assert!(below.is_empty(), "{below:?}");
}

/// A declared domain is checked at its own bounds, which the catalogue's roughness values (0, 1e-4, 1e-2, ...)
/// miss, and what fp32 loses there is said (at a floor of 0.02, the fp32 peak of (NoH a2 - NoH) NoH + 1 is 20%
/// low).
#[test]
fn a_declared_domain_is_checked_at_its_own_bounds() {
    let dir = tempfile::tempdir().unwrap();
    let file = fixture("exact-ggx.brdf");
    let (spec, md, _) = stability(dir.path(), "odd", &file, &["--roughness", "0.0731..1"], 0);
    let bounds = spec["at_domain_bounds"].as_array().unwrap();
    assert!(
        bounds.iter().any(|b| b["case"].as_str().unwrap().contains("roughness minimum 0.0731")
            && b["inputs"].as_str().unwrap().contains("roughness 0.0731")),
        "{bounds:?}"
    );
    assert!(md.contains("## At the domain's bounds"), "{md}");
    let (spec, md, _) = stability(dir.path(), "floor", &fixture("floor-002-ggx.brdf"), &[], 0);
    let peak = spec["at_domain_bounds"]
        .as_array()
        .unwrap()
        .iter()
        .find(|b| b["case"].as_str().unwrap().ends_with("minimum 0.02, N = H"))
        .cloned()
        .expect("the peak at the roughness minimum");
    let loss = peak["loss"].as_f64().unwrap();
    assert!(loss < -0.1, "fp32's loss at the peak at the floor 0.02: {loss}");
    assert!(md.contains("% low "), "{md}");
}

/// LearnOpenGL-style Schlick-GGX with k = (r + 1)^2 / 8 is the `schlick-ggx-karis` term: its file matches the
/// reference it names within 2e-3 on N.V, N.L in [0.2, 1] and roughness in [0.1, 1].
#[test]
fn learnopengl_style_code_matches_schlick_ggx_karis() {
    let dir = tempfile::tempdir().unwrap();
    let file = fixture("learnopengl-style.brdf");
    let args =
        ["diff", "--model", &file, "--nov", "0.2..1", "--nol", "0.2..1", "--roughness", "0.1..1", "--json", "r.json"];
    run_in(dir.path(), &args).ok();
    let r: Value = serde_json::from_str(&std::fs::read_to_string(dir.path().join("r.json")).unwrap()).unwrap();
    let max = r["diffs"][0]["difference"]["max_rel"].as_f64().unwrap();
    assert!(max < 2e-3, "max rel {max} against d=ggx,vis=schlick-ggx-karis,f=schlick");
    // The plain Schlick-GGX (k = a/2) is not what it is.
    let args = [
        "diff",
        "--model",
        &file,
        "--reference",
        "d=ggx,vis=schlick-ggx,f=schlick",
        "--nov",
        "0.2..1",
        "--nol",
        "0.2..1",
        "--roughness",
        "0.1..1",
        "--json",
        "k.json",
    ];
    run_in(dir.path(), &args);
    let k: Value = serde_json::from_str(&std::fs::read_to_string(dir.path().join("k.json")).unwrap()).unwrap();
    assert!(k["diffs"][0]["difference"]["max_rel"].as_f64().unwrap() > 0.1);
}

/// An engine's own code is also compared with the reference without brdfprof's guards, and a net the
/// memory-only kernel sets reads "harness-bound", not 0.00.
#[test]
fn an_engine_file_is_costed_against_ggx_unguarded_too() {
    let dir = tempfile::tempdir().unwrap();
    let file = fixture("exact-ggx.brdf");
    let r = run_in(dir.path(), &["inspect", "--device", "radv:navi21", "--model", &file, "--json", "i.json"]).ok();
    assert!(r.stdout.contains("net vs ggx,guards=off"), "{}", r.stdout);
    let report: Value = serde_json::from_str(&std::fs::read_to_string(dir.path().join("i.json")).unwrap()).unwrap();
    let rows = report["cost"]["rows"].as_array().or(report["reports"][0]["cost"]["rows"].as_array()).unwrap();
    assert!(rows.iter().any(|r| r["model"] == "ggx,guards=off"), "{rows:?}");
    // On Mali the memory-only kernel binds on load/store above a constant BRDF's arithmetic: no ratio at all.
    let clean = fixture("clean.brdf");
    let r = run_in(dir.path(), &["inspect", "--device", "mali:g52", "--model", &clean]).ok();
    let line =
        r.stdout.lines().filter(|l| l.starts_with("| clean ")).last().expect("a cost row for the constant model");
    assert!(line.contains("harness-bound") && !line.contains("| 0.00 |"), "{line}");
}

/// `report`'s summary gives a diffed model's signed figure (its best-fit scale and the shares brighter and
/// darker) beside the unsigned maximum.
#[test]
fn the_report_summary_says_how_a_diffed_model_is_wrong() {
    let dir = tempfile::tempdir().unwrap();
    let file = fixture("learnopengl-style.brdf");
    run_in(dir.path(), &["diff", "--model", &file, "--samples", "2000", "--json", "d.json"]).no_validation();
    run_in(dir.path(), &["report", "d.json", "--out", "r.html"]).ok();
    let html = std::fs::read_to_string(dir.path().join("r.html")).unwrap();
    let summary = &html[html.find("id=\"summary\"").expect("a summary")..];
    assert!(summary.contains("signed vs") && summary.contains("% brighter"), "no signed figure in the summary");
}

/// A LearnOpenGL-style fragment shader pasted whole, its stage interface (`in`, `out`, `layout(location)`,
/// `flat`) and uniforms included, evaluates: they are dropped as private globals (said once with a count) and
/// it matches its reference within 2e-3.
#[test]
fn a_fragment_shader_pasted_whole_evaluates() {
    let dir = tempfile::tempdir().unwrap();
    let file = common::repo_root().join("tests/fixtures/brdf/engine/learnopengl-pasted.brdf").display().to_string();
    let args =
        ["diff", "--model", &file, "--nov", "0.2..1", "--nol", "0.2..1", "--roughness", "0.1..1", "--json", "r.json"];
    let r = run_in(dir.path(), &args).ok();
    let said: Vec<&str> = r.stderr.lines().filter(|l| l.contains("dropped from")).collect();
    assert!(
        said.iter()
            .any(|l| l.contains("`layout(location=0) out` dropped from `FragColor`") && l.contains("more alike")),
        "{}",
        r.stderr
    );
    let report: Value = serde_json::from_str(&std::fs::read_to_string(dir.path().join("r.json")).unwrap()).unwrap();
    let max = report["diffs"][0]["difference"]["max_rel"].as_f64().unwrap();
    assert!(max < 2e-3, "max rel {max}");
}

/// The HTML page names what the Markdown names: each out-of-tolerance value with its inputs, and the cases at
/// the domain's bounds with the loss there.
#[test]
fn the_html_names_the_inputs_out_of_tolerance_and_the_loss_at_the_bounds() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let file = fixture("floor-002-ggx.brdf");
    let r =
        run_in(d, &["stability", "--no-energy", "--model", &file, "--out", "st", "--html", "s.html"]).no_validation();
    assert_eq!(r.code, Some(0), "{}", r.stderr);
    let html = std::fs::read_to_string(d.join("s.html")).unwrap();
    assert!(html.contains("Out of tolerance: where") && html.contains("NoV "), "no out-of-tolerance inputs");
    assert!(html.contains("At the domain") && html.contains("% low"), "no loss at the domain's bounds");
}
