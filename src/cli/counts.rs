//! `brdfprof inspect` and `check`: instruction counts of the kernels, and the regression gate on them.

use super::{check_output, fresh_compilation, on_device, parse_size, DeviceArgs, ModelArgs};
use anyhow::{anyhow, bail, Result};
use brdfprof::brdf::THESIS_MODELS;
use brdfprof::inspect::callgrind::CallgrindOptions;
use brdfprof::inspect::check::{self, CheckOptions, Thresholds};
use brdfprof::inspect::timing::TimingOptions;
use brdfprof::inspect::{self, InspectOptions};
use brdfprof::shaders::Shaders;
use brdfprof::{io, report};
use clap::Args;
use std::path::PathBuf;
use std::process::ExitCode;

/// What `inspect` and `check` share: the kernels measured and how.
#[derive(Args, Clone)]
pub struct CountArgs {
    /// Directional lights per pixel (default 8; `check` defaults to the baseline's).
    #[arg(long)]
    pub lights: Option<u32>,
    /// Compile the kernels from this GLSL directory (a copy of glsl/, with its kernels.txt) with glslang
    /// instead of using the embedded SPIR-V.
    #[arg(long)]
    pub glsl: Option<PathBuf>,
    /// Skip the callgrind run.
    #[arg(long)]
    pub no_callgrind: bool,
    /// G-buffer of the callgrind dispatch, WIDTHxHEIGHT.
    #[arg(long, default_value = "64x64")]
    pub callgrind_size: String,
}

impl CountArgs {
    fn shaders(&self) -> Result<Shaders> {
        self.glsl.as_deref().map_or_else(|| Ok(Shaders::embedded()), Shaders::from_glsl)
    }

    /// How to run the callgrind child (None: --no-callgrind); it inherits validation from the parent.
    fn callgrind(&self, device: &DeviceArgs) -> Result<Option<CallgrindOptions>> {
        let (width, height) = parse_size("--callgrind-size", &self.callgrind_size)?;
        Ok((!self.no_callgrind).then_some(CallgrindOptions { width, height, device: None, validate: device.validation() }))
    }
}

#[derive(Args)]
pub struct InspectArgs {
    #[command(flatten)]
    pub model: ModelArgs,
    #[command(flatten)]
    pub counts: CountArgs,
    /// JSON report path (default: results/inspect-<device>.json).
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// Markdown report path (default: results/inspect-<device>.md).
    #[arg(long)]
    pub markdown: Option<PathBuf>,
    /// A `brdfprof profile` JSON report: adds callgrind's instructions per evaluation next to its ns per
    /// evaluation, with their rank correlation.
    #[arg(long)]
    pub profile: Option<PathBuf>,
    #[command(flatten)]
    pub device: DeviceArgs,
}

pub fn inspect(args: &InspectArgs) -> Result<ExitCode> {
    let lights = args.counts.lights.unwrap_or(8);
    if lights == 0 {
        bail!("--lights must be at least 1");
    }
    check_output("--json", args.json.as_deref(), "results", "inspect-<device>.json")?;
    check_output("--markdown", args.markdown.as_deref(), "results", "inspect-<device>.md")?;
    let options = InspectOptions { models: args.model.models(&THESIS_MODELS)?, lights, callgrind: args.counts.callgrind(&args.device)? };
    let profile = args.profile.as_deref().map(inspect::correlate::load_profile).transpose()?;
    let shaders = args.counts.shaders()?;
    let (gpu, mut result) = on_device(&args.device, |gpu, _| inspect::run(gpu, &shaders, &options))?;
    if let Some(p) = &profile {
        result.vs_profile = Some(inspect::correlate::correlate_with(&result, p)?);
    }
    let slug = report::device_slug(&gpu.info);
    let json = args.json.clone().unwrap_or_else(|| PathBuf::from(format!("results/inspect-{slug}.json")));
    let markdown = args.markdown.clone().unwrap_or_else(|| PathBuf::from(format!("results/inspect-{slug}.md")));
    let text = format!("# brdfprof inspect\n\n{}\n\n{}", result.summary(), result.markdown());
    report::write_json(&json, &result)?;
    io::write_output(&markdown, text.as_bytes())?;
    print!("{text}");
    println!("JSON: {}\nMarkdown: {}", json.display(), markdown.display());
    Ok(ExitCode::SUCCESS)
}

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
        callgrind: args.counts.callgrind(&args.device)?,
        timing: TimingOptions { width, height, lights: 0, rounds: args.rounds, reps: args.reps, seed: 1 },
    };
    let outcome = check::run(&options, &args.counts.shaders()?, || args.device.open())?;
    print!("{}", outcome.text);
    Ok(ExitCode::from(outcome.exit))
}
