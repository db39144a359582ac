//! Every compilation runs under a time limit (`--compile-timeout SECONDS`, default `DEFAULT`; children get
//! it through `ENV`): glslang, spirv-opt, the driver's pipeline creation, lavapipe's first dispatch, the
//! compile-only child processes, and any compiler a target adds (NVRTC, ocloc: `output` for a compiler
//! process, `bounded` for a compiler library call). A compilation that takes longer than `PROGRESS_AFTER` says
//! on stderr what it is compiling; past the limit the command stops with exit status 2, naming what it was
//! compiling and the limit, its children killed, its temporary files removed and no output written (outputs
//! are staged until the command succeeds: `io::write_output`).
//!
//! Three places, because a process can be killed and a driver call cannot:
//! - `output` runs a compiler process (glslang, spirv-opt, a compile-only child) and kills it at the limit;
//!   the caller gets an error, and the command exits 2 with its staged outputs discarded.
//! - `bounded` runs a call that cannot be interrupted (vkCreateComputePipelines, a synchronous driver call in
//!   which RADV runs ACO, and NVRTC or ocloc when they are called in-process) on a worker thread and waits with
//!   a deadline. Past it, the call is still inside the driver, holding the device: nothing can be destroyed or
//!   returned safely (destroying the device under it is undefined, and exit-time teardown could crash), so the
//!   process reports, cleans up as on a signal (`cleanup::stop`: children killed, temporaries and staged
//!   outputs removed) and ends with `_exit(2)`.
//! - lavapipe compiles a pipeline with LLVM at its first dispatch, on its queue thread, not in
//!   vkCreateComputePipelines: a submission that holds a kernel's first dispatch is waited for under the limit
//!   (`Gpu::submit`, with this module's `Watch`), and past it stops the command as `bounded` does. That wait
//!   includes the dispatch's own run, seconds at most for brdfprof's largest first submissions.

use anyhow::{Result, anyhow, bail};
use std::process::{Command, Output, Stdio};
use std::sync::Mutex;
use std::time::{Duration, Instant};

/// The limit when neither `--compile-timeout` nor `ENV` sets one: 60 s, ten times the slowest compilation
/// brdfprof accepts on the 2-core VM it was developed on (a 128-light scene kernel, 6.8 s).
pub const DEFAULT: Duration = Duration::from_secs(60);
/// The environment variable that sets the limit (the parent passes its limit to its children through it).
pub const ENV: &str = "BRDFPROF_COMPILE_TIMEOUT";
/// A compilation that runs longer says so on stderr (and again every `PROGRESS_EVERY`).
pub const PROGRESS_AFTER: Duration = Duration::from_secs(5);
const PROGRESS_EVERY: Duration = Duration::from_secs(30);
/// The largest limit accepted (a day, as `--budget`).
const MAX_SECONDS: f64 = 86_400.0;

static LIMIT: Mutex<Option<Duration>> = Mutex::new(None);

/// Seconds as `--compile-timeout` and `ENV` take them: more than 0, at most a day.
pub fn parse(text: &str) -> std::result::Result<Duration, String> {
    match text.trim().parse::<f64>() {
        Ok(s) if s.is_finite() && s > 0.0 && s <= MAX_SECONDS => Ok(Duration::from_secs_f64(s)),
        _ => Err(format!("`{text}`: give seconds, more than 0 and at most {MAX_SECONDS}")),
    }
}

/// Sets the limit for this process: `flag` (`--compile-timeout`) if given, else `ENV`, else `DEFAULT`. An
/// unusable `ENV` is an error naming it.
pub fn init(flag: Option<Duration>) -> Result<()> {
    let limit = match (flag, std::env::var(ENV)) {
        (Some(l), _) => l,
        (None, Ok(text)) if !text.trim().is_empty() => parse(&text).map_err(|e| anyhow!("{ENV}={e}"))?,
        _ => DEFAULT,
    };
    set(limit);
    Ok(())
}

pub fn set(limit: Duration) {
    *LIMIT.lock().unwrap_or_else(|e| e.into_inner()) = Some(limit);
}

/// The limit in force: set by `init`/`set`, else `ENV` (when valid), else `DEFAULT`.
pub fn limit() -> Duration {
    if let Some(l) = *LIMIT.lock().unwrap_or_else(|e| e.into_inner()) {
        return l;
    }
    std::env::var(ENV).ok().and_then(|t| parse(&t).ok()).unwrap_or(DEFAULT)
}

/// Multiplies the limit (a child that compiles under valgrind, which runs LLVM many times slower).
pub fn scale(factor: u32) {
    set(limit().saturating_mul(factor));
}

/// Passes this process' limit to a child.
pub fn export(cmd: &mut Command) -> &mut Command {
    cmd.env(ENV, format!("{}", limit().as_secs_f64()))
}

/// The variable that sets the address-space bound of a compiler process, in MiB (`bound_memory`).
pub const MEMORY_ENV: &str = "BRDFPROF_CHILD_MEMORY_MB";

/// The address-space bound of a compiler process in bytes: `MEMORY_ENV` where set (a number of MiB, at least
/// 64), else half the machine's memory, within [1, 8] GiB: a runaway compiler (slangc unrolling nested loops
/// reached 6 GB) fails on its own allocation instead of taking the machine (a 7 GB CI runner) with it.
pub fn memory_bound() -> Result<u64> {
    if let Some(text) = std::env::var(MEMORY_ENV).ok().filter(|t| !t.trim().is_empty()) {
        return match text.trim().parse::<u64>() {
            Ok(mb) if (64..=1 << 30).contains(&mb) => Ok(mb << 20),
            _ => bail!("{MEMORY_ENV}={text}: give MiB, a whole number from 64"),
        };
    }
    // SAFETY: sysconf has no preconditions.
    let (pages, size) = unsafe { (libc::sysconf(libc::_SC_PHYS_PAGES), libc::sysconf(libc::_SC_PAGE_SIZE)) };
    let total = (pages.max(0) as u64).saturating_mul(size.max(0) as u64);
    Ok((total / 2).clamp(1 << 30, 8 << 30))
}

/// Bounds `cmd`'s address space at `memory_bound()` (RLIMIT_AS, set between fork and exec; no cgroup needed).
/// For the compilers brdfprof runs (glslang, slangc, spirv-opt, spirv-cross, g++, ocloc, nvdisasm); not for
/// valgrind, whose tool reserves the client's address space, nor for brdfprof's own children, whose Vulkan
/// drivers map the device's.
pub fn bound_memory(cmd: &mut Command) -> Result<&mut Command> {
    use std::os::unix::process::CommandExt;
    let bound = memory_bound()?;
    // SAFETY: setrlimit is async-signal-safe; the closure allocates nothing.
    unsafe {
        cmd.pre_exec(move || {
            let limit = libc::rlimit { rlim_cur: bound as libc::rlim_t, rlim_max: bound as libc::rlim_t };
            if libc::setrlimit(libc::RLIMIT_AS, &limit) != 0 {
                return Err(std::io::Error::last_os_error());
            }
            Ok(())
        });
    }
    Ok(cmd)
}

/// What a bounded compiler's failure may owe to its memory bound, said after its own message.
pub fn memory_note() -> String {
    let bound = memory_bound().map_or(0, |b| b >> 20);
    format!(
        "(compilers run with their address space bounded at {bound} MiB; where one ran out of memory, {MEMORY_ENV} raises the bound)"
    )
}

/// "60 s" / "0.5 s".
fn seconds(d: Duration) -> String {
    format!("{} s", (d.as_secs_f64() * 1000.0).round() / 1000.0)
}

/// The message of a compilation that went past the limit.
pub fn over_limit(what: &str, limit: Duration) -> String {
    format!(
        "{what}: the compilation took longer than the compile limit of {} (set it with --compile-timeout SECONDS or {ENV})",
        seconds(limit)
    )
}

/// Says, from `PROGRESS_AFTER` on, what has been compiling for how long: for a compiler whose end is waited
/// for elsewhere (a fence, a child's pipe), `tick` it while waiting.
pub struct Watch<'a> {
    what: &'a str,
    started: Instant,
    next: Duration,
}

impl<'a> Watch<'a> {
    pub fn new(what: &'a str) -> Self {
        Watch { what, started: Instant::now(), next: PROGRESS_AFTER }
    }

    /// Prints the progress line when it is due.
    pub fn tick(&mut self, limit: Duration) {
        let elapsed = self.started.elapsed();
        if elapsed >= self.next {
            crate::messages::progress(format!(
                "still compiling {} after {} (the limit is {})",
                self.what,
                seconds(Duration::from_secs(elapsed.as_secs())),
                seconds(limit)
            ));
            self.next += PROGRESS_EVERY;
        }
    }

    pub fn elapsed(&self) -> Duration {
        self.started.elapsed()
    }
}

/// Runs a compiler process (`cmd`, compiling `what`) to completion under the limit and returns its output.
/// Past the limit the process is killed and reaped, and the error names `what` and the limit.
pub fn output(cmd: &mut Command, what: &str) -> Result<Output> {
    output_within(cmd, what, limit())
}

/// `output` with an explicit limit (a child that compiles several kernels, each under the limit itself).
pub fn output_within(cmd: &mut Command, what: &str, limit: Duration) -> Result<Output> {
    run(cmd, None, what, limit)
}

/// `output` of a compiler that reads its source on stdin (spirv-opt).
pub fn output_with_input(cmd: &mut Command, input: Vec<u8>, what: &str) -> Result<Output> {
    run(cmd, Some(input), what, limit())
}

/// The most bytes read from a child's stdout or stderr: brdfprof's largest listing (a 128-light scene
/// kernel's SASS) is a few MB. A tool that prints more is not printing what it promises (`yes` as nvdisasm),
/// and is killed rather than read into memory.
pub const MAX_OUTPUT_BYTES: usize = 256 << 20;

/// `output` for a query that answers at once (a tool's version, a probe): the compile limit, at most 30 s.
pub fn output_quick(cmd: &mut Command, what: &str) -> Result<Output> {
    run(cmd, None, what, limit().min(Duration::from_secs(30)))
}

fn over_output(what: &str) -> String {
    format!(
        "{what}: the tool printed more than {} MiB, far more than it prints for any kernel: not its promised output",
        MAX_OUTPUT_BYTES >> 20
    )
}

fn run(cmd: &mut Command, input: Option<Vec<u8>>, what: &str, limit: Duration) -> Result<Output> {
    use std::io::{Read, Write};
    use std::sync::Arc;
    use std::sync::atomic::{AtomicBool, Ordering};
    let stdin = if input.is_some() { Stdio::piped() } else { Stdio::null() };
    let mut child = cmd.stdin(stdin).stdout(Stdio::piped()).stderr(Stdio::piped()).spawn()?;
    let _guard = crate::cleanup::ChildGuard::new(&child);
    // Written on a thread so that a large output cannot deadlock against the input.
    let writer =
        child.stdin.take().zip(input).map(|(mut pipe, bytes)| std::thread::spawn(move || pipe.write_all(&bytes)));
    // Readers drain the pipes while this thread watches the clock (a full pipe would stall the child).
    let overflow = Arc::new(AtomicBool::new(false));
    let read_all = |pipe: Option<Box<dyn Read + Send>>| {
        let overflow = Arc::clone(&overflow);
        std::thread::spawn(move || {
            let mut bytes = Vec::new();
            if let Some(p) = pipe {
                let _ = p.take(MAX_OUTPUT_BYTES as u64 + 1).read_to_end(&mut bytes);
            }
            if bytes.len() > MAX_OUTPUT_BYTES {
                overflow.store(true, Ordering::SeqCst);
            }
            bytes
        })
    };
    let stdout = read_all(child.stdout.take().map(|p| Box::new(p) as Box<dyn Read + Send>));
    let stderr = read_all(child.stderr.take().map(|p| Box::new(p) as Box<dyn Read + Send>));
    let mut progress = Watch::new(what);
    let status = loop {
        if let Some(status) = child.try_wait()? {
            break status;
        }
        if progress.elapsed() >= limit {
            crate::cleanup::kill_group(child.id());
            let _ = child.wait();
            bail!(over_limit(what, limit));
        }
        if overflow.load(Ordering::SeqCst) {
            crate::cleanup::kill_group(child.id());
            let _ = child.wait();
            bail!(over_output(what));
        }
        progress.tick(limit);
        std::thread::sleep(Duration::from_millis(10));
    };
    let (stdout, stderr) = (stdout.join().unwrap_or_default(), stderr.join().unwrap_or_default());
    // A tool cut off at the bound may end (SIGPIPE) before the loop above saw the bound reached.
    if overflow.load(Ordering::SeqCst) {
        bail!(over_output(what));
    }
    if let Some(w) = writer {
        // A compiler that exits without reading all of its input has said why on stderr.
        let _ = w.join();
    }
    Ok(Output { status, stdout, stderr })
}

/// Runs `work` (compiling `what`: a driver or compiler library call that cannot be interrupted) under the
/// limit. Past it the process stops: the error is reported, children killed, temporary files and staged
/// outputs removed, exit status 2 (`cleanup::stop`).
pub fn bounded<T: Send>(what: &str, work: impl FnOnce() -> T + Send) -> T {
    let limit = limit();
    std::thread::scope(|s| {
        let (tx, rx) = std::sync::mpsc::channel();
        s.spawn(move || {
            let _ = tx.send(work());
        });
        let mut progress = Watch::new(what);
        loop {
            match rx.recv_timeout(Duration::from_millis(50)) {
                Ok(value) => return value,
                Err(std::sync::mpsc::RecvTimeoutError::Disconnected) => {
                    panic!("{what}: the compiling thread ended without a result")
                }
                Err(std::sync::mpsc::RecvTimeoutError::Timeout) => {}
            }
            if progress.elapsed() >= limit {
                crate::cleanup::stop(2, &format!("brdfprof: error: {}", over_limit(what, limit)));
            }
            progress.tick(limit);
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn limits_parse_as_seconds() {
        assert_eq!(parse("2.5"), Ok(Duration::from_millis(2500)));
        for bad in ["0", "-1", "nan", "inf", "x", "86401"] {
            assert!(parse(bad).unwrap_err().contains("give seconds"), "{bad}");
        }
        assert_eq!(over_limit("a.brdf:eval_f32", Duration::from_secs(2)).split(':').next(), Some("a.brdf"));
    }

    #[test]
    fn a_process_past_the_limit_is_killed_and_named() {
        let started = Instant::now();
        let e = output_within(Command::new("sleep").arg("30"), "sleep 30", Duration::from_millis(300))
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("sleep 30: the compilation took longer than the compile limit of 0.3 s"), "{e}");
        assert!(started.elapsed() < Duration::from_secs(5), "killed at the limit");
        let out =
            output_within(Command::new("sh").args(["-c", "echo out; echo err >&2"]), "sh", Duration::from_secs(30))
                .unwrap();
        assert_eq!(
            (out.stdout.as_slice(), out.stderr.as_slice(), out.status.success()),
            (&b"out\n"[..], &b"err\n"[..], true)
        );
    }

    #[test]
    fn a_tool_that_prints_without_end_is_killed() {
        let started = Instant::now();
        let e = output_within(&mut Command::new("yes"), "yes as a disassembler", Duration::from_secs(60))
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("yes as a disassembler: the tool printed more than 256 MiB"), "{e}");
        assert!(started.elapsed() < Duration::from_secs(50), "stopped at the byte bound, not the time limit");
    }

    #[test]
    fn bounded_work_within_the_limit_returns_its_value() {
        assert_eq!(bounded("a sum", || 2 + 2), 4);
    }
}
