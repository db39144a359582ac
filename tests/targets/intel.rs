//! Compile-only Intel targets (`--device intel:FAMILY`): Intel's real compiler (IGC through ocloc, Debian's
//! intel-opencl-icd, `make setup`) on the kernels' OpenCL C translation, with IGA's listing, run without an
//! Intel GPU or driver, after the translation agreed with the Vulkan kernels on the test device. Every command
//! that executes refuses the targets; a missing compiler is an error naming the fix.

use crate::common::{self, run};
use crate::compile_only;
use brdfprof::targets::intel::{Class, FAMILIES};
use std::path::Path;

fn inspect_json(dir: &Path, name: &str, devices: &[&str], extra: &[&str]) -> serde_json::Value {
    compile_only::inspect_json(dir, name, devices, extra, "IGC statistics")
}

fn igc(row: &serde_json::Value, name: &str) -> f64 {
    compile_only::stat(row, "IGC", name)
}

#[test]
fn every_preset_and_example_file_gets_igc_statistics_on_all_five_families() {
    let dir = tempfile::tempdir().unwrap();
    let models = compile_only::every_preset_and_example();
    let mut extra: Vec<&str> = Vec::new();
    for m in &models {
        extra.extend(["--model", m.as_str()]);
    }
    let report = inspect_json(dir.path(), "all", &["intel:all"], &extra);
    let reports = report["reports"].as_array().unwrap();
    assert_eq!(reports.len(), FAMILIES.len());
    for (r, family) in reports.iter().zip(&FAMILIES) {
        assert_eq!(r["provenance"]["target"], format!("intel:{}", family.name));
        assert_eq!(r["provenance"]["compiler"]["device"], family.device);
        assert!(r["provenance"]["compiler"]["options"].as_str().unwrap().contains("-cl-mad-enable"));
        let rows = r["rows"].as_array().unwrap();
        // The example files bring ggx without its guards beside ggx (`model::with_reference`).
        assert_eq!(rows.len(), models.len() + 2, "every model, ggx,guards=off and the memory-only kernel");
        for row in rows {
            assert!([8.0, 16.0, 32.0].contains(&igc(row, "SIMD Width")), "{} {}", family.name, row["model"]);
            assert!([128.0, 256.0].contains(&igc(row, "Register Count")), "{} {}", family.name, row["model"]);
            for stat in [
                "Instruction Count",
                "Binary Size",
                "Issue Cycles",
                Class::Fma.name(),
                Class::Send.name(),
                Class::Control.name(),
            ] {
                assert!(igc(row, stat) > 0.0, "{} {}: {stat} is 0", family.name, row["model"]);
            }
            let classes: f64 = Class::ALL.iter().map(|c| igc(row, c.name())).sum();
            assert_eq!(
                classes,
                igc(row, "Instruction Count"),
                "{} {}: the classes partition the listing",
                family.name,
                row["model"]
            );
            let note = row["notes"]["translation"]
                .as_str()
                .unwrap_or_else(|| panic!("{} {}: no translation check", family.name, row["model"]));
            assert!(note.contains("translation checked on the host against"), "{note}");
        }
        compile_only::assert_translated_costs(family.name, &r["cost"], |c| c["stats"]["SIMD Width"].as_f64().unwrap());
    }
    assert_eq!(report["costs"]["correlations"].as_array().unwrap().len(), 10);
}

#[test]
fn the_statistics_are_deterministic_and_the_precise_forms_cost_more() {
    compile_only::assert_deterministic_and_precise_costs_more("intel:gen12lp", "IGC statistics", "-cl-mad-enable");
}

#[test]
fn isa_writes_the_translation_and_igas_listing_per_kernel_and_family() {
    let dir = tempfile::tempdir().unwrap();
    let isa = dir.path().join("isa");
    inspect_json(dir.path(), "one", &["intel:xe-hpg"], &["--model", "ggx", "--isa", isa.to_str().unwrap()]);
    for kernel in ["ggx", "baseline"] {
        let cl = std::fs::read_to_string(isa.join("intel-xe-hpg").join(format!("{kernel}.cl"))).unwrap();
        assert!(cl.contains("__kernel") && cl.contains("fn_main"), "{}", &cl[..cl.len().min(400)]);
        let asm = std::fs::read_to_string(isa.join("intel-xe-hpg").join(format!("{kernel}.asm"))).unwrap();
        assert!(asm.contains("send") && asm.contains("EOT") && asm.contains("GRF"), "{}", &asm[..asm.len().min(400)]);
    }
}

#[test]
fn commands_that_execute_refuse_an_intel_target_and_unknown_families_are_named() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("o");
    let out = out.to_str().unwrap();
    for args in [
        vec!["profile", "--device", "intel:gen12lp", "--json", out],
        vec!["stability", "--device", "intel:gen9", "--out", out],
    ] {
        let r = common::brdfprof().args(&args).current_dir(common::repo_root()).output().unwrap();
        assert_eq!(r.status.code(), Some(2), "{args:?}");
        assert!(
            String::from_utf8_lossy(&r.stderr).contains("compiles only"),
            "{args:?}: {}",
            String::from_utf8_lossy(&r.stderr)
        );
    }
    run(&["inspect", "--device", "intel:gen8"]).fails(2, "unknown Intel family `gen8`");
    let listed = run(&["devices", "--targets"]).ok();
    for f in &FAMILIES {
        assert!(
            listed.stdout.lines().any(|l| l.starts_with(&format!("| intel:{} ", f.name)) && l.contains(f.architecture)),
            "{}",
            listed.stdout
        );
    }
}

#[test]
fn a_missing_compiler_says_make_setup() {
    compile_only::a_missing_compiler_says_make_setup("intel:gen12lp", "BRDFPROF_OCLOC", "nowhere/ocloc", "Intel");
}

/// `inspect --chart` draws the cost table across devices as compare does: one colour per
/// device (the chart's palette), its bars drawn; one device is refused with exit 2.
#[test]
fn inspect_charts_the_cost_across_devices() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let out = |n: &str| d.join(n).display().to_string();
    let r = run(&[
        "inspect",
        "--no-callgrind",
        "--device",
        "nvidia:sm_89",
        "--device",
        "intel:gen12lp",
        "--json",
        &out("i.json"),
        "--markdown",
        &out("i.md"),
        "--chart",
        &out("c.png"),
    ])
    .ok();
    assert!(r.stdout.contains("Chart: "), "{}", r.stdout);
    let img = image::open(d.join("c.png")).unwrap().to_rgb8();
    assert!(img.width() >= 400 && img.height() >= 300, "{}x{}", img.width(), img.height());
    // Each device's cell of each model is filled with the colour of its ratio to ggx (the JSON's net figures).
    let table: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(d.join("i.json")).unwrap()).unwrap();
    let columns = table["costs"]["columns"].as_array().unwrap();
    assert_eq!(columns.len(), 2);
    for c in columns {
        let net = |m: &str| c["net"][m].as_f64().unwrap();
        for model in ["blinn", "cook-torrance", "burley"] {
            let colour = brdfprof::export::heat_table::colour(net(model) / net("ggx"));
            let n = img.pixels().filter(|p| p.0 == [colour.0, colour.1, colour.2]).count();
            assert!(n > 1_000, "{} {model}: its cell's colour covers {n} pixels", c["name"]);
        }
    }
    assert!(!d.join("x.png").exists());
    run(&[
        "inspect",
        "--no-callgrind",
        "--device",
        "intel:gen12lp",
        "--json",
        &out("j.json"),
        "--markdown",
        &out("j.md"),
        "--chart",
        &out("x.png"),
    ])
    .fails(2, "give several --device");
    assert!(!d.join("x.png").exists());
}
