//! `brdfprof profile`: the cost per BRDF evaluation of models over a synthetic G-buffer, or with `--scene` of a
//! scene's kernels and effects.

use super::args::{BenchArg, DeviceArgs, HtmlArg, ModelArgs, TimingArgs, device_name};
use super::{check_output, cost_targets, fresh_compilation, just_measured, on_device};
use anyhow::{Result, bail};
use brdfprof::brdf::THESIS_MODELS;
use brdfprof::{export::json, io, profile, scene};
use clap::Args;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Args)]
pub struct ProfileArgs {
    #[command(flatten)]
    pub model: ModelArgs,
    #[command(flatten)]
    pub timing: TimingArgs,
    /// G-buffer size, WIDTHxHEIGHT (default 960x540, a quarter of 1080p; why: docs/measurement.md).
    #[arg(long)]
    pub size: Option<String>,
    /// Timed dispatches of each kernel per round.
    #[arg(long, default_value_t = 1)]
    pub reps: usize,
    /// Seconds the whole command may take: building the G-buffer, compiling, warming up and the timed
    /// rounds (which also stop once every ratio is resolved).
    #[arg(long, default_value_t = 30.0)]
    pub budget: f64,
    /// Stop when every ratio's 95% CI half-width is below this fraction of the ratio.
    #[arg(long, default_value_t = 0.02)]
    pub target_ci: f64,
    /// JSON report path (default: results/profile-<device>.json; with --scene results/scene-<name>-<device>.json).
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// Profile a scene file instead (see `brdfprof scene --explain`): what is compiled in, each kernel's
    /// ns/pixel and each effect's cost, measured by toggling it. The G-buffer size and models are the scene's.
    #[arg(long)]
    pub scene: Option<PathBuf>,
    /// With --scene: also compile every kernel the scene profile times (each kernel as compiled and without
    /// each effect) for a compile-only target (radv:, nvidia:, intel:, adreno:, mali:, anv: or nak:FAMILY,
    /// PREFIX:all; repeatable; see `devices --targets`): modelled cycles per pixel and per effect beside the measured ns.
    #[arg(long = "cost-device", value_name = "DEVICE", value_parser = device_name)]
    pub cost_devices: Vec<String>,
    /// With --cost-device: write each kernel's compiler output per target as `inspect --isa` does
    /// (DIR/<family>/, DIR/nvidia-<family>/, DIR/intel-<family>/; a kernel per variant, "ggx-without-diffuse").
    #[arg(long)]
    pub isa: Option<PathBuf>,
    #[command(flatten)]
    pub html: HtmlArg,
    #[command(flatten)]
    pub bench: BenchArg,
    #[command(flatten)]
    pub device: DeviceArgs,
}

impl super::Run for ProfileArgs {
    fn run(&self) -> Result<ExitCode> {
        profile(self)
    }
}

pub fn profile(args: &ProfileArgs) -> Result<ExitCode> {
    if let Some(path) = &args.scene {
        return profile_scene(args, path);
    }
    if !args.cost_devices.is_empty() || args.isa.is_some() {
        let device = args.cost_devices.first().map_or("radv:navi21", String::as_str);
        bail!(
            "--cost-device and --isa apply to --scene; for models, `brdfprof inspect --device {device} [--isa DIR]` gives the compile-only targets' figures and listings"
        );
    }
    check_output("--json", args.json.as_deref(), "results", "profile-<device>.json")?;
    args.html.check()?;
    args.bench.check()?;
    fresh_compilation(args.timing.shader_cache);
    let size = args.size.as_deref().unwrap_or("960x540");
    let models = args.model.models(&THESIS_MODELS)?;
    let asked = [
        ("--json", args.json.as_deref()),
        ("--html", args.html.html.as_deref()),
        ("--bench-json", args.bench.bench_json.as_deref()),
    ];
    super::checked_outputs(&asked, &super::model_inputs(&models))?;
    let options = args.timing.options(models, size, args.reps, args.budget, args.target_ci)?;
    let (gpu, result) = on_device(&args.device, |gpu, progress| profile::run(gpu, &options, progress))?;
    let path = args.json.clone().unwrap_or_else(|| {
        PathBuf::from(format!("{}/profile-{}.json", super::DEFAULT_OUT, brdfprof::targets::device_slug(&gpu.info)))
    });
    json::write_report(&path, json::Kind::Profile, &result)?;
    args.html.write(&[just_measured(&path, &result)?], Some(&gpu))?;
    args.bench.write(&result.bench_entries("profile"))?;
    outln!("{}\n", result.summary());
    out!("{}{}{}", result.table().markdown(), result.interval_notes(), result.placement_notes());
    if let Some(t) = result.light_table() {
        outln!("\nns/eval by light count (net of the baseline; the baseline gross):\n\n{}", t.markdown());
    }
    let harness = result.harness_warning();
    if let Some(text) = harness.trim_end().strip_prefix("warning: ") {
        brdfprof::messages::warning(text);
    }
    outln!("\nJSON: {}", path.display());
    Ok(ExitCode::SUCCESS)
}

fn profile_scene(args: &ProfileArgs, path: &std::path::Path) -> Result<ExitCode> {
    if !args.model.models.is_empty() || !args.model.params.is_empty() {
        bail!(
            "--scene: the scene's materials choose the models; --model and --param do not apply (edit the scene file)"
        );
    }
    if args.size.is_some() {
        bail!("--scene: the G-buffer size is the scene's; --size does not apply");
    }
    if let Some(html) = &args.html.html {
        bail!(
            "--html {}: the HTML report does not draw scene profiles; the scene's tables are in the JSON and printed Markdown (`brdfprof render --scene` draws its pictures)",
            html.display()
        );
    }
    let cost_targets = cost_targets(&args.cost_devices)?;
    if let Some(dir) = &args.isa {
        if cost_targets.is_empty() {
            bail!(
                "--isa {}: the listings are a compile-only target's; give --cost-device too (e.g. --cost-device radv:navi21)",
                dir.display()
            );
        }
        io::check_output_dir("--isa", dir)?;
    }
    let scene = scene::Scene::load(path)?;
    check_output("--json", args.json.as_deref(), "results", &format!("scene-{}-<device>.json", scene.name()))?;
    fresh_compilation(args.timing.shader_cache);
    let base = args.timing.options(Vec::new(), "1x1", args.reps, args.budget, args.target_ci)?;
    let options = scene::profile::SceneProfileOptions {
        protocol: base.protocol,
        target_rel_ci: args.target_ci,
        max_chunk: None,
        instances: base.instances,
        cost_targets,
        validate: args.device.validation(),
        isa_dir: args.isa.clone(),
    };
    let (gpu, result) = on_device(&args.device, |gpu, progress| scene::profile::run(gpu, &scene, &options, progress))?;
    let path = args.json.clone().unwrap_or_else(|| {
        PathBuf::from(format!(
            "{}/scene-{}-{}.json",
            super::DEFAULT_OUT,
            scene.name(),
            brdfprof::targets::device_slug(&gpu.info)
        ))
    });
    json::write_report(&path, json::Kind::SceneProfile, &result)?;
    outln!("{}\n", result.summary());
    out!("{}", result.markdown());
    outln!("\nJSON: {}", path.display());
    Ok(ExitCode::SUCCESS)
}
