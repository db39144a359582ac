//! `brdfprof inspect`: instruction counts of each model's shading kernel, on devices and compile-only targets.

use super::args::{BenchArg, CountArgs, DeviceArgs, HtmlArg, ModelArgs, device_name};
use super::{check_output, just_measured, on_device_with};
use anyhow::{Result, bail};
use brdfprof::brdf::THESIS_MODELS;
use brdfprof::gpu::Gpu;
use brdfprof::inspect::devices as across_devices;
use brdfprof::inspect::{self, InspectOptions};
use brdfprof::{export::json, io};
use clap::Args;
use std::path::PathBuf;
use std::process::ExitCode;

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
    /// PNG chart of each model's net cost relative to ggx per device, as `compare --chart` draws it (needs
    /// several --device).
    #[arg(long)]
    pub chart: Option<PathBuf>,
    /// Write each kernel's compiler output for every compile-only target: RADV's internal representations
    /// (NIR, ACO IR, disassembly) to DIR/<family>/<kernel>.<representation>.txt; NVIDIA's CUDA C++
    /// translation and SASS to DIR/nvidia-<family>/<kernel>.{cu,sass}; Intel's OpenCL C translation and IGA
    /// listing to DIR/intel-<family>/<kernel>.{cl,asm}.
    #[arg(long)]
    pub isa: Option<PathBuf>,
    /// Device, repeatable: an index or name substring (see `brdfprof devices`), or a compile-only target
    /// (`radv:FAMILY`: Mesa RADV's compiler for an AMD family; `nvidia:FAMILY`: NVIDIA's compiler for a compute
    /// capability; `intel:FAMILY`: Intel's IGC for a GPU generation; `adreno:`, `mali:`, `anv:` and `nak:`:
    /// Mesa's Freedreno, Panfrost, ANV and NVK compilers on its noop drm-shim; `PREFIX:all` for the default set;
    /// see `devices --targets`). Default: the first discrete or integrated GPU, else lavapipe.
    #[arg(long = "device", value_name = "DEVICE", value_parser = device_name)]
    pub devices: Vec<String>,
    /// Run under the Khronos validation layer and fail on any message (also BRDFPROF_VALIDATION=1).
    #[arg(long)]
    pub validate: bool,
    /// Inspect the default sweep's specs (`brdfprof sweep`'s 61) instead of the thesis models.
    #[arg(long, conflicts_with = "models")]
    pub sweep_specs: bool,
    /// Compile-only targets that translate the kernels compile them with their IEEE-exact defaults instead of
    /// the precision freedom a Vulkan driver has (NVIDIA: without -use_fast_math).
    #[arg(long)]
    pub precise_math: bool,
    /// Cost per source line: each model's kernel compiled again with line information on the nvidia: and
    /// intel: targets (NVRTC -lineinfo, IGC -gline-tables-only), every instruction attributed to the line of the .brdf file or
    /// of glsl/ it came from and summed per line by the cost rule; the costliest lines in the Markdown and HTML,
    /// all of them in the JSON (`lines`). ACO (radv:) in Mesa 22.3 names no source lines.
    #[arg(long)]
    pub lines: bool,
    #[command(flatten)]
    pub html: HtmlArg,
    #[command(flatten)]
    pub bench: BenchArg,
}

impl super::Run for InspectArgs {
    fn run(&self) -> Result<ExitCode> {
        inspect(self)
    }
}

pub fn inspect(args: &InspectArgs) -> Result<ExitCode> {
    let lights = args.counts.lights.unwrap_or(8);
    if lights == 0 {
        bail!("--lights must be at least 1");
    }
    let validate = DeviceArgs { device: None, validate: args.validate }.validation();
    let plan = across_devices::plan(&args.devices)?;
    let models = if args.sweep_specs {
        brdfprof::sweep::default_specs().into_iter().map(brdfprof::model::Model::spec).collect()
    } else {
        args.model.models(&THESIS_MODELS)?
    };
    check_outputs(args, &plan, &models)?;
    let options = InspectOptions { models, lights, callgrind: args.counts.callgrind(validate)? };
    let profile = args.profile.as_deref().map(inspect::correlate::load_profile).transpose()?;
    let shaders = args.counts.shaders()?;
    // A named device may be a compile-only one (RADV's null device); the default device verifies translations.
    let local = |device: Option<&str>, work: &mut dyn FnMut(&Gpu) -> Result<()>| -> Result<()> {
        let d = DeviceArgs { device: device.map(str::to_string), validate };
        on_device_with(&d, device.is_some(), |gpu, _| work(gpu)).map(|_| ())
    };
    let run = across_devices::Run {
        options: &options,
        shaders: &shaders,
        validate,
        isa_dir: args.isa.as_deref(),
        precise: args.precise_math,
        lines: args.lines,
    };
    let result = across_devices::inspect(&plan, &run, &local, profile.as_ref())?;
    let stem = result.stem();
    let json = args.json.clone().unwrap_or_else(|| PathBuf::from(format!("results/{stem}.json")));
    let markdown = args.markdown.clone().unwrap_or_else(|| PathBuf::from(format!("results/{stem}.md")));
    let value = result.json_value()?;
    json::write_json(&json, &value)?;
    let input = just_measured(&json, &value)?;
    if args.html.html.is_some() {
        // The lobes and spheres are drawn on the default local device (the inspected ones may only compile).
        let gpu = DeviceArgs { device: None, validate }.open()?;
        args.html.write(&[input], Some(&gpu))?;
        gpu.check_validation()?;
    }
    io::write_markdown(&markdown, &result.markdown)?;
    args.bench.write(&result.bench_entries())?;
    if let (Some(chart), Some(multi)) = (&args.chart, &result.multi) {
        multi.costs.chart(chart)?;
    }
    out!("{}", result.markdown);
    outln!(
        "JSON: {}\nMarkdown: {}{}",
        json.display(),
        markdown.display(),
        args.chart.as_ref().map_or(String::new(), |c| format!("\nChart: {}", c.display()))
    );
    // A model that failed on a target has its reason under that target's cost table; the others were costed.
    let failed: Vec<String> = result
        .reports
        .iter()
        .filter_map(|r| r.cost.as_ref())
        .flat_map(|c| c.failed.iter().map(move |(m, _)| format!("{m} on {}", c.target.as_deref().unwrap_or(&c.device))))
        .collect();
    if !failed.is_empty() {
        eprintln!("brdfprof: inspect: not costed: {} (each reason under its cost table); exit 1", failed.join(", "));
        return Ok(ExitCode::from(1));
    }
    Ok(ExitCode::SUCCESS)
}

/// Refuses, before anything runs, options that `plan`'s devices cannot serve and outputs that cannot be written.
fn check_outputs(
    args: &InspectArgs,
    plan: &[across_devices::Planned],
    models: &[brdfprof::model::Model],
) -> Result<()> {
    let mut inputs = super::model_inputs(models);
    inputs.extend(args.profile.as_deref().map(|p| ("--profile", p)));
    let asked = [
        ("--json", args.json.as_deref()),
        ("--markdown", args.markdown.as_deref()),
        ("--chart", args.chart.as_deref()),
        ("--html", args.html.html.as_deref()),
        ("--bench-json", args.bench.bench_json.as_deref()),
    ];
    super::checked_outputs(&asked, &inputs)?;
    if args.lines
        && !plan.iter().any(|p| matches!(p, across_devices::Planned::Target(t) if brdfprof::targets::names_lines(t)))
    {
        bail!(
            "--lines: only the nvidia: and intel: targets' compilers name each instruction's source line; give one (e.g. --device nvidia:sm_89 --device intel:gen12lp)"
        );
    }
    // A compile-only target's default name is known now (`across_devices::slug`); a local device's only once it is open.
    let default_name = match plan {
        [across_devices::Planned::Target(t)] => format!("inspect-{}", t.slug()),
        [_] => "inspect-<device>".to_string(),
        _ => "inspect-devices".to_string(),
    };
    check_output("--json", args.json.as_deref(), "results", &format!("{default_name}.json"))?;
    check_output("--markdown", args.markdown.as_deref(), "results", &format!("{default_name}.md"))?;
    args.html.check()?;
    args.bench.check()?;
    if let Some(chart) = &args.chart {
        if plan.len() < 2 {
            bail!(
                "--chart {}: the chart compares devices; give several --device (e.g. --device radv:all --device nvidia:all)",
                chart.display()
            );
        }
        io::check_output_path("--chart", chart)?;
    }
    if let Some(dir) = &args.isa {
        if !plan.iter().any(|p| matches!(p, across_devices::Planned::Target(_))) {
            bail!(
                "--isa {}: the listings are a compile-only target's; give one, e.g. --device radv:navi21 or nvidia:sm_89 (see `brdfprof devices --targets`)",
                dir.display()
            );
        }
        io::check_output_dir("--isa", dir)?;
    }
    Ok(())
}
