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
    common::run(&["diff", "--model", "filament-high", "--model", "filament-high", "--samples", "3000", "--tolerance", "0", "--json", out.to_str().unwrap()]).ok();
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
    let args = ["diff", "--model", "ggx", "--model", "filament-high", "--samples", "4000", "--seed", "5", "--json", out.to_str().unwrap(), "--csv", csv.to_str().unwrap(), "--png", png.to_str().unwrap()];
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
        assert!((got["max_rel"].as_f64().unwrap() - max).abs() <= 1e-4 * max, "channel {c}: max rel {} vs the twins' {max}", got["max_rel"]);
        assert!((got["rms_rel"].as_f64().unwrap() - rms).abs() <= 1e-4 * rms, "channel {c}: RMS rel {} vs the twins' {rms}", got["rms_rel"]);
    }
    assert_eq!(std::fs::read_to_string(&csv).unwrap().lines().count(), n + 1);
    let picture = image::open(&png).unwrap();
    assert!(picture.width() > 1000 && picture.height() > 400, "{}x{}", picture.width(), picture.height());
    let max_rel = j["difference"]["max_rel"].as_f64().unwrap();
    let below = format!("{}", max_rel * 0.5);
    common::run(&["diff", "--model", "ggx", "--model", "filament-high", "--samples", "4000", "--seed", "5", "--tolerance", &below]).fails(1, "");
    let above = format!("{}", max_rel * 2.0);
    common::run(&["diff", "--model", "ggx", "--model", "filament-high", "--samples", "4000", "--seed", "5", "--tolerance", &above]).ok();
}

#[test]
fn labels_name_the_sides_and_leave_the_specs_alone() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("named.json");
    common::run(&["diff", "--model", "ggx,name=base", "--model", "examples/brdf/ggx.brdf", "--samples", "500", "--json", out.to_str().unwrap()]).ok();
    let j = json(&out);
    assert_eq!((j["a"]["name"].as_str(), j["b"]["name"].as_str()), (Some("base"), Some("ggx.brdf")), "the label, and a file's name (not its path; ggx.brdf keeps its extension, as its stem is a preset's)");
    assert_eq!(j["a"]["canonical"].as_str().unwrap(), ModelSpec::parse("ggx").unwrap().canonical(), "a label is not part of the canonical spec");
    common::run(&["diff", "--model", "ggx,name=x", "--model", "blinn,name=x"]).fails(2, "--model ggx,name=x and --model blinn,name=x: both are labelled `x`");
    common::run(&["diff", "--model", "ggx,name=a/b", "--model", "blinn"]).fails(2, "name=a/b");
}

#[test]
fn diff_reads_an_input_csv_and_names_its_lines() {
    let dir = tempfile::tempdir().unwrap();
    let (input, out) = (dir.path().join("in.csv"), dir.path().join("d.json"));
    std::fs::write(&input, "nx,ny,nz,vx,vy,vz,lx,ly,lz,roughness,f0r,f0g,f0b\n0,0,1,0,0.6,0.8,0.6,0,0.8,0.5,0.04,0.04,0.04\n0,0,1,0,0.8,0.6,0.3,0,0.9,0.2,0.9,0.5,0.1\n").unwrap();
    common::run(&["diff", "--model", "ggx", "--model", "blinn", "--input", input.to_str().unwrap(), "--json", out.to_str().unwrap(), "--worst", "2"]).ok();
    let j = json(&out);
    assert_eq!(j["rows"].as_u64(), Some(2));
    let lines: Vec<u64> = j["worst"].as_array().unwrap().iter().map(|w| w["line"].as_u64().unwrap()).collect();
    assert_eq!({ let mut l = lines.clone(); l.sort(); l }, [2, 3]);
    std::fs::write(&input, "nx,ny,nz,vx,vy,vz,lx,ly,lz,roughness,f0r,f0g,f0b\n0,0,1,0,0.6,x,0.6,0,0.8,0.5,0.04,0.04,0.04\n").unwrap();
    common::run(&["diff", "--model", "ggx", "--model", "blinn", "--input", input.to_str().unwrap()]).fails(2, "in.csv:2: column 6");
}

#[test]
fn diff_refuses_bad_arguments() {
    common::run(&["diff", "--model", "ggx"]).fails(2, "exactly two --model");
    common::run(&["diff", "--model", "ggx", "--model", "blinn", "--tolerance=-1"]).fails(2, "--tolerance");
    common::run(&["diff", "--model", "ggx", "--model", "blinn", "--samples", "0"]).fails(2, "--samples 0");
    let dir = tempfile::tempdir().unwrap();
    let p = dir.path().join("x.out");
    common::run(&["diff", "--model", "ggx", "--model", "blinn", "--csv", p.to_str().unwrap(), "--json", p.to_str().unwrap()]).fails(2, "is also given to --csv");
    assert!(!p.exists());
}
