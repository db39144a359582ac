//! `brdfprof diff` end to end: a preset against itself differs by nothing; ggx against filament-high differs by
//! what their f64 twins say on the same samples; the tolerance sets the exit status; the CSV, JSON and picture
//! are written; bad arguments fail with exit 2.

use crate::common;
use brdfprof::brdf::ModelSpec;
use brdfprof::diff;

fn json(path: &std::path::Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

#[test]
fn a_preset_against_itself_differs_by_nothing() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("same.json");
    common::run(&[
        "diff",
        "--model",
        "filament-high",
        "--model",
        "filament-high",
        "--samples",
        "3000",
        "--tolerance",
        "0",
        "--json",
        out.to_str().unwrap(),
    ])
    .ok();
    let j = json(&out);
    assert_eq!(j["kind"], "diff");
    for c in j["difference"]["channels"].as_array().unwrap() {
        for key in ["max_rel", "rms_rel", "max_abs", "rms_abs"] {
            assert_eq!(c[key].as_f64(), Some(0.0), "{key} of {c}");
        }
    }
    assert_eq!(j["histogram"]["identical"].as_u64(), Some(3000));
}

#[test]
fn ggx_against_filament_high_differs_as_the_twins_do() {
    let dir = tempfile::tempdir().unwrap();
    let (out, csv, png) = (dir.path().join("d.json"), dir.path().join("d.csv"), dir.path().join("d.png"));
    let (n, seed) = (4000, 5);
    let args = [
        "diff",
        "--model",
        "ggx",
        "--model",
        "filament-high",
        "--samples",
        "4000",
        "--seed",
        "5",
        "--json",
        out.to_str().unwrap(),
        "--csv",
        csv.to_str().unwrap(),
        "--png",
        png.to_str().unwrap(),
    ];
    common::run(&args).ok();
    // The known difference: the two presets' f64 twins on the same samples, B against A.
    let samples = diff::default_samples(n, seed);
    let (a, b) = (ModelSpec::parse("ggx").unwrap(), ModelSpec::parse("filament-high").unwrap());
    let j = json(&out);
    for (c, got) in j["difference"]["channels"].as_array().unwrap().iter().enumerate() {
        let rel: Vec<f64> = samples.iter().map(|s| common::rel_err(b.eval(s)[c], a.eval(s)[c])).collect();
        let max = rel.iter().copied().fold(0.0, f64::max);
        let rms = (rel.iter().map(|e| e * e).sum::<f64>() / n as f64).sqrt();
        assert!(max > 0.05, "the presets differ (Vis and f90): {max}");
        assert!(
            (got["max_rel"].as_f64().unwrap() - max).abs() <= 1e-4 * max,
            "channel {c}: max rel {} vs the twins' {max}",
            got["max_rel"]
        );
        assert!(
            (got["rms_rel"].as_f64().unwrap() - rms).abs() <= 1e-4 * rms,
            "channel {c}: RMS rel {} vs the twins' {rms}",
            got["rms_rel"]
        );
    }
    assert_eq!(std::fs::read_to_string(&csv).unwrap().lines().count(), n + 1);
    let picture = image::open(&png).unwrap();
    assert!(picture.width() > 1000 && picture.height() > 400, "{}x{}", picture.width(), picture.height());
    let max_rel = j["difference"]["max_rel"].as_f64().unwrap();
    let below = format!("{}", max_rel * 0.5);
    common::run(&[
        "diff",
        "--model",
        "ggx",
        "--model",
        "filament-high",
        "--samples",
        "4000",
        "--seed",
        "5",
        "--tolerance",
        &below,
    ])
    .fails(1, "");
    let above = format!("{}", max_rel * 2.0);
    common::run(&[
        "diff",
        "--model",
        "ggx",
        "--model",
        "filament-high",
        "--samples",
        "4000",
        "--seed",
        "5",
        "--tolerance",
        &above,
    ])
    .ok();
}

#[test]
fn labels_name_the_sides_and_leave_the_specs_alone() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("named.json");
    common::run(&[
        "diff",
        "--model",
        "ggx,name=base",
        "--model",
        "examples/brdf/ggx.brdf",
        "--samples",
        "500",
        "--json",
        out.to_str().unwrap(),
    ])
    .ok();
    let j = json(&out);
    assert_eq!(
        (j["a"]["name"].as_str(), j["b"]["name"].as_str()),
        (Some("base"), Some("ggx.brdf")),
        "the label, and a file's name (not its path; ggx.brdf keeps its extension, as its stem is a preset's)"
    );
    assert_eq!(
        j["a"]["canonical"].as_str().unwrap(),
        ModelSpec::parse("ggx").unwrap().canonical(),
        "a label is not part of the canonical spec"
    );
    common::run(&["diff", "--model", "ggx,name=x", "--model", "blinn,name=x"])
        .fails(2, "--model ggx,name=x and --model blinn,name=x: both are labelled `x`");
    common::run(&["diff", "--model", "ggx,name=a/b", "--model", "blinn"]).fails(2, "name=a/b");
}

#[test]
fn diff_reads_an_input_csv_and_names_its_lines() {
    let dir = tempfile::tempdir().unwrap();
    let (input, out) = (dir.path().join("in.csv"), dir.path().join("d.json"));
    std::fs::write(&input, "nx,ny,nz,vx,vy,vz,lx,ly,lz,roughness,f0r,f0g,f0b\n0,0,1,0,0.6,0.8,0.6,0,0.8,0.5,0.04,0.04,0.04\n0,0,1,0,0.8,0.6,0.3,0,0.9,0.2,0.9,0.5,0.1\n").unwrap();
    common::run(&[
        "diff",
        "--model",
        "ggx",
        "--model",
        "blinn",
        "--input",
        input.to_str().unwrap(),
        "--json",
        out.to_str().unwrap(),
        "--worst",
        "2",
    ])
    .ok();
    let j = json(&out);
    assert_eq!(j["rows"].as_u64(), Some(2));
    let lines: Vec<u64> = j["worst"].as_array().unwrap().iter().map(|w| w["line"].as_u64().unwrap()).collect();
    assert_eq!(
        {
            let mut l = lines.clone();
            l.sort();
            l
        },
        [2, 3]
    );
    std::fs::write(
        &input,
        "nx,ny,nz,vx,vy,vz,lx,ly,lz,roughness,f0r,f0g,f0b\n0,0,1,0,0.6,x,0.6,0,0.8,0.5,0.04,0.04,0.04\n",
    )
    .unwrap();
    common::run(&["diff", "--model", "ggx", "--model", "blinn", "--input", input.to_str().unwrap()])
        .fails(2, "in.csv:2: column 6");
}

#[test]
fn diff_refuses_bad_arguments() {
    common::run(&["diff", "--model", "ggx"]).fails(2, "exactly two --model");
    common::run(&["diff", "--model", "ggx", "--model", "blinn", "--tolerance=-1"]).fails(2, "--tolerance");
    common::run(&["diff", "--model", "ggx", "--model", "blinn", "--samples", "0"]).fails(2, "--samples 0");
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("x.out");
    common::run(&[
        "diff",
        "--model",
        "ggx",
        "--model",
        "blinn",
        "--csv",
        p.to_str().unwrap(),
        "--json",
        p.to_str().unwrap(),
    ])
    .fails(2, "is also given to --csv");
    assert!(!p.exists());
}

/// `diff --reference SPEC` measures any number of models against one reference's exact f64 values
/// in one table. The reference's own kernel is within fp32 rounding of its f64 values; the engine-shaped GGX
/// files (written for the tests) within 1e-3 inside their declared roughness domain; the thesis's ggx preset
/// (another visibility term) is not, so --tolerance 1e-3 exits 1 with it and 0 without it. Each model's
/// figures are what the f64 reference and that model's values give, recomputed here from the CSV.
#[test]
fn diff_against_a_reference_measures_every_model_in_one_table() {
    let dir = tempfile::tempdir().unwrap();
    let engine = |name: &str| common::repo_root().join("tests/fixtures/brdf/engine").join(name).display().to_string();
    let (file, file_f) = (engine("engine-ggx.brdf"), engine("engine-ggx-f.brdf"));
    let reference = "d=ggx,vis=smith-ggx-correlated,f=schlick";
    let (out, csv, html) = (dir.path().join("set.json"), dir.path().join("set.csv"), dir.path().join("set.html"));
    let run = |models: &[&str], extra: &[&str]| {
        let mut args = vec![
            "diff",
            "--reference",
            reference,
            "--samples",
            "3000",
            "--tolerance",
            "1e-3",
            "--json",
            out.to_str().unwrap(),
        ];
        for m in models {
            args.extend(["--model", m]);
        }
        args.extend(extra);
        common::run(&args)
    };
    let r =
        run(&[reference, "ggx", &file, &file_f], &["--csv", csv.to_str().unwrap(), "--html", html.to_str().unwrap()]);
    assert_eq!(r.code, Some(1), "ggx is beyond 1e-3 of the correlated Smith: {}", r.stderr);
    let j = json(&out);
    assert_eq!(j["kind"], diff::SET_KIND);
    let diffs = j["diffs"].as_array().unwrap();
    assert_eq!(diffs.len(), 4);
    let max_rel = |k: usize| diffs[k]["difference"]["max_rel"].as_f64().unwrap();
    assert!(
        diffs.iter().all(|d| d["a"]["name"].as_str().unwrap().ends_with("(f64, no floor)")),
        "A is the reference's f64 values"
    );
    assert!(max_rel(0) < 1e-4, "the reference's kernel against its own f64 values: {}", max_rel(0));
    assert!(max_rel(1) > 1e-2, "ggx's SmithJointApprox against the correlated Smith: {}", max_rel(1));
    assert!(
        max_rel(2) < 1e-3 && max_rel(3) < 1e-3,
        "the engine files within their domain: {} {}",
        max_rel(2),
        max_rel(3)
    );
    // The CSV's columns recompute the table: the reference's values (f64 rounded to f32, which moves a
    // relative difference by at most 2^-24) and each model's.
    let text = std::fs::read_to_string(&csv).unwrap();
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    assert_eq!(header.len(), 13 + 3 * 5);
    let mut worst = [0f64; 4];
    for line in lines {
        let x: Vec<f64> = line.split(',').map(|f| f.parse().unwrap()).collect();
        for (m, w) in worst.iter_mut().enumerate() {
            for c in 0..3 {
                *w = w.max(common::rel_err(x[16 + 3 * m + c], x[13 + c]));
            }
        }
    }
    for (m, w) in worst.iter().enumerate() {
        assert!(
            (w - max_rel(m)).abs() <= 1e-7 + 1e-6 * max_rel(m),
            "model {m}: CSV {w} against the report's {}",
            max_rel(m)
        );
    }
    let page = std::fs::read_to_string(&html).unwrap();
    assert!(page.contains("4 models against") && page.contains("diffset0/ggx"), "the page's one table");

    let r = run(&[reference, &file, &file_f], &[]);
    assert_eq!(r.code, Some(0), "{}", r.stderr);
    assert!(r.stdout.contains("| engine-ggx ") && r.stdout.contains("within"), "{}", r.stdout);
}

/// A reference is the formula at the sampled roughness, with no roughness floor: a floor-free fp32 file of the
/// formula is within 1e-2 of it down to roughness 0.02 (with the fp32 floor of 0.045 in the reference, rows
/// below it differed by most of their value); rows of roughness 0, where D is singular, are left out and
/// counted.
#[test]
fn a_reference_has_no_roughness_floor_and_leaves_out_singular_rows() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let file = common::repo_root().join("tests/fixtures/brdf/reference/ggx-no-floor.brdf").display().to_string();
    let args = ["diff", "--model", &file, "--roughness", "0.02..1", "--samples", "4000", "--json", "r.json"];
    common::run_in(d, &args).ok();
    let r: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(d.join("r.json")).unwrap()).unwrap();
    let max = r["diffs"][0]["difference"]["max_rel"].as_f64().unwrap();
    assert!(max < 1e-2, "max rel {max} against the reference over roughness 0.02..1");
    assert!(r["diffs"][0]["a"]["name"].as_str().unwrap().ends_with("(f64, no floor)"));
    // Below the floor the reference differs from its own floored twin: the floor is the model's, not the reference's.
    let ggx = ModelSpec::parse("d=ggx,vis=smith-ggx-correlated,f=schlick").unwrap();
    let s = brdfprof::brdf::samples::well_conditioned_in(1, 3, (0.9, 1.0), (0.9, 1.0), 0.02..0.021)[0];
    let (exact, floored) = (ggx.eval_reference(&s).unwrap(), ggx.eval(&s));
    assert!((exact[0] / floored[0] - 1.0).abs() > 0.5, "{exact:?} against the floored twin {floored:?}");
    // Rows of roughness 0 have no reference value: left out, counted, named.
    let mut csv = String::from("nx,ny,nz,vx,vy,vz,lx,ly,lz,roughness,f0r,f0g,f0b\n");
    for r in ["0", "0.5", "0", "0.3"] {
        csv += &format!("0,0,1,0,0.6,0.8,0.6,0,0.8,{r},0.04,0.04,0.04\n");
    }
    std::fs::write(d.join("in.csv"), csv).unwrap();
    let out = common::run_in(d, &["diff", "--model", &file, "--input", "in.csv", "--json", "z.json"]).ok();
    assert!(out.stderr.contains("2 rows with roughness 0 left out"), "{}", out.stderr);
    let z: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(d.join("z.json")).unwrap()).unwrap();
    assert_eq!(z["rows"], 2);
}

/// Signed figures say how a model is wrong: a file that returns 4 times the reference's formula reads a
/// best-fit scale and a B/A median near 4 and is brighter on every value, where the unsigned max rel says 3.
#[test]
fn a_model_four_times_the_reference_reads_a_best_fit_scale_of_four() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let exact = std::fs::read_to_string(common::repo_root().join("tests/fixtures/brdf/reference/ggx-no-floor.brdf"));
    let four = exact.unwrap().replacen("return D * Vis *", "return 4.0 * D * Vis *", 1);
    assert!(four.contains("4.0 * D"));
    std::fs::write(d.join("four.brdf"), four).unwrap();
    let r = common::run_in(d, &["diff", "--model", "four.brdf", "--roughness", "0.1..1", "--json", "f.json"]).ok();
    let j: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(d.join("f.json")).unwrap()).unwrap();
    let signed = &j["diffs"][0]["signed"];
    let scale = signed["best_fit_scale"].as_f64().unwrap();
    assert!((scale - 4.0).abs() < 0.01, "best-fit scale {scale}");
    let median = signed["ratio_percentiles"].as_array().unwrap().iter().find(|p| p[0] == 50.0).unwrap()[1].as_f64();
    assert!((median.unwrap() - 4.0).abs() < 0.01, "{signed}");
    assert!(signed["brighter"].as_f64().unwrap() > 0.99, "{signed}");
    assert!(r.stdout.contains("best-fit scale B ~ s A with s = 4.0"), "{}", r.stdout);
}

/// `--f0` chooses the default samples' F0: a range keeps every sample's F0 within it; the default draws real
/// materials' F0 (never a reflectance like 0.0004 that no material has), and `uniform` the old cube.
#[test]
fn f0_sets_keep_the_samples_f0_where_they_say() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let f0_of = |extra: &[&str]| -> Vec<[f64; 3]> {
        let args = [&["diff", "--model", "ggx", "--model", "blinn", "--samples", "2000", "--csv", "c.csv"][..], extra];
        common::run_in(d, &args.concat()).ok();
        let text = std::fs::read_to_string(d.join("c.csv")).unwrap();
        let header: Vec<&str> = text.lines().next().unwrap().split(',').collect();
        let at = header.iter().position(|h| *h == "f0r").unwrap();
        text.lines()
            .skip(1)
            .map(|l| {
                let v: Vec<f64> = l.split(',').map(|x| x.parse().unwrap()).collect();
                [v[at], v[at + 1], v[at + 2]]
            })
            .collect()
    };
    let ranged = f0_of(&["--f0", "0.02..0.08"]);
    assert!(ranged.iter().flatten().all(|f| (0.02..=0.08).contains(f)), "F0 outside 0.02..0.08");
    let materials: Vec<[f64; 3]> =
        brdfprof::brdf::f0::materials().iter().map(|(_, f)| f.map(|x| x as f32 as f64)).collect();
    let default = f0_of(&[]);
    assert!(default.iter().all(|f| materials.iter().any(|m| (0..3).all(|c| (m[c] - f[c]).abs() < 1e-6))));
    assert!(default.iter().flatten().all(|&f| f >= 0.02), "no reflectance below water's");
    let uniform = f0_of(&["--f0", "uniform"]);
    assert!(uniform.iter().flatten().any(|&f| f < 0.01) && uniform.iter().flatten().any(|&f| f > 0.99));
    common::run_in(d, &["diff", "--model", "ggx", "--model", "blinn", "--f0", "0.5..0.1"]).fails(2, "--f0");
}
