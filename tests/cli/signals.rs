//! Nothing outlives an interrupted brdfprof: SIGINT or SIGTERM during the callgrind run of `inspect` or
//! `check` kills the valgrind child, removes the callgrind files (and what the child left in its temporary
//! directory) and exits with status 130, writing no report; SIGINT during `render` leaves none of its
//! pictures; SIGKILL, which no handler sees, still takes the child with it (PR_SET_PDEATHSIG). Runs that end
//! normally leave no temporary directory either.

use crate::common::{self, brdfprof};
use std::path::{Path, PathBuf};
use std::process::{Child, Stdio};
use std::time::{Duration, Instant};

/// A brdfprof run whose TMPDIR is a directory of its own, so its children and files can be told apart from
/// other runs on the machine.
struct Run {
    child: Child,
    tmp: tempfile::TempDir,
    cwd: tempfile::TempDir,
    stderr: PathBuf,
}

fn start(args: &[&str]) -> Run {
    let (tmp, cwd) = (tempfile::tempdir().unwrap(), tempfile::tempdir().unwrap());
    let stderr = cwd.path().join("stderr.txt");
    let child = brdfprof()
        .args(args)
        .current_dir(cwd.path())
        .env("TMPDIR", tmp.path())
        .env("BRDFPROF_CACHE_DIR", "")
        .stdout(Stdio::null())
        .stderr(std::fs::File::create(&stderr).unwrap())
        .spawn()
        .unwrap();
    Run { child, tmp, cwd, stderr }
}

/// Sends `signal` to the run and waits (at most 15 s) for its exit status.
fn stop(run: &mut Run, signal: libc::c_int) -> Option<i32> {
    // SAFETY: a signal to the process this test spawned, which it has not yet reaped.
    assert_eq!(unsafe { libc::kill(run.child.id() as libc::pid_t, signal) }, 0);
    let start = Instant::now();
    loop {
        if let Some(s) = run.child.try_wait().unwrap() {
            return s.code();
        }
        if start.elapsed() > Duration::from_secs(15) {
            let _ = run.child.kill();
            panic!("brdfprof still running 15 s after signal {signal}");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// Processes whose command line contains `__callgrind-child` and whose TMPDIR is in `tmp` (brdfprof gives each
/// child a directory of its own there; a zombie has neither).
fn callgrind_children(tmp: &Path) -> Vec<u32> {
    processes_under(tmp, "__callgrind-child")
}

/// Processes whose command line contains `needle` and whose TMPDIR is in `tmp`.
fn processes_under(tmp: &Path, needle: &str) -> Vec<u32> {
    let marker = format!("TMPDIR={}/", tmp.display());
    let mut pids = Vec::new();
    for entry in std::fs::read_dir("/proc").unwrap().flatten() {
        let Ok(pid) = entry.file_name().to_string_lossy().parse::<u32>() else { continue };
        let read = |f: &str| std::fs::read(entry.path().join(f)).unwrap_or_default();
        let has = |bytes: Vec<u8>, needle: &str| {
            bytes.split(|&b| b == 0).any(|s| String::from_utf8_lossy(s).contains(needle))
        };
        if has(read("cmdline"), needle) && read("environ").split(|&b| b == 0).any(|s| s.starts_with(marker.as_bytes()))
        {
            pids.push(pid);
        }
    }
    pids
}

/// Every file under `dir`, recursively.
fn files_under(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    for e in std::fs::read_dir(dir).into_iter().flatten().flatten() {
        let p = e.path();
        if p.is_dir() {
            out.push(p.clone());
            out.extend(files_under(&p));
        } else {
            out.push(p);
        }
    }
    out
}

fn wait_for(what: &str, limit: Duration, mut ready: impl FnMut() -> bool) {
    let start = Instant::now();
    while !ready() {
        assert!(start.elapsed() < limit, "no {what} after {limit:?}");
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// Starts `args`, waits until its valgrind child has written a first callgrind dump, sends `signal`, and
/// returns the run with its exit status.
fn interrupt(args: &[&str], signal: libc::c_int) -> (Run, Option<i32>) {
    let mut run = start(args);
    let tmp = run.tmp.path().to_path_buf();
    wait_for("valgrind child", Duration::from_secs(240), || !callgrind_children(&tmp).is_empty());
    // Mid-measurement: callgrind writes callgrind.out at its start, and a dump callgrind.out.N per kernel.
    let dumped = |p: &PathBuf| p.file_name().is_some_and(|n| n.to_string_lossy().starts_with("callgrind.out."));
    wait_for("first callgrind dump", Duration::from_secs(240), || files_under(&tmp).iter().any(dumped));
    let code = stop(&mut run, signal);
    wait_for("end of the valgrind child", Duration::from_secs(10), || callgrind_children(&tmp).is_empty());
    (run, code)
}

fn assert_cleaned_up(run: &Run, code: Option<i32>) {
    let stderr = std::fs::read_to_string(&run.stderr).unwrap();
    assert_eq!(code, Some(130), "exit status; stderr:\n{stderr}");
    assert!(stderr.contains("brdfprof: interrupted"), "{stderr}");
    let left = files_under(run.tmp.path());
    assert!(left.is_empty(), "left in TMPDIR: {left:?}");
    assert!(!run.cwd.path().join("results").exists(), "an interrupted run wrote reports");
}

/// Nothing is left behind: not a `.brdf` run's `$TMPDIR/brdfprof-XXXXXX` (its GLSL tree), not a killed child's
/// own, not the pictures an interrupted `render` has written so far. Here 20 evals, an interrupted render and
/// an interrupted callgrind run of a `.brdf` model (whose child composes its kernel in its own temporary
/// directory) leave nothing in TMPDIR and no picture.
#[test]
fn evals_and_interrupted_runs_leave_no_temporary_and_no_picture() {
    let dir = tempfile::tempdir().unwrap();
    let (d, tmp) = (dir.path(), dir.path().join("tmp"));
    std::fs::create_dir(&tmp).unwrap();
    std::fs::write(
        d.join("in.csv"),
        "nx,ny,nz,vx,vy,vz,lx,ly,lz,roughness,f0r,f0g,f0b\n0,0,1,0,0.6,0.8,0.6,0,0.8,0.5,0.04,0.04,0.04\n",
    )
    .unwrap();
    let ggx = common::repo_root().join("examples/brdf/ggx.brdf");
    let model = format!("{},roughness=@roughness,f0=@f0", ggx.display());
    for i in 0..20 {
        // Every other run compiles (the disk cache off), the others take the cached kernel.
        let cache = if i % 2 == 0 { String::new() } else { d.join("cache").display().to_string() };
        let out = brdfprof()
            .args(["eval", "--model", &model, "--input", "in.csv", "--output", "out.csv"])
            .env("TMPDIR", &tmp)
            .env("BRDFPROF_CACHE_DIR", cache)
            .current_dir(d)
            .output()
            .unwrap();
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    }
    assert!(files_under(&tmp).is_empty(), "left in TMPDIR after 20 evals: {:?}", files_under(&tmp));

    let scene = common::repo_root().join("scenes/statues.json");
    let mut render = start(&["render", "--scene", scene.to_str().unwrap(), "--out", "pictures"]);
    let pictures = render.cwd.path().join("pictures");
    // The first picture is being written (staged beside its name) when the signal comes.
    let staged = |p: &PathBuf| p.file_name().is_some_and(|n| n.to_string_lossy().ends_with(".tmp"));
    wait_for("a picture being written", Duration::from_secs(240), || files_under(&pictures).iter().any(staged));
    let code = stop(&mut render, libc::SIGINT);
    assert_eq!(code, Some(130), "{}", std::fs::read_to_string(&render.stderr).unwrap());
    let left: Vec<PathBuf> = files_under(&pictures);
    assert!(left.is_empty(), "an interrupted render left {left:?}");
    assert!(files_under(render.tmp.path()).is_empty(), "left in TMPDIR: {:?}", files_under(render.tmp.path()));

    let (run, code) = interrupt(&["inspect", "--model", &model], libc::SIGINT);
    assert_cleaned_up(&run, code);
}

#[test]
fn sigterm_during_check_kills_valgrind_and_removes_its_files() {
    let baseline = common::repo_root().join("results/baseline-llvmpipe.json");
    let (run, code) = interrupt(
        &["check", "--baseline", baseline.to_str().unwrap(), "--model", "ggx", "--rounds", "0"],
        libc::SIGTERM,
    );
    assert_cleaned_up(&run, code);
}

#[test]
fn sigkill_takes_the_valgrind_child_along() {
    let mut run = start(&["inspect", "--model", "ggx"]);
    let tmp = run.tmp.path().to_path_buf();
    wait_for("valgrind child", Duration::from_secs(240), || !callgrind_children(&tmp).is_empty());
    run.child.kill().unwrap();
    run.child.wait().unwrap();
    // No handler runs on SIGKILL, so files may remain (the TempDir removes them); the child must not.
    wait_for("end of the valgrind child", Duration::from_secs(10), || callgrind_children(&tmp).is_empty());
}

/// A tool's own children are killed with it: SIGTERM while g++ compiles the NVIDIA translation's host build
/// leaves no cc1plus behind (it ran on for seconds when only g++ itself was killed).
#[test]
fn sigterm_during_the_translation_check_kills_the_compilers_children() {
    let mut run = start(&["inspect", "--no-callgrind", "--device", "nvidia:sm_89", "--model", "ggx"]);
    let tmp = run.tmp.path().to_path_buf();
    wait_for("cc1plus under g++", Duration::from_secs(240), || !processes_under(&tmp, "cc1plus").is_empty());
    let code = stop(&mut run, libc::SIGTERM);
    let stderr = std::fs::read_to_string(&run.stderr).unwrap();
    assert_eq!(code, Some(130), "{stderr}");
    let left = processes_under(&tmp, "cc1plus");
    assert!(left.is_empty(), "cc1plus still running after brdfprof exited: {left:?}\n{stderr}");
    assert!(files_under(&tmp).is_empty(), "left in TMPDIR: {:?}", files_under(&tmp));
}
