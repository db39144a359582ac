//! The stability suite on lavapipe (validation layer on): every built-in spec in fp32 gives no NaN, Inf or
//! negative value over the hard-case catalogue and the dense grid, every hard case is within tolerance of its
//! expected value, no out-of-tolerance step, reciprocity holds. fp16 is reported; the test asserts what fp16
//! can do: never negative, never poisoned by invalid input, finite and close on well-conditioned inputs; and
//! the CLI exits 1 and says so where it fails. The guards are the same constants in GLSL and Rust.

use crate::common;
use brdfprof::brdf::{ModelSpec, PRESETS, Precision, guards, samples};
use brdfprof::kernels::{self, RunLimits};
use brdfprof::stability::{self, catalogue, grid};

#[test]
fn every_fp32_spec_is_stable_over_catalogue_and_grid() {
    let gpu = common::gpu();
    let cases = catalogue::hard_cases();
    let grid = grid::samples();
    let reciprocity = samples::well_conditioned(5_000, 4, 1e-3, 0.0..1.0);
    let specs: Vec<ModelSpec> =
        stability::default_specs().into_iter().filter(|s| s.precision == Precision::F32).collect();
    assert!(specs.len() >= 80, "every D x Vis and every Fresnel");
    let mut problems = Vec::new();
    for spec in &specs {
        let r = stability::check_model(&gpu, &common::model(*spec), &Default::default(), &cases, &grid, &reciprocity)
            .unwrap();
        if r.fails() {
            problems.push(format!(
                "{}: {} NaN, {} Inf, {} negative (worst at {})",
                r.spec, r.nan, r.inf, r.negative, r.worst.input
            ));
        }
        for c in &r.cases_out_of_tolerance {
            problems.push(format!(
                "{}: case `{}` got {:?}, expected {:?} ({:.2} x tolerance)",
                r.spec, c.case, c.got, c.expected, c.deviation
            ));
        }
        if r.grid_out_of_tolerance > 0 || r.discontinuities > 0 {
            problems.push(format!(
                "{}: {} grid points out of tolerance, {} steps; worst {:.2} x tolerance at {}",
                r.spec, r.grid_out_of_tolerance, r.discontinuities, r.worst.deviation, r.worst.input
            ));
        }
        if r.invalid_input_poisoned > 0 {
            problems.push(format!("{}: NaN/Inf input came out non-finite or negative", r.spec));
        }
        if r.reciprocity.is_none_or(|x| x > 1e-4) || r.reciprocity_nonfinite > 0 {
            problems.push(format!(
                "{}: f(v,l) and f(l,v) differ by {:?} ({} NaN/Inf)",
                r.spec, r.reciprocity, r.reciprocity_nonfinite
            ));
        }
    }
    assert!(problems.is_empty(), "{} problems:\n{}", problems.len(), problems.join("\n"));
    common::assert_no_validation_messages(&gpu);
}

#[test]
fn fp16_does_what_it_can_and_the_report_says_where_it_cannot() {
    let gpu = common::gpu();
    // On the well-conditioned domain of the foundation tests, every preset in fp16 is finite, non-negative and
    // close to its f64 twin (fp16's 11-bit significand; Blinn's exponent m amplifies it most).
    let s = samples::well_conditioned(50_000, 3, 0.05, 0.2..1.0);
    for p in PRESETS {
        let spec = ModelSpec { precision: Precision::F16, ..ModelSpec::preset(p.name).unwrap() };
        let bound = match p.name {
            "blinn" => 0.25,
            "cook-torrance" => 0.08,
            _ => 0.04,
        };
        let got = kernels::eval(&gpu, &common::model(spec), &s, RunLimits::default()).unwrap();
        let mut worst = 0f64;
        for (x, g) in s.iter().zip(&got) {
            let e = spec.eval(x);
            for c in 0..3 {
                assert!(g[c].is_finite() && g[c] >= 0.0, "{}: {} at {x:?}", spec, g[c]);
                worst = worst.max(common::rel_err(g[c] as f64, e[c]));
            }
        }
        println!("{:16} fp16 max relative error {worst:.3e}", p.name);
        assert!(worst <= bound, "{spec}: {worst}");
    }
    // Over the hard cases and the grid, fp16 may overflow; it must never go negative nor pass poison on.
    let cases = catalogue::hard_cases();
    let grid = grid::samples();
    for name in ["ggx", "cook-torrance", "burley"] {
        let spec = ModelSpec { precision: Precision::F16, ..ModelSpec::preset(name).unwrap() };
        let r = stability::check_model(&gpu, &common::model(spec), &Default::default(), &cases, &grid, &[]).unwrap();
        assert_eq!((r.negative, r.invalid_input_poisoned), (0, 0), "{spec}");
        // Every failure is visible: in the heat map of grid cells or among the failing hard cases.
        let in_cases = r.cases_out_of_tolerance.iter().any(|c| c.got.iter().any(|x| !x.is_finite()));
        assert!(!r.fails() || r.bad_cells.is_some() || in_cases, "{spec}: fails but shows nothing");
    }
    common::assert_no_validation_messages(&gpu);
}

#[test]
fn cli_exits_1_and_reports_failing_fp16_and_0_when_stable() {
    let dir = tempfile::tempdir().unwrap();
    let run = |models: &[&str]| {
        let mut c = common::brdfprof();
        c.args(["stability", "--validate", "--out"]).arg(dir.path());
        for m in models {
            c.args(["--model", m]);
        }
        c.output().unwrap()
    };
    let ok = run(&["ggx", "burley"]);
    assert_eq!(ok.status.code(), Some(0), "{}", String::from_utf8_lossy(&ok.stderr));
    let md = std::fs::read_to_string(common::device_file(dir.path(), "stability-", ".md")).unwrap();
    assert!(md.contains("| ggx ") && md.contains("| ok "));
    assert!(image::open(common::device_file(dir.path(), "furnace-", ".png")).is_ok());
    assert!(image::open(common::device_file(dir.path(), "albedo-", ".png")).is_ok());
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(common::device_file(dir.path(), "stability-", ".json")).unwrap())
            .unwrap();
    let burley = json["specs"].as_array().unwrap().iter().find(|s| s["spec"] == "burley").unwrap();
    assert!(burley["energy"]["gains_energy"].as_bool().unwrap(), "Burley's GTR with GGX's Smith G gains energy");

    let failing = run(&["ggx", "ggx,precision=f16"]);
    assert_eq!(failing.status.code(), Some(1), "{}", String::from_utf8_lossy(&failing.stderr));
    assert!(String::from_utf8_lossy(&failing.stderr).contains("1 spec(s) give NaN, Inf or negative values"));
    let md = std::fs::read_to_string(common::device_file(dir.path(), "stability-", ".md")).unwrap();
    assert!(md.contains("| ggx,precision=f16") && md.contains("FAIL"));
    let failures = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().path())
        .find(|p| p.to_string_lossy().ends_with("-failures.png"));
    assert!(failures.is_some_and(|p| image::open(p).is_ok()), "a heat map for the failing spec");
}

#[test]
fn guards_are_the_same_constants_in_glsl_and_rust() {
    let glsl = std::fs::read_to_string(common::repo_root().join("glsl/generated/brdf_table.glsl")).unwrap();
    let constant = |name: &str, occurrence: usize| -> f64 {
        let needle = format!("const float {name} = ");
        let start = glsl.match_indices(&needle).nth(occurrence).unwrap_or_else(|| panic!("{name} in brdf.glsl")).0
            + needle.len();
        glsl[start..].split(';').next().unwrap().trim().parse().unwrap()
    };
    // MIN_ROUGHNESS appears twice: the fp16 branch first, then fp32.
    assert_eq!(constant("MIN_ROUGHNESS", 0), guards::MIN_ROUGHNESS_F16);
    assert_eq!(constant("MIN_ROUGHNESS", 1), guards::MIN_ROUGHNESS_F32);
    assert_eq!(constant("MIN_COSINE", 0), guards::MIN_COSINE);
    assert_eq!(constant("MIN_VECTOR", 0) as f32 as f64, guards::MIN_VECTOR);
    assert_eq!(constant("GTR_SERIES_BAND", 0), guards::GTR_SERIES_BAND);
    assert_eq!(constant("F0_MAX", 0), guards::F0_MAX);
}

/// Which hard cases each guard saves. Presets run with all their guards, all off, each off alone
/// and each on alone (`with_guard_variants`): the guarded spec passes; without its guards `L = -V` is out of
/// tolerance, and the reference (GGX) gives NaN or Inf, as measured (docs/guards.md); no guard set that keeps
/// the safe half vector lets `L = -V` out of tolerance.
#[test]
fn stability_says_what_each_guard_saves() {
    let gpu = common::gpu();
    let presets: Vec<brdfprof::model::Model> =
        PRESETS.iter().take(2).map(|p| common::model(ModelSpec::preset(p.name).unwrap())).collect();
    let models = stability::with_guard_variants(presets.clone());
    assert_eq!(
        models.len(),
        presets.len() * (2 + 2 * guards::SWITCHES.len()),
        "each preset, off, each off alone, each on alone"
    );
    let options =
        stability::StabilityOptions { models, energy: false, reference: None, roughness: None, nov: None, nol: None };
    let report = stability::run(&gpu, &options, &indicatif::ProgressBar::hidden()).unwrap();
    common::assert_no_validation_messages(&gpu);
    assert_eq!(report.guard_savings.len(), presets.len() * (1 + 2 * guards::SWITCHES.len()));
    let safe_h = guards::SWITCHES.iter().find(|g| g.name == "safe-h").unwrap();
    let no_half_vector = catalogue::hard_cases().into_iter().find(|c| c.name.starts_with("L = -V")).unwrap().name;
    for p in &presets {
        let guarded = report.specs.iter().find(|s| s.spec == p.name()).unwrap();
        assert!(!guarded.fails(), "{}: fails with its guards", guarded.spec);
        let mine: Vec<&stability::GuardSaving> = report.guard_savings.iter().filter(|g| g.spec == p.name()).collect();
        let all_off = mine.iter().find(|g| g.off == "off").unwrap();
        assert!(all_off.cases.contains(&no_half_vector), "{}: without its guards: {all_off:?}", p.name());
        if p.name() == ModelSpec::reference().name() {
            assert!(all_off.nan + all_off.inf > 0, "the reference without its guards: {all_off:?}");
        }
        for g in &mine {
            let set = guards::GuardSet::parse(&g.off).unwrap();
            if set.0 & safe_h.bit != 0 {
                assert!(
                    !g.cases.contains(&no_half_vector),
                    "{} {}: L = -V out of tolerance with the safe half vector on",
                    p.name(),
                    g.off
                );
            }
        }
    }
    let md = report.markdown();
    assert!(
        md.contains("## What each guard saves") && md.contains("only safe-h") && md.contains("all but lit-mask"),
        "{md}"
    );
}

/// A `.brdf` file's failures named where they happen. unclamped-ggx.brdf (written for the tests, no
/// roughness floor) is 0/0 at roughness 0 on the peak: `stability` names each failing hard case with its input
/// values and says the roughness floor, applied to the input, removes it; the grid's failures are counted with
/// what each input guard removes. Within a roughness domain that leaves 0 out the file passes; against a
/// `--reference`, tolerances and jumps are counted as for a built-in spec.
#[test]
fn stability_names_a_files_failing_inputs_and_the_guard_that_removes_them() {
    let dir = tempfile::tempdir().unwrap();
    let file = common::repo_root().join("tests/fixtures/brdf/engine/unclamped-ggx.brdf");
    let run = |extra: &[&str]| -> (Option<i32>, String, serde_json::Value) {
        let out = common::brdfprof()
            .args(["stability", "--validate", "--no-energy", "--model"])
            .arg(&file)
            .arg("--out")
            .arg(dir.path())
            .args(extra)
            .output()
            .unwrap();
        let md = std::fs::read_to_string(common::device_file(dir.path(), "stability-", ".md")).unwrap();
        let json = serde_json::from_str(
            &std::fs::read_to_string(common::device_file(dir.path(), "stability-", ".json")).unwrap(),
        )
        .unwrap();
        (out.status.code(), md, json)
    };
    let html = dir.path().join("report.html");
    let (code, md, json) = run(&["--html", html.to_str().unwrap()]);
    assert_eq!(code, Some(1), "{md}");
    let page = std::fs::read_to_string(&html).unwrap();
    assert!(
        page.contains("Where the failing specs fail")
            && page.contains("removed by `roughness-floor`")
            && page.contains("(no twin)"),
        "the page says what the Markdown says"
    );
    let spec = &json["specs"][0];
    let failures = &spec["failures"];
    let cases = failures["cases"].as_array().unwrap();
    let peak = cases
        .iter()
        .find(|c| c["at"] == "roughness 0, N = H")
        .unwrap_or_else(|| panic!("the 0/0 case is named: {failures}"));
    assert_eq!(peak["input"]["roughness"].as_f64(), Some(0.0));
    assert!(peak["got"].as_array().unwrap().iter().all(|x| x.is_null()), "NaN, written as null: {peak}");
    let removed: Vec<&str> = peak["removed_by"].as_array().unwrap().iter().map(|x| x.as_str().unwrap()).collect();
    assert_eq!(removed, ["roughness-floor", "all"], "only the roughness floor removes a 0/0 at roughness 0");
    for c in cases {
        assert!(
            (c["input"]["roughness"].as_f64().unwrap()) < guards::MIN_ROUGHNESS_F32,
            "a failure above the floor: {c}"
        );
    }
    let grid_points = failures["grid_points"].as_u64().unwrap();
    assert!(grid_points > 0);
    let floor =
        failures["grid_removed_by"].as_array().unwrap().iter().find(|g| g["guard"] == "roughness-floor").unwrap();
    assert_eq!(floor["removes"].as_u64(), Some(grid_points), "{failures}");
    assert!(
        md.contains("hard cases `roughness 0, N = H`")
            && md.contains("roughness 0, F0")
            && md.contains("removed by `roughness-floor`"),
        "{md}"
    );
    assert!(spec["jumps_checked"] == false && md.contains("- (no reference)"), "no jumps counted without a reference");

    let (code, md, json) = run(&["--roughness", "0.05..1", "--reference", "d=ggx,vis=smith-ggx-correlated,f=schlick"]);
    assert_eq!(code, Some(0), "above the floor it gives no NaN: {md}");
    let spec = &json["specs"][0];
    assert!(spec["cases_outside_domain"].as_u64().unwrap() > 0 && spec["grid_outside_domain"].as_u64().unwrap() > 0);
    assert_eq!(
        spec["expected_from"],
        "reference `d=ggx,vis=smith-ggx-correlated,f=schlick` (its formula exactly, no floor)"
    );
    assert_eq!(spec["jumps_checked"], true);
    let out: Vec<&str> =
        spec["cases_out_of_tolerance"].as_array().unwrap().iter().map(|c| c["case"].as_str().unwrap()).collect();
    assert!(
        !out.contains(&"L = V") && !out.contains(&"N = H exactly"),
        "the same maths within tolerance of its reference where both are well conditioned: {out:?}"
    );
    assert!(md.contains("checked against the reference") && md.contains("not counted"), "{md}");

    // The same domain and reference declared in the file, with grazing N.V left out too: no flag needed.
    let declared = dir.path().join("declared.brdf");
    let text = std::fs::read_to_string(&file).unwrap();
    let with = text.replacen("bind roughness=@roughness f0=@f0", "bind roughness=@roughness f0=@f0\ndomain roughness 0.05 1\ndomain nov 0.1 1\nreference d=ggx,vis=smith-ggx-correlated,f=schlick", 1);
    assert_ne!(with, text);
    std::fs::write(&declared, with).unwrap();
    let out = common::brdfprof()
        .args(["stability", "--validate", "--no-energy", "--model"])
        .arg(&declared)
        .arg("--out")
        .arg(dir.path())
        .output()
        .unwrap();
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(common::device_file(dir.path(), "stability-", ".json")).unwrap())
            .unwrap();
    let decl = &json["specs"][0];
    assert_eq!(out.status.code(), Some(0), "{decl}");
    assert_eq!(decl["expected_from"], spec["expected_from"], "the file's own reference");
    assert_eq!(decl["domain"], "roughness in [0.05, 1], NoV in [0.1, 1]");
    assert!(
        decl["grid_outside_domain"].as_u64() > spec["grid_outside_domain"].as_u64(),
        "grazing N.V left out as well: {} against {}",
        decl["grid_outside_domain"],
        spec["grid_outside_domain"]
    );
}
