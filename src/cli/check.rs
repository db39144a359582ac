//! `brdfprof check`: the regression gate on the instruction counts and a short timing run, against a baseline.

use super::args::{CountArgs, DeviceArgs, ModelArgs, parse_size};
use super::fresh_compilation;
use anyhow::{Result, anyhow, bail};
use brdfprof::check::{self, CheckOptions, Thresholds};
use brdfprof::inspect::timing::TimingOptions;
use brdfprof::io;
use clap::Args;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Args)]
pub struct CheckArgs {
    /// Baseline to compare with (from `check --save-baseline`).
    #[arg(long)]
    pub baseline: Option<PathBuf>,
    /// Write this run as a baseline (atomically), whatever the comparison found.
    #[arg(long)]
    pub save_baseline: Option<PathBuf>,
    /// Regression threshold of a statistic or a section, e.g. spirv/total=0.02, callgrind=0.005, timing=0.1
    /// (defaults: 0.01 for counts, 0.05 for timings).
    #[arg(long = "threshold")]
    pub thresholds: Vec<String>,
    /// Compare timings and callgrind counts even when the baseline comes from another environment.
    #[arg(long)]
    pub force: bool,
    /// Models (default: the baseline's, else the thesis models).
    #[command(flatten)]
    pub model: ModelArgs,
    #[command(flatten)]
    pub counts: CountArgs,
    /// Interleaved timing rounds (at least 9 for the significance test; 0 skips timing).
    #[arg(long, default_value_t = 15)]
    pub rounds: usize,
    /// Timed dispatches of each kernel per round.
    #[arg(long, default_value_t = 3)]
    pub reps: usize,
    /// G-buffer of the timing run, WIDTHxHEIGHT.
    #[arg(long, default_value = "960x540")]
    pub timing_size: String,
    /// Keep Mesa's on-disk shader cache (timed runs switch it off by default; see `fresh_compilation`).
    #[arg(long)]
    pub shader_cache: bool,
    #[command(flatten)]
    pub device: DeviceArgs,
}

pub fn check(args: &CheckArgs) -> Result<ExitCode> {
    if let Some(p) = &args.save_baseline {
        io::check_output_path("--save-baseline", p)?;
    }
    fresh_compilation(args.shader_cache);
    let (width, height) = parse_size("--timing-size", &args.timing_size)?;
    let options = CheckOptions {
        baseline: args.baseline.clone(),
        save: args.save_baseline.clone(),
        thresholds: Thresholds::parse(&args.thresholds)?,
        force: args.force,
        models: args.model.models(&[]).map_err(|e| anyhow!("{e:#}"))?,
        lights: args.counts.lights,
        callgrind: args.counts.callgrind(args.device.validation())?,
        timing: TimingOptions { width, height, lights: 0, rounds: args.rounds, reps: args.reps, seed: 1 },
    };
    let shaders = args.counts.shaders()?;
    let outcome = match args.device.device.as_deref().map(brdfprof::targets::parse).transpose()?.flatten() {
        Some(ts) if ts.len() == 1 => {
            // A target that compiles a translation checks it against the default device first.
            let verify = if ts[0].vendor.needs_verification() {
                Some(DeviceArgs { device: None, validate: args.device.validate }.open()?)
            } else {
                None
            };
            check::run_target(&options, &shaders, ts[0], args.device.validation(), verify.as_ref())?
        }
        Some(_) => bail!(
            "--device {}: check compares one family with its baseline; give one target, e.g. radv:navi21",
            args.device.device.as_deref().unwrap_or_default()
        ),
        None => check::run(&options, &shaders, || args.device.open_with(true))?,
    };
    print!("{}", outcome.text);
    Ok(ExitCode::from(outcome.exit))
}
