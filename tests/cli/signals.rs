//! Nothing outlives an interrupted brdfprof: SIGINT or SIGTERM during the callgrind run of `inspect` or
//! `check` kills the valgrind child, removes the callgrind files and exits with status 130, writing no report;
//! SIGKILL, which no handler sees, still takes the child with it (PR_SET_PDEATHSIG).

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
        .stdout(Stdio::null())
        .stderr(std::fs::File::create(&stderr).unwrap())
        .spawn()
        .unwrap();
    Run { child, tmp, cwd, stderr }
}

/// Processes whose command line contains `__callgrind-child` and whose TMPDIR is `tmp` (a zombie has neither).
fn callgrind_children(tmp: &Path) -> Vec<u32> {
    let marker = format!("TMPDIR={}", tmp.display());
    let mut pids = Vec::new();
    for entry in std::fs::read_dir("/proc").unwrap().flatten() {
        let Ok(pid) = entry.file_name().to_string_lossy().parse::<u32>() else { continue };
        let read = |f: &str| std::fs::read(entry.path().join(f)).unwrap_or_default();
        let has = |bytes: Vec<u8>, needle: &str| bytes.split(|&b| b == 0).any(|s| String::from_utf8_lossy(s).contains(needle));
        if has(read("cmdline"), "__callgrind-child") && read("environ").split(|&b| b == 0).any(|s| s == marker.as_bytes()) {
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
    // SAFETY: a signal to the process this test spawned, which it has not yet reaped.
    assert_eq!(unsafe { libc::kill(run.child.id() as libc::pid_t, signal) }, 0);
    let start = Instant::now();
    let status = loop {
        if let Some(s) = run.child.try_wait().unwrap() {
            break s;
        }
        if start.elapsed() > Duration::from_secs(15) {
            let _ = run.child.kill();
            panic!("brdfprof still running 15 s after signal {signal}");
        }
        std::thread::sleep(Duration::from_millis(20));
    };
    wait_for("end of the valgrind child", Duration::from_secs(10), || callgrind_children(&tmp).is_empty());
    (run, status.code())
}

fn assert_cleaned_up(run: &Run, code: Option<i32>) {
    let stderr = std::fs::read_to_string(&run.stderr).unwrap();
    assert_eq!(code, Some(130), "exit status; stderr:\n{stderr}");
    assert!(stderr.contains("brdfprof: interrupted"), "{stderr}");
    let left = files_under(run.tmp.path());
    assert!(left.is_empty(), "left in TMPDIR: {left:?}");
    assert!(!run.cwd.path().join("results").exists(), "an interrupted run wrote reports");
}

#[test]
fn sigint_during_inspect_kills_valgrind_and_removes_its_files() {
    let (run, code) = interrupt(&["inspect", "--model", "ggx"], libc::SIGINT);
    assert_cleaned_up(&run, code);
}

#[test]
fn sigterm_during_check_kills_valgrind_and_removes_its_files() {
    let baseline = common::repo_root().join("results/baseline-llvmpipe.json");
    let (run, code) = interrupt(&["check", "--baseline", baseline.to_str().unwrap(), "--model", "ggx", "--rounds", "0"], libc::SIGTERM);
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
