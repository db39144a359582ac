//! `brdfprof sweep`: many model specs timed in one interleaved run and measured for accuracy; error against
//! cost and the Pareto frontier, also with compile-only targets' modelled cost.

use super::args::{BenchArg, DeviceArgs, HtmlArg, ModelArgs, TimingArgs, cosine_range, device_name, roughness_range};
use super::{cost_targets, fresh_compilation, just_measured, on_device, out_dir, written};
use anyhow::Result;
use brdfprof::model::Model;
use brdfprof::sweep;
use clap::Args;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

#[derive(Args)]
pub struct SweepArgs {
    /// Specs to sweep (default: every D with its sensible Vis terms and Schlick, every Fresnel on ggx,
    /// the thesis models in fp16).
    #[command(flatten)]
    pub model: ModelArgs,
    #[command(flatten)]
    pub timing: TimingArgs,
    /// G-buffer size, WIDTHxHEIGHT (why this default: docs/results-lavapipe.md, the sweep).
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
    #[arg(long, value_parser = roughness_range)]
    pub roughness: Option<(f64, f64)>,
    /// N.V range of the sample set, MIN..MAX within [0, 1] (default [0.05, 1], or every `.brdf` model's `domain nov`).
    #[arg(long, value_parser = cosine_range)]
    pub nov: Option<(f64, f64)>,
    /// N.L range of the sample set, as --nov (`domain nol`).
    #[arg(long, value_parser = cosine_range)]
    pub nol: Option<(f64, f64)>,
    /// F0 of the sample set: MIN..MAX (every channel), R0..R1,G0..G1,B0..B1, `materials` (13 real materials,
    /// as diff's) or `uniform` ([0, 1]^3); default: dielectric F0 (0.02, 0.04, 0.08) or (0.03, 0.05, 0.045).
    /// With --exact-fresnel physical a Schlick spec's reference is the exact dielectric Fresnel at the sample's
    /// F0, so a metal's F0 reads as a dielectric's; --exact-fresnel own leaves Fresnel out of the error.
    #[arg(long, value_parser = brdfprof::diff::F0Set::parse)]
    pub f0: Option<brdfprof::diff::F0Set>,
    /// Also draw the table, JSON and Pareto chart with a compile-only target's modelled cycles per evaluation
    /// as the cost (radv:, nvidia:, intel:, adreno:, mali:, anv: or nak:FAMILY, PREFIX:all; repeatable; see
    /// `devices --targets`):
    /// sweep-<device>-<compiler>-<family>.* (aco, ptxas, igc); with several, sweep-<device>-frontiers.md/.json:
    /// the specs on every target's frontier, and those on some only.
    #[arg(long = "cost-device", value_name = "DEVICE", value_parser = device_name)]
    pub cost_devices: Vec<String>,
    #[command(flatten)]
    pub html: HtmlArg,
    #[command(flatten)]
    pub bench: BenchArg,
    #[command(flatten)]
    pub device: DeviceArgs,
}

/// `--exact-fresnel physical|own`.
fn exact_fresnel(text: &str) -> Result<brdfprof::brdf::exact::ExactFresnel, String> {
    brdfprof::brdf::exact::ExactFresnel::parse(text)
        .ok_or_else(|| format!("`{text}`: give one of {}", brdfprof::brdf::exact::ExactFresnel::NAMES.join(", ")))
}

impl super::Run for SweepArgs {
    fn run(&self) -> Result<ExitCode> {
        sweep(self)
    }
}

pub fn sweep(args: &SweepArgs) -> Result<ExitCode> {
    let out = out_dir(args.out.as_deref(), &["sweep-*"])?;
    args.html.check()?;
    args.bench.check()?;
    let cost_targets = cost_targets(&args.cost_devices)?;
    if let Some(d) = args.device.device.as_deref().filter(|d| brdfprof::targets::is_compile_only(d)) {
        return Err(super::compiles_only_error(d));
    }
    fresh_compilation(args.timing.shader_cache);
    let models = if args.model.models.is_empty() {
        sweep::default_specs().into_iter().map(Model::spec).collect()
    } else {
        args.model.models(&[])?
    };
    let asked = [("--html", args.html.html.as_deref()), ("--bench-json", args.bench.bench_json.as_deref())];
    super::checked_outputs(&asked, &super::model_inputs(&models))?;
    let reference = args
        .reference
        .as_deref()
        .map(|r| Model::parse(r).map_err(|e| anyhow::anyhow!("--reference {r}: {e:#}")))
        .transpose()?;
    let (domain, why) = super::sample_domain(
        [args.roughness, args.nov, args.nol],
        brdfprof::accuracy::STANDARD_DOMAIN,
        &models.iter().collect::<Vec<_>>(),
    )?;
    let accuracy =
        sweep::AccuracyOptions { reference, exact_fresnel: args.exact_fresnel, domain, domain_why: why, f0: args.f0 };
    let options = sweep::SweepOptions {
        profile: args.timing.options(models, &args.size, args.reps, args.budget, args.target_ci)?,
        accuracy,
    };
    let shaders = options
        .profile
        .glsl
        .as_deref()
        .map(brdfprof::shaders::Shaders::from_glsl)
        .transpose()?
        .unwrap_or_else(brdfprof::shaders::Shaders::embedded);
    let validate = args.device.validation();
    let (gpu, (result, costs)) = on_device(&args.device, |gpu, progress| {
        // The targets' figures first (seconds): a missing compiler fails before the long measurement.
        let request = brdfprof::targets::Request {
            models: &options.profile.models,
            lights: options.profile.lights[0],
            shaders: &shaders,
            validate,
            isa_dir: None,
            precise: false,
            verify_on: Some(gpu),
            lines: false,
        };
        let costs = brdfprof::targets::compile_all(&cost_targets, &request)?;
        Ok((sweep::run(gpu, &options, progress)?, costs))
    })?;
    for r in result.rows.iter().filter(|r| r.accuracy.vs_exact.nonfinite > 0) {
        brdfprof::messages::warning(format!(
            "{}: {} of {} values on the sample set are NaN or Inf",
            r.spec, r.accuracy.vs_exact.nonfinite, r.accuracy.vs_exact.values
        ));
    }
    let slug = brdfprof::targets::device_slug(&gpu.info);
    let mut files = result.write(&out, &slug)?;
    files.extend(args.html.write(&[just_measured(&out.join(format!("sweep-{slug}.json")), &result)?], Some(&gpu))?);
    args.bench.write(&result.profile.bench_entries("sweep"))?;
    out!("{}", result.markdown());
    let missing = write_cost_tables(&result, &costs, &out, &slug, &mut files)?;
    outln!("\n{}", written(&files));
    Ok(if missing { ExitCode::from(1) } else { ExitCode::SUCCESS })
}

/// Each target's cost table of the swept specs beside `result`'s files in `out` (added to `files`), printed,
/// and the frontiers across targets where there are several. True when some spec has no figure on some target.
fn write_cost_tables(
    result: &sweep::SweepReport,
    costs: &[brdfprof::targets::Run],
    out: &Path,
    slug: &str,
    files: &mut Vec<PathBuf>,
) -> Result<bool> {
    let mut missing = false;
    let mut swept_all = Vec::new();
    for run in costs {
        let name = run.target.name();
        let table = run
            .report
            .cost
            .clone()
            .ok_or_else(|| anyhow::anyhow!("{name}: the compiler reported no statistics the cost model reads"))?;
        let note =
            run.report.section_notes.get("driver/").map(String::as_str).filter(|n| n.starts_with("not compiled"));
        let swept = brdfprof::sweep::cost::build(result, &name, &table, note)?;
        if let Some(skipped) = &swept.skipped {
            // Every model asked for is in every table, or the command says which is not, and exits 1.
            brdfprof::messages::warning(format!("{skipped}: those specs have no {name} figure"));
            missing = true;
        }
        let family = table.family.clone().unwrap_or_else(|| name.replace(':', "-"));
        files.extend(swept.write(&out.join(format!("sweep-{slug}-{}-{family}", table.compiler.to_ascii_lowercase())))?);
        out!("\n{}", swept.markdown());
        swept_all.push(swept);
    }
    if swept_all.len() > 1 {
        let frontiers = brdfprof::sweep::cost::Frontiers::of(&swept_all);
        files.extend(frontiers.write(&out.join(format!("sweep-{slug}-frontiers")))?);
        out!("\n{}", frontiers.markdown());
    }
    Ok(missing)
}
