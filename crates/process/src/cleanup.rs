//! brdfprof leaves nothing behind when it stops, however it stops. Child processes (valgrind, glslang,
//! spirv-opt) die with it: on Linux they are spawned with PR_SET_PDEATHSIG = SIGKILL, which holds even when
//! brdfprof itself is killed. Temporary files and directories are registered here while they exist; on
//! SIGINT, SIGTERM or SIGHUP a handler (on its own thread, via `ctrlc`) kills the registered children, removes
//! the registered paths and exits with status 130. Other exit paths (success, errors, panics) drop the guards,
//! which remove their paths as usual.

use anyhow::{Context, Result};
use std::path::{Path, PathBuf};
use std::process::{Child, Command};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Mutex, MutexGuard};
use std::time::{Duration, Instant};

/// Exit status after SIGINT/SIGTERM/SIGHUP (128 + SIGINT, as shells report an interrupted command).
pub const INTERRUPTED_EXIT: i32 = 130;

struct Registry {
    children: Vec<u32>,
    paths: Vec<PathBuf>,
    /// Directories created for staged outputs, outermost first: removed when empty.
    created_dirs: Vec<PathBuf>,
}

static REGISTRY: Mutex<Registry> =
    Mutex::new(Registry { children: Vec::new(), paths: Vec::new(), created_dirs: Vec::new() });
static INTERRUPTED: AtomicBool = AtomicBool::new(false);

/// The registry, even if a panicking thread poisoned it (it holds plain lists; nothing is half-updated).
fn registry() -> MutexGuard<'static, Registry> {
    REGISTRY.lock().unwrap_or_else(|e| e.into_inner())
}

/// Installs the SIGINT/SIGTERM/SIGHUP handler (once, from `main`).
pub fn install_signal_handler() -> Result<()> {
    ctrlc::set_handler(on_signal).context("cannot install the SIGINT/SIGTERM handler")
}

/// Whether a signal asked brdfprof to stop.
pub fn interrupted() -> bool {
    INTERRUPTED.load(Ordering::SeqCst)
}

/// Once a signal has arrived, the thread that calls this waits for the handler to exit the process, so that
/// an interrupted command neither writes an output nor exits with its own status in the meantime.
pub fn park_if_interrupted() {
    while interrupted() {
        std::thread::park_timeout(Duration::from_secs(1));
    }
}

fn on_signal() {
    stop(INTERRUPTED_EXIT, "brdfprof: interrupted");
}

/// Held while staged outputs are renamed into place (`committing`): `stop` waits for it, so a command that
/// stops leaves all of its outputs or none.
static COMMIT: Mutex<()> = Mutex::new(());

/// Runs `f` (the renames that publish a command's outputs) so that no `stop` cuts it short.
pub fn committing<T>(f: impl FnOnce() -> T) -> T {
    let _lock = COMMIT.lock().unwrap_or_else(|e| e.into_inner());
    f()
}

/// Ends the process now with `code`: kills the registered children, removes the registered paths (staged
/// outputs and temporaries, then the directories created for outputs, where empty) and prints `message`
/// with what was cleaned up. For a signal, and for work that cannot be stopped otherwise (a driver call past
/// the compile limit, a fence that never signals). A second caller waits for the first to end the process.
pub fn stop(code: i32, message: &str) -> ! {
    if INTERRUPTED.swap(true, Ordering::SeqCst) {
        loop {
            std::thread::park();
        }
    }
    let _commit = COMMIT.lock().unwrap_or_else(|e| e.into_inner());
    let (children, paths, dirs) = {
        let r = registry();
        (r.children.clone(), r.paths.clone(), r.created_dirs.clone())
    };
    for pid in &children {
        kill_and_reap(*pid);
    }
    // After the children: none of them can write into a directory once it is gone.
    for p in &paths {
        remove(p);
    }
    for d in dirs.iter().rev() {
        let _ = std::fs::remove_dir(d);
    }
    crate::messages::line(&format!(
        "{message}; stopped {} child process(es) and removed {} temporary path(s)",
        children.len(),
        paths.len()
    ));
    // _exit, not exit: other threads may be inside the Vulkan driver, whose exit-time teardown must not run
    // under them. Nothing buffered is lost that matters for a stopped run.
    // SAFETY: _exit ends the process at once; it has no preconditions.
    unsafe { libc::_exit(code) }
}

/// SIGKILL, then wait up to 2 s for it to be gone (so it writes nothing after the cleanup).
fn kill_and_reap(pid: u32) {
    let Ok(pid) = libc::pid_t::try_from(pid) else { return };
    // SAFETY: plain system calls on a pid this process spawned and has not yet reaped (the guard is dropped
    // only after `wait`); a pid already reaped by the waiting thread makes waitpid return -1 (ECHILD).
    kill_group(pid as u32);
    // SAFETY: as in `kill_group`.
    unsafe {
        let start = Instant::now();
        while start.elapsed() < Duration::from_secs(2) {
            if libc::waitpid(pid, std::ptr::null_mut(), libc::WNOHANG) != 0 {
                return;
            }
            std::thread::sleep(Duration::from_millis(10));
        }
    }
}

fn remove(p: &Path) {
    match std::fs::symlink_metadata(p) {
        Ok(m) if m.is_dir() => drop(std::fs::remove_dir_all(p)),
        Ok(_) => drop(std::fs::remove_file(p)),
        Err(_) => {}
    }
}

/// A path removed by the signal handler while this guard lives (the owner removes it otherwise).
pub struct PathGuard(PathBuf);

impl PathGuard {
    pub fn new(path: &Path) -> PathGuard {
        registry().paths.push(path.to_path_buf());
        PathGuard(path.to_path_buf())
    }
}

impl Drop for PathGuard {
    fn drop(&mut self) {
        let mut r = registry();
        if let Some(i) = r.paths.iter().position(|p| *p == self.0) {
            r.paths.swap_remove(i);
        }
    }
}

/// Directories created for a command's outputs (outermost first), removed by `stop` where they are empty,
/// until `forget_created_dirs`.
pub fn register_created_dirs(dirs: &[PathBuf]) {
    registry().created_dirs.extend(dirs.iter().cloned());
}

/// The directories registered by `register_created_dirs`, no longer registered.
pub fn forget_created_dirs() -> Vec<PathBuf> {
    std::mem::take(&mut registry().created_dirs)
}

/// A temporary directory (under TMPDIR), removed when dropped and by the signal handler.
pub struct TempDir {
    // Field order: the registration goes first, then the directory is removed.
    _guard: PathGuard,
    dir: tempfile::TempDir,
}

impl TempDir {
    pub fn new() -> std::io::Result<TempDir> {
        let dir = tempfile::Builder::new().prefix("brdfprof-").tempdir()?;
        Ok(TempDir { _guard: PathGuard::new(dir.path()), dir })
    }

    pub fn path(&self) -> &Path {
        self.dir.path()
    }
}

/// A spawned child the signal handler kills while this guard lives; drop it only after the child is reaped.
pub struct ChildGuard(u32);

impl ChildGuard {
    pub fn new(child: &Child) -> ChildGuard {
        registry().children.push(child.id());
        ChildGuard(child.id())
    }
}

impl Drop for ChildGuard {
    fn drop(&mut self) {
        let mut r = registry();
        if let Some(i) = r.children.iter().position(|p| *p == self.0) {
            r.children.swap_remove(i);
        }
    }
}

/// `Command::new(program)` whose child dies with brdfprof. PR_SET_PDEATHSIG fires when the spawning thread
/// ends, so spawn from the thread that waits for the child (as every caller here does). In brdfprof itself
/// the child leads a process group of its own, which `kill_group` kills whole: what a tool starts (cc1plus
/// and as under g++, ocloc's children, a brdfprof child's own tools) goes with it. In a brdfprof child
/// process the tools stay in the child's group, so that killing the child's group reaches them too.
pub fn command(program: &str) -> Command {
    let mut cmd = Command::new(program);
    die_with_parent(&mut cmd);
    if !crate::messages::is_child_process() {
        std::os::unix::process::CommandExt::process_group(&mut cmd, 0);
    }
    cmd
}

/// SIGKILL to `pid`'s process group (which `command` made it lead) and to `pid` itself, whose group it may
/// not lead (a command built without `command`).
pub fn kill_group(pid: u32) {
    let Ok(pid) = libc::pid_t::try_from(pid) else { return };
    // SAFETY: plain system calls on a pid this process spawned and has not yet reaped; a group already gone
    // makes kill return -1 (ESRCH).
    unsafe {
        if libc::getpgid(pid) == pid {
            libc::kill(-pid, libc::SIGKILL);
        }
        libc::kill(pid, libc::SIGKILL);
    }
}

#[cfg(target_os = "linux")]
fn die_with_parent(cmd: &mut Command) {
    use std::os::unix::process::CommandExt;
    // SAFETY: getpid() is async-signal-safe; it runs before the fork.
    let parent = unsafe { libc::getpid() };
    // SAFETY: the closure runs between fork and exec and calls only async-signal-safe functions (prctl,
    // getppid), allocating nothing.
    unsafe {
        cmd.pre_exec(move || {
            if libc::prctl(libc::PR_SET_PDEATHSIG, libc::SIGKILL) == -1 {
                return Err(std::io::Error::last_os_error());
            }
            // The parent may have died before prctl took effect: then no signal would come.
            if libc::getppid() != parent {
                return Err(std::io::Error::other("brdfprof exited before its child started"));
            }
            Ok(())
        });
    }
}

#[cfg(not(target_os = "linux"))]
fn die_with_parent(_cmd: &mut Command) {}

/// Gives `cmd` a TMPDIR of its own, inside a directory of this process that is removed when the guard is
/// dropped (after the child is reaped) and by the signal handler: what a child leaves there when it is
/// killed (it cannot clean up after SIGKILL) goes with it.
pub fn child_tmpdir(cmd: &mut Command) -> Result<TempDir> {
    let dir = TempDir::new().context("cannot create a temporary directory for a child process")?;
    cmd.env("TMPDIR", dir.path());
    Ok(dir)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn guards_register_while_they_live() {
        let dir = TempDir::new().unwrap();
        let path = dir.path().to_path_buf();
        assert!(registry().paths.contains(&path));
        drop(dir);
        assert!(!registry().paths.contains(&path) && !path.exists());
        let out = command("sh").args(["-c", "echo $PPID"]).output().unwrap();
        assert_eq!(String::from_utf8_lossy(&out.stdout).trim(), std::process::id().to_string());
    }
}
