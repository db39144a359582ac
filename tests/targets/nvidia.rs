//! Compile-only NVIDIA targets (`--device nvidia:FAMILY`): NVIDIA's real compiler (NVRTC and ptxas, from its
//! PyPI wheels, `make setup`) on the kernels' CUDA C++ translation, run without an NVIDIA GPU or driver, after
//! the translation agreed with the Vulkan kernels on the test device. Every command that executes refuses the
//! targets; a missing compiler and a construct the translation lacks are errors naming the fix and the line.

use crate::common::{self, run};
use crate::compile_only;
use brdfprof::targets::nvidia::FAMILIES;
use std::path::Path;

fn inspect_json(dir: &Path, name: &str, devices: &[&str], extra: &[&str]) -> serde_json::Value {
    compile_only::inspect_json(dir, name, devices, extra, "ptxas statistics")
}

fn sass(row: &serde_json::Value, name: &str) -> f64 {
    compile_only::stat(row, "SASS", name)
}

#[test]
fn every_preset_and_example_file_gets_sass_statistics_on_all_five_families() {
    let dir = tempfile::tempdir().unwrap();
    let models = compile_only::every_preset_and_example();
    let mut extra: Vec<&str> = Vec::new();
    for m in &models {
        extra.extend(["--model", m.as_str()]);
    }
    let report = inspect_json(dir.path(), "all", &["nvidia:all"], &extra);
    let reports = report["reports"].as_array().unwrap();
    assert_eq!(reports.len(), FAMILIES.len());
    for (r, family) in reports.iter().zip(&FAMILIES) {
        assert_eq!(r["provenance"]["target"], format!("nvidia:{}", family.name));
        assert!(r["provenance"]["compiler"]["options"].as_str().unwrap().contains("-use_fast_math"));
        let rows = r["rows"].as_array().unwrap();
        // The example files bring ggx without its guards beside ggx (`model::with_reference`).
        assert_eq!(rows.len(), models.len() + 2, "every model, ggx,guards=off and the memory-only kernel");
        for row in rows {
            for stat in [
                "Instruction Count",
                "Register Count",
                "Binary Size",
                "Issue Cycles",
                "Warps per SM",
                "FP32 (FMA, MUL, ADD, compare)",
            ] {
                assert!(sass(row, stat) > 0.0, "{} {}: {stat} is 0", family.name, row["model"]);
            }
            let note = row["notes"]["translation"]
                .as_str()
                .unwrap_or_else(|| panic!("{} {}: no translation check", family.name, row["model"]));
            assert!(note.contains("translation checked on the host against"), "{note}");
        }
        compile_only::assert_translated_costs(family.name, &r["cost"], |_| 32.0);
    }
    // The cost table across the five families has every pair's rank correlation.
    assert_eq!(report["costs"]["correlations"].as_array().unwrap().len(), 10);
}

#[test]
fn the_statistics_are_deterministic_and_the_exact_defaults_cost_more() {
    compile_only::assert_deterministic_and_precise_costs_more("nvidia:sm_89", "ptxas statistics", "-use_fast_math");
}

#[test]
fn isa_writes_the_translation_and_its_sass_per_kernel_and_family() {
    let dir = tempfile::tempdir().unwrap();
    let isa = dir.path().join("isa");
    inspect_json(dir.path(), "one", &["nvidia:sm_90"], &["--model", "ggx", "--isa", isa.to_str().unwrap()]);
    for kernel in ["ggx", "baseline"] {
        let cu = std::fs::read_to_string(isa.join("nvidia-sm_90").join(format!("{kernel}.cu"))).unwrap();
        assert!(cu.contains("extern \"C\" __global__") && cu.contains("fn_main"), "{}", &cu[..cu.len().min(400)]);
        let sass = std::fs::read_to_string(isa.join("nvidia-sm_90").join(format!("{kernel}.sass"))).unwrap();
        assert!(sass.contains("EXIT") && sass.contains("registers"), "{}", &sass[..sass.len().min(400)]);
    }
}

#[test]
fn fp16_kernels_compare_and_clamp_in_half_precision_where_the_family_has_the_instructions() {
    let dir = tempfile::tempdir().unwrap();
    let isa = dir.path().join("isa");
    // sm_75 has no f16 min/max (the f32 fallback), sm_89 has (PTX min.f16, SASS HMNMX2); both compare in f16.
    inspect_json(
        dir.path(),
        "f16",
        &["nvidia:sm_75,sm_89"],
        &["--model", "ggx,precision=f16", "--isa", isa.to_str().unwrap()],
    );
    let sass = |family: &str| {
        std::fs::read_to_string(isa.join(format!("nvidia-{family}")).join("ggx-precision-f16.sass")).unwrap()
    };
    let (turing, ada) = (sass("sm_75"), sass("sm_89"));
    assert!(
        turing.contains("HFMA2") && turing.contains("HSETP2") && !turing.contains("HMNMX2"),
        "sm_75 SASS:\n{}",
        &turing[..turing.len().min(2000)]
    );
    assert!(ada.contains("HMNMX2") && ada.contains("HSETP2"), "sm_89 SASS:\n{}", &ada[..ada.len().min(2000)]);
}

#[test]
fn commands_that_execute_refuse_an_nvidia_target_and_unknown_families_are_named() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("o");
    let out = out.to_str().unwrap();
    for args in [
        vec!["profile", "--device", "nvidia:sm_89", "--json", out],
        vec!["stability", "--device", "nvidia:sm_89", "--out", out],
        vec!["render", "--scene", "scenes/sphere-grid.json", "--device", "nvidia:sm_89", "--out", out],
    ] {
        let mut cmd = common::brdfprof();
        let r = cmd.args(&args).current_dir(common::repo_root()).output().unwrap();
        assert_eq!(r.status.code(), Some(2), "{args:?}");
        assert!(
            String::from_utf8_lossy(&r.stderr).contains("compiles only"),
            "{args:?}: {}",
            String::from_utf8_lossy(&r.stderr)
        );
    }
    run(&["inspect", "--device", "nvidia:sm_87"]).fails(2, "unknown NVIDIA family `sm_87`");
    let listed = run(&["devices", "--targets"]).ok();
    for f in &FAMILIES {
        assert!(
            listed
                .stdout
                .lines()
                .any(|l| l.starts_with(&format!("| nvidia:{} ", f.name)) && l.contains(f.architecture)),
            "{}",
            listed.stdout
        );
    }
}

#[test]
fn a_missing_compiler_says_make_setup() {
    compile_only::a_missing_compiler_says_make_setup("nvidia:sm_89", "BRDFPROF_NVIDIA_DIR", "nowhere", "NVIDIA");
}

#[test]
fn a_construct_the_translation_lacks_is_refused_at_the_files_line() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("volume.brdf");
    std::fs::write(
        &file,
        "analytic\n::begin parameters\nfloat roughness 0 1 0.5\n::end parameters\n::begin shader\nfloat frame_volume(vec3 a, vec3 b, vec3 c)\n{\n    return determinant(mat3(a, b, c));\n}\n\nvec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y)\n{\n    return vec3(abs(frame_volume(X, Y, N)) * roughness);\n}\n::end shader\n",
    )
    .unwrap();
    let json = dir.path().join("x.json");
    let r = run(&[
        "inspect",
        "--no-callgrind",
        "--device",
        "nvidia:sm_89",
        "--model",
        file.to_str().unwrap(),
        "--json",
        json.to_str().unwrap(),
        "--markdown",
        dir.path().join("x.md").to_str().unwrap(),
    ]);
    // The model fails on the target alone: the others would be costed, the outputs are written, exit 1.
    r.fails(1, &format!("{}:8: the C translation cannot express the GLSL.std.450 function Determinant (GLSL's determinant) (in function `frame_volume`)", file.display()));
    let report: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(report["cost"]["failed"][0][0], "volume", "{}", report["cost"]);
    // The same file runs on Vulkan: the refusal is the translation's, not the file's.
    let csv = dir.path().join("in.csv");
    std::fs::write(
        &csv,
        "nx,ny,nz,vx,vy,vz,lx,ly,lz,roughness,f0r,f0g,f0b\n0,0,1,0,0.6,0.8,0,-0.6,0.8,0.5,0.04,0.04,0.04\n",
    )
    .unwrap();
    run(&[
        "eval",
        "--model",
        file.to_str().unwrap(),
        "--input",
        csv.to_str().unwrap(),
        "--output",
        dir.path().join("out.csv").to_str().unwrap(),
    ])
    .ok();
}

/// A correct model whose values run past 1e5 (a power of a sum) is priced: the profiling kernel's R11G11B10F
/// store saturates at 65024 on the device and in the translation alike, and the f64 reference is held to that
/// store, not to the unsaturated value (which called the translation a defect).
#[test]
fn a_model_past_the_stores_range_is_priced() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(
        d.join("big.brdf"),
        "analytic\n::begin shader\nvec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y)\n{\n    float s = max(dot(N, L), 0.0) + max(dot(N, V), 0.0);\n    return vec3(pow(s + 1.0, 12.0), pow(s + 1.0, 11.0), pow(s, 16.0));\n}\n::end shader\n",
    )
    .unwrap();
    let r = common::run_in(d, &["inspect", "--device", "nvidia:sm_89", "--model", "big.brdf", "--json", "i.json"]).ok();
    assert!(!r.stdout.contains("failed, so no figure"), "{}", r.stdout);
    assert_eq!(brdfprof::translate::judge::r11g11b10_max(6), 65024.0);
    assert_eq!(brdfprof::translate::judge::r11g11b10_max(5), 64512.0);
}
