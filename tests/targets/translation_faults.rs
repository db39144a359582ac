//! The translation paths never crash brdfprof or run unbounded, and a vendor tool's output is
//! believed only when it is the whole kernel. Each shader here is written for the test; the tools are the real
//! ones, or a script standing in front of the real one that damages its output as a broken install would.

use crate::common::{self, run};
use std::os::unix::fs::PermissionsExt;
use std::path::{Path, PathBuf};

/// A .brdf file with `body` as BRDF's body (one line per statement), under `dir`.
fn brdf(dir: &Path, name: &str, body: &str) -> PathBuf {
    let path = dir.join(format!("{name}.brdf"));
    std::fs::write(
        &path,
        format!(
            "analytic\n::begin shader\nvec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y) {{\n{body}\n}}\n::end shader\n"
        ),
    )
    .unwrap();
    path
}

/// Rows whose L.x and V.y move an index computed from them far out of bounds, and one row at the pole.
fn inputs(dir: &Path) -> PathBuf {
    let csv = dir.join("in.csv");
    std::fs::write(&csv, "nx,ny,nz,vx,vy,vz,lx,ly,lz\n0,0,1,0.3,0.2,0.93,0.2,-0.3,0.93\n0,0,1,0,0,1,0,0,1\n0,0,1,-0.5,0.1,0.86,0.7,0.1,0.7\n").unwrap();
    csv
}

fn eval_rows(dir: &Path, model: &Path, csv: &Path, device: Option<&str>) -> String {
    let out = dir.join(format!("out-{}.csv", device.unwrap_or("vulkan")));
    let mut args = vec![
        "eval",
        "--model",
        model.to_str().unwrap(),
        "--input",
        csv.to_str().unwrap(),
        "--output",
        out.to_str().unwrap(),
    ];
    if let Some(d) = device {
        args.extend(["--device", d]);
    }
    run(&args).ok();
    std::fs::read_to_string(out).unwrap()
}

fn inspect(dir: &Path, devices: &[&str], model: &Path, env: &[(&str, &Path)]) -> common::Run {
    let mut cmd = common::brdfprof();
    cmd.args(["inspect", "--no-callgrind", "--model", model.to_str().unwrap()]).current_dir(dir);
    for d in devices {
        cmd.args(["--device", d]);
    }
    cmd.arg("--json").arg(dir.join("i.json")).arg("--markdown").arg(dir.join("i.md"));
    for (k, v) in env {
        cmd.env(k, v);
    }
    let out = cmd.output().unwrap();
    common::Run {
        code: out.status.code(),
        stdout: String::from_utf8_lossy(&out.stdout).into_owned(),
        stderr: String::from_utf8_lossy(&out.stderr).into_owned(),
    }
}

/// An index past an array's end, and past a vector's, is clamped as lavapipe clamps it: OpenCL and
/// Vulkan give the same values (before the fix: SIGSEGV in the host check, garbage on PoCL).
#[test]
fn an_out_of_bounds_index_is_clamped_as_on_vulkan_and_never_faults() {
    let dir = tempfile::tempdir().unwrap();
    let model = brdf(
        dir.path(),
        "oob",
        "    float a[4];\n    a[0] = 0.1; a[1] = 0.2; a[2] = 0.3; a[3] = 0.4;\n    a[4 + int(abs(L.x) * 1e8)] = 1.0;\n    vec3 v = vec3(0.5, 0.6, 0.7);\n    float w = v[3 + int(abs(V.x) * 1e7)];\n    return vec3(a[0] + a[3], a[1], a[2 + int(abs(V.y) * 1e8)] + w);",
    );
    let csv = inputs(dir.path());
    let vulkan = eval_rows(dir.path(), &model, &csv, None);
    assert_eq!(eval_rows(dir.path(), &model, &csv, Some("opencl")), vulkan);
    // The write past the end landed on the last element on Vulkan: the clamp the translation copies.
    assert!(vulkan.lines().nth(1).unwrap().starts_with("1.1,"), "{vulkan}");
    inspect(dir.path(), &["nvidia:sm_89", "intel:gen12lp"], &model, &[]).ok();
}

/// An endless loop on PoCL ends at the host's loop limit instead of spinning.
#[test]
fn an_endless_loop_on_opencl_stops_at_the_loop_limit() {
    let dir = tempfile::tempdir().unwrap();
    let model = brdf(
        dir.path(),
        "spin",
        "    float x = 1.0 + abs(L.x) * 1e-30;\n    while (true) { x = x * 1.0000001; if (x > 1e30) break; }\n    return vec3(x * 1e-30);",
    );
    let started = std::time::Instant::now();
    eval_rows(dir.path(), &model, &inputs(dir.path()), Some("opencl"));
    assert!(started.elapsed() < std::time::Duration::from_secs(60), "{:?}", started.elapsed());
}

/// The host build runs under the compile limit, its temporaries in the command's directory.
#[test]
fn a_host_compiler_that_hangs_stops_at_the_compile_limit() {
    let dir = tempfile::tempdir().unwrap();
    let bin = dir.path().join("bin");
    std::fs::create_dir(&bin).unwrap();
    script(&bin.join("g++"), "#!/bin/sh\nsleep 60\n");
    let path = format!("{}:{}", bin.display(), std::env::var("PATH").unwrap());
    let model = brdf(dir.path(), "plain", "    return vec3(dot(N, L) * 0.1);");
    let cache = dir.path().join("cache");
    let started = std::time::Instant::now();
    let out = common::brdfprof()
        .args([
            "inspect",
            "--no-callgrind",
            "--compile-timeout",
            "3",
            "--device",
            "nvidia:sm_89",
            "--model",
            model.to_str().unwrap(),
            "--json",
            "i.json",
            "--markdown",
            "i.md",
        ])
        .current_dir(dir.path())
        .env("PATH", path)
        .env("BRDFPROF_CACHE_DIR", &cache)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(
        stderr.contains(
            "the host build of the translation (g++): the compilation took longer than the compile limit of 3 s"
        ),
        "{stderr}"
    );
    assert!(started.elapsed() < std::time::Duration::from_secs(45), "{:?}", started.elapsed());
}

/// A constant array longer than a constructor takes (80 > 64 elements) translates.
#[test]
fn a_long_constant_array_translates() {
    let dir = tempfile::tempdir().unwrap();
    let table: Vec<String> = (0..80).map(|k| format!("{:.2}", k as f64 / 100.0)).collect();
    let body = format!(
        "    const float table[80] = float[80]({});\n    int i = int(clamp(dot(N, L), 0.0, 1.0) * 79.0);\n    return vec3(table[i], table[79 - i], 1.0);",
        table.join(", ")
    );
    let model = brdf(dir.path(), "table", &body);
    let csv = inputs(dir.path());
    assert_eq!(eval_rows(dir.path(), &model, &csv, Some("opencl")), eval_rows(dir.path(), &model, &csv, None));
    inspect(dir.path(), &["nvidia:sm_89", "intel:gen12lp"], &model, &[]).ok();
}

/// fp64 on a family without it leaves that family's row out with ocloc's reason, not the command.
#[test]
fn fp64_is_left_out_of_the_intel_families_without_it() {
    let dir = tempfile::tempdir().unwrap();
    let model = brdf(
        dir.path(),
        "wide",
        "    double d = double(dot(N, L)) * double(dot(N, V));\n    return vec3(float(sqrt(d + 1.0lf)));",
    );
    let r = inspect(dir.path(), &["intel:gen9", "intel:gen12lp"], &model, &[]).ok();
    assert!(
        r.stderr.contains("not compiled for intel:gen12lp: wide (tgllp has no fp64 (cl_khr_fp64); ocloc:")
            && r.stderr.contains("requires cl_khr_fp64"),
        "{}",
        r.stderr
    );
    let md = std::fs::read_to_string(dir.path().join("i.md")).unwrap();
    let across = md.split("### Cost per BRDF evaluation across devices").nth(1).unwrap();
    let row: Vec<&str> = across.lines().find(|l| l.starts_with("| wide ")).unwrap().split('|').map(str::trim).collect();
    assert!(row[2] != "-" && row[5] == "-", "gen9 priced, gen12lp left out: {row:?}");
}

/// Integer % of a negative value, where lavapipe computes srem and SPIR-V's
/// OpSMod takes the divisor's sign: named as the device's deviation, by inspect and by a scene alike.
#[test]
fn smod_on_negatives_is_named_as_lavapipes_deviation_on_every_path() {
    let dir = tempfile::tempdir().unwrap();
    let model = brdf(
        dir.path(),
        "smod",
        "    int k = int(floor(L.x * 10.0)) - 7;\n    int r = k % 3;\n    return vec3(float(r + 3) * 0.1);",
    );
    let cache = dir.path().join("cache");
    let r = inspect(dir.path(), &["nvidia:sm_89"], &model, &[("BRDFPROF_CACHE_DIR", &cache)]).ok();
    let said = "computes it with the dividend's sign (srem: -7 % 3 = -1) where SPIR-V's OpSMod and the translation take the divisor's (2)";
    assert!(
        r.stderr.contains(&format!(
            "smod (eval kernel): the kernel takes integer `%` (SPIR-V OpSMod) of a negative value: llvmpipe"
        )) && r.stderr.contains(said),
        "{}",
        r.stderr
    );
    // The same verdict from the cache, and from a scene whose clamped radiance alone might hide it.
    let again = inspect(dir.path(), &["nvidia:sm_89"], &model, &[("BRDFPROF_CACHE_DIR", &cache)]).ok();
    assert!(again.stderr.contains(said), "{}", again.stderr);
    let scene = dir.path().join("scene.json");
    let m = model.to_str().unwrap();
    std::fs::write(
        &scene,
        format!(
            r#"{{"name": "smod", "gbuffer": {{"procedural": {{"kind": "sphere-grid", "size": [64, 32], "rows": ["a"], "columns": 2, "floor": "a"}}}},
  "lights": [{{"type": "directional", "direction": [0.45, -0.55, -0.7], "colour": [1, 1, 1], "intensity": 3}}],
  "materials": [{{"name": "a", "model": "{m}", "base_colour": [0.5, 0.5, 0.5], "metallic": 0, "roughness": 0.5}}]}}"#
        ),
    )
    .unwrap();
    let s = run(&[
        "profile",
        "--scene",
        scene.to_str().unwrap(),
        "--cost-device",
        "nvidia:sm_89",
        "--budget",
        "2",
        "--json",
        dir.path().join("s.json").to_str().unwrap(),
    ])
    .ok();
    assert!(s.stderr.contains("smod (eval kernel)") && s.stderr.contains(said), "{}", s.stderr);
    // eval on OpenCL runs the Vulkan kernel too and says where the two executions part (-7 % 3 at line 2).
    let csv = dir.path().join("neg.csv");
    std::fs::write(
        &csv,
        "nx,ny,nz,vx,vy,vz,lx,ly,lz\n0,0,1,0.3,0.2,0.93,0.0,-0.3,0.95\n0,0,1,0.3,0.2,0.93,0.9,0.0,0.43\n",
    )
    .unwrap();
    let e = run(&[
        "eval",
        "--model",
        m,
        "--device",
        "opencl",
        "--input",
        csv.to_str().unwrap(),
        "--output",
        dir.path().join("o.csv").to_str().unwrap(),
    ])
    .ok();
    assert!(
        e.stderr.contains("1 of 2 rows differ between")
            && e.stderr.contains("first: line 2")
            && e.stderr.contains("which lavapipe computes as srem"),
        "{}",
        e.stderr
    );
}

fn script(path: &Path, text: &str) {
    std::fs::write(path, text).unwrap();
    std::fs::set_permissions(path, std::fs::Permissions::from_mode(0o755)).unwrap();
}

/// The NVIDIA install with the real NVRTC and `fake` as nvdisasm (it answers --version with a build line of
/// its own, so no listing of the real one is taken from the cache).
fn nvidia_with(dir: &Path, fake: &str) -> PathBuf {
    let real = Path::new(env!("CARGO_MANIFEST_DIR")).join(".tools/nvidia/nvidia/cu13");
    let root = dir.join("nv");
    std::fs::create_dir_all(root.join("nvidia/cu13/bin")).unwrap();
    std::os::unix::fs::symlink(real.join("lib"), root.join("nvidia/cu13/lib")).unwrap();
    let nvdisasm = real.join("bin/nvdisasm");
    script(
        &root.join("nvidia/cu13/bin/nvdisasm"),
        &format!(
            "#!/bin/sh\nif [ \"$1\" = --version ]; then echo 'Build fake_nvdisasm'; exit 0; fi\nREAL={}\n{fake}\n",
            nvdisasm.display()
        ),
    );
    root
}

/// A disassembler whose listing is not the kernel's (nothing, one EXIT,
/// a cut listing, endless output) is refused with exit 2 naming it.
#[test]
fn a_disassembler_listing_that_is_not_the_kernel_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let model = brdf(dir.path(), "plain", "    return vec3(dot(N, L) * 0.1);");
    for (case, fake, said) in [
        ("empty", "exit 0", "its listing of the cubin is not the kernel's code (no EXIT in 0 instruction lines)"),
        (
            "one",
            "echo '        /*0000*/                   EXIT ;'",
            "1 instructions listed up to byte 16, where the code section holds",
        ),
        ("cut", "\"$REAL\" \"$@\" | head -n 40", "its listing of the cubin is not the kernel's code"),
        ("endless", "yes '        /*0000*/                   EXIT ;'", "the tool printed more than 256 MiB"),
    ] {
        let d = dir.path().join(case);
        std::fs::create_dir(&d).unwrap();
        let nv = nvidia_with(&d, fake);
        let r = inspect(
            &d,
            &["nvidia:sm_89"],
            &model,
            &[("BRDFPROF_NVIDIA_DIR", &nv), ("BRDFPROF_CACHE_DIR", &d.join("cache"))],
        );
        let r = r.fails(2, said);
        assert!(r.stderr.contains("nvdisasm"), "{case}: {}", r.stderr);
        assert!(!d.join("i.json").exists(), "{case}");
    }
}

/// A sleeping nvdisasm --version stops at the compile limit (it ran outside the launcher before).
#[test]
fn a_version_query_that_hangs_stops_at_the_compile_limit() {
    let dir = tempfile::tempdir().unwrap();
    let model = brdf(dir.path(), "plain", "    return vec3(dot(N, L) * 0.1);");
    let nv = nvidia_with(dir.path(), "");
    script(&nv.join("nvidia/cu13/bin/nvdisasm"), "#!/bin/sh\nsleep 60\n");
    let started = std::time::Instant::now();
    let out = common::brdfprof()
        .args([
            "inspect",
            "--no-callgrind",
            "--compile-timeout",
            "2",
            "--device",
            "nvidia:sm_89",
            "--model",
            model.to_str().unwrap(),
            "--json",
            "i.json",
            "--markdown",
            "i.md",
        ])
        .current_dir(dir.path())
        .env("BRDFPROF_NVIDIA_DIR", &nv)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{stderr}");
    assert!(stderr.contains("--version: the compilation took longer than the compile limit of 2 s"), "{stderr}");
    assert!(started.elapsed() < std::time::Duration::from_secs(30));
}

/// An ocloc that writes nothing, or whose listing is cut, is named.
#[test]
fn an_ocloc_that_writes_nothing_or_a_cut_listing_is_named() {
    let dir = tempfile::tempdir().unwrap();
    let model = brdf(dir.path(), "plain", "    return vec3(dot(N, L) * 0.1);");
    for (case, fake, said) in [
        (
            "silent",
            "#!/bin/sh\nif [ \"$1\" = query ]; then exec ocloc \"$@\"; fi\nexit 0\n",
            "`ocloc compile` for tgllp exited 0 but wrote no device binary",
        ),
        (
            "cut",
            "#!/bin/sh\nocloc \"$@\" || exit $?\nif [ \"$1\" = disasm ]; then d=$(echo \"$@\" | sed 's/.*-dump //'); head -n 3 \"$d/brdfprof_kernel_KernelHeap.asm\" > \"$d/x\"; mv \"$d/x\" \"$d/brdfprof_kernel_KernelHeap.asm\"; fi\n",
            "ocloc disasm's listing is not the kernel's code",
        ),
    ] {
        let d = dir.path().join(case);
        std::fs::create_dir(&d).unwrap();
        let fake_path = d.join("ocloc");
        script(&fake_path, fake);
        let r = inspect(
            &d,
            &["intel:gen12lp"],
            &model,
            &[("BRDFPROF_OCLOC", &fake_path), ("BRDFPROF_CACHE_DIR", &d.join("cache"))],
        );
        r.fails(2, said);
    }
    // A directory named as ocloc is called one.
    let r = inspect(dir.path(), &["intel:gen12lp"], &model, &[("BRDFPROF_OCLOC", dir.path())]);
    r.fails(2, "is a directory, not the ocloc executable");
}

/// NaN on both sides is not "within tolerance", and an input without rows is refused.
#[test]
fn diff_claims_no_tolerance_for_nan_and_refuses_an_empty_input() {
    let dir = tempfile::tempdir().unwrap();
    let model = brdf(dir.path(), "nan", "    return vec3(sqrt(-1.0 - abs(L.x)));");
    let m = model.to_str().unwrap();
    let r = run(&[
        "diff",
        "--model",
        m,
        "--model",
        m,
        "--samples",
        "50",
        "--tolerance",
        "0",
        "--json",
        dir.path().join("d.json").to_str().unwrap(),
    ]);
    assert_eq!(r.code, Some(1), "{}", r.stderr);
    assert!(r.stdout.contains("NOT within --tolerance 0: 150 values are NaN on both sides"), "{}", r.stdout);
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("d.json")).unwrap()).unwrap();
    assert_eq!(json["within_tolerance"], false);
    let empty = dir.path().join("empty.csv");
    std::fs::write(&empty, "nx,ny,nz,vx,vy,vz,lx,ly,lz,roughness,f0r,f0g,f0b\n").unwrap();
    run(&["diff", "--model", "ggx", "--model", "blinn", "--input", empty.to_str().unwrap()])
        .fails(2, "the file has a header but no rows");
}

/// Every saved report names its kind; a scene profile is refused by --html and by `report` by name.
#[test]
fn saved_reports_name_their_kind_and_scene_profiles_are_refused_by_the_html_report() {
    let dir = tempfile::tempdir().unwrap();
    let scene = Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/sphere-grid.json");
    let json = dir.path().join("scene.json");
    run(&["profile", "--scene", scene.to_str().unwrap(), "--html", dir.path().join("s.html").to_str().unwrap()])
        .fails(2, "the HTML report does not draw scene profiles");
    assert!(!dir.path().join("s.html").exists());
    run(&["profile", "--scene", scene.to_str().unwrap(), "--budget", "2", "--json", json.to_str().unwrap()]).ok();
    let saved: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    assert_eq!(saved["kind"], "scene-profile");
    run(&["report", json.to_str().unwrap(), "--out", dir.path().join("r.html").to_str().unwrap()])
        .fails(2, "a `scene-profile` report, which the HTML report does not draw");
    let profile = dir.path().join("p.json");
    run(&["profile", "--model", "ggx", "--size", "64x64", "--budget", "2", "--json", profile.to_str().unwrap()]).ok();
    let saved: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&profile).unwrap()).unwrap();
    assert_eq!(saved["kind"], "profile");
    run(&["report", profile.to_str().unwrap(), "--out", dir.path().join("p.html").to_str().unwrap()]).ok();
}

/// Defines that would rewrite BRDF's signature or continue a line, a report
/// given twice, a device as a report, and a constant BRDF's net cost (not above zero), each named.
#[test]
fn minor_refusals_and_notes_name_their_cause() {
    let dir = tempfile::tempdir().unwrap();
    let model = brdf(dir.path(), "flat", "    return vec3(0.5);");
    let m = model.to_str().unwrap();
    let csv = inputs(dir.path());
    let out = dir.path().join("o.csv");
    let eval = |define: &str| {
        run(&[
            "eval",
            "--model",
            m,
            "--define",
            define,
            "--input",
            csv.to_str().unwrap(),
            "--output",
            out.to_str().unwrap(),
        ])
    };
    eval("L=1").fails(2, "`L` is a name of the entry `vec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y)`");
    eval("Q=1\\").fails(2, "the value ends with a backslash");
    run(&["report", "/dev/zero", "--out", dir.path().join("z.html").to_str().unwrap()]).fails(2, "not a regular file");
    let r = inspect(dir.path(), &["nvidia:sm_89"], &model, &[]).ok();
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.path().join("i.json")).unwrap()).unwrap();
    assert_eq!(json["kind"], "inspect");
    // A constant BRDF cannot drop the loads the memory-only kernel keeps (glsl/shade.glsl's keep_inputs): it
    // nets at or just above zero, far below ggx.
    let net = |m: &str| {
        json["cost"]["rows"].as_array().unwrap().iter().find(|r| r["model"] == m).unwrap()["net_cycles_per_eval"]
            .as_f64()
            .unwrap()
    };
    assert!(
        (0.0..0.05 * net("ggx")).contains(&net("flat")),
        "{} against ggx {}\n{}",
        net("flat"),
        net("ggx"),
        r.stderr
    );
    let i = dir.path().join("i.json");
    let copy = dir.path().join("copy.json");
    std::fs::copy(&i, &copy).unwrap();
    run(&["report", i.to_str().unwrap(), copy.to_str().unwrap(), "--out", dir.path().join("r.html").to_str().unwrap()])
        .fails(2, "is the same report as");
    // A file's parameters left at their values are compiled in, and the report says so.
    let tinted = dir.path().join("tinted.brdf");
    std::fs::write(&tinted, "analytic\n::begin parameters\nfloat gain 0 2 0.7\n::end parameters\n::begin shader\nvec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y) { return vec3(gain * dot(N, L)); }\n::end shader\n").unwrap();
    let r = inspect(dir.path(), &["nvidia:sm_89"], &tinted, &[]).ok();
    let said = "parameters compiled in as constants, so the figures are for these values (the compiler may fold them): gain=0.7";
    assert!(
        r.stderr.contains(said) && std::fs::read_to_string(dir.path().join("i.md")).unwrap().contains(said),
        "{}",
        r.stderr
    );
}

/// Matrix operations as engine code applies a tangent frame translate, and agree with Vulkan.
#[test]
fn matrix_operations_translate_and_agree_with_vulkan() {
    let dir = tempfile::tempdir().unwrap();
    let model = brdf(
        dir.path(),
        "frame",
        "    mat3 tbn = mat3(X, Y, N);\n    vec3 l = transpose(tbn) * L;\n    mat3 m2 = tbn * tbn;\n    mat3 m3 = m2 * 0.5 + tbn;\n    mat3 m4 = m3 - outerProduct(L, V);\n    return abs(vec3(l.z, m4[1][1], (V * m4).x)) * 0.3;",
    );
    let csv = inputs(dir.path());
    let values = |text: String| -> Vec<f64> {
        text.lines().skip(1).flat_map(|l| l.split(',').map(|v| v.parse::<f64>().unwrap()).collect::<Vec<_>>()).collect()
    };
    let (vulkan, opencl) = (
        values(eval_rows(dir.path(), &model, &csv, None)),
        values(eval_rows(dir.path(), &model, &csv, Some("opencl"))),
    );
    assert_eq!(vulkan.len(), opencl.len());
    for (a, b) in vulkan.iter().zip(&opencl) {
        assert!((a - b).abs() <= 1e-5 * a.abs().max(1e-3), "{vulkan:?} against {opencl:?}");
    }
    inspect(dir.path(), &["nvidia:sm_89", "intel:gen12lp"], &model, &[]).ok();
}

/// A .brdf model with `name=` is in the compile-only target's sweep table, by its label.
#[test]
fn sweep_cost_tables_hold_every_model_by_its_label() {
    let dir = tempfile::tempdir().unwrap();
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/brdf/blinn.brdf");
    let spec = format!("{},name=mine", file.display());
    let out = dir.path().join("sw");
    let r = run(&[
        "sweep",
        "--model",
        "ggx",
        "--model",
        &spec,
        "--cost-device",
        "radv:navi21",
        "--budget",
        "3",
        "--out",
        out.to_str().unwrap(),
    ])
    .ok();
    assert!(!r.stderr.contains("not compiled for"), "{}", r.stderr);
    let md = std::fs::read_to_string(out.join("sweep-llvmpipe-aco-navi21.md"))
        .or_else(|_| {
            let f = std::fs::read_dir(&out)
                .unwrap()
                .map(|e| e.unwrap().path())
                .find(|p| p.to_string_lossy().ends_with("-aco-navi21.md"))
                .unwrap();
            std::fs::read_to_string(f)
        })
        .unwrap();
    assert!(md.lines().any(|l| l.starts_with("| mine ")) && md.lines().any(|l| l.starts_with("| ggx ")), "{md}");
}

/// A model that reads a struct field it never wrote (as kajiya's `BrdfValue::invalid()` leaves one): its f32 and
/// f64 translations differ by anything, which is the model's doing, not the translator's. `inspect` says so on
/// the targets that compile the translation, costs the other models there and the model itself where the SPIR-V
/// is compiled directly, writes every output, and exits 1.
#[test]
fn a_model_reading_an_unwritten_field_fails_alone_and_named_as_such() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    write_unwritten(d);
    let out = common::brdfprof()
        .args(["inspect", "--no-callgrind", "--model", "unwritten.brdf", "--model", "blinn"])
        .args(["--device", "nvidia:sm_89", "--device", "radv:navi21", "--json", "i.json", "--markdown", "i.md"])
        .current_dir(d)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("reads a value the model's code never wrote"), "{stderr}");
    assert!(!stderr.contains("translator defect"), "{stderr}");
    let json: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(d.join("i.json")).unwrap()).unwrap();
    let cost = |target: &str| {
        json["reports"].as_array().unwrap().iter().find(|r| r["cost"]["target"] == target).unwrap()["cost"].clone()
    };
    let models = |c: &serde_json::Value| -> Vec<String> {
        c["rows"].as_array().unwrap().iter().map(|r| r["model"].as_str().unwrap().to_string()).collect()
    };
    let nvidia = cost("nvidia:sm_89");
    assert_eq!(nvidia["failed"][0][0], "unwritten", "{nvidia}");
    assert!(models(&nvidia).contains(&"blinn".to_string()) && !models(&nvidia).contains(&"unwritten".to_string()));
    assert!(models(&cost("radv:navi21")).contains(&"unwritten".to_string()), "ACO compiles the SPIR-V itself");
    let md = std::fs::read_to_string(d.join("i.md")).unwrap();
    assert!(md.contains("**unwritten: failed, so no figure**"), "{md}");
}

/// A model that reads a struct field it never wrote (kajiya's `BrdfValue::invalid()` in brdfprof's own words).
fn write_unwritten(d: &std::path::Path) {
    std::fs::write(
        d.join("unwritten.brdf"),
        "analytic\n::begin shader\nstruct Value { vec3 value; float pdf; };\nValue invalid_value() { Value v; v.pdf = -1.0; return v; }\nvec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y) {\n    Value v = invalid_value();\n    if (dot(N, L) > 0.5) { v.value = vec3(dot(N, L)); }\n    return v.value;\n}\n::end shader\n",
    )
    .unwrap();
}

/// `check` on a target where one model fails its translation's check: the other model is measured and saved,
/// the failed one is named with its reason in the report and as a SARIF result at its file, and the gate fails
/// (exit 1) rather than passing over a model it could not measure.
#[test]
fn check_fails_naming_a_model_it_could_not_measure() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    write_unwritten(d);
    let out = common::brdfprof()
        .args(["check", "--device", "nvidia:sm_89", "--model", "unwritten.brdf", "--model", "blinn"])
        .args(["--save-baseline", "b.json", "--sarif", "s.sarif"])
        .current_dir(d)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(1), "{stdout}\n{}", String::from_utf8_lossy(&out.stderr));
    let section = &stdout[stdout.find("## Models with no figures").expect("the report names the failed model")..];
    assert!(section.contains("unwritten on nvidia:sm_89") && section.contains("never wrote"), "{section}");
    let baseline: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(d.join("b.json")).unwrap()).unwrap();
    let rows = baseline["inspect"]["cost"]["rows"].as_array().unwrap();
    assert!(rows.iter().any(|r| r["model"] == "blinn"), "the other model is measured: {rows:?}");
    let sarif: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(d.join("s.sarif")).unwrap()).unwrap();
    let results = sarif["runs"][0]["results"].as_array().unwrap();
    let failed = results.iter().find(|r| r["ruleId"] == "brdfprof/model-failed").expect("a SARIF result for it");
    let uri = failed["locations"][0]["physicalLocation"]["artifactLocation"]["uri"].as_str().unwrap();
    assert!(uri.ends_with("unwritten.brdf"), "{failed}");
}
