//! `--device` with an empty or blank value is an error on every command that opens a device (a blank name
//! is a substring of every device's name, so it would silently pick device 0).

use crate::common::{self, run_in};

#[test]
fn an_empty_or_blank_device_is_refused_by_every_gpu_command() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(
        d.join("in.csv"),
        "nx,ny,nz,vx,vy,vz,lx,ly,lz,roughness,f0r,f0g,f0b\n0,0,1,0,0.6,0.8,0.6,0,0.8,0.5,0.04,0.04,0.04\n",
    )
    .unwrap();
    let baseline = common::repo_root().join("results/baseline-llvmpipe.json");
    let scene = common::repo_root().join("scenes/sphere-grid.json");
    let (baseline, scene) = (baseline.to_str().unwrap(), scene.to_str().unwrap());
    let commands: [&[&str]; 8] = [
        &["eval", "--model", "ggx", "--input", "in.csv", "--output", "out.csv"],
        &["profile", "--model", "ggx", "--size", "8x8"],
        &["profile", "--scene", scene],
        &["sweep", "--model", "ggx", "--size", "8x8"],
        &["stability", "--model", "ggx"],
        &["inspect", "--model", "ggx", "--no-callgrind"],
        &["check", "--baseline", baseline, "--rounds", "0", "--no-callgrind"],
        &["render", "--scene", scene, "--out", "pictures"],
    ];
    for args in commands {
        for device in ["--device=", "--device= ", "--device=\t"] {
            let run = run_in(d, &[args, &[device]].concat())
                .fails(2, &format!("invalid value '{}' for '--device <DEVICE>': empty", &device[9..]));
            assert!(run.stdout.is_empty(), "{args:?} {device:?} printed: {}", run.stdout);
        }
    }
    assert_eq!(std::fs::read_dir(d).unwrap().count(), 1, "nothing but the input in the directory");
}

/// `RADV_FORCE_FAMILY=garbage` (or empty) in the user's environment makes RADV abort (134, "radv: Unknown
/// family"); it must not abort `devices` or `eval`. Any value of it, and of the other Mesa variables brdfprof
/// sets for its children, gives a working run (or exit 2 with a message), never a crash.
#[test]
fn mesa_variables_in_the_environment_cannot_crash_it() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(
        d.join("in.csv"),
        "nx,ny,nz,vx,vy,vz,lx,ly,lz,roughness,f0r,f0g,f0b\n0,0,1,0,0.6,0.8,0.6,0,0.8,0.5,0.04,0.04,0.04\n",
    )
    .unwrap();
    let run = |var: &str, value: &str, args: &[&str]| {
        let out = common::brdfprof().args(args).env(var, value).current_dir(d).output().unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
        assert!(matches!(out.status.code(), Some(0 | 2)), "{var}={value:?} {args:?}: {:?}\n{stderr}", out.status);
        (out.status.code(), stderr)
    };
    for value in ["garbage", "", " navi21", "-1"] {
        let (code, stderr) = run("RADV_FORCE_FAMILY", value, &["devices"]);
        assert_eq!(code, Some(0), "{stderr}");
        assert!(
            stderr.contains(&format!("warning: RADV_FORCE_FAMILY=`{value}` is not a GPU family Mesa's RADV knows")),
            "{stderr}"
        );
        let (code, stderr) =
            run("RADV_FORCE_FAMILY", value, &["eval", "--model", "ggx", "--input", "in.csv", "--output", "out.csv"]);
        assert_eq!(code, Some(0), "{stderr}");
    }
    // A family brdfprof lists is used as the user meant it (its null device listed, compiling only).
    let out = common::brdfprof().args(["devices"]).env("RADV_FORCE_FAMILY", "navi21").output().unwrap();
    assert!(
        out.status.success() && String::from_utf8_lossy(&out.stdout).contains("NAVI21"),
        "{}",
        String::from_utf8_lossy(&out.stdout)
    );
    for var in ["MESA_SHADER_CACHE_DISABLE", "LP_NUM_THREADS"] {
        for value in ["garbage", "", "-1", "99999999999"] {
            run(var, value, &["eval", "--model", "ggx", "--input", "in.csv", "--output", "out.csv"]);
        }
    }
}

/// `scripts/gpu-check.sh` (run by hand on a lent GPU machine; its whole run on lavapipe takes minutes, so the
/// test checks only what it refuses): a wrong mode and a `measure` with nothing prepared exit 2, saying why.
#[test]
fn gpu_check_refuses_a_wrong_mode_and_a_measure_before_prepare() {
    let script = common::repo_root().join("scripts/gpu-check.sh");
    let dir = tempfile::tempdir().unwrap();
    let run_script = |args: &[&str]| std::process::Command::new("sh").arg(&script).args(args).output().unwrap();
    let wrong = run_script(&["measur", dir.path().to_str().unwrap()]);
    assert_eq!(wrong.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&wrong.stderr).contains("usage: "), "{wrong:?}");
    let early = run_script(&["measure", dir.path().to_str().unwrap()]);
    assert_eq!(early.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&early.stderr).contains("gpu-check.sh prepare"), "{early:?}");
}

/// An installed binary finds its tools without its build checkout: beside it (`<prefix>/share/brdfprof/tools`,
/// `make install`) first, then in the per-user data directory (`make setup`, `make mesa`); `devices --targets`
/// says where each was found, and `--json -` gives it as JSON on stdout alone.
#[test]
fn an_installed_binary_finds_its_tools_beside_it_or_in_the_data_directory() {
    let dir = tempfile::tempdir().unwrap();
    let prefix = dir.path().join("prefix");
    std::fs::create_dir_all(prefix.join("bin")).unwrap();
    std::fs::create_dir_all(prefix.join("share/brdfprof/tools")).unwrap();
    std::fs::copy(env!("CARGO_BIN_EXE_brdfprof"), prefix.join("bin/brdfprof")).unwrap();
    let nvidia = brdfprof::tools::dir("nvidia");
    std::os::unix::fs::symlink(&nvidia, prefix.join("share/brdfprof/tools/nvidia")).unwrap();
    let data = dir.path().join("data");
    std::fs::create_dir_all(data.join("brdfprof/tools")).unwrap();
    std::os::unix::fs::symlink(brdfprof::tools::dir("slang"), data.join("brdfprof/tools/slang")).unwrap();
    let out = std::process::Command::new(prefix.join("bin/brdfprof"))
        .args(["devices", "--targets", "--json", "-"])
        .env("XDG_DATA_HOME", &data)
        .env_remove("BRDFPROF_NVIDIA_DIR")
        .env_remove("BRDFPROF_SLANG_DIR")
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let json: serde_json::Value = serde_json::from_slice(&out.stdout).expect("stdout holds the JSON alone");
    let tool = |name: &str| json["tools"].as_array().unwrap().iter().find(|t| t["tool"] == name).unwrap().clone();
    assert_eq!(tool("nvidia")["how"], "beside the binary (make install)", "{json}");
    assert_eq!(tool("slang")["how"], "the per-user data directory", "{json}");
    assert!(String::from_utf8_lossy(&out.stderr).contains("## Tools"), "the table goes to stderr");
    // It compiles with them: NVRTC from beside the binary.
    let out = std::process::Command::new(prefix.join("bin/brdfprof"))
        .args(["inspect", "--device", "nvidia:sm_89", "--model", "ggx", "--json", "-"])
        .env("XDG_DATA_HOME", &data)
        .env("BRDFPROF_VALIDATION", "1")
        .current_dir(dir.path())
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert!(report["cost"]["rows"].as_array().is_some_and(|r| !r.is_empty()), "{report}");
}

/// `brdfprof completions SHELL` prints a completion script; `models --json -` the term tables.
#[test]
fn completions_and_json_listings() {
    let r = common::run(&["completions", "bash"]).ok();
    assert!(
        r.stdout.contains("_brdfprof()") && r.stdout.contains("stability"),
        "{}",
        &r.stdout[..200.min(r.stdout.len())]
    );
    let r = common::run(&["models", "--json", "-"]).ok();
    let json: serde_json::Value = serde_json::from_str(&r.stdout).expect("stdout holds the JSON alone");
    assert!(json["vis"].as_array().unwrap().iter().any(|v| v["name"] == "schlick-ggx-karis"));
    assert!(r.stderr.contains("Presets"), "the tables go to stderr");
}

/// Each flag that takes a compile-only target says every prefix there is (`targets::VENDORS`, listed once).
#[test]
fn the_help_of_every_cost_device_flag_names_every_prefix() {
    let prefixes = brdfprof::targets::prefixes();
    for command in ["inspect", "profile", "sweep"] {
        let help = common::run(&[command, "--help"]).ok().stdout;
        for p in prefixes.split(", ") {
            assert!(help.contains(p), "`{command} --help` names no `{p}` target:\n{help}");
        }
    }
}
