//! SwiftShader (Chromium's CPU Vulkan driver, which Debian's chromium package ships and `make setup` installs)
//! as a second, independent Vulkan implementation beside lavapipe, under the Khronos validation layer: eval
//! agrees with lavapipe's, a short profile labels its intervals with their real coverage and gives no net
//! ratio to an unresolved reference, stability runs clean on the thesis models' fp32 kernels.

use crate::common::{self, Run};
use std::path::{Path, PathBuf};

/// SwiftShader's ICD manifest, or None (the tests say they were skipped and why).
fn icd() -> Option<PathBuf> {
    let icd = PathBuf::from("/usr/lib/chromium/vk_swiftshader_icd.json");
    if icd.exists() {
        Some(icd)
    } else {
        eprintln!("SKIPPED: {} is absent (SwiftShader comes with Debian's chromium: run `make setup`)", icd.display());
        None
    }
}

/// `brdfprof ARGS` in `dir` on SwiftShader alone, validation on.
fn on_swiftshader(icd: &Path, dir: &Path, args: &[&str]) -> Run {
    let out = common::brdfprof()
        .args(args)
        .current_dir(dir)
        .env("VK_ICD_FILENAMES", icd)
        .env_remove("BRDFPROF_TEST_DEVICE")
        .output()
        .unwrap();
    Run {
        code: out.status.code(),
        stdout: String::from_utf8_lossy(&out.stdout).into_owned(),
        stderr: String::from_utf8_lossy(&out.stderr).into_owned(),
    }
}

#[test]
fn eval_on_swiftshader_agrees_with_lavapipe() {
    let Some(icd) = icd() else { return };
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let mut csv = String::from("nx,ny,nz,vx,vy,vz,lx,ly,lz,roughness,f0r,f0g,f0b\n");
    for s in brdfprof::brdf::samples::well_conditioned(500, 8, 0.05, 0.05..1.0) {
        let [n, v, l, f] = [s.n, s.v, s.l, s.f0];
        let row = [n[0], n[1], n[2], v[0], v[1], v[2], l[0], l[1], l[2], s.roughness, f[0], f[1], f[2]];
        csv += &(row.map(|x| x.to_string()).join(",") + "\n");
    }
    std::fs::write(d.join("in.csv"), csv).unwrap();
    for model in ["ggx", "cook-torrance", "burley"] {
        let r = on_swiftshader(&icd, d, &["eval", "--model", model, "--input", "in.csv", "--output", "s.csv"]).ok();
        assert!(r.stderr.contains("SwiftShader"), "{}", r.stderr);
        common::run_in(d, &["eval", "--model", model, "--input", "in.csv", "--output", "l.csv"]).ok();
        let (s, l) = (common::csv_values(&d.join("s.csv")), common::csv_values(&d.join("l.csv")));
        let worst =
            s.iter().zip(&l).flat_map(|(a, b)| (0..3).map(move |c| common::rel_err(a[c], b[c]))).fold(0.0, f64::max);
        assert!(worst < 1e-4, "{model}: SwiftShader and lavapipe differ by {worst}");
    }
}

#[test]
fn a_short_profile_on_swiftshader_labels_its_intervals_and_its_unresolved_ratios() {
    let Some(icd) = icd() else { return };
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let args =
        ["profile", "--model", "ggx", "--model", "blinn", "--size", "128x128", "--budget", "0.3", "--json", "p.json"];
    let r = on_swiftshader(&icd, d, &args).ok();
    let p: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(d.join("p.json")).unwrap()).unwrap();
    let rows = p["rows"].as_array().unwrap();
    let coverage = rows.iter().map(|r| r["ns_per_eval"]["coverage"].as_f64().unwrap()).fold(1.0, f64::min);
    let header = r.stdout.lines().find(|l| l.starts_with("| model")).expect("the table");
    // A run this short has fewer rounds than a 95% interval of a median needs.
    assert!(coverage < 0.95, "{coverage}: a longer run than intended");
    assert!(!header.contains("95% CI") && header.contains("interval of coverage"), "{header}");
    let ggx = rows.iter().find(|r| r["model"] == "ggx").unwrap();
    let resolved = ggx["net_ns_per_eval"]["lo"].as_f64().unwrap() > 0.0;
    for row in rows.iter().filter(|r| r["model"] != "baseline") {
        assert_eq!(row["net_vs_reference"].is_null(), !resolved, "{row}");
        assert_eq!(row["net_ratio_unresolved"].is_string(), !resolved, "{row}");
    }
    assert_eq!(r.stdout.contains("unresolved"), !resolved, "{}", r.stdout);
}

#[test]
fn stability_on_swiftshader_finds_the_thesis_models_clean() {
    let Some(icd) = icd() else { return };
    let dir = tempfile::tempdir().unwrap();
    let args = ["stability", "--model", "ggx", "--model", "blinn", "--model", "cook-torrance", "--out", "st"];
    let r = on_swiftshader(&icd, dir.path(), &args).ok();
    assert!(r.stdout.contains("SwiftShader") || r.stderr.contains("SwiftShader"), "{}", r.stdout);
}
