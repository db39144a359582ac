//! `brdfprof profile`, `sweep` and `stability`: the commands that run kernels and measure them.

use super::{check_output, fresh_compilation, on_device, written, DeviceArgs, ModelArgs, TimingArgs};
use anyhow::{bail, Result};
use brdfprof::brdf::THESIS_MODELS;
use brdfprof::model::Model;
use brdfprof::{io, profile, results, scene, stability, sweep};
use clap::Args;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Args)]
pub struct ProfileArgs {
    #[command(flatten)]
    pub model: ModelArgs,
    #[command(flatten)]
    pub timing: TimingArgs,
    /// G-buffer size, WIDTHxHEIGHT (default 960x540: a quarter of 1080p gives the same ratios on lavapipe as
    /// 1080p and four times the rounds per second, docs/measurement.md).
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
    /// each effect) for a compile-only target (radv:FAMILY, nvidia:FAMILY, intel:FAMILY, PREFIX:all;
    /// repeatable; see `devices --targets`): modelled cycles per pixel and per effect beside the measured ns.
    #[arg(long = "cost-device", value_name = "DEVICE", value_parser = super::device_name)]
    pub cost_devices: Vec<String>,
    /// With --cost-device: write each kernel's compiler output per target as `inspect --isa` does
    /// (DIR/<family>/, DIR/nvidia-<family>/, DIR/intel-<family>/; a kernel per variant, "ggx-without-diffuse").
    #[arg(long)]
    pub isa: Option<PathBuf>,
    #[command(flatten)]
    pub html: super::report::HtmlArg,
    #[command(flatten)]
    pub device: DeviceArgs,
}

pub fn profile(args: &ProfileArgs) -> Result<ExitCode> {
    if let Some(path) = &args.scene {
        return profile_scene(args, path);
    }
    if !args.cost_devices.is_empty() || args.isa.is_some() {
        let device = args.cost_devices.first().map_or("radv:navi21", String::as_str);
        bail!("--cost-device and --isa apply to --scene; for models, `brdfprof inspect --device {device} [--isa DIR]` gives the compile-only targets' figures and listings");
    }
    check_output("--json", args.json.as_deref(), "results", "profile-<device>.json")?;
    args.html.check()?;
    fresh_compilation(args.timing.shader_cache);
    let size = args.size.as_deref().unwrap_or("960x540");
    let options = args.timing.options(args.model.models(&THESIS_MODELS)?, size, args.reps, args.budget, args.target_ci)?;
    let (gpu, result) = on_device(&args.device, |gpu, progress| profile::run(gpu, &options, progress))?;
    let path = args.json.clone().unwrap_or_else(|| PathBuf::from(format!("{}/profile-{}.json", super::DEFAULT_OUT, brdfprof::targets::device_slug(&gpu.info))));
    results::write_report(&path, results::Kind::Profile, &result)?;
    args.html.write(&[super::report::just_measured(&path, &result)?], Some(&gpu))?;
    println!("{}\n", result.summary());
    print!("{}{}", result.table().markdown(), result.placement_notes());
    if let Some(t) = result.light_table() {
        println!("\nns/eval by light count (net of the baseline; the baseline gross):\n\n{}", t.markdown());
    }
    let harness = result.harness_warning();
    if let Some(text) = harness.trim_end().strip_prefix("warning: ") {
        brdfprof::messages::warning(text);
    }
    println!("\nJSON: {}", path.display());
    Ok(ExitCode::SUCCESS)
}

/// `--out`, checked writable; else the default results/, refused where the command's `files` there (patterns,
/// `*` for the device) match a file git tracks.
fn out_dir(given: Option<&std::path::Path>, files: &[&str]) -> Result<PathBuf> {
    if let Some(out) = given {
        io::check_output_dir("--out", out)?;
        return Ok(out.to_path_buf());
    }
    let out = PathBuf::from(super::DEFAULT_OUT);
    io::check_output_dir("--out (default results)", &out)?;
    io::refuse_tracked_default("--out", &out, &files.iter().map(|f| f.to_string()).collect::<Vec<_>>())?;
    Ok(out)
}

fn profile_scene(args: &ProfileArgs, path: &std::path::Path) -> Result<ExitCode> {
    if !args.model.models.is_empty() || !args.model.params.is_empty() {
        bail!("--scene: the scene's materials choose the models; --model and --param do not apply (edit the scene file)");
    }
    if args.size.is_some() {
        bail!("--scene: the G-buffer size is the scene's; --size does not apply");
    }
    if let Some(html) = &args.html.html {
        bail!("--html {}: the HTML report does not draw scene profiles; the scene's tables are in the JSON and printed Markdown (`brdfprof render --scene` draws its pictures)", html.display());
    }
    let cost_targets = cost_targets(&args.cost_devices)?;
    if let Some(dir) = &args.isa {
        if cost_targets.is_empty() {
            bail!("--isa {}: the listings are a compile-only target's; give --cost-device too (e.g. --cost-device radv:navi21)", dir.display());
        }
        io::check_output_dir("--isa", dir)?;
    }
    let scene = scene::Scene::load(path)?;
    check_output("--json", args.json.as_deref(), "results", &format!("scene-{}-<device>.json", scene.name()))?;
    fresh_compilation(args.timing.shader_cache);
    let base = args.timing.options(Vec::new(), "1x1", args.reps, args.budget, args.target_ci)?;
    let options = scene::profile::SceneProfileOptions { protocol: base.protocol, target_rel_ci: args.target_ci, max_chunk: None, instances: base.instances, cost_targets, validate: args.device.validation(), isa_dir: args.isa.clone() };
    let (gpu, result) = on_device(&args.device, |gpu, progress| scene::profile::run(gpu, &scene, &options, progress))?;
    let path = args.json.clone().unwrap_or_else(|| PathBuf::from(format!("{}/scene-{}-{}.json", super::DEFAULT_OUT, scene.name(), brdfprof::targets::device_slug(&gpu.info))));
    results::write_report(&path, results::Kind::SceneProfile, &result)?;
    println!("{}\n", result.summary());
    print!("{}", result.markdown());
    println!("\nJSON: {}", path.display());
    Ok(ExitCode::SUCCESS)
}

#[derive(Args)]
pub struct SweepArgs {
    /// Specs to sweep (default: every D with its sensible Vis terms and Schlick, every Fresnel on ggx,
    /// the thesis models in fp16).
    #[command(flatten)]
    pub model: ModelArgs,
    #[command(flatten)]
    pub timing: TimingArgs,
    /// G-buffer size, WIDTHxHEIGHT: 256x256 gives the same cost ratios as 512x512 on lavapipe (within 2.3%,
    /// inside the CIs) and four times the rounds.
    #[arg(long, default_value = "256x256")]
    pub size: String,
    #[arg(long, default_value_t = 1)]
    pub reps: usize,
    /// Seconds the whole command may take: accuracy, G-buffer, compilation, warm-up and timed rounds.
    #[arg(long, default_value_t = 150.0)]
    pub budget: f64,
    /// CI half-width target: 1.5% resolves neighbours 3% apart.
    #[arg(long, default_value_t = 0.015)]
    pub target_ci: f64,
    /// Directory for sweep-<device>.md, .json and .png (default results/, refused where that would overwrite a
    /// file git tracks).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// What every model's accuracy is measured against: a spec (its exact f64 model) or a model file (.brdf,
    /// .hlsl, .ush, .wgsl, ...: its GPU values). Default: each built-in spec against its own exact model, each
    /// model file against the reference its .brdf names (`reference SPEC`), else ggx.
    #[arg(long)]
    pub reference: Option<String>,
    /// The Fresnel of the exact models: `physical` (the exact dielectric or the metal's conductor Fresnel, so
    /// that the error includes the Fresnel approximation) or `own` (the spec's own F term: the error of its D
    /// and visibility alone).
    #[arg(long, default_value = "physical", value_parser = exact_fresnel)]
    pub exact_fresnel: brdfprof::brdf::exact::ExactFresnel,
    /// Perceptual roughness range of the sample set, MIN..MAX within [0, 1] (default [0.1, 1], or the range
    /// every `.brdf` model's `domain roughness` admits).
    #[arg(long, value_parser = super::roughness_range)]
    pub roughness: Option<(f64, f64)>,
    /// N.V range of the sample set, MIN..MAX within [0, 1] (default [0.05, 1], or every `.brdf` model's `domain nov`).
    #[arg(long, value_parser = super::cosine_range)]
    pub nov: Option<(f64, f64)>,
    /// N.L range of the sample set, as --nov (`domain nol`).
    #[arg(long, value_parser = super::cosine_range)]
    pub nol: Option<(f64, f64)>,
    /// Also draw the table, JSON and Pareto chart with a compile-only target's modelled cycles per evaluation
    /// as the cost (radv:FAMILY, nvidia:FAMILY, intel:FAMILY, PREFIX:all; repeatable; see `devices --targets`):
    /// sweep-<device>-<compiler>-<family>.* (aco, ptxas, igc); with several, sweep-<device>-frontiers.md/.json:
    /// the specs on every target's frontier, and those on some only.
    #[arg(long = "cost-device", value_name = "DEVICE", value_parser = super::device_name)]
    pub cost_devices: Vec<String>,
    #[command(flatten)]
    pub html: super::report::HtmlArg,
    #[command(flatten)]
    pub device: DeviceArgs,
}

/// `--exact-fresnel physical|own`.
fn exact_fresnel(text: &str) -> Result<brdfprof::brdf::exact::ExactFresnel, String> {
    brdfprof::brdf::exact::ExactFresnel::parse(text).ok_or_else(|| format!("`{text}`: give one of {}", brdfprof::brdf::exact::ExactFresnel::NAMES.join(", ")))
}

/// The compile-only targets of `--cost-device`, in order, each once.
fn cost_targets(devices: &[String]) -> Result<Vec<brdfprof::targets::Target>> {
    let mut out: Vec<brdfprof::targets::Target> = Vec::new();
    for d in devices {
        let Some(ts) = brdfprof::targets::parse(d)? else {
            anyhow::bail!("--cost-device {d}: give a compile-only target ({}FAMILY or PREFIX:all; see `brdfprof devices --targets`); the command's own --device is the one that measures", brdfprof::targets::prefixes());
        };
        for t in ts {
            if !out.contains(&t) {
                out.push(t);
            }
        }
    }
    Ok(out)
}

pub fn sweep(args: &SweepArgs) -> Result<ExitCode> {
    let out = out_dir(args.out.as_deref(), &["sweep-*"])?;
    args.html.check()?;
    let cost_targets = cost_targets(&args.cost_devices)?;
    if let Some(d) = args.device.device.as_deref().filter(|d| brdfprof::targets::is_compile_only(d)) {
        return Err(super::compiles_only_error(d));
    }
    fresh_compilation(args.timing.shader_cache);
    let models = if args.model.models.is_empty() { sweep::default_specs().into_iter().map(Model::spec).collect() } else { args.model.models(&[])? };
    let reference = args.reference.as_deref().map(|r| Model::parse(r).map_err(|e| anyhow::anyhow!("--reference {r}: {e:#}"))).transpose()?;
    let (domain, why) = super::sample_domain([args.roughness, args.nov, args.nol], brdfprof::accuracy::STANDARD_DOMAIN, &models.iter().collect::<Vec<_>>())?;
    let accuracy = sweep::AccuracyOptions { reference, exact_fresnel: args.exact_fresnel, domain, domain_why: why };
    let options = sweep::SweepOptions { profile: args.timing.options(models, &args.size, args.reps, args.budget, args.target_ci)?, accuracy };
    let shaders = options.profile.glsl.as_deref().map(brdfprof::shaders::Shaders::from_glsl).transpose()?.unwrap_or_else(brdfprof::shaders::Shaders::embedded);
    let validate = args.device.validation();
    let (gpu, (result, costs)) = on_device(&args.device, |gpu, progress| {
        // The targets' figures first (seconds): a missing compiler fails before the long measurement.
        let request = brdfprof::targets::Request { models: &options.profile.models, lights: options.profile.lights[0], shaders: &shaders, validate, isa_dir: None, precise: false, verify_on: Some(gpu), lines: false };
        let costs = brdfprof::targets::compile_all(&cost_targets, &request)?;
        Ok((sweep::run(gpu, &options, progress)?, costs))
    })?;
    for r in result.rows.iter().filter(|r| r.accuracy.vs_exact.nonfinite > 0) {
        brdfprof::messages::warning(format!("{}: {} of {} values on the sample set are NaN or Inf", r.spec, r.accuracy.vs_exact.nonfinite, r.accuracy.vs_exact.values));
    }
    let slug = brdfprof::targets::device_slug(&gpu.info);
    let mut files = result.write(&out, &slug)?;
    files.extend(args.html.write(&[super::report::just_measured(&out.join(format!("sweep-{slug}.json")), &result)?], Some(&gpu))?);
    print!("{}", result.markdown());
    let mut missing = false;
    let mut swept_all = Vec::new();
    for run in &costs {
        let name = run.target.name();
        let table = run.report.cost.clone().ok_or_else(|| anyhow::anyhow!("{name}: the compiler reported no statistics the cost model reads"))?;
        let note = run.report.section_notes.get("driver/").map(String::as_str).filter(|n| n.starts_with("not compiled"));
        let swept = brdfprof::sweep_cost::build(&result, &name, &table, note)?;
        if let Some(skipped) = &swept.skipped {
            // Every model asked for is in every table, or the command says which is not, and exits 1.
            brdfprof::messages::warning(format!("{skipped}: those specs have no {name} figure"));
            missing = true;
        }
        let family = table.family.clone().unwrap_or_else(|| name.replace(':', "-"));
        files.extend(swept.write(&out.join(format!("sweep-{slug}-{}-{family}", table.compiler.to_ascii_lowercase())))?);
        print!("\n{}", swept.markdown());
        swept_all.push(swept);
    }
    if swept_all.len() > 1 {
        let frontiers = brdfprof::sweep_cost::Frontiers::of(&swept_all);
        files.extend(frontiers.write(&out.join(format!("sweep-{slug}-frontiers")))?);
        print!("\n{}", frontiers.markdown());
    }
    println!("\n{}", written(&files));
    Ok(if missing { ExitCode::from(1) } else { ExitCode::SUCCESS })
}

#[derive(Args)]
pub struct StabilityArgs {
    #[command(flatten)]
    pub model: ModelArgs,
    /// Skip the directional-albedo (energy) part.
    #[arg(long)]
    pub no_energy: bool,
    /// Also check each spec without brdfprof's guards (`guards=off`, docs/guards.md) and with each guard off
    /// alone (`guards=off:NAME`), listed next to it: the hard cases it then fails are the ones its guards save
    /// (the report's "What each guard saves").
    #[arg(long)]
    pub unguarded: bool,
    /// Check the models that have no f64 twin (`.brdf` files) against this built-in spec's f64 values: their
    /// tolerances and jumps then mean what a built-in spec's do (e.g. `--reference ggx`).
    #[arg(long, value_parser = super::reference_spec)]
    pub reference: Option<brdfprof::brdf::ModelSpec>,
    /// Perceptual roughness range checked, MIN..MAX within [0, 1]: hard cases and grid points outside it are
    /// not counted (default: each `.brdf` file's `domain roughness`, else all).
    #[arg(long, value_parser = super::roughness_range)]
    pub roughness: Option<(f64, f64)>,
    /// N.V range checked, MIN..MAX within [0, 1] (default: each `.brdf` file's `domain nov`, else all).
    #[arg(long, value_parser = super::cosine_range)]
    pub nov: Option<(f64, f64)>,
    /// N.L range checked, MIN..MAX within [0, 1] (default: each `.brdf` file's `domain nol`, else all).
    #[arg(long, value_parser = super::cosine_range)]
    pub nol: Option<(f64, f64)>,
    /// Directory for stability-<device>.md/.json and the furnace, albedo and failure PNGs (default results/,
    /// refused where that would overwrite a file git tracks).
    #[arg(long)]
    pub out: Option<PathBuf>,
    #[command(flatten)]
    pub html: super::report::HtmlArg,
    #[command(flatten)]
    pub device: DeviceArgs,
}

pub fn stability(args: &StabilityArgs) -> Result<ExitCode> {
    let out = out_dir(args.out.as_deref(), &["stability-*", "furnace-*.png", "albedo-*.png"])?;
    args.html.check()?;
    let models = if args.model.models.is_empty() { stability::default_specs().into_iter().map(Model::spec).collect() } else { args.model.models(&[])? };
    let options = stability::StabilityOptions { models: if args.unguarded { stability::with_guard_variants(models) } else { models }, energy: !args.no_energy, reference: args.reference, roughness: args.roughness, nov: args.nov, nol: args.nol };
    let (gpu, result) = on_device(&args.device, |gpu, progress| stability::run(gpu, &options, progress))?;
    let slug = brdfprof::targets::device_slug(&gpu.info);
    let mut files = result.write(&out, &slug)?;
    files.extend(args.html.write(&[super::report::just_measured(&out.join(format!("stability-{slug}.json")), &result)?], Some(&gpu))?);
    print!("{}", result.markdown());
    println!("\n{}", written(&files));
    let failing = result.failing();
    if failing.is_empty() {
        return Ok(ExitCode::SUCCESS);
    }
    brdfprof::messages::progress(format!("{} spec(s) give NaN, Inf or negative values on valid inputs", failing.len()));
    Ok(ExitCode::from(1))
}
