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

    /// Registers `path`, then runs `create` (which makes it) with the registry held: `stop` takes the
    /// registry only after it marks the process stopping, so a path is either made before `stop` looks (and
    /// removed by it) or not made at all (the caller waits for the process to end), never made after the
    /// cleanup (a worker thread's temporary directory created while the signal handler ran).
    pub fn create<T>(path: &Path, create: impl FnOnce() -> std::io::Result<T>) -> std::io::Result<(PathGuard, T)> {
        let mut r = registry();
        if interrupted() {
            // The process is ending (`stop` exits it); nothing more is made.
            drop(r);
            loop {
                std::thread::park();
            }
        }
        r.paths.push(path.to_path_buf());
        match create() {
            Ok(made) => Ok((PathGuard(path.to_path_buf()), made)),
            Err(e) => {
                r.paths.retain(|p| p != path);
                Err(e)
            }
        }
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

/// A temporary directory (under TMPDIR), removed when dropped and by the signal handler; registered before it
/// is created (`PathGuard::create`).
pub struct TempDir {
    path: PathBuf,
    _guard: PathGuard,
}

impl TempDir {
    pub fn new() -> std::io::Result<TempDir> {
        use std::hash::{BuildHasher, Hasher};
        static COUNT: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
        let parent = std::env::temp_dir();
        loop {
            let mut h = std::collections::hash_map::RandomState::new().build_hasher();
            h.write_u64(COUNT.fetch_add(1, Ordering::SeqCst));
            h.write_u32(std::process::id());
            let path = parent.join(format!("brdfprof-{:016x}", h.finish()));
            match PathGuard::create(&path, || std::fs::create_dir(&path)) {
                Ok((guard, ())) => return Ok(TempDir { path, _guard: guard }),
                Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => continue,
                Err(e) => return Err(e),
            }
        }
    }

    pub fn path(&self) -> &Path {
        &self.path
    }
}

impl Drop for TempDir {
    fn drop(&mut self) {
        // Removed while still registered; the guard unregisters it after.
        let _ = std::fs::remove_dir_all(&self.path);
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
/// and as under g++, ocloc's children, a brdfprof child's own tools) goes with it, and a sentinel in that
/// group kills the rest of it once the tool is gone, so that what it started dies with it even where brdfprof
/// was killed (SIGKILL: no handler runs, and the death signal reaches only the tool itself). In a brdfprof
/// child process the tools stay in the child's group, so that killing the child's group reaches them too.
pub fn command(program: &str) -> Command {
    let mut cmd = Command::new(program);
    let leads = !crate::messages::is_child_process();
    die_with_parent(&mut cmd, leads);
    if leads {
        std::os::unix::process::CommandExt::process_group(&mut cmd, 0);
    }
    cmd
}

/// brdfprof's own executable, for the children it starts of itself (`__noop-child`, `__callgrind-child`,
/// `__run-translation`, `__probe-vulkan`): this process' executable, or, in a test binary of the same build,
/// the `brdfprof` beside its `deps/` folder (cargo's layout).
pub fn own_executable() -> Result<PathBuf> {
    let own = std::env::current_exe().context("cannot find brdfprof's own executable")?;
    if own.file_stem().is_some_and(|s| s == "brdfprof") {
        return Ok(own);
    }
    match own.parent().and_then(Path::parent).map(|d| d.join("brdfprof")) {
        Some(sibling) if sibling.is_file() => Ok(sibling),
        _ => anyhow::bail!("cannot find the brdfprof executable to run a child of (looked beside {})", own.display()),
    }
}

/// brdfprof itself running the hidden command `subcommand`, as `command` makes every child: the one way
/// brdfprof starts itself.
pub fn self_command(subcommand: &str) -> Result<Command> {
    let mut cmd = command(&own_executable()?.to_string_lossy());
    cmd.arg(subcommand);
    Ok(cmd)
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
fn die_with_parent(cmd: &mut Command, leads_group: bool) {
    use std::os::unix::process::CommandExt;
    // SAFETY: getpid() is async-signal-safe; it runs before the fork.
    let parent = unsafe { libc::getpid() };
    // SAFETY: the closure runs between fork and exec and calls only async-signal-safe functions (prctl,
    // getppid, getpid, fork, waitpid, and in the sentinel close, kill, nanosleep, _exit), allocating nothing.
    unsafe {
        cmd.pre_exec(move || {
            if libc::prctl(libc::PR_SET_PDEATHSIG, libc::SIGKILL) == -1 {
                return Err(std::io::Error::last_os_error());
            }
            // The parent may have died before prctl took effect: then no signal would come.
            if libc::getppid() != parent {
                return Err(std::io::Error::other("brdfprof exited before its child started"));
            }
            if leads_group {
                start_sentinel();
            }
            Ok(())
        });
    }
}

/// In a tool's process (between fork and exec, already its process group's leader): starts a sentinel, a
/// grandchild of the tool that no one waits for (its intermediate parent exits at once and the tool reaps it,
/// so the tool sees no child it did not start). The sentinel closes every descriptor (it holds no pipe of
/// brdfprof's open), then checks every 50 ms whether the tool is gone (exited and reaped, or killed with
/// brdfprof by its death signal) and then kills the tool's process group, itself included: whatever the tool
/// left running goes with it.
///
/// SAFETY: call only between fork and exec; it uses async-signal-safe calls only.
#[cfg(target_os = "linux")]
unsafe fn start_sentinel() {
    // SAFETY: as the function's contract says.
    unsafe {
        let tool = libc::getpid();
        let middle = libc::fork();
        if middle == 0 {
            if libc::fork() == 0 {
                if libc::syscall(libc::SYS_close_range, 0u32, u32::MAX, 0u32) != 0 {
                    for fd in 0..4096 {
                        libc::close(fd);
                    }
                }
                let pause = libc::timespec { tv_sec: 0, tv_nsec: 50_000_000 };
                // The tool's pid names its group as long as the group has a member (this one), so it is not
                // reused while this loop runs.
                while !(libc::kill(tool, 0) == -1 && *libc::__errno_location() == libc::ESRCH) {
                    libc::nanosleep(&pause, std::ptr::null_mut());
                }
                libc::kill(-tool, libc::SIGKILL);
                libc::_exit(0);
            }
            libc::_exit(0);
        }
        if middle > 0 {
            libc::waitpid(middle, std::ptr::null_mut(), 0);
        }
    }
}

#[cfg(not(target_os = "linux"))]
fn die_with_parent(_cmd: &mut Command, _leads_group: bool) {}

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

    /// What a tool starts dies with brdfprof even where brdfprof is killed: a stand-in for brdfprof (this test
    /// binary, run again as `sentinel_helper`) starts `sh`, which starts a `sleep` and waits; SIGKILL of the
    /// stand-in kills `sh` (its death signal), and the sentinel then kills the `sleep` it left.
    #[test]
    fn a_tools_own_children_die_when_brdfprof_is_killed() {
        use std::io::BufRead;
        let mut helper = Command::new(std::env::current_exe().unwrap())
            .args(["--exact", "cleanup::tests::sentinel_helper", "--nocapture", "--test-threads", "1"])
            .env("BRDFPROF_SENTINEL_HELPER", "1")
            .stdout(std::process::Stdio::piped())
            .spawn()
            .unwrap();
        let mut lines = std::io::BufReader::new(helper.stdout.take().unwrap()).lines();
        let sleep: i32 = loop {
            let line = lines.next().expect("the helper prints the grandchild's pid").unwrap();
            // libtest's own "test ... " may begin the line.
            if let Some((_, pid)) = line.split_once("grandchild ") {
                break pid.trim().parse().unwrap();
            }
        };
        // SAFETY: signals to processes this test started.
        let alive = |pid: i32| unsafe { libc::kill(pid, 0) == 0 };
        assert!(alive(sleep));
        helper.kill().unwrap();
        helper.wait().unwrap();
        let start = Instant::now();
        while alive(sleep) && start.elapsed() < Duration::from_secs(5) {
            std::thread::sleep(Duration::from_millis(20));
        }
        let zombie = std::fs::read_to_string(format!("/proc/{sleep}/stat")).is_ok_and(|s| s.contains(") Z "));
        assert!(!alive(sleep) || zombie, "the tool's child {sleep} outlived brdfprof");
    }

    #[test]
    fn sentinel_helper() {
        if std::env::var_os("BRDFPROF_SENTINEL_HELPER").is_none() {
            return;
        }
        let out = command("sh")
            .args(["-c", "sleep 60 & echo grandchild $!; wait"])
            .stdout(std::process::Stdio::inherit())
            .spawn()
            .unwrap();
        std::thread::sleep(Duration::from_secs(60));
        drop(out);
    }

    /// A tool that ends leaves its sentinel nothing to do but end too: no process of its group is left, and
    /// its output is read to the end at once (the sentinel holds no pipe).
    #[test]
    fn a_tool_that_ends_leaves_nothing_running() {
        let start = Instant::now();
        let out = command("sh").args(["-c", "echo $$"]).output().unwrap();
        assert!(start.elapsed() < Duration::from_secs(2));
        let group: i32 = String::from_utf8_lossy(&out.stdout).trim().parse().unwrap();
        let start = Instant::now();
        // SAFETY: a signal 0 probe of a process group this test started.
        while unsafe { libc::kill(-group, 0) } == 0 && start.elapsed() < Duration::from_secs(5) {
            std::thread::sleep(Duration::from_millis(20));
        }
        // SAFETY: as above.
        assert_ne!(unsafe { libc::kill(-group, 0) }, 0, "a process of the tool's group is still running");
    }

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

#[cfg(test)]
mod own_executable_tests {
    /// In this test binary (not brdfprof) the executable is the `brdfprof` beside `deps/` when the build made
    /// one, and otherwise an error that says where it looked.
    #[test]
    fn a_test_binary_finds_the_brdfprof_beside_its_deps_folder_or_says_where_it_looked() {
        let own = std::env::current_exe().unwrap();
        let sibling = own.parent().and_then(std::path::Path::parent).unwrap().join("brdfprof");
        match super::own_executable() {
            Ok(found) => assert_eq!(found, sibling),
            Err(e) => {
                assert!(!sibling.is_file());
                assert!(format!("{e:#}").contains("looked beside"), "{e:#}");
            }
        }
    }
}
