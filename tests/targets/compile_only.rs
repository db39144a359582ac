//! What the tests of the compile-only targets (tests/targets/radv.rs, nvidia.rs, intel.rs and the rest, and the
//! tests/cli tests that price a model on a target) share: an inspect run with the binary's kernel cache or a cache
//! of its own, a compiler statistic of a row, and the models every target must take (every preset and each example
//! `.brdf` file).

use crate::common;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// The kernel cache the tests of this binary share, as a developer's cache is shared by their runs: a kernel one
/// test compiled and checked (its translation judged against its f64 evaluation included) is read by the next
/// test that needs it. Emptied once per run, so every kernel is compiled afresh at least once in it.
fn shared_cache() -> &'static Path {
    static DIR: OnceLock<PathBuf> = OnceLock::new();
    DIR.get_or_init(|| {
        let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(concat!(env!("CARGO_CRATE_NAME"), "-kernel-cache"));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    })
}

/// `inspect --no-callgrind` on `devices` with `extra` arguments, writing NAME.json and NAME.md in `dir`, with the
/// binary's shared kernel cache; its output must have `section` (the compiler's statistics heading). Returns the
/// JSON.
pub fn inspect_json(dir: &Path, name: &str, devices: &[&str], extra: &[&str], section: &str) -> serde_json::Value {
    inspect_with_cache(dir, name, devices, extra, section, shared_cache())
}

/// `inspect_json` with a cache of its own: every kernel compiled and checked afresh (a rerun compared with a first
/// run, so that a cache cannot make two runs agree).
pub fn inspect_json_afresh(
    dir: &Path,
    name: &str,
    devices: &[&str],
    extra: &[&str],
    section: &str,
) -> serde_json::Value {
    inspect_with_cache(dir, name, devices, extra, section, &dir.join(format!("cache-{name}")))
}

fn inspect_with_cache(
    dir: &Path,
    name: &str,
    devices: &[&str],
    extra: &[&str],
    section: &str,
    cache: &Path,
) -> serde_json::Value {
    let json = dir.join(format!("{name}.json"));
    let md = dir.join(format!("{name}.md"));
    let mut args =
        vec!["inspect", "--no-callgrind", "--json", json.to_str().unwrap(), "--markdown", md.to_str().unwrap()];
    for d in devices {
        args.extend(["--device", d]);
    }
    args.extend(extra);
    let out = common::brdfprof().args(&args).env("BRDFPROF_CACHE_DIR", cache).output().unwrap();
    let out = common::Run {
        code: out.status.code(),
        stdout: String::from_utf8_lossy(&out.stdout).into_owned(),
        stderr: String::from_utf8_lossy(&out.stderr).into_owned(),
    }
    .ok();
    assert!(out.stdout.contains(section), "{}", out.stdout);
    serde_json::from_str(&std::fs::read_to_string(json).unwrap()).unwrap()
}

/// The row's `driver/COMPILER/NAME` statistic.
pub fn stat(row: &serde_json::Value, compiler: &str, name: &str) -> f64 {
    row["stats"][format!("driver/{compiler}/{name}")]
        .as_f64()
        .unwrap_or_else(|| panic!("{} has no {name}: {row}", row["model"]))
}

/// Every preset and each example `.brdf` file (parameters bound to the kernel inputs).
pub fn every_preset_and_example() -> Vec<String> {
    let mut models: Vec<String> = brdfprof::brdf::spec::PRESETS.iter().map(|p| p.name.to_string()).collect();
    let dir = common::repo_root().join("examples/brdf");
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "brdf"))
        .collect();
    files.sort();
    models.extend(files.iter().map(|p| format!("{},roughness=@roughness,f0=@f0", p.display())));
    models
}

/// The one rule on a translated target's cost table (NVIDIA, Intel): per row, cycles/eval = max(busiest pipe,
/// latency / resident waves) / (`lanes(row)` x 8 lights), no pipe busier than the serial sum of the same rates
/// (Issue Cycles), and every BRDF above the memory-only kernel.
pub fn assert_translated_costs(family: &str, cost: &serde_json::Value, lanes: impl Fn(&serde_json::Value) -> f64) {
    for c in cost["rows"].as_array().unwrap() {
        let stat = |k: &str| c["stats"][k].as_f64().unwrap();
        let per_wave = stat("busiest pipe (cycles/wave)").max(stat("latency / waves"));
        assert!(
            (c["cycles_per_eval"].as_f64().unwrap() - per_wave / (lanes(c) * 8.0)).abs() < 1e-9,
            "{family} {}: {c}",
            c["model"]
        );
        assert!(
            stat("busiest pipe (cycles/wave)") <= stat("Issue Cycles"),
            "{family} {}: a pipe busier than the serial sum",
            c["model"]
        );
        if c["model"] != "baseline" {
            assert!(c["net_cycles_per_eval"].as_f64().unwrap() > 0.0, "{family} {}", c["model"]);
        }
    }
}

/// A translated target's statistics are the same on a second run with a cache of its own, and without the
/// translation's fast-maths option (`fast_option`, gone from the compiler's options under --precise-math)
/// the IEEE forms of pow, division and square root cost Blinn-Phong more than 1.2x.
pub fn assert_deterministic_and_precise_costs_more(target: &str, section: &str, fast_option: &str) {
    let dir = tempfile::tempdir().unwrap();
    let fast = inspect_json(dir.path(), "fast", &[target], &["--model", "blinn"], section);
    let again = inspect_json_afresh(dir.path(), "again", &[target], &["--model", "blinn"], section);
    for (a, b) in fast["rows"].as_array().unwrap().iter().zip(again["rows"].as_array().unwrap()) {
        for (key, value) in a["stats"].as_object().unwrap().iter().filter(|(k, _)| k.starts_with("driver/")) {
            assert_eq!(&b["stats"][key], value, "{target} {} {key} changed between runs", a["model"]);
        }
    }
    let precise = inspect_json(dir.path(), "precise", &[target], &["--model", "blinn", "--precise-math"], section);
    assert!(!precise["provenance"]["compiler"]["options"].as_str().unwrap().contains(fast_option));
    let net = |r: &serde_json::Value| r["cost"]["rows"][0]["net_cycles_per_eval"].as_f64().unwrap();
    assert!(
        net(&precise) > 1.2 * net(&fast),
        "{target}: IEEE pow, division and square root cost more: {} vs {}",
        net(&precise),
        net(&fast)
    );
}

/// `inspect --device DEVICE` with the vendor's compiler pointed at nowhere (`variable` set to `nowhere`, a path
/// under a temporary folder): exit 2, `vendor`'s "compiler not installed: run `make setup`", no output written.
pub fn a_missing_compiler_says_make_setup(device: &str, variable: &str, nowhere: &str, vendor: &str) {
    let dir = tempfile::tempdir().unwrap();
    let out = common::brdfprof()
        .args(["inspect", "--no-callgrind", "--device", device, "--model", "ggx", "--json"])
        .arg(dir.path().join("x.json"))
        // Outside the checkout: its committed results/inspect-*.md would refuse the default --markdown first.
        .current_dir(dir.path())
        .env(variable, dir.path().join(nowhere))
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains(&format!("{vendor} compiler not installed: run `make setup`")), "{stderr}");
    assert!(!dir.path().join("x.json").exists());
}
