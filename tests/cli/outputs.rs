//! Every output path is checked before anything is measured: a directory given as a file output, a file given
//! as an output directory, or a path under a file, fails at once with exit 2, naming the flag and the path,
//! and nothing is written.

use crate::common::{self, run_in};
use std::path::Path;
use std::time::{Duration, Instant};

const CSV: &str = "nx,ny,nz,vx,vy,vz,lx,ly,lz,roughness,f0r,f0g,f0b\n0,0,1,0,0.6,0.8,0.6,0,0.8,0.5,0.04,0.04,0.04\n";

/// Every file in `dir`, recursively, relative to it.
fn files(dir: &Path) -> Vec<String> {
    let mut out = Vec::new();
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            out.extend(files(&p).into_iter().map(|f| format!("{}/{f}", p.file_name().unwrap().to_string_lossy())));
        } else {
            out.push(p.file_name().unwrap().to_string_lossy().into_owned());
        }
    }
    out.sort();
    out
}

#[test]
fn profile_json_naming_a_directory_fails_before_measuring() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("reports")).unwrap();
    let start = Instant::now();
    // The default profile (1920x1080, the four thesis models) takes minutes here; the check takes none.
    run_in(dir.path(), &["profile", "--json", "reports"]).fails(2, "--json reports: is a directory; give a file path");
    assert!(start.elapsed() < Duration::from_secs(30), "took {:?}: measured first?", start.elapsed());
    assert!(files(dir.path()).is_empty());
}

#[test]
fn every_output_flag_is_checked_first() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("in.csv"), CSV).unwrap();
    std::fs::write(d.join("a-file"), "x").unwrap();
    std::fs::create_dir(d.join("a-dir")).unwrap();
    let baseline = common::repo_root().join("results/baseline-llvmpipe.json");
    let scene = common::repo_root().join("scenes/sphere-grid.json");
    let (baseline, scene) = (baseline.to_str().unwrap(), scene.to_str().unwrap());
    let eval = ["eval", "--model", "ggx", "--input", "in.csv"];
    let inspect = ["inspect", "--model", "ggx", "--no-callgrind"];
    let check = ["check", "--baseline", baseline, "--rounds", "0", "--no-callgrind"];
    let cases: Vec<(Vec<&str>, &str)> = vec![
        ([&eval[..], &["--output", "a-dir"]].concat(), "--output a-dir: is a directory"),
        ([&eval[..], &["--output", "a-file/out.csv"]].concat(), "--output a-file/out.csv: a-file is not a directory"),
        ([&eval[..], &["--output", "new/"]].concat(), "--output new/: names a directory"),
        (
            vec!["profile", "--model", "ggx", "--size", "8x8", "--json", "a-file/p.json"],
            "--json a-file/p.json: a-file is not a directory",
        ),
        (vec!["profile", "--scene", scene, "--json", "a-dir"], "--json a-dir: is a directory"),
        (
            vec!["sweep", "--model", "ggx", "--size", "8x8", "--out", "a-file"],
            "--out a-file: exists and is not a directory",
        ),
        (vec!["stability", "--model", "ggx", "--out", "a-file/sub"], "--out a-file/sub: a-file is not a directory"),
        ([&inspect[..], &["--json", "a-dir"]].concat(), "--json a-dir: is a directory"),
        ([&inspect[..], &["--json", "i.json", "--markdown", "a-dir"]].concat(), "--markdown a-dir: is a directory"),
        ([&check[..], &["--save-baseline", "a-dir"]].concat(), "--save-baseline a-dir: is a directory"),
        (vec!["render", "--scene", scene, "--out", "a-file"], "--out a-file: exists and is not a directory"),
    ];
    for (args, expected) in &cases {
        let start = Instant::now();
        run_in(d, args).fails(2, expected);
        assert!(start.elapsed() < Duration::from_secs(30), "{args:?} took {:?}", start.elapsed());
        assert_eq!(files(d), ["a-file", "in.csv"], "{args:?} wrote something");
    }
    // The defaults' directory is checked too: `results` is a file here.
    std::fs::write(d.join("results"), "x").unwrap();
    run_in(d, &inspect)
        .fails(2, "--json (default results/inspect-<device>.json) results: exists and is not a directory");
}

/// An output that is the input (by any path) is refused before anything runs: `eval --input X --output X`
/// silently replaced its input.
#[test]
fn an_output_that_is_an_input_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("in.csv"), CSV).unwrap();
    std::os::unix::fs::symlink("in.csv", d.join("link.csv")).unwrap();
    for out in ["in.csv", "./in.csv", "link.csv"] {
        run_in(d, &["eval", "--model", "ggx", "--input", "in.csv", "--output", out])
            .fails(2, &format!("--output {out}: is the same file as --input in.csv"));
        assert_eq!(std::fs::read_to_string(d.join("in.csv")).unwrap(), CSV, "the input is untouched");
    }
    let ggx = common::repo_root().join("examples/brdf/ggx.brdf");
    std::fs::copy(&ggx, d.join("m.brdf")).unwrap();
    run_in(d, &["eval", "--model", "m.brdf", "--input", "in.csv", "--output", "m.brdf"])
        .fails(2, "--output m.brdf: is the same file as --model m.brdf");
    assert_eq!(std::fs::read(d.join("m.brdf")).unwrap(), std::fs::read(&ggx).unwrap());
}

/// A command that fails after writing some of its outputs leaves none of them: every output is staged and
/// published only when the command succeeds. Here `compare` writes its JSON and Markdown, then cannot write its
/// chart (/dev/full).
#[test]
fn a_command_that_fails_midway_leaves_none_of_its_outputs() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let report = common::repo_root().join("results/radv/profile-llvmpipe.json");
    run_in(
        d,
        &[
            "compare",
            report.to_str().unwrap(),
            "--json",
            "out/c.json",
            "--markdown",
            "out/c.md",
            "--chart",
            "/dev/full",
        ],
    )
    .fails(2, "/dev/full");
    assert!(!d.join("out").exists(), "left: {:?}", files(d));
    run_in(
        d,
        &[
            "compare",
            report.to_str().unwrap(),
            "--json",
            "out/c.json",
            "--markdown",
            "out/c.md",
            "--chart",
            "out/c.png",
        ],
    )
    .ok();
    assert_eq!(files(d), ["out/c.json", "out/c.md", "out/c.png"]);
}

/// `git` in `dir`, which must succeed.
fn git(dir: &Path, args: &[&str]) {
    let s = std::process::Command::new("git")
        .args(["-c", "user.name=t", "-c", "user.email=t@t"])
        .args(args)
        .current_dir(dir)
        .output()
        .expect("git runs");
    assert!(s.status.success(), "git {args:?}: {}", String::from_utf8_lossy(&s.stderr));
}

#[test]
fn a_default_output_never_overwrites_a_file_git_tracks() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    git(d, &["init", "-q"]);
    std::fs::create_dir(d.join("results")).unwrap();
    for f in
        ["profile-somegpu.json", "sweep-somegpu.md", "stability-somegpu.json", "compare.json", "inspect-somegpu.md"]
    {
        std::fs::write(d.join("results").join(f), "committed\n").unwrap();
    }
    git(d, &["add", "results"]);
    git(d, &["commit", "-q", "-m", "results"]);
    for (args, flag, file) in [
        (&["profile", "--budget", "5"][..], "--json", "profile-somegpu.json"),
        (&["sweep", "--budget", "5"][..], "--out", "sweep-somegpu.md"),
        (&["stability"][..], "--out", "stability-somegpu.json"),
        (&["inspect", "--no-callgrind", "--json", "i.json"][..], "--markdown", "inspect-somegpu.md"),
        (&["compare", "a.json"][..], "--json", "compare.json"),
    ] {
        let r = run_in(d, args).fails(2, "a file git tracks");
        assert!(
            r.stderr.contains(flag)
                && r.stderr.contains(&format!("results/{file}"))
                && r.stderr.contains(&format!("{flag} PATH")),
            "{args:?}: {}",
            r.stderr
        );
    }
    for f in std::fs::read_dir(d.join("results")).unwrap() {
        assert_eq!(std::fs::read_to_string(f.unwrap().path()).unwrap(), "committed\n", "nothing overwritten");
    }
    assert!(!d.join("i.json").exists());
    // A compile-only target's default is its own name, so another device's tracked report
    // does not refuse it (inspect-somegpu.md is tracked; inspect-nvidia-sm_89.md is not).
    run_in(d, &["inspect", "--no-callgrind", "--device", "nvidia:sm_89", "--model", "ggx"]).ok();
    assert!(
        d.join("results/inspect-nvidia-sm_89.md").is_file() && d.join("results/inspect-nvidia-sm_89.json").is_file()
    );
    std::fs::remove_file(d.join("results/inspect-nvidia-sm_89.md")).unwrap();
    std::fs::remove_file(d.join("results/inspect-nvidia-sm_89.json")).unwrap();
    // Not tracked (outside any repository, or untracked in one): the defaults stand.
    assert!(brdfprof::io::tracked_by_git(&d.join("results"), "*").len() == 5);
    std::fs::write(d.join("results").join("profile-other.json"), "").unwrap();
    assert!(brdfprof::io::tracked_by_git(&d.join("results"), "profile-other.json").is_empty(), "an untracked file");
    let plain = tempfile::tempdir().unwrap();
    std::fs::write(plain.path().join("compare.json"), "").unwrap();
    assert!(
        brdfprof::io::tracked_by_git(plain.path(), "*").is_empty() || git_above(plain.path()),
        "outside a repository"
    );
}

/// Whether `dir` is inside some git repository (a temp dir under a checkout would be).
fn git_above(dir: &Path) -> bool {
    std::process::Command::new("git")
        .args(["rev-parse", "--git-dir"])
        .current_dir(dir)
        .output()
        .is_ok_and(|o| o.status.success())
}
