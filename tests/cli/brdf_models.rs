//! `.brdf` models through the command line: parameters per CSV row and per flag, non-finite output, the
//! SPIR-V cache, bad files, and the file's kernel in profile, inspect, check, stability and sweep.

use crate::common::{self, run_in};
use brdfprof::brdf::samples;
use serde_json::Value;
use std::path::Path;

fn example(name: &str) -> String {
    common::repo_root().join("examples/brdf").join(format!("{name}.brdf")).display().to_string()
}

/// An eval CSV of well-conditioned samples, with a `gamma` column cycling through `gammas`.
fn write_csv(path: &Path, n: usize, gammas: &[f64]) {
    let mut text = String::from("nx,ny,nz,vx,vy,vz,lx,ly,lz,roughness,f0r,f0g,f0b,gamma\n");
    for (i, s) in samples::well_conditioned(n, 5, 0.05, 0.2..1.0).iter().enumerate() {
        let [n, v, l, f] = [s.n, s.v, s.l, s.f0];
        text += &format!(
            "{},{},{},{},{},{},{},{},{},{},{},{},{},{}\n",
            n[0],
            n[1],
            n[2],
            v[0],
            v[1],
            v[2],
            l[0],
            l[1],
            l[2],
            s.roughness,
            f[0],
            f[1],
            f[2],
            gammas[i % gammas.len()]
        );
    }
    std::fs::write(path, text).unwrap();
}

fn rows(path: &Path) -> Vec<String> {
    std::fs::read_to_string(path).unwrap().lines().skip(1).map(str::to_string).collect()
}

#[test]
fn a_parameter_per_csv_row_gives_the_rows_of_separate_param_runs() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("in.csv");
    let gammas = [1.0, 1.5, 2.0, 2.5];
    write_csv(&input, 400, &gammas);
    let burley = example("burley");
    let out = dir.path().join("rows.csv");
    let r = run_in(dir.path(), &["eval", "--model", &burley, "--input", "in.csv", "--output", "rows.csv"]).ok();
    assert!(r.stderr.contains("gamma set per row"), "{}", r.stderr);
    let per_row = rows(&out);
    for (k, g) in gammas.iter().enumerate() {
        let param = format!("gamma={g}");
        run_in(
            dir.path(),
            &["eval", "--model", &burley, "--param", &param, "--input", "in.csv", "--output", "one.csv"],
        )
        .ok();
        let one = rows(&dir.path().join("one.csv"));
        for i in (k..per_row.len()).step_by(gammas.len()) {
            assert_eq!(per_row[i], one[i], "row {i} (gamma {g}): per-row column vs --param {param}");
        }
    }
    // The built-in burley reads gamma the same way (within fp32 rounding), so the column did set it.
    run_in(dir.path(), &["eval", "--model", "burley,gamma=2.5", "--input", "in.csv", "--output", "builtin.csv"]).ok();
    let builtin = rows(&dir.path().join("builtin.csv"));
    for i in (3..per_row.len()).step_by(4) {
        let a: Vec<f64> = per_row[i].split(',').map(|x| x.parse().unwrap()).collect();
        let b: Vec<f64> = builtin[i].split(',').map(|x| x.parse().unwrap()).collect();
        for c in 0..3 {
            assert!(common::rel_err(a[c], b[c]) <= 1e-4, "row {i}: {a:?} vs built-in {b:?}");
        }
    }
}

#[test]
fn non_finite_values_are_written_and_counted() {
    let dir = tempfile::tempdir().unwrap();
    write_csv(&dir.path().join("in.csv"), 10, &[1.0]);
    std::fs::write(dir.path().join("nan.brdf"), "analytic\n::begin parameters\nfloat k 0 1 0.5\n::end parameters\n::begin shader\nvec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y) { return vec3(sqrt(dot(N, L) - 2.0), k, 1.0); }\n::end shader\n").unwrap();
    let r = run_in(dir.path(), &["eval", "--model", "nan.brdf", "--input", "in.csv", "--output", "out.csv"]).ok();
    assert!(r.stderr.contains("10 of 10 rows of nan.brdf are not finite"), "{}", r.stderr);
    for row in rows(&dir.path().join("out.csv")) {
        let f: Vec<&str> = row.split(',').collect();
        assert_eq!(f[0], "NaN", "written as is, not turned into a number: {row}");
        assert_eq!(&f[1..], ["0.5", "1"], "{row}");
    }
}

#[test]
fn a_rerun_takes_the_cached_spirv_without_compiling() {
    let dir = tempfile::tempdir().unwrap();
    write_csv(&dir.path().join("in.csv"), 10, &[1.0]);
    let cache = dir.path().join("cache");
    // glslangValidator behind a wrapper that logs every compilation (calls with -o).
    let bin = dir.path().join("bin");
    std::fs::create_dir(&bin).unwrap();
    let log = dir.path().join("compilations.log");
    let real = String::from_utf8(
        std::process::Command::new("sh").args(["-c", "command -v glslangValidator"]).output().unwrap().stdout,
    )
    .unwrap();
    let wrapper = bin.join("glslangValidator");
    std::fs::write(
        &wrapper,
        format!(
            "#!/bin/sh\ncase \"$*\" in *' -o '*) echo compile >> '{}';; esac\nexec '{}' \"$@\"\n",
            log.display(),
            real.trim()
        ),
    )
    .unwrap();
    std::fs::set_permissions(&wrapper, std::os::unix::fs::PermissionsExt::from_mode(0o755)).unwrap();
    let path = format!("{}:{}", bin.display(), std::env::var("PATH").unwrap());
    let compilations = || std::fs::read_to_string(&log).map_or(0, |t| t.lines().count());
    let eval = |model: &str| {
        let out = common::brdfprof()
            .args(["eval", "--model", model, "--input", "in.csv", "--output", "out.csv"])
            .env("BRDFPROF_CACHE_DIR", &cache)
            .env("PATH", &path)
            .current_dir(dir.path())
            .output()
            .unwrap();
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    };
    std::fs::copy(example("ggx"), dir.path().join("mine.brdf")).unwrap();
    eval("mine.brdf");
    assert_eq!(compilations(), 1, "the first run compiles");
    assert_eq!(std::fs::read_dir(&cache).unwrap().count(), 1, "and caches the kernel");
    eval("mine.brdf");
    assert_eq!(compilations(), 1, "a rerun takes the cached SPIR-V");
    // The cache is keyed on the content: an edited file compiles again.
    let text = std::fs::read_to_string(dir.path().join("mine.brdf")).unwrap();
    std::fs::write(
        dir.path().join("mine.brdf"),
        text.replace("const float PI", "const float UNUSED = 1.0;\nconst float PI"),
    )
    .unwrap();
    eval("mine.brdf");
    assert_eq!(compilations(), 2, "an edited file compiles again");
}

#[test]
fn unknown_and_bad_parameters_name_the_file_and_the_parameter() {
    let dir = tempfile::tempdir().unwrap();
    write_csv(&dir.path().join("in.csv"), 4, &[1.0]);
    let burley = example("burley");
    let cases: [(&str, &str); 4] = [
        ("gama=2", "no model takes `gama`"),
        ("gamma=x", "burley.brdf: parameter `gamma` (float at line"),
        ("f0=0.1,0.2", "a colour is r,g,b"),
        ("gamma=@shininess", "unknown input `@shininess`"),
    ];
    for (param, needle) in cases {
        let r = run_in(
            dir.path(),
            &["eval", "--model", &burley, "--param", param, "--input", "in.csv", "--output", "out.csv"],
        )
        .fails(2, needle);
        assert!(r.stderr.contains("burley.brdf"), "{param}: {}", r.stderr);
        assert!(!dir.path().join("out.csv").exists(), "{param}: nothing written");
    }
    let r = run_in(
        dir.path(),
        &["eval", "--model", &burley, "--param", "gamma=9", "--input", "in.csv", "--output", "out.csv"],
    )
    .ok();
    assert!(r.stderr.contains("gamma = 9 is outside the file's range [1, 3]"), "{}", r.stderr);
}

#[test]
fn bad_files_exit_2_naming_the_line_and_write_nothing() {
    let dir = tempfile::tempdir().unwrap();
    write_csv(&dir.path().join("in.csv"), 4, &[1.0]);
    std::fs::write(dir.path().join("out.csv"), "kept\n").unwrap();
    let shader =
        "::begin shader\nvec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y) { return vec3(1.0); }\n::end shader\n";
    let cases: Vec<(&str, Vec<u8>, &str)> = vec![
        ("missing-end", format!("analytic\n{shader}::begin parameters\nfloat k 0 1 0.5\n").into_bytes(), ":5: section `parameters` has no `::end parameters`"),
        ("nested", format!("analytic\n::begin parameters\nfloat k 0 1 0.5\n{shader}").into_bytes(), ":4: `::begin shader` inside section `parameters`"),
        ("unknown-type", format!("analytic\n::begin parameters\nvec2 k 0 1\n::end parameters\n{shader}").into_bytes(), ":3: unknown parameter type"),
        ("bad-number", format!("analytic\n::begin parameters\nfloat k 0 1 zero\n::end parameters\n{shader}").into_bytes(), ":3: DEFAULT of `k`: `zero` is not a finite number"),
        ("duplicate", format!("analytic\n::begin parameters\nfloat k 0 1 0.5\nfloat k 0 1 0.5\n::end parameters\n{shader}").into_bytes(), ":4: parameter `k` is declared twice"),
        ("no-brdf", b"analytic\n::begin shader\nvec3 f(vec3 L) { return L; }\n::end shader\n".to_vec(), ":2: the shader defines no function `BRDF`"),
        ("glsl-error", b"analytic\n::begin shader\nvec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y) {\n  return vec3(undefined_thing);\n}\n::end shader\n".to_vec(), ":4: 'undefined_thing' : undeclared identifier"),
        ("empty", Vec::new(), ":1: empty file"),
        ("binary", vec![0x7f, b'E', b'L', b'F', 0, 1, 2, 3], ":1: binary content"),
    ];
    for (name, bytes, needle) in cases {
        let file = format!("{name}.brdf");
        std::fs::write(dir.path().join(&file), bytes).unwrap();
        let r = run_in(dir.path(), &["eval", "--model", &file, "--input", "in.csv", "--output", "out.csv"]);
        assert_eq!(r.code, Some(2), "{name}: {}", r.stderr);
        assert!(r.stderr.contains(&format!("{file}{needle}")), "{name}: expected `{file}{needle}` in:\n{}", r.stderr);
        assert_eq!(
            std::fs::read_to_string(dir.path().join("out.csv")).unwrap(),
            "kept\n",
            "{name}: the existing output is untouched"
        );
    }
}

fn json(path: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

#[test]
fn profile_times_a_file_and_a_spec_interleaved() {
    let dir = tempfile::tempdir().unwrap();
    let model = format!("{},roughness=@roughness,f0=@f0", example("ggx"));
    run_in(
        dir.path(),
        &[
            "profile",
            "--model",
            &model,
            "--model",
            "ggx",
            "--size",
            "64x64",
            "--min-rounds",
            "3",
            "--budget",
            "20",
            "--json",
            "p.json",
        ],
    )
    .ok();
    let p = json(&dir.path().join("p.json"));
    let names: Vec<&str> = p["rows"].as_array().unwrap().iter().map(|r| r["model"].as_str().unwrap()).collect();
    assert!(
        names.contains(&"ggx.brdf,roughness=@roughness,f0=@f0") && names.contains(&"ggx"),
        "the file by its name, not its path: {names:?}"
    );
    for r in p["rows"].as_array().unwrap() {
        assert!(r["ns_per_eval"]["median"].as_f64().unwrap() > 0.0, "{r}");
    }
}

#[test]
fn check_gates_a_file_and_catches_an_extra_pow() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::copy(example("ggx"), dir.path().join("mine.brdf")).unwrap();
    let model = "mine.brdf,roughness=@roughness";
    let gate = ["check", "--model", model, "--no-callgrind", "--rounds", "0", "--baseline", "base.json"];
    run_in(dir.path(), &["check", "--model", model, "--no-callgrind", "--rounds", "0", "--save-baseline", "base.json"])
        .ok();
    run_in(dir.path(), &gate).ok();
    let inspect = json(&dir.path().join("base.json"));
    let text = inspect.to_string();
    assert!(text.contains("mine.brdf"), "the baseline records the file's model");
    let src = std::fs::read_to_string(dir.path().join("mine.brdf")).unwrap();
    let edited = src.replace("return a2 / (PI * d * d);", "return a2 / (PI * pow(d, 2.0) * pow(max(d, 1.0), 0.5));");
    assert_ne!(src, edited, "the edit applies");
    std::fs::write(dir.path().join("mine.brdf"), edited).unwrap();
    let r = run_in(dir.path(), &gate);
    assert_eq!(r.code, Some(1), "{}", r.stderr);
    assert!(r.stdout.contains("REGRESSION"), "{}", r.stdout);
    assert!(
        r.stdout.contains("mine,roughness=@roughness") && r.stdout.contains("glsl.Pow"),
        "the file by its label: {}",
        r.stdout
    );
}

#[test]
fn inspect_counts_the_file_kernel() {
    let dir = tempfile::tempdir().unwrap();
    let model = format!("{},roughness=@roughness", example("blinn"));
    run_in(dir.path(), &["inspect", "--model", &model, "--no-callgrind", "--json", "i.json", "--markdown", "i.md"])
        .ok();
    let md = std::fs::read_to_string(dir.path().join("i.md")).unwrap();
    assert!(md.contains("blinn.brdf"), "{md}");
    let i = json(&dir.path().join("i.json"));
    let rows = i["rows"].as_array().unwrap();
    let row =
        rows.iter().find(|r| r["model"] == "blinn.brdf,roughness=@roughness").expect("a row for the file, by its name");
    assert!(row.to_string().contains("\"spirv/total\""), "{row}");
    // The reference is added as profile adds it, so the file's cost has a ggx to be compared with, and beside
    // it the same formula without brdfprof's guards, which a file's code does not carry either.
    assert_eq!(
        rows.iter().map(|r| r["model"].as_str().unwrap()).collect::<Vec<_>>(),
        ["ggx", "ggx,guards=off", "blinn.brdf,roughness=@roughness", "baseline"]
    );
}

#[test]
fn stability_fails_a_file_that_goes_negative_and_passes_the_examples() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("neg.brdf"), "analytic\n::begin shader\nvec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y) { return vec3(dot(L, V) - 0.5); }\n::end shader\n").unwrap();
    let r = run_in(dir.path(), &["stability", "--model", "neg.brdf", "--no-energy", "--out", "st"]);
    assert_eq!(r.code, Some(1), "{}", r.stderr);
    let ok = format!("{},roughness=@roughness,f0=@f0", example("ggx"));
    run_in(dir.path(), &["stability", "--model", &ok, "--out", "st2"]).ok();
    let s = json(&common::device_file(&dir.path().join("st2"), "stability-", ".json"));
    let spec = &s["specs"][0];
    assert_eq!(spec["has_twin"], false);
    assert_eq!(spec["nan"].as_u64(), Some(0));
    let max_e = spec["energy"]["max_e"].as_f64().unwrap();
    assert!(max_e > 0.5 && max_e < 1.01, "GGX's white furnace with F0 = 1 through @f0: {max_e}");
}

#[test]
fn sweep_measures_a_file_against_a_reference() {
    let dir = tempfile::tempdir().unwrap();
    let model = format!("{},roughness=@roughness,f0=@f0", example("ggx"));
    run_in(
        dir.path(),
        &[
            "sweep",
            "--model",
            &model,
            "--model",
            "ggx",
            "--reference",
            "ggx",
            "--size",
            "64x64",
            "--min-rounds",
            "3",
            "--budget",
            "60",
            "--f0",
            "0.02..0.08",
            "--out",
            "sw",
        ],
    )
    .ok();
    let s = json(&common::device_file(&dir.path().join("sw"), "sweep-", ".json"));
    let set = s["sample_set"].as_str().unwrap();
    assert!(set.contains("F0 in [0.02, 0.08]^3") && !set.contains("dielectric F0"), "--f0 names the set: {set}");
    let rows = s["rows"].as_array().unwrap();
    let file = rows.iter().find(|r| r["spec"].as_str().unwrap().contains("ggx.brdf")).unwrap();
    let builtin = rows.iter().find(|r| r["spec"] == "ggx").unwrap();
    assert_eq!(file["accuracy"]["reference"], "ggx");
    // The numerical error of a file is against the reference spec's own f64 formula (a transcription
    // of ggx's formula matches it to fp32 rounding), its error against exact GGX is the preset's.
    let numerical = file["accuracy"]["numerical"]["max"].as_f64().unwrap();
    assert!(numerical < 1e-3, "the file against ggx's f64 formula: {numerical}");
    let (a, b) = (
        file["accuracy"]["vs_exact"]["rms"].as_f64().unwrap(),
        builtin["accuracy"]["vs_exact"]["rms"].as_f64().unwrap(),
    );
    assert!((a - b).abs() <= 1e-3 * b, "the file's error against exact GGX is the preset's: {a} vs {b}");
}

#[test]
fn a_file_gates_on_a_compile_only_amd_target() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::copy(example("ggx"), dir.path().join("mine.brdf")).unwrap();
    let model = "mine.brdf,roughness=@roughness,f0=@f0";
    run_in(dir.path(), &["check", "--device", "radv:navi21", "--model", model, "--save-baseline", "aco.json"]).ok();
    let base = json(&dir.path().join("aco.json")).to_string();
    assert!(base.contains("mine.brdf"), "the baseline records the file's model");
    let src = std::fs::read_to_string(dir.path().join("mine.brdf")).unwrap();
    std::fs::write(
        dir.path().join("mine.brdf"),
        src.replace("return a2 / (PI * d * d);", "return a2 / (PI * pow(d, 2.0) * pow(max(d, 1.0), 0.5));"),
    )
    .unwrap();
    let r = run_in(dir.path(), &["check", "--device", "radv:navi21", "--model", model, "--baseline", "aco.json"]);
    assert_eq!(r.code, Some(1), "{}\n{}", r.stdout, r.stderr);
    assert!(
        r.stdout.contains("driver/inverse-throughput") && r.stdout.contains("mine,roughness=@roughness,f0=@f0"),
        "the file by its label: {}",
        r.stdout
    );
}

const NAN_FILE: &str = "analytic\n::begin shader\nvec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y) { return vec3(sqrt(dot(N, L) - 2.0)); }\n::end shader\n";

/// Stability of an all-NaN file counts and names NaN wherever it is: not a reciprocity of 0.0 (perfect), not a
/// max E of "inf gain" (JSON null), not NaN results as "(inf)".
#[test]
fn stability_counts_and_names_nan_instead_of_calling_it_perfect() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("nan.brdf"), NAN_FILE).unwrap();
    let r = run_in(dir.path(), &["stability", "--model", "nan.brdf", "--out", "st"]);
    assert_eq!(r.code, Some(1), "{}", r.stderr);
    let s = json(&common::device_file(&dir.path().join("st"), "stability-", ".json"));
    let spec = &s["specs"][0];
    assert!(spec["nan"].as_u64().unwrap() > 0);
    assert!(spec["reciprocity"].is_null() && spec["reciprocity_nonfinite"].as_u64().unwrap() > 0, "{spec}");
    let energy = &spec["energy"];
    assert!(energy["max_e"].is_null() && !energy["gains_energy"].as_bool().unwrap(), "{energy}");
    assert_eq!(
        energy["nonfinite"].as_u64().unwrap(),
        (energy["e"].as_array().unwrap().len() * energy["e"][0].as_array().unwrap().len()) as u64
    );
    let md = std::fs::read_to_string(common::device_file(&dir.path().join("st"), "stability-", ".md")).unwrap();
    let row = md.lines().find(|l| l.starts_with("| nan ")).expect("a row for the file, by its stem");
    assert!(
        row.contains("NaN/Inf") && !row.contains("gain") && !row.contains("(inf)") && !row.contains("0.0e0"),
        "{row}"
    );
    assert!(row.contains("FAIL"), "{row}");
}

/// A reference that is not finite is refused before anything is measured or written (the sweep wrote its
/// .md and .json, then exited 2 without saying why).
#[test]
fn sweep_refuses_a_non_finite_reference_before_writing() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("nan.brdf"), NAN_FILE).unwrap();
    let model = format!("{},roughness=@roughness,f0=@f0", example("ggx"));
    run_in(dir.path(), &["sweep", "--model", &model, "--reference", "nan.brdf", "--size", "16x16", "--out", "sw"])
        .fails(2, "--reference nan.brdf: the reference is not finite");
    assert!(!dir.path().join("sw").exists(), "nothing written");
}

/// `render` of a model whose values are NaN counts its bad pixels, names the picture and draws them in
/// magenta, not black.
#[test]
fn render_counts_nan_pixels() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("nan.brdf"), NAN_FILE).unwrap();
    let mut scene: Value =
        serde_json::from_str(&std::fs::read_to_string(common::repo_root().join("scenes/sphere-grid.json")).unwrap())
            .unwrap();
    scene["gbuffer"]["procedural"]["size"] = serde_json::json!([96, 48]);
    scene["render"]["models"] = serde_json::json!(["ggx", "nan.brdf"]);
    std::fs::write(d.join("s.json"), scene.to_string()).unwrap();
    let r = run_in(d, &["render", "--scene", "s.json", "--out", "pictures"]).ok();
    let warned = r.stderr.lines().find(|l| l.contains("warning: nan.brdf:")).unwrap_or_else(|| panic!("{}", r.stderr));
    assert!(warned.contains(" of 4608 pixels are NaN or Inf (drawn magenta in pictures/"), "{warned}");
    let picture = std::fs::read_dir(d.join("pictures"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .find(|p| p.file_name().unwrap().to_string_lossy().starts_with("nan"))
        .unwrap();
    let img = image::open(&picture).unwrap().to_rgb8();
    assert!(img.pixels().filter(|p| p.0 == [255, 0, 255]).count() > 1000, "{}: magenta pixels", picture.display());
}

/// lavapipe ends every loop after 65535 iterations without a word; a file's loops are said out loud, with
/// the bound where the source gives one.
#[test]
fn loops_are_warned_about_with_their_bounds() {
    let dir = tempfile::tempdir().unwrap();
    write_csv(&dir.path().join("in.csv"), 4, &[1.0]);
    let shader = "::begin shader\nvec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y)\n{\n    float s = 0.0;\n    for (int i = 0; i < 100000; i++) s += 1e-6;\n    for (int i = 0; i < 8; i++) s += 1.0;\n    while (s > 1e9) s -= 1.0;\n    return vec3(s);\n}\n::end shader\n";
    std::fs::write(dir.path().join("loops.brdf"), format!("analytic\n{shader}")).unwrap();
    let r = run_in(dir.path(), &["eval", "--model", "loops.brdf", "--input", "in.csv", "--output", "out.csv"]).ok();
    assert!(
        r.stderr.contains(
            "warning: loops.brdf:6: a `for` loop of 100000 iterations: lavapipe ends every loop after 65535 iterations"
        ),
        "{}",
        r.stderr
    );
    assert!(
        r.stderr.contains("loops.brdf:8: a `while` loop whose iterations brdfprof cannot bound from the source"),
        "{}",
        r.stderr
    );
    // A loop within the limit needs nothing done: said with --verbose only.
    assert!(!r.stderr.contains("loops.brdf:7:"), "{}", r.stderr);
    let args = ["eval", "--verbose", "--model", "loops.brdf", "--input", "in.csv", "--output", "out.csv"];
    let r = run_in(dir.path(), &args).ok();
    assert!(r.stderr.contains("loops.brdf:7: a `for` loop of 8 iterations: within the 65535"), "{}", r.stderr);
}

/// Alike notes about one file are one line with a count (`uniform` dropped from eight globals), each on its
/// own line with --verbose.
#[test]
fn alike_notes_are_one_line_with_a_count() {
    let dir = tempfile::tempdir().unwrap();
    write_csv(&dir.path().join("in.csv"), 4, &[1.0]);
    let globals: String = (0..8).map(|k| format!("uniform float u{k};\n")).collect();
    let shader = format!(
        "::begin shader\n{globals}vec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y)\n{{\n    return vec3(u0 + u7);\n}}\n::end shader\n"
    );
    std::fs::write(dir.path().join("u.brdf"), format!("analytic\n{shader}")).unwrap();
    let r = run_in(dir.path(), &["eval", "--model", "u.brdf", "--input", "in.csv", "--output", "out.csv"]).ok();
    let said: Vec<&str> = r.stderr.lines().filter(|l| l.contains("`uniform` dropped")).collect();
    assert_eq!(said.len(), 1, "{}", r.stderr);
    assert!(said[0].contains("and 7 more alike") && said[0].contains("`u7`"), "{}", said[0]);
    let args = ["eval", "--verbose", "--model", "u.brdf", "--input", "in.csv", "--output", "out.csv"];
    let r = run_in(dir.path(), &args).ok();
    assert_eq!(r.stderr.lines().filter(|l| l.contains("`uniform` dropped")).count(), 8, "{}", r.stderr);
}

/// Smaller checks of `.brdf` models, each as the user meets it: parameters as CSV columns, a key given twice,
/// a path with commas, a recursion error's names, and defines.
#[test]
fn csv_columns_follow_the_parameters_declarations() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let header = "nx,ny,nz,vx,vy,vz,lx,ly,lz,roughness,f0r,f0g,f0b";
    let row = "0,0,1,0,0.6,0.8,0.6,0,0.8";
    let file = "analytic\n::begin parameters\nfloat roughness 0 10 1\nbool on 1\nfloat nx 0 1 0.5\nfloat k 0 1 0.5\n::end parameters\n::begin shader\nvec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y) { return on ? vec3(roughness, nx, k) : vec3(0.0); }\n::end shader\n";
    std::fs::write(d.join("p.brdf"), file).unwrap();
    // A bool column takes 0 or 1 only.
    std::fs::write(
        d.join("bool.csv"),
        format!("{header},on\n{row},0.5,0.04,0.04,0.04,1\n{row},0.5,0.04,0.04,0.04,0.5\n"),
    )
    .unwrap();
    run_in(d, &["eval", "--model", "p.brdf", "--input", "bool.csv", "--output", "out.csv"])
        .fails(2, "bool.csv:3: column 14 `on`: 0.5 is not a bool (0 or 1)");
    // The file's 0..10 roughness comes from the CSV; outside the slider range is a warning; a parameter
    // named like a normal's column is not read per row, and says so.
    std::fs::write(
        d.join("range.csv"),
        format!("{header},k\n{row},5,0.04,0.04,0.04,0.25\n{row},0.5,0.04,0.04,0.04,2\n"),
    )
    .unwrap();
    let r = run_in(d, &["eval", "--model", "p.brdf", "--input", "range.csv", "--output", "out.csv"]).ok();
    assert!(r.stderr.contains("range.csv: column 14 `k`: 1 of 2 rows are outside the file's range [0, 1] (BRDF Explorer's slider bounds), the first at line 3 (2)"), "{}", r.stderr);
    assert!(
        r.stderr.contains("parameter `nx` is not read per row: column(s) nx hold the geometry's vectors"),
        "{}",
        r.stderr
    );
    assert_eq!(rows(&d.join("out.csv")), ["5,0.5,0.25", "0.5,0.5,2"]);
    // With roughness bound to the input, the column is the input's and must be in [0, 1].
    run_in(d, &["eval", "--model", "p.brdf,roughness=@roughness", "--input", "range.csv", "--output", "out.csv"])
        .fails(2, "range.csv:2: column 10 `roughness`: 5 is outside [0, 1]");
}

#[test]
fn model_files_errors_say_why() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    write_csv(&d.join("in.csv"), 4, &[1.0]);
    std::fs::create_dir(d.join("dir.brdf")).unwrap();
    std::os::unix::fs::symlink("loop.brdf", d.join("loop.brdf")).unwrap();
    std::os::unix::fs::symlink("gone.brdf", d.join("dangling.brdf")).unwrap();
    let eval = |model: &str| run_in(d, &["eval", "--model", model, "--input", "in.csv", "--output", "out.csv"]);
    eval("dir.brdf").fails(2, "cannot read dir.brdf: not a regular file (a directory)");
    eval("loop.brdf").fails(2, "cannot read loop.brdf: Too many levels of symbolic links");
    eval("dangling.brdf")
        .fails(2, "cannot read dangling.brdf: it is a symbolic link to gone.brdf, which does not exist");
    // A key given twice is an error, as for a built-in spec.
    eval(&format!("{},gamma=1.5,gamma=2", example("burley"))).fails(2, "`gamma` is given twice");
    // A path may hold commas.
    std::fs::create_dir(d.join("a,b")).unwrap();
    std::fs::copy(example("ggx"), d.join("a,b/m.brdf")).unwrap();
    eval("a,b/m.brdf,roughness=0.3").ok();
    // A recursion error names the file's own functions, not renamed ones, and no temporary path.
    std::fs::write(d.join("rec.brdf"), "analytic\n::begin shader\nfloat f(float x) { return x < 1.0 ? x : f(x - 1.0); }\nvec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y) { return vec3(f(dot(N, L))); }\n::end shader\n").unwrap();
    let r = eval("rec.brdf").fails(2, "rec.brdf: glslang cannot compile");
    assert!(
        r.stderr.contains("Recursion detected")
            && r.stderr.contains("f(f1; calling f(f1;")
            && r.stderr.contains("GLSL forbids recursion"),
        "{}",
        r.stderr
    );
    assert!(
        !r.stderr.contains("brdf_f") && !r.stderr.contains("/tmp") && !r.stderr.contains("brdfprof-"),
        "{}",
        r.stderr
    );
}

/// Engine-style code with a quality switch (tests/fixtures/brdf/quality-switch.brdf, written for this test):
/// glslang's preprocessor selects the branch the defines select, from `--define`, from the spec's `define=`,
/// or the file's own default, and each branch's value is the f64 formula's.
#[test]
fn the_preprocessor_selects_the_branch_the_defines_select() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let file = common::repo_root().join("tests/fixtures/brdf/quality-switch.brdf").display().to_string();
    let samples = samples::well_conditioned(500, 7, 0.05, 0.2..1.0);
    let mut text = String::from("nx,ny,nz,vx,vy,vz,lx,ly,lz,roughness,f0r,f0g,f0b\n");
    for s in &samples {
        let [n, v, l, f] = [s.n, s.v, s.l, s.f0];
        text += &format!(
            "{},{},{},{},{},{},{},{},{},{},{},{},{}\n",
            n[0], n[1], n[2], v[0], v[1], v[2], l[0], l[1], l[2], s.roughness, f[0], f[1], f[2]
        );
    }
    std::fs::write(d.join("in.csv"), text).unwrap();
    let values = |args: &[&str]| -> Vec<f64> {
        let r = run_in(d, &[&["eval", "--input", "in.csv", "--output", "out.csv"], args].concat()).ok();
        assert!(!r.stderr.contains("dropped"), "no directive is dropped: {}", r.stderr);
        rows(&d.join("out.csv")).iter().map(|row| row.split(',').next().unwrap().parse().unwrap()).collect()
    };
    let schlick = |s: &brdfprof::brdf::Sample| {
        let (v, l) = (glam::Vec3::from(s.v).as_dvec3(), glam::Vec3::from(s.l).as_dvec3());
        let voh = v.dot((v + l).normalize()).clamp(0.0, 1.0);
        0.04 + 0.96 * (1.0 - voh).powi(5)
    };
    let pi = std::f64::consts::PI;
    let check = |got: &[f64], expected: &dyn Fn(&brdfprof::brdf::Sample) -> f64, what: &str| {
        assert_eq!(got.len(), samples.len());
        for (g, s) in got.iter().zip(&samples) {
            assert!(common::rel_err(*g, expected(s)) <= 1e-5, "{what}: {g} vs {}", expected(s));
        }
    };
    check(&values(&["--model", &file]), &|_| 0.04 / pi, "default (QUALITY_LOW)");
    let high = values(&["--model", &file, "--define", "QUALITY_LEVEL=1"]);
    check(&high, &|s| schlick(s) / pi, "--define QUALITY_LEVEL=1");
    assert_eq!(
        values(&["--model", &format!("{file},define=QUALITY_LEVEL=QUALITY_HIGH,scale=1")]),
        high,
        "the spec's define= selects the same branch"
    );
    check(
        &values(&["--model", &file, "--define", "QUALITY_LEVEL=1", "--param", "scale=2"]),
        &|s| 2.0 * schlick(s) / pi,
        "a define and a parameter together",
    );
    // A define is for a file; a bad one names what is wrong.
    run_in(d, &["eval", "--model", "ggx", "--define", "Q=1", "--input", "in.csv", "--output", "x.csv"])
        .fails(2, "no --model is a .brdf file");
    run_in(d, &["eval", "--model", &file, "--define", "scale=1", "--input", "in.csv", "--output", "x.csv"])
        .fails(2, "is the file's parameter");
    run_in(d, &["eval", "--model", &file, "--define", "1Q=1", "--input", "in.csv", "--output", "x.csv"])
        .fails(2, "NAME an identifier");
    // A file that refuses to preprocess without its macro is read with it, from --define or define=.
    std::fs::write(d.join("needs.brdf"), "analytic\n::begin shader\n#ifndef GAIN\n#error GAIN must be defined\n#endif\nvec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y) { return vec3(GAIN); }\n::end shader\n").unwrap();
    run_in(d, &["eval", "--model", "needs.brdf", "--input", "in.csv", "--output", "x.csv"])
        .fails(2, "GAIN must be defined");
    check(&values(&["--model", "needs.brdf", "--define", "GAIN=0.25"]), &|_| 0.25, "--define on a file that needs it");
    check(&values(&["--model", "needs.brdf,define=GAIN=0.5"]), &|_| 0.5, "define= on a file that needs it");
    // A define names the model: the two kernels are two models.
    let r = run_in(
        d,
        &[
            "inspect",
            "--no-callgrind",
            "--model",
            &file,
            "--model",
            &format!("{file},define=QUALITY_LEVEL=1"),
            "--json",
            "i.json",
            "--markdown",
            "i.md",
        ],
    )
    .ok();
    let report = std::fs::read_to_string(d.join("i.md")).unwrap();
    assert!(report.contains("| quality-switch+QUALITY_LEVEL=1 |"), "{report}\n{}", r.stderr);
    assert!(r.stderr.contains("share a default label; called `quality-switch+QUALITY_LEVEL=1`"), "{}", r.stderr);
    let json = std::fs::read_to_string(d.join("i.json")).unwrap();
    assert!(json.contains(",define=QUALITY_LEVEL=1"), "the full spec is kept in the JSON: {json}");
}
