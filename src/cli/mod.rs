//! What the commands share besides their arguments (those are in `args`): the sequence every command runs in
//! (`prepare`, `finish`), the one that opens the device, shows progress, runs the work and checks the validation
//! layer (`on_device`), and the checks and names of their outputs. Each public command is in its own file,
//! `cli/<command>.rs`; the hidden ones are in `hidden`.

/// `print!` for what a command reports on stdout: through `messages::safe_text`, so that no name or text from
/// an input starts a line of its own there (a GitHub workflow command, a forged table row).
macro_rules! out {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let text = brdfprof::messages::safe_text(&format!($($arg)*));
        // With `--json -`, stdout carries the JSON alone and the report goes to stderr.
        if brdfprof::io::stdout_claimed() {
            let _ = write!(std::io::stderr().lock(), "{text}");
        } else {
            let _ = write!(std::io::stdout().lock(), "{text}");
        }
    }};
}

/// `println!` through `messages::safe_text` (`out!`).
macro_rules! outln {
    ($($arg:tt)*) => {{
        out!("{}\n", format!($($arg)*))
    }};
}

/// A command's arguments, run: each `cli/<command>.rs` implements it for its arguments type, and main.rs's one
/// list of commands (`commands!`) derives both the command line and the dispatch from those types.
pub trait Run {
    fn run(&self) -> Result<std::process::ExitCode>;
    /// A child process brdfprof starts of itself (`prepare` sets it up as one).
    fn child(&self) -> bool {
        false
    }
}

pub mod args;
pub mod cache;
pub mod check;
pub mod compare;
pub mod devices;
pub mod diff;
pub mod eval;
pub mod hidden;
pub mod inspect;
pub mod models;
pub mod profile;
pub mod render;
pub mod report;
pub mod scene;
pub mod stability;
pub mod sweep;

use anyhow::{Result, anyhow, bail};
use args::DeviceArgs;
use brdfprof::gpu::Gpu;
use brdfprof::io;
use brdfprof::model::Model;
use brdfprof::report::Input;
use brdfprof::targets;
use indicatif::{ProgressBar, ProgressStyle};
use std::path::{Path, PathBuf};
use std::time::Duration;

/// One range of the default samples: the flag's, else the intersection of `default` with the models' declared
/// domains (named in the words returned), else `default`; models whose domains do not meet are refused.
fn range_of(
    flag: (&str, Option<(f64, f64)>),
    default: (f64, f64),
    declared: Vec<(String, (f64, f64))>,
    what: &str,
) -> Result<((f64, f64), String)> {
    if let Some(r) = flag.1 {
        return Ok((r, format!(" ({})", flag.0)));
    }
    if declared.is_empty() {
        return Ok((default, String::new()));
    }
    let lo = declared.iter().map(|(_, d)| d.0).fold(default.0, f64::max);
    let hi = declared.iter().map(|(_, d)| d.1).fold(default.1, f64::min);
    let names = declared.iter().map(|(n, (a, b))| format!("{n} [{a}, {b}]")).collect::<Vec<_>>().join(", ");
    if lo > hi {
        bail!(
            "the models' {what} domains do not meet within [{}, {}] ({names}); give {} MIN..MAX to compare them anyway",
            default.0,
            default.1,
            flag.0
        );
    }
    Ok(((lo, hi), format!(" (the models' declared domain: {names})")))
}

/// The sample ranges of a command (its `--roughness`, `--nov`, `--nol` flags, else the models' declared domains
/// within `d`, else `d`), and the words saying where each comes from.
pub fn sample_domain(
    flags: [Option<(f64, f64)>; 3],
    d: brdfprof::diff::SampleDomain,
    models: &[&Model],
) -> Result<(brdfprof::diff::SampleDomain, [String; 3])> {
    let declared = |pick: &dyn Fn(&Model) -> Option<(f64, f64)>| {
        models.iter().filter_map(|m| pick(m).map(|r| (m.label(), r))).collect::<Vec<_>>()
    };
    let (roughness, rw) =
        range_of(("--roughness", flags[0]), d.roughness, declared(&|m| m.roughness_domain()), "roughness")?;
    let (nov, vw) = range_of(("--nov", flags[1]), d.nov, declared(&|m| m.cosine_domains().0), "N.V")?;
    let (nol, lw) = range_of(("--nol", flags[2]), d.nol, declared(&|m| m.cosine_domains().1), "N.L")?;
    Ok((brdfprof::diff::SampleDomain { roughness, nov, nol }, [rw, vw, lw]))
}

/// The error of a command that must execute kernels given a compile-only device.
pub fn compiles_only_error(device: &str) -> anyhow::Error {
    anyhow!(
        "--device {device}: a compile-only device ({}: a vendor's compiler without its GPU) compiles only and cannot run \
         kernels; this command must execute them. Use `inspect`, `check`, `sweep --cost-device` or `profile --scene --cost-device` with it, and a device \
         from `brdfprof devices` here",
        targets::prefixes()
    )
}

/// Opens the device, runs `work` with a progress bar, and fails if the validation layer said anything.
pub fn on_device<T>(device: &DeviceArgs, work: impl FnOnce(&Gpu, &ProgressBar) -> Result<T>) -> Result<(Gpu, T)> {
    on_device_with(device, false, work)
}

/// `on_device`; `compile_only_ok`: the work only compiles, so a compile-only device will do.
pub fn on_device_with<T>(
    device: &DeviceArgs,
    compile_only_ok: bool,
    work: impl FnOnce(&Gpu, &ProgressBar) -> Result<T>,
) -> Result<(Gpu, T)> {
    let gpu = device.open_with(compile_only_ok)?;
    let progress = ProgressBar::new(0)
        .with_style(ProgressStyle::with_template("{spinner} {elapsed} {pos} {msg}").expect("valid progress template"));
    progress.enable_steady_tick(Duration::from_millis(200));
    let bar = progress.clone();
    let messages = brdfprof::messages::ProgressGuard::new(move |print| bar.suspend(print));
    // A CI log shows no progress bar: what it shows, every 10 s there.
    let p = progress.clone();
    let heartbeat = brdfprof::messages::Heartbeat::start(move || {
        let of = p.length().filter(|l| *l > 0).map_or(String::new(), |l| format!(" of {l}"));
        let what = p.message();
        format!("{}: {}{of}", if what.is_empty() { "working" } else { what.as_str() }, p.position())
    });
    let result = work(&gpu, &progress);
    drop(heartbeat);
    drop(messages);
    progress.finish_and_clear();
    let result = result?;
    gpu.check_validation()?;
    Ok((gpu, result))
}

/// Everything before a command runs: the signal handler (children have none: they die with brdfprof), the
/// compile limit, the environment knobs checked, a `RADV_FORCE_FAMILY` that would abort the process
/// removed, and outputs staged until the command succeeds (`finish`).
pub fn prepare(child: bool, compile_timeout: Option<Duration>) -> Result<()> {
    if child {
        brdfprof::messages::set_child_process();
    } else {
        brdfprof::cleanup::install_signal_handler()?;
    }
    brdfprof::launch::init(compile_timeout)?;
    check_env_seconds(brdfprof::gpu::FENCE_TIMEOUT_ENV)?;
    brdfprof::host_cpu::memory_limit()?;
    if !child {
        brdfprof::targets::radv::env::sanitise()?;
    }
    brdfprof::io::stage_outputs();
    Ok(())
}

/// An environment variable that holds seconds, when set: more than 0, at most a day.
fn check_env_seconds(var: &str) -> Result<()> {
    match std::env::var(var) {
        Ok(v) if !v.trim().is_empty() => brdfprof::launch::parse(&v).map(|_| ()).map_err(|e| anyhow!("{var}={e}")),
        _ => Ok(()),
    }
}

/// The end of every command: its staged outputs published if it succeeded (exit 0 or 1), removed if it
/// failed; an error printed with exit status 2. An interrupted command ends in the signal handler instead.
pub fn finish(result: Result<std::process::ExitCode>) -> std::process::ExitCode {
    brdfprof::cleanup::park_if_interrupted();
    match result.and_then(|code| brdfprof::io::commit_outputs().map(|_| code)) {
        Ok(code) => code,
        Err(e) => {
            brdfprof::io::discard_outputs();
            brdfprof::messages::error(format!("{e:#}"));
            std::process::ExitCode::from(2)
        }
    }
}

/// When this command began (the first call, from `main`, fixes it): `--budget` counts from here.
pub fn command_started() -> std::time::Instant {
    static STARTED: std::sync::OnceLock<std::time::Instant> = std::sync::OnceLock::new();
    *STARTED.get_or_init(std::time::Instant::now)
}

/// Timed runs compile every pipeline afresh (MESA_SHADER_CACHE_DISABLE=true unless the user set it or asked
/// to keep the cache): with Mesa's on-disk shader cache a process runs binaries an earlier process compiled,
/// and on lavapipe that moved one scene effect's cost from 0.3 to 19 ns/pixel between runs, where fresh
/// compilation gave the same figure run after run. The variable is recorded in every report's environment.
pub fn fresh_compilation(keep_cache: bool) {
    if !keep_cache && std::env::var_os("MESA_SHADER_CACHE_DISABLE").is_none() {
        // SAFETY: called on the main thread before the Vulkan driver, which reads the variable, is loaded,
        // while the only other thread is the signal handler's, which reads no environment variable.
        unsafe { std::env::set_var("MESA_SHADER_CACHE_DISABLE", "true") };
    }
}

/// The directory of every default output (relative to the working directory; a default path git tracks there is
/// refused, `io::refuse_tracked_default`).
pub const DEFAULT_OUT: &str = "results";

/// Checks a file output given by `flag` (see `io::check_output_path`), or, when it defaults to a file in
/// `default_dir` that is named only once the device is open, that directory, and that no file git tracks there
/// has the default's name.
pub fn check_output(flag: &str, path: Option<&Path>, default_dir: &str, default_name: &str) -> Result<()> {
    match path {
        Some(p) if io::is_stdout(p) => Ok(()),
        Some(p) => io::check_output_path(flag, p),
        None => {
            io::check_output_dir(&format!("{flag} (default {default_dir}/{default_name})"), Path::new(default_dir))?;
            // The device is not known yet: a `<device>` name is refused where git tracks it for any device.
            io::refuse_tracked_default(flag, Path::new(default_dir), &[default_name.replace("<device>", "*")])
        }
    }
}

/// The file outputs a command was asked for (flag, path), each checked the same way for every command before
/// anything is measured: a path it may write (`io::check_output_path`), none of the command's `inputs` (the
/// same file after links, hard links included: `io::check_not_input`), and no path given to two flags.
pub fn checked_outputs(
    asked: &[(&'static str, Option<&Path>)],
    inputs: &[(&str, &Path)],
) -> Result<Vec<(&'static str, PathBuf)>> {
    let outs: Vec<(&'static str, PathBuf)> =
        asked.iter().filter_map(|(f, p)| p.map(|p| (*f, p.to_path_buf()))).collect();
    for (i, (flag, path)) in outs.iter().enumerate() {
        if io::is_stdout(path) {
            if !flag.ends_with("json") {
                anyhow::bail!("{flag} -: only JSON goes to stdout (--json -); give {flag} a file");
            }
            if let Some((other, _)) = outs[..i].iter().find(|(_, p)| io::is_stdout(p)) {
                anyhow::bail!("{flag} -: {other} already writes to stdout; one output can");
            }
            io::claim_stdout();
            continue;
        }
        io::check_output_path(flag, path)?;
        io::check_not_input(flag, path, inputs)?;
        if let Some((other, _)) = outs[..i].iter().find(|(_, p)| p == path || io::same_file(p, path)) {
            anyhow::bail!("{flag} {}: is also given to {other}; give each output its own path", path.display());
        }
    }
    Ok(outs)
}

/// Each model file, and every file it includes, as an input a command must not overwrite (`checked_outputs`).
pub fn model_inputs(models: &[Model]) -> Vec<(&'static str, &Path)> {
    let mut inputs: Vec<(&'static str, &Path)> = Vec::new();
    for f in models.iter().filter_map(Model::file) {
        inputs.push(("--model", Path::new(&f.path)));
        for file in f.file.front_end_origins.iter().flatten().map(|o| &o.0) {
            if !inputs.iter().any(|(_, p)| *p == Path::new(file)) {
                inputs.push(("an included file of --model", Path::new(file)));
            }
        }
    }
    inputs
}

/// "written: a, b, c" for a command's outputs.
pub fn written(paths: &[std::path::PathBuf]) -> String {
    format!("written: {}", paths.iter().map(|p| p.display().to_string()).collect::<Vec<_>>().join(", "))
}

/// `--out`, checked writable; else the default results/, refused where the command's `files` there (patterns,
/// `*` for the device) match a file git tracks.
pub fn out_dir(given: Option<&std::path::Path>, files: &[&str]) -> Result<PathBuf> {
    if let Some(out) = given {
        io::check_output_dir("--out", out)?;
        return Ok(out.to_path_buf());
    }
    let out = PathBuf::from(DEFAULT_OUT);
    io::check_output_dir("--out (default results)", &out)?;
    io::refuse_tracked_default("--out", &out, &files.iter().map(|f| f.to_string()).collect::<Vec<_>>())?;
    Ok(out)
}

/// The compile-only targets of `--cost-device`, in order, each once.
pub fn cost_targets(devices: &[String]) -> Result<Vec<brdfprof::targets::Target>> {
    let mut out: Vec<brdfprof::targets::Target> = Vec::new();
    for d in devices {
        let Some(ts) = brdfprof::targets::parse(d)? else {
            anyhow::bail!(
                "--cost-device {d}: give a compile-only target ({}FAMILY or PREFIX:all; see `brdfprof devices --targets`); the command's own --device is the one that measures",
                brdfprof::targets::prefixes()
            );
        };
        for t in ts {
            if !out.contains(&t) {
                out.push(t);
            }
        }
    }
    Ok(out)
}

/// The report just measured, read back as its saved JSON would be.
pub fn just_measured(json: &Path, report: &impl serde::Serialize) -> Result<Input> {
    brdfprof::report::from_report(json, report)
}
