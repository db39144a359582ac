//! `brdfprof check`: the regression gate on the instruction counts and a short timing run, against a baseline.

use super::args::{CountArgs, DeviceArgs, ModelArgs, parse_size};
use super::fresh_compilation;
use anyhow::{Result, anyhow, bail};
use brdfprof::check::timing::TimingOptions;
use brdfprof::check::{self, CheckOptions, Thresholds};
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
    /// Write the regressions as SARIF 2.1.0 (code scanning): one result per regressed model, at the lines of its
    /// file whose cost rose most (per-line cost is kept in baselines of nvidia: and intel: targets), else at its
    /// file; no regression writes a log with no results.
    #[arg(long, value_name = "FILE")]
    pub sarif: Option<PathBuf>,
    /// Print workflow commands for the CI's own annotations: `github` (`::error file=...,line=...::...`, the
    /// largest regressions first, at most 10, GitHub's limit per step).
    #[arg(long, value_name = "FORMAT", value_parser = ["github"])]
    pub annotations: Option<String>,
    /// Append the Markdown report to FILE (GitHub's $GITHUB_STEP_SUMMARY; cut at its 1 MiB limit).
    #[arg(long, value_name = "FILE")]
    pub summary: Option<PathBuf>,
}

impl super::Run for CheckArgs {
    fn run(&self) -> Result<ExitCode> {
        check(self)
    }
}

pub fn check(args: &CheckArgs) -> Result<ExitCode> {
    let models = args.model.models(&[]).map_err(|e| anyhow!("{e:#}"))?;
    let mut inputs = super::model_inputs(&models);
    let asked = [
        ("--save-baseline", args.save_baseline.as_deref()),
        ("--sarif", args.sarif.as_deref()),
        ("--summary", args.summary.as_deref()),
    ];
    super::checked_outputs(&asked, &inputs)?;
    // `--save-baseline` may replace the baseline it was compared with (the documented refresh); the CI outputs
    // never.
    inputs.extend(args.baseline.as_deref().map(|b| ("--baseline", b)));
    super::checked_outputs(&asked[1..], &inputs)?;
    fresh_compilation(args.shader_cache);
    let (width, height) = parse_size("--timing-size", &args.timing_size)?;
    let options = CheckOptions {
        baseline: args.baseline.clone(),
        save: args.save_baseline.clone(),
        thresholds: Thresholds::parse(&args.thresholds)?,
        force: args.force,
        models,
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
    out!("{}", outcome.text);
    write_ci_outputs(args, &outcome)?;
    Ok(ExitCode::from(outcome.exit))
}

/// The SARIF log, the annotations and the step summary of a check's outcome, where asked for.
fn write_ci_outputs(args: &CheckArgs, outcome: &check::Outcome) -> Result<()> {
    use brdfprof::export::{github, sarif};
    if let Some(path) = &args.sarif {
        let root = std::env::current_dir()?;
        let (target, compiler) = &outcome.measured_on;
        let properties = serde_json::json!({
            "baseline": args.baseline.as_ref().map(|b| b.display().to_string()),
            "target": target,
            "compiler": compiler,
        });
        let log = sarif::log(env!("CARGO_PKG_VERSION"), &check::findings::RULES, &outcome.findings, &root, properties);
        io::write_output(path, format!("{}\n", serde_json::to_string_pretty(&log)?).as_bytes())?;
    }
    if args.annotations.is_some() {
        print!("{}", github::annotations(&outcome.findings));
    }
    if let Some(path) = &args.summary {
        github::append_summary(path, &outcome.text)?;
    }
    Ok(())
}
