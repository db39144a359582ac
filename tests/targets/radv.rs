//! Compile-only AMD targets (`--device radv:FAMILY`): Mesa RADV's real ACO compiler run by brdfprof in a
//! child process with RADV_FORCE_FAMILY set, under the validation layer. The statistics are ACO's own for the
//! family, deterministic, and every command that must execute refuses the device.

use crate::common::{self, run, run_in};
use brdfprof::targets::radv::families::FAMILIES as TARGETS;
use std::path::Path;

const KERNELS: [&str; 5] = ["ggx", "blinn", "cook-torrance", "burley", "baseline"];

fn inspect_json(dir: &Path, name: &str, devices: &[&str], extra: &[&str]) -> serde_json::Value {
    crate::compile_only::inspect_json(dir, name, devices, extra, "ACO statistics")
}

fn stat(row: &serde_json::Value, name: &str) -> f64 {
    crate::compile_only::stat(row, "Compute Shader", name)
}

#[test]
fn inspect_reports_aco_statistics_for_rdna2_gfx9_and_rdna3_identical_across_runs() {
    let dir = tempfile::tempdir().unwrap();
    let devices = ["radv:navi21", "radv:vega10", "radv:gfx1100"];
    let first = inspect_json(dir.path(), "first", &devices, &[]);
    let second = crate::compile_only::inspect_json_afresh(dir.path(), "second", &devices, &[], "ACO statistics");
    assert_eq!(first["format"], "brdfprof-inspect-devices/1");
    let reports = first["reports"].as_array().unwrap();
    assert_eq!(reports.len(), 3);
    for (i, (report, again)) in reports.iter().zip(second["reports"].as_array().unwrap()).enumerate() {
        let family = &devices[i][5..];
        assert_eq!(report["provenance"]["device"]["name"], format!("Null hardware (RADV {})", family.to_uppercase()));
        let target = TARGETS.iter().find(|t| t.family == family).unwrap();
        let rows = report["rows"].as_array().unwrap();
        assert_eq!(rows.iter().map(|r| r["model"].as_str().unwrap()).collect::<Vec<_>>(), KERNELS);
        for (row, row_again) in rows.iter().zip(again["rows"].as_array().unwrap()) {
            for s in ["Instructions", "VGPRs", "Inverse Throughput", "Latency", "Subgroups per SIMD"] {
                assert!(stat(row, s) > 0.0, "{family} {}: {s} is 0", row["model"]);
            }
            // Deterministic: every driver statistic is the same in a second process.
            for (key, value) in row["stats"].as_object().unwrap().iter().filter(|(k, _)| k.starts_with("driver/")) {
                assert_eq!(&row_again["stats"][key], value, "{family} {} {key} changed between runs", row["model"]);
            }
            // The family table's wave size is the one the driver compiled for.
            assert_eq!(row["stats"]["driver/subgroup-size"].as_f64(), Some(f64::from(target.wave_size)), "{family}");
        }
        // ACO's derived figures: a BRDF costs more than the memory-only kernel, which costs something.
        let aco = report["cost"]["rows"].as_array().unwrap();
        let base = aco.iter().find(|r| r["model"] == "baseline").unwrap();
        assert!(base["cycles_per_eval"].as_f64().unwrap() > 0.0);
        for r in aco.iter().filter(|r| r["model"] != "baseline") {
            assert!(r["net_cycles_per_eval"].as_f64().unwrap() > 0.0, "{family} {}", r["model"]);
        }
        aco_schedule_is_acos_own_without_branches(family, rows, aco);
    }
    // GCN-class vega10 (8 waves per SIMD at most, wave64 over 16 lanes) is slower per evaluation than RDNA 2.
    let ggx = |i: usize| reports[i]["cost"]["rows"][0]["cycles_per_eval"].as_f64().unwrap();
    assert!(ggx(1) > 1.5 * ggx(0), "vega10 {} vs navi21 {}", ggx(1), ggx(0));
    // The cost table across devices has every pair's rank correlation.
    assert_eq!(first["costs"]["correlations"].as_array().unwrap().len(), 3);
}

/// On a kernel without branches ACO's block weights are all 1, so brdfprof's re-count of its perfinfo schedule
/// (every instruction once) must give ACO's own figures: each resource's usage, the latency, and cycles/eval
/// = Inverse Throughput / (64 x 8) (ACO rounds the statistic). Where ACO branches (GCN and Vega do in the
/// built-in kernels, RDNA does not), its weights are below 1 and the re-count is at least ACO's.
fn aco_schedule_is_acos_own_without_branches(family: &str, rows: &[serde_json::Value], costs: &[serde_json::Value]) {
    use brdfprof::targets::radv::aco_perfinfo::Resource;
    let target = TARGETS.iter().find(|t| t.family == family).unwrap();
    for row in rows {
        let model = row["model"].as_str().unwrap();
        let schedule =
            brdfprof::targets::radv::schedule(&serde_json::from_value(row["stats"].clone()).unwrap(), target)
                .expect("perfinfo statistics");
        let branch_free = stat(row, "Branches") == 0.0;
        assert!(
            branch_free || !family.starts_with("navi"),
            "{family} {model}: RDNA compiles the built-in kernels without branches"
        );
        let same = |ours: f64, aco: f64, what: &str| match branch_free {
            true => assert_eq!(ours, aco, "{family} {model}: {what}"),
            false => assert!(ours >= aco, "{family} {model}: {what} {ours} against ACO's weighted {aco}"),
        };
        for r in Resource::ALL {
            let ours = schedule.pipes.iter().find(|(n, _)| n == r.name()).unwrap().1;
            same(ours, stat(row, &format!("perfinfo: weighted {}", r.perfinfo())), r.name());
        }
        same(schedule.latency.unwrap(), stat(row, "Latency"), "latency");
        let cost = costs.iter().find(|c| c["model"] == model).unwrap();
        let it = stat(row, "Inverse Throughput");
        let ours = cost["cycles_per_eval"].as_f64().unwrap() * 64.0 * 8.0;
        assert!(
            if branch_free { (ours - it).abs() <= 0.5 } else { ours >= it - 0.5 },
            "{family} {model}: {ours} against ACO's Inverse Throughput {it}"
        );
    }
}

#[test]
fn isa_writes_acos_disassembly_per_kernel_and_family() {
    let dir = tempfile::tempdir().unwrap();
    let isa = dir.path().join("isa");
    let report =
        inspect_json(dir.path(), "one", &["radv:vangogh"], &["--model", "ggx", "--isa", isa.to_str().unwrap()]);
    assert!(report["cost"].is_object(), "a single device's JSON is that device's report");
    for kernel in ["ggx", "baseline"] {
        let text = std::fs::read_to_string(isa.join("vangogh").join(format!("{kernel}.assembly.txt"))).unwrap();
        assert!(text.contains("s_endpgm") && text.contains("v_"), "{kernel}: {}", &text[..text.len().min(400)]);
    }
    // --isa without a compile-only device is refused before anything runs.
    run_in(dir.path(), &["inspect", "--no-callgrind", "--isa", "x"])
        .fails(2, "--isa x: the listings are a compile-only target's");
    assert!(!dir.path().join("x").exists());
}

#[test]
fn commands_that_execute_refuse_a_compile_only_device() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(
        d.join("in.csv"),
        "nx,ny,nz,vx,vy,vz,lx,ly,lz,roughness,f0r,f0g,f0b\n0,0,1,0,0.6,0.8,0.6,0,0.8,0.5,0.04,0.04,0.04\n",
    )
    .unwrap();
    let scene = common::repo_root().join("scenes/sphere-grid.json");
    let commands: [&[&str]; 5] = [
        &["eval", "--model", "ggx", "--input", "in.csv", "--output", "out.csv"],
        &["profile", "--model", "ggx", "--size", "8x8"],
        &["stability", "--model", "ggx"],
        &["sweep", "--model", "ggx", "--size", "8x8"],
        &["render", "--scene", scene.to_str().unwrap(), "--out", "pictures"],
    ];
    for args in commands {
        run_in(d, &[args, &["--device", "radv:navi21"]].concat()).fails(2, "compiles only and cannot run kernels");
    }
    // An unknown family names the flag and lists the known ones.
    let run = run_in(d, &["inspect", "--device", "radv:navi31"]).fails(2, "unknown AMD family `navi31`");
    assert!(TARGETS.iter().all(|t| run.stderr.contains(t.family)), "{}", run.stderr);
    run_in(d, &["profile", "--device", "radv:nope"]).fails(2, "invalid value 'radv:nope' for '--device <DEVICE>'");
    assert_eq!(std::fs::read_dir(d).unwrap().count(), 1, "nothing but the input in the directory");
}

/// The default device's line of `brdfprof devices`.
fn default_device(env: Option<(&str, &str)>) -> (String, String) {
    let mut cmd = common::brdfprof();
    cmd.arg("devices");
    if let Some((k, v)) = env {
        cmd.env(k, v);
    }
    let out = cmd.output().unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    let line =
        stdout.lines().find(|l| l.contains("(default)")).unwrap_or_else(|| panic!("no default device:\n{stdout}"));
    (line.split('|').nth(2).unwrap().trim().to_string(), stdout)
}

#[test]
fn radv_force_family_in_the_users_environment_changes_no_default() {
    let (plain, _) = default_device(None);
    let (forced, listing) = default_device(Some(("RADV_FORCE_FAMILY", "navi21")));
    assert_eq!(plain, forced, "{listing}");
    assert!(!forced.starts_with("Null hardware"));
    // The null device is listed, marked, and refused by a command that executes even when chosen by index.
    let null =
        listing.lines().find(|l| l.contains("Null hardware (RADV NAVI21)")).unwrap_or_else(|| panic!("{listing}"));
    assert!(null.contains("(compiles only)"), "{null}");
    let index = null.trim_start_matches('|').split_whitespace().next().unwrap().to_string();
    let dir = tempfile::tempdir().unwrap();
    let json = dir.path().join("p.json");
    let profile = |device: Option<&str>| {
        let mut cmd = common::brdfprof();
        cmd.args([
            "profile",
            "--model",
            "ggx",
            "--size",
            "16x16",
            "--min-rounds",
            "2",
            "--max-rounds",
            "2",
            "--json",
            json.to_str().unwrap(),
        ])
        .env("RADV_FORCE_FAMILY", "navi21");
        if let Some(d) = device {
            cmd.args(["--device", d]);
        }
        cmd.output().unwrap()
    };
    let out = profile(Some(&index));
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("compiles only"), "{}", String::from_utf8_lossy(&out.stderr));
    let out = profile(None);
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    let report: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(report["provenance"]["device"]["name"].as_str(), Some(plain.as_str()));
}

#[test]
fn devices_targets_lists_every_family_of_the_table() {
    let out = run(&["devices", "--targets"]).ok();
    for t in &TARGETS {
        let line = out
            .stdout
            .lines()
            .find(|l| l.starts_with(&format!("| radv:{} ", t.family)))
            .unwrap_or_else(|| panic!("{}", out.stdout));
        assert!(line.contains(t.architecture) && line.contains(&format!("wave{} ", t.wave_size)), "{line}");
    }
}

#[test]
fn a_child_that_crashes_after_its_report_still_gives_the_report_and_exit_0() {
    let dir = tempfile::tempdir().unwrap();
    let json = dir.path().join("r.json");
    let out = common::brdfprof()
        .args([
            "inspect",
            "--no-callgrind",
            "--model",
            "ggx",
            "--device",
            "radv:navi21",
            "--json",
            json.to_str().unwrap(),
            "--markdown",
            dir.path().join("r.md").to_str().unwrap(),
        ])
        .env(brdfprof::targets::mesa_noop::CRASH_AFTER_REPLY, "1")
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(0), "{stderr}");
    assert!(stderr.contains("crashed after writing its complete report") && stderr.contains("SIGSEGV"), "{stderr}");
    let report: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(json).unwrap()).unwrap();
    assert!(report["section_notes"]["driver/"].as_str().unwrap().contains("crashed after writing its complete report"));
    assert!(report["cost"]["rows"][0]["stats"]["Inverse Throughput"].as_f64().unwrap() > 0.0);
}

#[test]
fn sweep_cost_device_draws_the_frontier_again_with_acos_cycles() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let base = [
        "sweep",
        "--model",
        "ggx",
        "--model",
        "blinn",
        "--model",
        "ggx,vis=smith-ggx-correlated,f=dielectric",
        "--size",
        "16x16",
        "--min-rounds",
        "2",
        "--max-rounds",
        "2",
        "--out",
        "out",
    ];
    run_in(d, &[&base[..], &["--cost-device", "0"]].concat()).fails(2, "--cost-device 0: give a compile-only target");
    run_in(d, &[&base[..], &["--cost-device", "radv:navi31"]].concat()).fails(2, "unknown AMD family `navi31`");
    assert!(!d.join("out").exists());
    let out = run_in(
        d,
        &[
            &base[..],
            &["--cost-device", "radv:navi21", "--cost-device", "radv:vega10", "--cost-device", "nvidia:sm_89"],
        ]
        .concat(),
    )
    .ok();
    assert!(out.stdout.contains("# brdfprof sweep: cost on navi21 (RDNA 2)"), "{}", out.stdout);
    let file = |suffix: &str| {
        std::fs::read_dir(d.join("out"))
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .find(|n| n.ends_with(suffix))
            .unwrap()
    };
    let read = |name: &str| -> serde_json::Value {
        serde_json::from_str(&std::fs::read_to_string(d.join("out").join(name)).unwrap()).unwrap()
    };
    // The frontiers of the three targets at once: every spec on some target's frontier, with the targets
    // whose frontier it is on as the per-target files say; the exact model on all of them.
    let frontiers = read(&file("-frontiers.json"));
    assert_eq!(frontiers["kind"], "sweep-frontiers");
    assert_eq!(frontiers["targets"], serde_json::json!(["radv:navi21", "radv:vega10", "nvidia:sm_89"]));
    let exact = frontiers["on_every"].as_array().unwrap().iter().any(|l| l.as_str().unwrap().contains("dielectric"));
    assert!(exact, "{frontiers}");
    for (k, suffix) in ["-aco-navi21.json", "-aco-vega10.json", "-ptxas-sm_89.json"].iter().enumerate() {
        for r in read(&file(suffix))["rows"].as_array().unwrap() {
            let row = frontiers["rows"].as_array().unwrap().iter().find(|x| x["label"] == r["label"]);
            assert_eq!(row.is_some_and(|x| x["on"][k] == true), r["pareto"] == true, "{suffix} {}", r["label"]);
        }
    }
    assert!(out.stdout.contains("On every target's frontier:"), "{}", out.stdout);
    for family in ["navi21", "vega10"] {
        let stem = file(&format!("-aco-{family}.json"));
        let report: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(d.join("out").join(&stem)).unwrap()).unwrap();
        let rows = report["rows"].as_array().unwrap();
        assert_eq!(rows.len(), 3);
        assert_eq!(rows[0]["cost_vs_fastest"].as_f64(), Some(1.0), "sorted by cost, relative to the cheapest");
        assert!(
            rows.iter()
                .all(|r| r["cycles_per_eval"].as_f64().unwrap() > 0.0 && r["accuracy"]["vs_exact"]["rms"].is_number())
        );
        assert!(rows.iter().any(|r| r["pareto"] == true));
        // The exact model (most accurate) is on every frontier.
        assert!(
            rows.iter().any(|r| r["spec"].as_str().unwrap().contains("dielectric") && r["pareto"] == true),
            "{rows:?}"
        );
        assert!(d.join("out").join(stem.replace(".json", ".png")).exists());
    }
}

#[test]
fn a_family_without_fp16_leaves_out_the_fp16_models_and_says_why() {
    let dir = tempfile::tempdir().unwrap();
    let report = inspect_json(dir.path(), "gcn", &["radv:tahiti"], &["--model", "ggx", "--model", "ggx,precision=f16"]);
    let models: Vec<&str> = report["rows"].as_array().unwrap().iter().map(|r| r["model"].as_str().unwrap()).collect();
    assert_eq!(models, ["ggx", "baseline"]);
    let note = report["section_notes"]["driver/"].as_str().unwrap();
    assert!(
        note.contains("not compiled for radv:tahiti: ggx,precision=f16") && note.contains("shaderFloat16"),
        "{note}"
    );
}

/// A driver that crashes on one model's kernel stops only that model: the child is run again per model, the
/// others are costed on the target, the crashed one is named with its signal under the table, and inspect exits
/// 1 with every output written.
#[test]
fn a_child_crashing_on_one_model_leaves_the_others_costed() {
    let dir = tempfile::tempdir().unwrap();
    let json = dir.path().join("r.json");
    let out = common::brdfprof()
        .args(["inspect", "--no-callgrind", "--model", "ggx", "--model", "blinn", "--device", "radv:navi21"])
        .args(["--json", json.to_str().unwrap(), "--markdown", dir.path().join("r.md").to_str().unwrap()])
        .env(brdfprof::targets::mesa_noop::CRASH_ON_MODEL, "blinn")
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    let report: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(json).unwrap()).unwrap();
    let cost = &report["cost"];
    let rows: Vec<&str> = cost["rows"].as_array().unwrap().iter().map(|r| r["model"].as_str().unwrap()).collect();
    assert!(rows.contains(&"ggx") && !rows.contains(&"blinn"), "{rows:?}");
    assert_eq!(cost["failed"][0][0], "blinn", "{cost}");
    assert!(cost["failed"][0][1].as_str().unwrap().contains("SIGSEGV"), "{cost}");
    let md = std::fs::read_to_string(dir.path().join("r.md")).unwrap();
    assert!(md.contains("**blinn: failed, so no figure**"), "{md}");
}
