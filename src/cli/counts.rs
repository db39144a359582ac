//! `brdfprof inspect` and `check`: instruction counts of the kernels, and the regression gate on them.

use super::{check_output, fresh_compilation, on_device_with, parse_size, DeviceArgs, ModelArgs};
use brdfprof::compare;
use brdfprof::gpu::targets;
use brdfprof::inspect::InspectReport;
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
    fn callgrind(&self, validate: bool) -> Result<Option<CallgrindOptions>> {
        let (width, height) = parse_size("--callgrind-size", &self.callgrind_size)?;
        Ok((!self.no_callgrind).then_some(CallgrindOptions { width, height, device: None, validate }))
    }
}

#[derive(Args)]
pub struct InspectArgs {
    #[command(flatten)]
    pub model: ModelArgs,
    #[command(flatten)]
    pub counts: CountArgs,
    /// JSON report path (default: results/inspect-<device>.json; with several devices
    /// results/inspect-devices.json).
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// Markdown report path (default: results/inspect-<device>.md; with several devices
    /// results/inspect-devices.md).
    #[arg(long)]
    pub markdown: Option<PathBuf>,
    /// A `brdfprof profile` JSON report: adds callgrind's instructions per evaluation next to its ns per
    /// evaluation, with their rank correlation, and its ns/eval to the cost table across devices.
    #[arg(long)]
    pub profile: Option<PathBuf>,
    /// Write each kernel's ACO disassembly (and RADV's other internal representations: NIR, ACO IR) to
    /// DIR/<family>/<kernel>.<representation>.txt, for every `--device radv:FAMILY`.
    #[arg(long)]
    pub isa: Option<PathBuf>,
    /// Device, repeatable: an index or name substring (see `brdfprof devices`), or `radv:FAMILY` (Mesa RADV's
    /// compiler for an AMD family, no AMD GPU needed; `radv:all` for the default set; see `devices
    /// --targets`). Default: the first discrete or integrated GPU, else lavapipe.
    #[arg(long = "device", value_name = "DEVICE", value_parser = super::device_name)]
    pub devices: Vec<String>,
    /// Run under the Khronos validation layer and fail on any message (also BRDFPROF_VALIDATION=1).
    #[arg(long)]
    pub validate: bool,
    /// Inspect the default sweep's specs (`brdfprof sweep`'s 61) instead of the thesis models.
    #[arg(long, conflicts_with = "models")]
    pub sweep_specs: bool,
}

/// What one `--device` stands for.
enum Planned {
    Local(Option<String>),
    Radv(&'static targets::Target),
}

/// The devices in the order given (a target named twice is measured once).
fn plan_devices(devices: &[String]) -> Result<Vec<Planned>> {
    if devices.is_empty() {
        return Ok(vec![Planned::Local(None)]);
    }
    let mut out: Vec<Planned> = Vec::new();
    for d in devices {
        match targets::parse(d).map_err(|e| anyhow!("--device {d}: {e:#}"))? {
            Some(ts) => {
                for t in ts {
                    if !out.iter().any(|p| matches!(p, Planned::Radv(x) if *x == t)) {
                        out.push(Planned::Radv(t));
                    }
                }
            }
            None => out.push(Planned::Local(Some(d.clone()))),
        }
    }
    Ok(out)
}

/// The devices' reports for `inspect`, in order: local devices in this process, compile-only targets in
/// children (several at once).
fn inspect_reports(args: &InspectArgs, plan: &[Planned], options: &InspectOptions, shaders: &Shaders, validate: bool) -> Result<Vec<InspectReport>> {
    let radv: Vec<&'static targets::Target> = plan.iter().filter_map(|p| if let Planned::Radv(t) = p { Some(*t) } else { None }).collect();
    let mut radv_runs = inspect::radv::run_all(&radv, &options.models, options.lights, shaders, validate, args.isa.as_deref())?.into_iter();
    let mut reports = Vec::new();
    for p in plan {
        match p {
            Planned::Local(device) => {
                let device = DeviceArgs { device: device.clone(), validate };
                let (_, result) = on_device_with(&device, true, |gpu, _| inspect::run(gpu, shaders, options))?;
                reports.push(result);
            }
            Planned::Radv(_) => {
                let run = radv_runs.next().expect("one run per target");
                let mut report = run.report;
                if let Some(note) = run.teardown_note {
                    brdfprof::messages::note(&note);
                    report.section_notes.insert("driver/".into(), note);
                }
                if !run.isa_files.is_empty() {
                    brdfprof::messages::progress(format!("inspect: radv:{}: {} ISA files under {}", run.target.family, run.isa_files.len(), args.isa.as_deref().map_or(String::new(), |d| d.join(run.target.family).display().to_string())));
                }
                reports.push(report);
            }
        }
    }
    Ok(reports)
}

/// The JSON of `inspect` over several devices.
#[derive(serde::Serialize)]
struct MultiReport<'a> {
    format: &'static str,
    reports: &'a [InspectReport],
    costs: &'a compare::CostTable,
    /// Why a `--profile` report is not in the cost table, if it is not.
    #[serde(skip_serializing_if = "Option::is_none")]
    profile_note: Option<String>,
}

pub fn inspect(args: &InspectArgs) -> Result<ExitCode> {
    let lights = args.counts.lights.unwrap_or(8);
    if lights == 0 {
        bail!("--lights must be at least 1");
    }
    let validate = args.validate || std::env::var("BRDFPROF_VALIDATION").is_ok_and(|v| !v.is_empty() && v != "0");
    let plan = plan_devices(&args.devices)?;
    let several = plan.len() > 1;
    let default_name = if several { "inspect-devices" } else { "inspect-<device>" };
    check_output("--json", args.json.as_deref(), "results", &format!("{default_name}.json"))?;
    check_output("--markdown", args.markdown.as_deref(), "results", &format!("{default_name}.md"))?;
    if let Some(dir) = &args.isa {
        if !plan.iter().any(|p| matches!(p, Planned::Radv(_))) {
            bail!("--isa {}: the disassembly is ACO's; give a compile-only device, e.g. --device radv:navi21 (see `brdfprof devices --targets`)", dir.display());
        }
        io::check_output_dir("--isa", dir)?;
    }
    let models = if args.sweep_specs { brdfprof::sweep::default_specs().into_iter().map(brdfprof::model::Model::spec).collect() } else { args.model.models(&THESIS_MODELS)? };
    let options = InspectOptions { models, lights, callgrind: args.counts.callgrind(validate)? };
    let profile = args.profile.as_deref().map(inspect::correlate::load_profile).transpose()?;
    let shaders = args.counts.shaders()?;
    let mut reports = inspect_reports(args, &plan, &options, &shaders, validate)?;
    if let Some(p) = &profile {
        for r in reports.iter_mut().filter(|r| r.callgrind.is_some()) {
            r.vs_profile = Some(inspect::correlate::correlate_with(r, p)?);
        }
    }
    let (json, markdown, text) = if !several {
        let result = &reports[0];
        let slug = result.provenance["device"]["name"].as_str().map(device_slug_of).unwrap_or_else(|| "device".into());
        let json = args.json.clone().unwrap_or_else(|| PathBuf::from(format!("results/inspect-{slug}.json")));
        let markdown = args.markdown.clone().unwrap_or_else(|| PathBuf::from(format!("results/inspect-{slug}.md")));
        let text = format!("# brdfprof inspect\n\n{}\n\n{}", result.summary(), result.markdown());
        report::write_json(&json, result)?;
        (json, markdown, text)
    } else {
        let mut columns: Vec<compare::CostColumn> = Vec::new();
        let mut profile_note = None;
        if let Some(p) = &profile {
            let cols = compare::profile_columns(&p.json, &format!("{}: ", p.file))?;
            let mut all = cols.clone();
            all.extend(reports.iter().flat_map(|r| compare::inspect_columns(r, "")));
            match compare::check_kernels(&all) {
                Ok(()) => columns.extend(cols),
                Err(e) => profile_note = Some(format!("--profile {} is not in the cost table: {e:#}", p.file)),
            }
        }
        for r in &reports {
            columns.extend(compare::inspect_columns(r, ""));
        }
        let costs = compare::build(columns);
        let mut text = String::from("# brdfprof inspect\n\n");
        for r in &reports {
            text += &format!("## {}\n\n{}\n\n", r.provenance["device"]["name"].as_str().unwrap_or("?"), r.summary());
            match &r.aco {
                // A compile-only device's SPIR-V and naga counts are the other devices' (same kernels): its
                // ACO table is what it adds; the JSON has everything.
                Some(a) if targets::family_of_device(&a.device).is_some() => {
                    text += &a.markdown();
                    text += "\n";
                    if let Some(n) = r.section_notes.get("driver/") {
                        text += &format!("{n}\n\n");
                    }
                }
                _ => text += &r.markdown(),
            }
        }
        text += &costs.markdown();
        if let Some(n) = &profile_note {
            text += &format!("{n}\n");
        }
        let json = args.json.clone().unwrap_or_else(|| PathBuf::from("results/inspect-devices.json"));
        let markdown = args.markdown.clone().unwrap_or_else(|| PathBuf::from("results/inspect-devices.md"));
        report::write_json(&json, &MultiReport { format: "brdfprof-inspect-devices/1", reports: &reports, costs: &costs, profile_note })?;
        (json, markdown, text)
    };
    io::write_output(&markdown, text.as_bytes())?;
    print!("{text}");
    println!("JSON: {}\nMarkdown: {}", json.display(), markdown.display());
    Ok(ExitCode::SUCCESS)
}

/// `report::device_slug` of a device name.
fn device_slug_of(name: &str) -> String {
    if let Some(t) = targets::family_of_device(name) {
        return format!("radv-{}", t.family);
    }
    let first = name.split(['(', ',']).next().unwrap_or("device").trim().to_lowercase();
    let slug: String = first.chars().map(|c| if c.is_ascii_alphanumeric() { c } else { '-' }).collect();
    let slug = slug.trim_matches('-').to_string();
    if slug.is_empty() { "device".into() } else { slug }
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
        callgrind: args.counts.callgrind(args.device.validation())?,
        timing: TimingOptions { width, height, lights: 0, rounds: args.rounds, reps: args.reps, seed: 1 },
    };
    let shaders = args.counts.shaders()?;
    let outcome = match args.device.device.as_deref().map(targets::parse).transpose()?.flatten() {
        Some(ts) if ts.len() == 1 => check::run_radv(&options, &shaders, ts[0], args.device.validation())?,
        Some(_) => bail!("--device {}: check compares one family with its baseline; give one radv:FAMILY", args.device.device.as_deref().unwrap_or_default()),
        None => check::run(&options, &shaders, || args.device.open_with(true))?,
    };
    print!("{}", outcome.text);
    Ok(ExitCode::from(outcome.exit))
}
