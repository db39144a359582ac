//! An engine's own function as a `.brdf` model's entry (`entry NAME(ARG, ...) returns f_nol` in the file's
//! `brdfprof` section, `entry=` / `returns=` in the spec) and per-file default bindings (`bind`): the
//! engine-shaped test file (tests/fixtures/brdf/engine/engine-ggx.brdf, written for the project) against its
//! twin written as BRDF Explorer's `BRDF` returning f_s (engine-ggx-f.brdf), with no glue written by the user.

use crate::common::{self, run_in};
use std::path::{Path, PathBuf};

fn fixture(name: &str) -> PathBuf {
    common::repo_root().join("tests/fixtures/brdf/engine").join(name)
}

fn engine() -> String {
    fixture("engine-ggx.brdf").display().to_string()
}

fn twin() -> String {
    fixture("engine-ggx-f.brdf").display().to_string()
}

/// Seeded rows over the hemisphere with N.L, N.V in (0.05, 1] and roughness at or above the engine's floor.
fn write_rows(path: &Path, n: usize) {
    let mut s = String::from("nx,ny,nz,vx,vy,vz,lx,ly,lz,roughness,f0r,f0g,f0b\n");
    let mut next = common::uniform(0x9e37_79b9_7f4a_7c15);
    let dir = |next: &mut dyn FnMut() -> f64| {
        let (c, phi) = (0.05 + 0.95 * next(), std::f64::consts::TAU * next());
        let s = (1.0 - c * c).sqrt();
        [s * phi.cos(), s * phi.sin(), c]
    };
    for _ in 0..n {
        let (v, l) = (dir(&mut next), dir(&mut next));
        let (r, f0) = (0.06 + 0.94 * next(), 0.02 + 0.9 * next());
        s += &format!("0,0,1,{},{},{},{},{},{},{r},{f0},0.5,0.9\n", v[0], v[1], v[2], l[0], l[1], l[2]);
    }
    std::fs::write(path, s).unwrap();
}

#[test]
fn an_entry_returning_f_nol_evaluates_as_its_twin_returning_f() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    write_rows(&d.join("in.csv"), 2000);
    for (model, out) in [(engine(), "engine.csv"), (twin(), "twin.csv")] {
        run_in(d, &["eval", "--model", &model, "--input", "in.csv", "--output", out]).ok();
    }
    let (a, b) = (common::csv_values(&d.join("engine.csv")), common::csv_values(&d.join("twin.csv")));
    assert_eq!(a.len(), 2000);
    let worst =
        a.iter().zip(&b).flat_map(|(x, y)| (0..3).map(move |c| common::rel_err(x[c], y[c]))).fold(0.0, f64::max);
    // The division by N.L happens on the host in f64; the rest is the same fp32 maths in another order.
    assert!(worst < 1e-5, "engine form against f form: worst relative difference {worst:e}");
    assert!(a.iter().any(|v| v[0] > 0.0));
}

#[test]
fn the_files_bindings_are_its_defaults_and_entry_and_returns_are_named_where_they_differ() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    write_rows(&d.join("in.csv"), 4);
    // `bind roughness=@roughness f0=@f0` in the file: the bare path is bound, and named by its stem alone.
    let json = d.join("p.json");
    run_in(d, &["profile", "--model", &engine(), "--size", "64x64", "--budget", "5", "--json", json.to_str().unwrap()])
        .ok();
    let report: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let names: Vec<String> =
        report["rows"].as_array().unwrap().iter().map(|r| r["model"].as_str().unwrap().to_string()).collect();
    assert!(names.contains(&"engine-ggx".to_string()), "{names:?}");
    // returns=f overrides the declaration (the value is then f_s N.L taken as f_s: smaller by N.L < 1).
    let forced = format!("{},returns=f", engine());
    run_in(d, &["eval", "--model", &forced, "--input", "in.csv", "--output", "f.csv"]).ok();
    run_in(d, &["eval", "--model", &engine(), "--input", "in.csv", "--output", "fnol.csv"]).ok();
    let (f, g) = (common::csv_values(&d.join("f.csv")), common::csv_values(&d.join("fnol.csv")));
    assert!(f.iter().zip(&g).all(|(x, y)| x[0] < y[0]), "{f:?} {g:?}");
    // The twin's BRDF can be chosen by name; an unknown entry is refused naming the declared ones.
    run_in(d, &["eval", "--model", &format!("{},entry=BRDF", twin()), "--input", "in.csv", "--output", "t.csv"]).ok();
    run_in(d, &["eval", "--model", &format!("{},entry=light", engine()), "--input", "in.csv", "--output", "x.csv"])
        .fails(2, "its entries: surface_light");
    run_in(d, &["eval", "--model", &format!("{},returns=fnol", engine()), "--input", "in.csv", "--output", "x.csv"])
        .fails(2, "expected returns=f or returns=f_nol");
    assert!(!d.join("x.csv").exists());
}

#[test]
fn its_compiler_statistics_on_radv_are_its_twins() {
    let dir = tempfile::tempdir().unwrap();
    let out = crate::compile_only::inspect_json(
        dir.path(),
        "e",
        &["radv:navi21"],
        &["--model", &engine(), "--model", &twin()],
        "ACO statistics",
    );
    let rows = out["rows"].as_array().unwrap();
    let row = |name: &str| rows.iter().find(|r| r["model"] == name).unwrap_or_else(|| panic!("no {name}: {rows:?}"));
    let (e, t) = (row("engine-ggx"), row("engine-ggx-f"));
    // The engine's f_s N.L times the light against the twin's f_s times N.L times the light: the harness weighs
    // a file's f_s as the engine form weighs its own, so ACO emits the same code (its hash is the code's; the
    // driver's pipeline hash also covers the SPIR-V, which differs).
    let stats = |r: &serde_json::Value| {
        r["stats"]
            .as_object()
            .unwrap()
            .iter()
            .filter(|(k, _)| k.starts_with("driver/") && !k.ends_with("Driver pipeline hash"))
            .map(|(k, v)| (k.clone(), v.clone()))
            .collect::<Vec<_>>()
    };
    assert!(stats(e).iter().any(|(k, _)| k.ends_with("/Instructions")), "{e}");
    assert_eq!(stats(e), stats(t), "every ACO statistic of the engine form is its twin's");
}

#[test]
fn bad_entry_declarations_exit_2_at_their_line() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    write_rows(&d.join("in.csv"), 2);
    let base = std::fs::read_to_string(fixture("engine-ggx.brdf")).unwrap();
    let entry_line = base.lines().position(|l| l.starts_with("entry ")).unwrap() + 1;
    let cases = [
        (
            "entry surface_light(N, L, V, f0, roughness) returns f_nol",
            "entry missing_fn(N, L, V) returns f_nol",
            format!(":{entry_line}: entry `missing_fn`: the shader defines no function"),
        ),
        (
            "entry surface_light(N, L, V, f0, roughness) returns f_nol",
            "entry surface_light(N, L, V) returns f_nol",
            format!(":{entry_line}: entry `surface_light` takes 5 arguments"),
        ),
        (
            "entry surface_light(N, L, V, f0, roughness) returns f_nol",
            "entry surface_light(N, L, V, f0, roughness) returns nol",
            format!(":{entry_line}: `returns nol`: expected f or f_nol"),
        ),
        (
            "entry surface_light(N, L, V, f0, roughness) returns f_nol",
            "entry surface_light(N, L, V, f0, roughness",
            format!(":{entry_line}: `entry surface_light(N, L, V, f0, roughness`: the argument list has no closing"),
        ),
        (
            "bind roughness=@roughness f0=@f0",
            "bind gloss=@roughness",
            ": `bind gloss=...`: the file has no parameter `gloss`".to_string(),
        ),
        (
            "bind roughness=@roughness f0=@f0",
            "bind roughness=0.5",
            ": `roughness=0.5`: `bind` binds a parameter to an input".to_string(),
        ),
        ("bind roughness=@roughness f0=@f0", "tint 1 2 3", ": unknown directive `tint`".to_string()),
        (
            "domain roughness 0.0525 1",
            "domain roughness 1 0.0525",
            ": `domain roughness 1 0.0525`: MIN 1 is above MAX 0.0525".to_string(),
        ),
        (
            "domain roughness 0.0525 1",
            "domain hov 0 1",
            ": `domain hov`: the domains declared are roughness, nov and nol".to_string(),
        ),
        (
            "domain roughness 0.0525 1",
            "domain nov 0.1 2",
            ": `domain nov 0.1 2`: MIN and MAX are numbers within [0, 1]".to_string(),
        ),
        (
            "domain roughness 0.0525 1",
            "domain roughness 0.0525 1\ndomain nol 0 1\ndomain nol 0.1 1",
            ": the nol domain is declared twice".to_string(),
        ),
        (
            "domain roughness 0.0525 1",
            "reference d=ggx,vis=nothing,f=schlick",
            ": `reference d=ggx,vis=nothing,f=schlick`:".to_string(),
        ),
        // An argument glslang refuses is reported at the entry's own line, with the file's names.
        (
            "entry surface_light(N, L, V, f0, roughness) returns f_nol",
            "entry surface_light(N, L, V, f0, gloss) returns f_nol",
            format!("engine.brdf:{entry_line}:"),
        ),
    ];
    for (from, to, needle) in cases {
        let text = base.replacen(from, to, 1);
        assert_ne!(text, base, "{from}");
        std::fs::write(d.join("engine.brdf"), text).unwrap();
        let r = run_in(d, &["eval", "--model", "engine.brdf", "--input", "in.csv", "--output", "out.csv"])
            .fails(2, &needle);
        assert!(!d.join("out.csv").exists(), "{}", r.stderr);
    }
}

#[test]
fn the_translating_targets_check_and_price_an_f_nol_entry() {
    // The translation check compares the translated eval kernel on the host with the Vulkan one, both as f_s:
    // an f_nol entry's host values are divided by N.L as the device's are.
    let dir = tempfile::tempdir().unwrap();
    let out = crate::compile_only::inspect_json(
        dir.path(),
        "t",
        &["nvidia:sm_89", "intel:gen12lp"],
        &["--model", &engine()],
        "ptxas statistics",
    );
    for report in out["reports"].as_array().unwrap() {
        let rows = report["cost"]["rows"].as_array().unwrap();
        let row = rows.iter().find(|r| r["model"] == "engine-ggx").unwrap_or_else(|| panic!("{rows:?}"));
        assert!(row["net_cycles_per_eval"].as_f64().unwrap() > 0.0, "{row}");
    }
}

/// The largest relative difference over the channels of a diff report.
fn max_rel(report: &serde_json::Value) -> f64 {
    report["difference"]["channels"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c["max_rel"].as_f64().unwrap())
        .fold(0.0, f64::max)
}

#[test]
fn diff_samples_the_files_declared_roughness_domain_unless_told_otherwise() {
    // engine-ggx.brdf declares `domain roughness 0.0525 1` (its roughness floor): within it, it is the term
    // library's GGX with the height-correlated Smith and Schlick; below it, the floor makes it differ.
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let spec = "d=ggx,vis=smith-ggx-correlated,f=schlick";
    let diff = |name: &str, extra: &[&str]| -> serde_json::Value {
        let json = d.join(format!("{name}.json"));
        let model = engine();
        let mut args =
            vec!["diff", "--model", spec, "--model", &model, "--samples", "4000", "--json", json.to_str().unwrap()];
        args.extend(extra);
        run_in(d, &args).ok();
        serde_json::from_str(&std::fs::read_to_string(json).unwrap()).unwrap()
    };
    let within = diff("within", &[]);
    assert!(
        within["input"]
            .as_str()
            .unwrap()
            .contains("roughness in [0.0525, 1] (the models' declared domain: engine-ggx [0.0525, 1])"),
        "{}",
        within["input"]
    );
    assert!(max_rel(&within) < 2e-3, "within the domain: {}", max_rel(&within));
    let all = diff("all", &["--roughness", "0..1"]);
    assert!(all["input"].as_str().unwrap().contains("roughness in [0, 1] (--roughness)"), "{}", all["input"]);
    assert!(max_rel(&all) > 0.5, "below the floor the file differs: {}", max_rel(&all));
    run_in(d, &["diff", "--model", spec, "--model", &engine(), "--roughness", "0.5..0.2"]).fails(2, "--roughness");

    // A file that names its reference and its N.V range is diffed alone: against the reference, on samples
    // drawn within its domains (read back from the CSV), and a range no model meets is refused.
    let base = std::fs::read_to_string(engine()).unwrap();
    let own = base.replacen(
        "domain roughness 0.0525 1",
        &format!("domain roughness 0.0525 1\ndomain nov 0.5 1\nreference {spec}"),
        1,
    );
    assert_ne!(own, base);
    std::fs::write(d.join("own.brdf"), own).unwrap();
    let (json, csv) = (d.join("own.json"), d.join("own.csv"));
    run_in(
        d,
        &[
            "diff",
            "--model",
            "own.brdf",
            "--samples",
            "2000",
            "--json",
            json.to_str().unwrap(),
            "--csv",
            csv.to_str().unwrap(),
        ],
    )
    .ok();
    let report: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(report["kind"], "diff-set", "{report}");
    let text = report.to_string();
    assert!(
        text.contains("NoV in [0.5, 1] (the models' declared domain: own [0.5, 1])")
            && text.contains("NoL in [0.05, 1]"),
        "{text}"
    );
    let rows: Vec<Vec<f64>> = std::fs::read_to_string(&csv)
        .unwrap()
        .lines()
        .skip(1)
        .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), 2000);
    for r in &rows {
        let (n, v) = ([r[0], r[1], r[2]], [r[3], r[4], r[5]]);
        let dot: f64 = n.iter().zip(v).map(|(a, b)| a * b).sum();
        assert!(dot > 0.5 - 1e-5 && r[9] >= 0.0525 - 1e-6, "a row outside the declared domain: {r:?}");
    }
    run_in(d, &["diff", "--model", "own.brdf", "--model", spec, "--nov", "0.2..0.1"]).fails(2, "--nov");
}

/// The glue forms of docs/engine-brdf.md, each a test file of tests/fixtures/brdf/engine/forms/ with the twin's
/// maths in another engine's shape.
fn glue_forms() -> Vec<PathBuf> {
    let mut forms: Vec<PathBuf> = std::fs::read_dir(fixture("forms"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "brdf"))
        .collect();
    forms.sort();
    forms
}

#[test]
fn every_glue_form_evaluates_as_its_twin_with_no_glue_written() {
    let dir = tempfile::tempdir().unwrap();
    let forms = glue_forms();
    assert!(forms.len() >= 4, "the page's four forms: {forms:?}");
    let docs = std::fs::read_to_string(common::repo_root().join("docs/engine-brdf.md")).unwrap();
    for form in &forms {
        let name = form.file_name().unwrap().to_str().unwrap();
        assert!(docs.contains(&format!("forms/{name}")), "docs/engine-brdf.md works through {name}");
        let json = dir.path().join(format!("{name}.json"));
        let r = run_in(
            dir.path(),
            &[
                "diff",
                "--samples",
                "2000",
                "--model",
                &twin(),
                "--model",
                form.to_str().unwrap(),
                "--json",
                json.to_str().unwrap(),
            ],
        )
        .ok();
        let j: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
        for c in j["difference"]["channels"].as_array().unwrap() {
            assert!(c["max_rel"].as_f64().unwrap() < 1e-5, "{name} against the twin: {c}\n{}", r.stdout);
            assert_eq!(c["a_nonfinite"].as_u64().unwrap() + c["b_nonfinite"].as_u64().unwrap(), 0, "{name}: {c}");
        }
    }
}

#[test]
fn bad_out_and_scratch_arguments_exit_2_at_the_entry_line() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    write_rows(&d.join("in.csv"), 2);
    let base = std::fs::read_to_string(fixture("forms/accumulator.brdf")).unwrap();
    let line = base.lines().position(|l| l.starts_with("entry ")).unwrap() + 1;
    let call = "roughness, @scratch, @out)";
    let cases = [
        ("roughness, @out, @out)", format!(":{line}: entry `light_compute`: `@out` is given 2 times")),
        ("roughness, @scratch, @scratch)", format!(":{line}: entry `light_compute` returns `void`")),
        ("@out, @scratch, vec3(0.0))", format!(":{line}: entry `light_compute`: argument 7 is `@out` but parameter 7")),
        (
            "roughness, @scratch, @diffuse)",
            format!(":{line}: entry `light_compute`: `@diffuse`: an argument is a GLSL expression"),
        ),
    ];
    for (to, needle) in cases {
        std::fs::write(d.join("engine.brdf"), base.replacen(call, to, 1)).unwrap();
        let r = run_in(d, &["eval", "--model", "engine.brdf", "--input", "in.csv", "--output", "out.csv"])
            .fails(2, &needle);
        assert!(!d.join("out.csv").exists(), "{}", r.stderr);
    }
    // An `@out` that is not a vec3.
    let float_out = base.replacen("inout vec3 specular_light", "inout float specular_light", 1).replacen(
        "specular_light += light_color",
        "specular_light += ndotl; vec3 unused = light_color",
        1,
    );
    std::fs::write(d.join("engine.brdf"), float_out).unwrap();
    run_in(d, &["eval", "--model", "engine.brdf", "--input", "in.csv", "--output", "out.csv"])
        .fails(2, &format!(":{line}: entry `light_compute`: the `@out` parameter 9"));
}

/// A domain outside its quantity's range is refused at its line; a domain or range that leaves the stability
/// suite nothing to check exits 2 saying so, never `ok`.
#[test]
fn a_domain_outside_its_range_or_leaving_nothing_to_check_exits_2() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let text = std::fs::read_to_string(engine()).unwrap();
    let line = text.lines().position(|l| l.trim().starts_with("domain roughness")).expect("a roughness domain") + 1;
    std::fs::write(d.join("beyond.brdf"), text.replacen("domain roughness 0.0525 1", "domain roughness 2 3", 1))
        .unwrap();
    run_in(d, &["stability", "--model", "beyond.brdf", "--out", "st"])
        .fails(2, &format!("beyond.brdf:{line}: `domain roughness 2 3`: MIN and MAX are numbers within [0, 1]"));
    // Between the grid's roughness values and the hard cases': nothing to check.
    run_in(d, &["stability", "--model", "ggx", "--roughness", "0.333..0.333", "--out", "st"])
        .fails(2, "ggx: roughness in [0.333, 0.333]: none of the");
    assert!(!d.join("st").exists(), "no report");
}

/// A model returning f N.L is not measured at N.L = 0, where its value is 0 whatever f is (dividing by N.L
/// there measures rounding: deviations of 1e15 tolerances): those grid points are left out and counted as
/// outside its domain, which says why; its twin returning f keeps them.
#[test]
fn stability_leaves_out_n_dot_l_zero_for_a_model_returning_f_nol() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let grid = brdfprof::stability::grid::samples();
    let unit = |v: [f32; 3]| glam::DVec3::new(v[0].into(), v[1].into(), v[2].into()).normalize();
    let low = |s: &brdfprof::brdf::Sample| !(0.0525..=1.0).contains(&f64::from(s.roughness));
    let zero = |s: &brdfprof::brdf::Sample| unit(s.n).dot(unit(s.l)).abs() < 1e-9;
    let outside = |f_nol: bool| grid.iter().filter(|s| low(s) || f_nol && zero(s)).count();
    assert!(outside(true) > outside(false), "the grid has N.L = 0 points in the domain");
    let reference = "d=ggx,vis=smith-ggx-correlated,f=schlick";
    for (model, f_nol) in [(engine(), true), (twin(), false)] {
        let out = d.join(if f_nol { "nol" } else { "f" });
        let r = run_in(d, &["stability", "--model", &model, "--reference", reference, "--out", out.to_str().unwrap()]);
        assert!(matches!(r.code, Some(0 | 1)), "{}", r.stderr);
        let json = std::fs::read_dir(&out)
            .unwrap()
            .map(|e| e.unwrap().path())
            .find(|p| p.extension().is_some_and(|e| e == "json"));
        let report: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(json.unwrap()).unwrap()).unwrap();
        let spec = &report["specs"][0];
        assert_eq!(spec["grid_outside_domain"], outside(f_nol) as u64, "{model}");
        assert_eq!(spec["domain"].as_str().unwrap().contains("NoL not 0 (the model returns f N.L"), f_nol, "{model}");
    }
}
