//! Mesa's Turnip (adreno:), PanVK (mali:), ANV (anv:) and NVK (nak:) on Mesa's noop drm-shims, built by
//! `make mesa`: the drivers' real compilers (ir3, Bifrost, brw, NAK) compile brdfprof's unchanged SPIR-V in child processes, and
//! their statistics and cost rules reach every compile-only command. Nothing here mocks a driver: a missing
//! or broken build is a real directory without (or with a broken) driver.

use crate::common::{self, run, run_in};
use brdfprof::targets;
use std::path::Path;

/// The shim targets: every family of each shim driver.
fn shim_targets() -> Vec<String> {
    targets::VENDORS
        .iter()
        .filter(|v| v.noop().is_some() && v.prefix() != "radv")
        .flat_map(|v| v.families().into_iter().map(move |f| format!("{}:{}", v.prefix(), f.name)))
        .collect()
}

fn inspect(dir: &Path, name: &str, devices: &[String], extra: &[&str]) -> serde_json::Value {
    let devices: Vec<&str> = devices.iter().map(String::as_str).collect();
    crate::compile_only::inspect_json(dir, name, &devices, extra, "on the noop drm-shim")
}

#[test]
fn every_shim_target_reports_its_compilers_statistics_and_cost_identically_on_a_rerun() {
    let dir = tempfile::tempdir().unwrap();
    let devices = shim_targets();
    assert!(devices.len() >= 9, "{devices:?}");
    let models = crate::compile_only::every_preset_and_example();
    let extra: Vec<&str> = models.iter().flat_map(|m| ["--model", m.as_str()]).collect();
    let first = inspect(dir.path(), "first", &devices, &extra);
    let shim_devices: Vec<&str> = devices.iter().map(String::as_str).collect();
    let second =
        crate::compile_only::inspect_json_afresh(dir.path(), "second", &shim_devices, &extra, "on the noop drm-shim");
    let reports = first["reports"].as_array().unwrap();
    assert_eq!(reports.len(), devices.len());
    for ((report, again), device) in reports.iter().zip(second["reports"].as_array().unwrap()).zip(&devices) {
        assert_eq!(report["provenance"]["target"], device.as_str());
        assert_eq!(report["cost"], again["cost"], "{device}: the cost table changed between runs");
        let cost = &report["cost"];
        assert_eq!(cost["target"], device.as_str(), "{device}: no cost table");
        let rule = cost["model"].as_str().unwrap();
        assert!(
            rule.starts_with("cycles/eval = ") || rule.starts_with(brdfprof::targets::cost::schedule::RULE),
            "{device}: the rule text is in the report"
        );
        let rows = cost["rows"].as_array().unwrap();
        // The example files bring ggx without its guards beside ggx (`model::with_reference`).
        assert_eq!(rows.len(), models.len() + 2, "{device}: every model, ggx,guards=off and the memory-only kernel");
        for r in rows {
            assert!(r["cycles_per_eval"].as_f64().unwrap() > 0.0, "{device} {}", r["model"]);
        }
        // The built-in BRDFs add work to the memory-only kernel on every compiler: on some term of its rule,
        // and never less than nothing to the bound (on g610 load/store binds the memory-only kernel and every
        // BRDF alike, so their nets are 0 while their FMA work grows).
        for r in rows.iter().filter(|r| brdfprof::brdf::spec::PRESETS.iter().any(|p| r["model"] == p.name)) {
            assert!(r["net_cycles_per_eval"].as_f64().unwrap() >= 0.0, "{device} {}", r["model"]);
            let added = r["net_terms"]
                .as_array()
                .map_or(0.0, |t| t.iter().map(|t| t[1].as_f64().unwrap()).fold(f64::NEG_INFINITY, f64::max));
            assert!(added > 0.0, "{device} {}: no term of the rule grew: {r}", r["model"]);
        }
        // Deterministic: every driver statistic is the same in a second process.
        for (row, row_again) in report["rows"].as_array().unwrap().iter().zip(again["rows"].as_array().unwrap()) {
            for (key, value) in row["stats"].as_object().unwrap().iter().filter(|(k, _)| k.starts_with("driver/")) {
                assert_eq!(&row_again["stats"][key], value, "{device} {} {key} changed between runs", row["model"]);
            }
            assert!(
                row["stats"]["driver/instructions"].as_f64().unwrap() > 0.0,
                "{device} {}: no instruction count",
                row["model"]
            );
        }
    }
}

#[test]
fn the_corpus_of_brdf_files_compiles_on_each_shim_driver() {
    let corpus = common::repo_root().join("tests/fixtures/brdf/corpus");
    let mut files: Vec<_> = std::fs::read_dir(&corpus)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "brdf"))
        .collect();
    files.sort();
    assert_eq!(files.len(), 40, "the corpus has 40 files");
    let models: Vec<String> = files.iter().map(|p| p.display().to_string()).collect();
    let extra: Vec<&str> = models.iter().flat_map(|m| ["--model", m.as_str()]).collect();
    let dir = tempfile::tempdir().unwrap();
    let devices = ["adreno:a660", "adreno:a740", "mali:g52", "mali:g610", "anv:tgl"].map(String::from);
    let out = inspect(dir.path(), "corpus", &devices, &extra);
    for (report, device) in out["reports"].as_array().unwrap().iter().zip(&devices) {
        let rows = report["cost"]["rows"].as_array().unwrap();
        // Each file by its stem (and ggx, which inspect adds as the reference, and the memory-only kernel).
        for f in &files {
            let stem = f.file_stem().unwrap().to_str().unwrap();
            assert!(
                rows.iter().any(|r| r["model"] == stem),
                "{device}: no row for {stem}: {}",
                report["section_notes"]
            );
        }
        assert!(rows.iter().all(|r| r["cycles_per_eval"].as_f64().unwrap() > 0.0), "{device}");
    }
}

#[test]
fn isa_writes_ir3_and_brw_listings_and_says_panvk_has_none() {
    let dir = tempfile::tempdir().unwrap();
    let isa = dir.path().join("isa");
    let devices = ["adreno:a660", "anv:tgl", "mali:g52", "adreno:a740", "mali:g610"].map(String::from);
    let out = inspect(dir.path(), "isa", &devices, &["--model", "ggx", "--isa", isa.to_str().unwrap()]);
    let ir3 = std::fs::read_to_string(isa.join("adreno-a660/ggx.ir3-assembly.txt")).unwrap();
    assert!(ir3.lines().any(|l| l.trim() == "end") && ir3.contains("(ss)"), "{}", &ir3[..ir3.len().min(400)]);
    let brw = std::fs::read_to_string(isa.join("anv-tgl/ggx.gen-assembly.txt")).unwrap();
    assert!(brw.contains("send"), "{}", &brw[..brw.len().min(400)]);
    assert!(!isa.join("mali-g52").exists());
    let note = out["reports"][2]["section_notes"]["driver/"].as_str().unwrap();
    assert!(note.contains("--isa: no listing for mali:g52") && note.contains("validation layer was not run"), "{note}");
    // Mesa 25.0's Turnip lists a7xx's code as 22.3's lists a6xx's; its PanVK gives statistics through the log only.
    let ir3 = std::fs::read_to_string(isa.join("adreno-a740/ggx.ir3-assembly.txt")).unwrap();
    assert!(ir3.lines().any(|l| l.trim() == "end"), "{}", &ir3[..ir3.len().min(400)]);
    assert!(!isa.join("mali-g610").exists());
    let note = out["reports"][4]["section_notes"]["driver/"].as_str().unwrap();
    assert!(note.contains("--isa: no listing for mali:g610"), "{note}");
}

/// A fresh machine: `make setup` and `make run` build no Mesa; asking for an adreno:, mali: or anv: target then
/// exits 2 naming `make mesa` (the Makefile target that builds them), not `make setup`. Needs no build: both
/// builds' variables name an empty folder.
#[test]
fn without_a_mesa_build_every_shim_target_exits_2_naming_make_mesa() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let empty = d.join("empty");
    std::fs::create_dir(&empty).unwrap();
    for (device, icd) in [
        ("adreno:a660", "freedreno_devenv_icd"),
        ("mali:g52", "panfrost_devenv_icd"),
        ("anv:tgl", "intel_devenv_icd"),
        ("adreno:a740", "freedreno_devenv_icd"),
        ("mali:g610", "panfrost_devenv_icd"),
        ("nak:sm_86", "nouveau_devenv_icd"),
    ] {
        let out = common::brdfprof()
            .args([
                "inspect",
                "--no-callgrind",
                "--model",
                "ggx",
                "--device",
                device,
                "--json",
                "r.json",
                "--markdown",
                "r.md",
            ])
            .current_dir(d)
            .env(targets::mesa_noop::builds::MESA_DEBIAN.var, &empty)
            .env(targets::mesa_noop::builds::MESA_BACKPORTS.var, &empty)
            .env(targets::mesa_noop::builds::MESA_NVK.var, &empty)
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{device}: {stderr}");
        assert!(
            stderr.contains("is not built") && stderr.contains("`make mesa`") && stderr.contains(icd),
            "{device}: {stderr}"
        );
        assert!(!stderr.contains("make setup"), "{device}: `make setup` builds no Mesa: {stderr}");
    }
    assert!(!d.join("r.json").exists() && !d.join("r.md").exists());
    // devices --targets says so too.
    let out = common::brdfprof()
        .args(["devices", "--targets"])
        .env(targets::mesa_noop::builds::MESA_DEBIAN.var, &empty)
        .env(targets::mesa_noop::builds::MESA_BACKPORTS.var, &empty)
        .env(targets::mesa_noop::builds::MESA_NVK.var, &empty)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("is not built") && stdout.contains("`make mesa`"), "{stdout}");
    // The Makefile has that target, running the script; `make run` does not need it, `make test` does.
    let makefile = std::fs::read_to_string(common::repo_root().join("Makefile")).unwrap();
    let rule = |target: &str| {
        makefile
            .lines()
            .find(|l| l.starts_with(&format!("{target}:")))
            .unwrap_or_else(|| panic!("no `{target}:` rule in the Makefile"))
            .to_string()
    };
    assert!(rule("mesa").contains("setup") && makefile.contains("sh scripts/mesa-noop.sh"), "{makefile}");
    assert!(rule("test").split_whitespace().any(|w| w == "mesa"), "{}", rule("test"));
    assert!(
        !rule("run").contains("mesa") && !rule("build").contains("mesa") && !rule("setup").contains("mesa"),
        "{makefile}"
    );
    let setup = std::fs::read_to_string(common::repo_root().join("scripts/setup.sh")).unwrap();
    assert!(
        !setup.lines().any(|l| !l.trim_start().starts_with('#') && l.contains("mesa-noop.sh")),
        "scripts/setup.sh runs scripts/mesa-noop.sh"
    );
}

#[test]
fn a_missing_or_broken_build_exits_2_naming_make_mesa() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let inspect_with = |build: &Path, device: &str| {
        let out = common::brdfprof()
            .args([
                "inspect",
                "--no-callgrind",
                "--model",
                "ggx",
                "--device",
                device,
                "--json",
                "r.json",
                "--markdown",
                "r.md",
            ])
            .current_dir(d)
            .env(targets::mesa_noop::builds::BUILD_DIR_VAR, build)
            .output()
            .unwrap();
        (out.status.code(), String::from_utf8_lossy(&out.stderr).into_owned())
    };
    // No build at all.
    let (code, stderr) = inspect_with(&d.join("nothing"), "adreno:a660");
    assert_eq!(code, Some(2), "{stderr}");
    assert!(
        stderr.contains("is not built") && stderr.contains("make mesa") && stderr.contains("freedreno_devenv_icd"),
        "{stderr}"
    );
    // bookworm-backports' build (Adreno 7xx, Valhall) missing: the families on it say so, naming its variable.
    for device in ["adreno:a740", "mali:g610"] {
        let out = common::brdfprof()
            .args([
                "inspect",
                "--no-callgrind",
                "--model",
                "ggx",
                "--device",
                device,
                "--json",
                "r.json",
                "--markdown",
                "r.md",
            ])
            .current_dir(d)
            .env(targets::mesa_noop::builds::MESA_BACKPORTS.var, d.join("nothing"))
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{stderr}");
        assert!(
            stderr.contains("is not built")
                && stderr.contains("make mesa")
                && stderr.contains("BRDFPROF_MESA25_DIR")
                && stderr.contains("Mesa 25.0"),
            "{stderr}"
        );
    }
    // The driver and its ICD file present, the shim absent.
    let real = targets::mesa_noop::builds::build_dir();
    let partial = d.join("partial");
    for f in ["src/intel/vulkan/intel_devenv_icd.x86_64.json", "src/intel/vulkan/libvulkan_intel.so"] {
        std::fs::create_dir_all(partial.join(f).parent().unwrap()).unwrap();
        std::fs::copy(real.join(f), partial.join(f)).unwrap();
    }
    let (code, stderr) = inspect_with(&partial, "anv:tgl");
    assert_eq!(code, Some(2), "{stderr}");
    assert!(stderr.contains("libintel_noop_drm_shim.so is missing") && stderr.contains("make mesa"), "{stderr}");
    // A shim that is not a library: the driver finds no GPU, and the child's failure names what to run.
    let shim = partial.join("src/intel/tools/libintel_noop_drm_shim.so");
    std::fs::create_dir_all(shim.parent().unwrap()).unwrap();
    std::fs::write(&shim, b"not a shared object").unwrap();
    let (code, stderr) = inspect_with(&partial, "anv:tgl");
    assert_eq!(code, Some(2), "{stderr}");
    assert!(stderr.contains("anv:tgl") && stderr.contains("make mesa"), "{stderr}");
    assert!(!d.join("r.json").exists() && !d.join("r.md").exists());
    // devices --targets says which vendor is not ready and why.
    let out = common::brdfprof()
        .args(["devices", "--targets"])
        .env(targets::mesa_noop::builds::BUILD_DIR_VAR, d.join("nothing"))
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("is not built"), "{stdout}");
}

#[test]
fn a_childs_report_is_cached_and_a_changed_driver_environment_compiles_afresh() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let cache = d.join("cache");
    let inspect_with = |name: &str, env: &[(&str, &str)]| -> serde_json::Value {
        let json = d.join(format!("{name}.json"));
        let mut cmd = common::brdfprof();
        cmd.args([
            "inspect",
            "--no-callgrind",
            "--model",
            "ggx",
            "--device",
            "adreno:a660",
            "--device",
            "mali:g52",
            "--json",
            json.to_str().unwrap(),
            "--markdown",
            d.join(format!("{name}.md")).to_str().unwrap(),
        ]);
        let out = cmd.env("BRDFPROF_CACHE_DIR", &cache).envs(env.iter().copied()).output().unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(0), "{stderr}");
        let mut value: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(json).unwrap()).unwrap();
        value["stderr"] = stderr.into_owned().into();
        value
    };
    let entry =
        |run: &serde_json::Value, i: usize| run["reports"][i]["provenance"]["cache_entry"].as_str().map(str::to_string);
    let first = inspect_with("first", &[]);
    let second = inspect_with("second", &[]);
    for i in 0..2 {
        assert_eq!(entry(&first, i), None, "a first run compiles");
        let path = entry(&second, i).expect("the second run reads the cache");
        assert!(Path::new(&path).starts_with(&cache) && path.ends_with(".noop_report"), "{path}");
        assert_eq!(first["reports"][i]["cost"], second["reports"][i]["cost"]);
        assert_eq!(first["reports"][i]["rows"], second["reports"][i]["rows"]);
    }
    // A variable the drivers read is part of the key.
    let third = inspect_with("third", &[("MESA_SPIRV_LOG_LEVEL", "error")]);
    assert!((0..2).all(|i| entry(&third, i).is_none()), "a changed driver variable compiles afresh");
    // A damaged entry is reported, discarded and replaced.
    let damaged = entry(&second, 0).unwrap();
    std::fs::write(&damaged, b"brdfprof-cache 1\nkind: noop_report\n").unwrap();
    let fourth = inspect_with("fourth", &[]);
    assert!(fourth["stderr"].as_str().unwrap().contains("is damaged"), "{}", fourth["stderr"]);
    assert_eq!(entry(&fourth, 0), None);
    assert_eq!(first["reports"][0]["cost"], fourth["reports"][0]["cost"]);
    assert!(entry(&inspect_with("fifth", &[]), 0).is_some(), "the replaced entry is read");
}

#[test]
fn a_noop_device_is_never_asked_to_run() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(
        d.join("in.csv"),
        "nx,ny,nz,vx,vy,vz,lx,ly,lz,roughness,f0r,f0g,f0b\n0,0,1,0,0.6,0.8,0.6,0,0.8,0.5,0.04,0.04,0.04\n",
    )
    .unwrap();
    for device in shim_targets() {
        run_in(d, &["profile", "--model", "ggx", "--size", "8x8", "--device", &device])
            .fails(2, "compiles only and cannot run kernels");
        run_in(d, &["eval", "--model", "ggx", "--input", "in.csv", "--output", "out.csv", "--device", &device])
            .fails(2, "compiles only and cannot run kernels");
    }
    assert_eq!(std::fs::read_dir(d).unwrap().count(), 1, "nothing but the input in the directory");
}

#[test]
fn a_shim_child_that_crashes_after_its_report_still_gives_the_report() {
    let dir = tempfile::tempdir().unwrap();
    let json = dir.path().join("r.json");
    let out = common::brdfprof()
        .args([
            "inspect",
            "--no-callgrind",
            "--model",
            "ggx",
            "--device",
            "anv:tgl",
            "--json",
            json.to_str().unwrap(),
            "--markdown",
            dir.path().join("r.md").to_str().unwrap(),
        ])
        .env(targets::mesa_noop::CRASH_AFTER_REPLY, "1")
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{stderr}");
    assert!(stderr.contains("the anv:tgl child crashed after writing its complete report"), "{stderr}");
    let report: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(json).unwrap()).unwrap();
    assert!(report["cost"]["rows"][0]["stats"]["Cycle Count"].as_f64().unwrap() > 0.0);
}

#[test]
fn scene_kernels_and_the_sweep_reach_the_shim_compilers() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let scene = common::repo_root().join("scenes/sphere-grid.json");
    let json = d.join("scene.json");
    let out = run_in(
        d,
        &[
            "profile",
            "--scene",
            scene.to_str().unwrap(),
            "--budget",
            "2",
            "--cost-device",
            "adreno:a660",
            "--cost-device",
            "mali:g52",
            "--cost-device",
            "anv:tgl",
            "--json",
            json.to_str().unwrap(),
        ],
    )
    .ok();
    for t in ["adreno:a660 cycles/pixel", "mali:g52 cycles/pixel", "anv:tgl cycles/pixel"] {
        assert!(out.stdout.contains(t), "{}", out.stdout);
    }
    let sweep = run_in(
        d,
        &[
            "sweep",
            "--model",
            "ggx",
            "--model",
            "blinn",
            "--model",
            "burley",
            "--size",
            "16x16",
            "--min-rounds",
            "2",
            "--max-rounds",
            "2",
            "--out",
            "out",
            "--cost-device",
            "mali:g52",
        ],
    )
    .ok();
    assert!(sweep.stdout.contains("cost on g52 (Bifrost (v7))"), "{}", sweep.stdout);
}

#[test]
fn devices_targets_lists_every_shim_family_and_its_compiler() {
    let out = run(&["devices", "--targets"]).ok();
    for device in shim_targets() {
        assert!(out.stdout.lines().any(|l| l.starts_with(&format!("| {device} "))), "{device}:\n{}", out.stdout);
    }
    for compiler in ["Turnip (ir3 compiler)", "PanVK (Bifrost compiler)", "ANV (brw compiler)", "NVK (NAK compiler)"] {
        assert!(out.stdout.contains(compiler), "{compiler}:\n{}", out.stdout);
    }
}

#[test]
fn setup_builds_every_file_each_shim_driver_loads() {
    let script = std::fs::read_to_string(common::repo_root().join("scripts/mesa-noop.sh")).unwrap();
    // A variable of the script (NAME="..."), with `$shim_products` expanded.
    let var = |name: &str| -> String {
        script
            .split(&format!("\n{name}=\""))
            .nth(1)
            .unwrap_or_else(|| panic!("no {name}="))
            .split('"')
            .next()
            .unwrap()
            .to_string()
    };
    let products = |name: &str| -> Vec<String> {
        let mut p: Vec<String> =
            var(name).replace("$shim_products", &var("shim_products")).split_whitespace().map(str::to_string).collect();
        p.sort();
        p.dedup();
        p
    };
    let shims = [&targets::adreno::ADRENO, &targets::mali::MALI, &targets::anv::ANV, &targets::nak::NAK];
    for (build, list) in [
        (&targets::mesa_noop::builds::MESA_DEBIAN, "products"),
        (&targets::mesa_noop::builds::MESA_BACKPORTS, "products25"),
        (&targets::mesa_noop::builds::MESA_NVK, "products_nvk"),
    ] {
        let mut loaded: Vec<String> = shims
            .iter()
            .filter(|s| s.families.iter().any(|f| std::ptr::eq(f.build, build)))
            .flat_map(|s| [s.icd, s.library, s.shim])
            .map(str::to_string)
            .collect();
        loaded.sort();
        assert_eq!(
            products(list),
            loaded,
            "scripts/mesa-noop.sh's {list} and the files of the Shims' families on {} differ",
            build.what
        );
        assert!(script.contains(&format!("link {} ", build.link)), "the script links {}", build.link);
    }
    // Every shim driver is in VENDORS.
    for s in shims {
        assert!(targets::VENDORS.iter().any(|v| v.prefix() == s.prefix), "{}", s.prefix);
    }
}

/// A model file edited between the parent's key and the child's compile (the test hook holds the parent until
/// the edit is made) never leaves the edited text's figures in the cache or in the report: the run exits 2
/// naming the file, and a later run of the original text reports the figures of a cold run of it.
#[test]
fn a_model_file_edited_during_a_run_never_mixes_two_texts() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let cache = d.join("cache");
    let model = d.join("m.brdf");
    let original = std::fs::read_to_string(common::repo_root().join("examples/brdf/ggx.brdf")).unwrap();
    // Another kernel: the BRDF's value doubled.
    let edited = original.replacen("return D_GGX(", "return 2.0 * D_GGX(", 1);
    assert_ne!(original, edited);
    std::fs::write(&model, &original).unwrap();
    let inspect = |name: &str, hold: Option<&Path>| {
        let json = d.join(format!("{name}.json"));
        let mut cmd = common::brdfprof();
        cmd.args(["inspect", "--no-callgrind", "--model", model.to_str().unwrap(), "--device", "adreno:a660"])
            .args(["--json", json.to_str().unwrap(), "--markdown", d.join(format!("{name}.md")).to_str().unwrap()])
            .env("BRDFPROF_CACHE_DIR", &cache)
            .stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::piped());
        if let Some(h) = hold {
            cmd.env(targets::mesa_noop::HOLD_BEFORE_CHILDREN, h);
        }
        (cmd.spawn().unwrap(), json)
    };
    let hold = d.join("hold");
    let (child, _) = inspect("edited", Some(&hold));
    let waiting = hold.with_extension("waiting");
    let start = std::time::Instant::now();
    while !waiting.exists() {
        assert!(start.elapsed().as_secs() < 240, "the parent never reached its children");
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    std::fs::write(&model, &edited).unwrap();
    std::fs::write(&hold, b"").unwrap();
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("m.brdf: the adreno:a660 child compiled another kernel"), "{stderr}");
    // The original text again, through the cache, then cold: the same figures.
    std::fs::write(&model, &original).unwrap();
    let rows = |name: &str| {
        let (child, json) = inspect(name, None);
        let out = child.wait_with_output().unwrap();
        assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
        let v: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(json).unwrap()).unwrap();
        v.get("reports").map_or(&v, |r| &r[0])["rows"].clone()
    };
    let warm = rows("after");
    std::fs::remove_dir_all(&cache).unwrap();
    let cold = rows("cold");
    assert_eq!(warm, cold, "the cache held another text's figures under the original's key");
}

/// NVK's NAK prices its own assembly: every instruction NVK counts is read from the "NAK assembly" it returns
/// (with its delays and scoreboards), the listing is written under --isa, and a model the family cannot compile
/// (fp16 arithmetic before SM80, where NVK offers no shaderFloat16) is named under the cost table, not dropped.
#[test]
fn nak_reads_every_instruction_of_its_assembly_and_names_what_a_family_cannot_compile() {
    let dir = tempfile::tempdir().unwrap();
    let isa = dir.path().join("isa");
    let devices = ["nak:sm_75", "nak:sm_86"].map(String::from);
    let extra = ["--model", "ggx", "--model", "burley,precision=f16", "--isa", isa.to_str().unwrap()];
    let out = inspect(dir.path(), "nak", &devices, &extra);
    let reports = out["reports"].as_array().unwrap();
    for (report, device) in reports.iter().zip(&devices) {
        for row in report["rows"].as_array().unwrap() {
            let stat = |name: &str| row["stats"][format!("driver/compute/{name}")].as_f64();
            assert!(stat("Instruction count").unwrap() > 0.0, "{device} {}", row["model"]);
            assert_eq!(stat("Assembly Instructions"), stat("Instruction count"), "{device} {}", row["model"]);
        }
        let listing = std::fs::read_to_string(isa.join(format!("{}/ggx.nak-assembly.txt", device.replace(':', "-"))))
            .unwrap_or_else(|e| panic!("{device}: {e}"));
        assert!(listing.contains("// delay=") && listing.contains("exit"), "{}", &listing[..listing.len().min(400)]);
    }
    let absent = |k: usize| reports[k]["cost"]["absent"].to_string();
    assert!(absent(0).contains("precision=f16"), "sm_75 names the fp16 model it cannot compile: {}", absent(0));
    assert!(!absent(1).contains("precision=f16"), "sm_86 compiles fp16: {}", absent(1));
}

/// A model file computing in double precision on families without shaderFloat64 (Turnip's a660 and a740,
/// PanVK's g610): left out with that reason, named under the cost table (`absent`), not handed to drivers that
/// crash compiling it (Mesa 22.3's ir3 aborts in `type_uint_size`, Mesa 25's Turnip and PanVK die of SIGSEGV);
/// the rest of the run is priced.
#[test]
fn fp64_is_left_out_of_the_shim_families_without_shader_float64() {
    let dir = tempfile::tempdir().unwrap();
    let model = dir.path().join("wide.brdf");
    std::fs::write(
        &model,
        "analytic\n::begin shader\nvec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y) {\n    dvec2 d = dvec2(dot(N, L), dot(N, V));\n    return vec3(float(d.x * d.y + 1.0lf));\n}\n::end shader\n",
    )
    .unwrap();
    let devices = ["adreno:a660", "adreno:a740", "mali:g610"].map(String::from);
    let out = inspect(dir.path(), "wide", &devices, &["--model", model.to_str().unwrap(), "--model", "ggx"]);
    for (report, device) in out["reports"].as_array().unwrap().iter().zip(&devices) {
        let cost = &report["cost"];
        let absent = cost["absent"].to_string();
        assert!(absent.contains("wide.brdf") && absent.contains("has no shaderFloat64"), "{device}: {absent}");
        assert!(
            cost["failed"].as_array().is_none_or(|f| f.is_empty()),
            "{device}: no child failed: {}",
            cost["failed"]
        );
        let priced = cost["rows"].as_array().unwrap().iter().any(|r| r["model"] == "ggx");
        assert!(priced, "{device}: ggx is still priced");
    }
}
