//! The brdfprof command line: parses arguments, calls the library, prints and writes reports.
//! Exit status: 0 success; 1 the command ran and found a problem (stability, regression); 2 bad input or
//! anything that stopped the command from measuring.

use anyhow::{anyhow, Result};
use brdfprof::brdf::{spec, ModelSpec, Metal, D, F, Vis};
use brdfprof::gpu::{self, Gpu, GpuOptions};
use brdfprof::profile::{self, protocol::ProtocolOptions, ProfileOptions};
use brdfprof::inspect::callgrind::CallgrindOptions;
use brdfprof::inspect::glsl::KernelSet;
use brdfprof::inspect::check::{self, CheckOptions, Thresholds};
use brdfprof::inspect::timing::TimingOptions;
use brdfprof::inspect::{self, InspectOptions};
use brdfprof::{io, kernels, report, scene, stability, sweep};
use clap::{Args, Parser, Subcommand};
use indicatif::{ProgressBar, ProgressStyle};
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Duration;

#[derive(Parser)]
#[command(name = "brdfprof", version, about = "Evaluate and profile specular BRDFs in Vulkan compute kernels")]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Args, Clone)]
struct DeviceArgs {
    /// Device index (see `brdfprof devices`) or a case-insensitive substring of its name.
    /// Default: the first discrete or integrated GPU, else lavapipe.
    #[arg(long)]
    device: Option<String>,
    /// Run under the Khronos validation layer and fail on any message (also BRDFPROF_VALIDATION=1).
    #[arg(long)]
    validate: bool,
}

impl DeviceArgs {
    fn open(&self) -> Result<Gpu> {
        let env = std::env::var("BRDFPROF_VALIDATION").is_ok_and(|v| !v.is_empty() && v != "0");
        Gpu::new(&GpuOptions { device: self.device.clone(), validation: self.validate || env })
    }
}

#[derive(Args, Clone)]
struct ModelArgs {
    /// Model spec: a preset (ggx, blinn, cook-torrance, burley, ue-default-lit, filament-high, filament-low)
    /// or d=..,vis=..,f=..,precision=..; see `brdfprof models`.
    #[arg(long = "model")]
    models: Vec<String>,
    /// Parameter override applied to every model, e.g. gamma=1.5 (GTR exponent), metal=copper, precision=f16.
    #[arg(long = "param")]
    params: Vec<String>,
}

impl ModelArgs {
    fn specs(&self, default: &[&str]) -> Result<Vec<ModelSpec>> {
        let names: Vec<String> = if self.models.is_empty() { default.iter().map(|s| s.to_string()).collect() } else { self.models.clone() };
        names
            .iter()
            .map(|m| ModelSpec::parse(m).and_then(|s| s.with_params(&self.params)).map_err(|e| anyhow!("--model {m}: {e}")))
            .collect()
    }
}

/// Size and protocol of a timed run, shared by `profile` and `sweep`.
#[derive(Args, Clone)]
struct TimingArgs {
    /// Directional lights per pixel (a specialisation constant: the light loop is unrolled).
    #[arg(long, default_value_t = 8)]
    lights: u32,
    /// Minimum and maximum number of interleaved rounds.
    #[arg(long, default_value_t = 12)]
    min_rounds: usize,
    #[arg(long, default_value_t = 400)]
    max_rounds: usize,
    /// Seed of the interleaving order.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Independently compiled pipelines per kernel, all timed every round (the faster counts): guards against
    /// one JIT compilation landing badly placed, seen to double a kernel's time on lavapipe.
    #[arg(long, default_value_t = 2)]
    instances: usize,
    /// Keep Mesa's on-disk shader cache (timed runs switch it off by default; see `fresh_compilation`).
    #[arg(long)]
    shader_cache: bool,
}

impl TimingArgs {
    fn options(&self, models: Vec<ModelSpec>, size: &str, reps: usize, budget: f64, target_ci: f64) -> Result<ProfileOptions> {
        let (width, height) = parse_size(size)?;
        if self.lights == 0 {
            return Err(anyhow!("--lights must be at least 1"));
        }
        let min_rounds = self.min_rounds.max(1);
        Ok(ProfileOptions {
            models,
            width,
            height,
            lights: self.lights,
            protocol: ProtocolOptions {
                min_rounds,
                max_rounds: self.max_rounds.max(min_rounds),
                reps: reps.max(1),
                budget: Duration::from_secs_f64(budget),
                seed: self.seed,
            },
            target_rel_ci: target_ci,
            max_chunk: None,
            instances: self.instances.max(1),
        })
    }
}

fn progress_bar() -> ProgressBar {
    let progress = ProgressBar::new(0)
        .with_style(ProgressStyle::with_template("{spinner} {elapsed} round {pos} {msg}").expect("valid progress template"));
    progress.enable_steady_tick(Duration::from_millis(200));
    progress
}

#[derive(Subcommand)]
enum Command {
    /// List Vulkan devices with the properties that matter for profiling.
    Devices,
    /// List the terms (with citations) and presets that model specs can name.
    Models,
    /// Evaluate f_s of one model on the GPU for every row of a CSV file.
    Eval {
        #[command(flatten)]
        model: ModelArgs,
        /// CSV with columns nx,ny,nz,vx,vy,vz,lx,ly,lz,roughness,f0r,f0g,f0b (any order; others ignored).
        #[arg(long)]
        input: PathBuf,
        /// CSV written with columns r,g,b, one row per input row (written atomically).
        #[arg(long)]
        output: PathBuf,
        #[command(flatten)]
        device: DeviceArgs,
    },
    /// Measure the cost per BRDF evaluation of models over a synthetic G-buffer lit by several lights.
    Profile {
        #[command(flatten)]
        model: ModelArgs,
        #[command(flatten)]
        timing: TimingArgs,
        /// G-buffer size, WIDTHxHEIGHT.
        #[arg(long, default_value = "1920x1080")]
        size: String,
        /// Timed dispatches of each kernel per round.
        #[arg(long, default_value_t = 3)]
        reps: usize,
        /// Seconds of timed rounds at most (the run also stops once every ratio is resolved).
        #[arg(long, default_value_t = 60.0)]
        budget: f64,
        /// Stop when every ratio's 95% CI half-width is below this fraction of the ratio.
        #[arg(long, default_value_t = 0.02)]
        target_ci: f64,
        /// JSON report path (default: results/profile-<device>.json; with --scene results/scene-<name>-<device>.json).
        #[arg(long)]
        json: Option<PathBuf>,
        /// Profile a scene file instead (see `brdfprof scene --explain`): what is compiled in, each kernel's
        /// ns/pixel and each effect's cost, measured by toggling it. The G-buffer size is the scene's.
        #[arg(long)]
        scene: Option<PathBuf>,
        #[command(flatten)]
        device: DeviceArgs,
    },
    /// Check a scene file and say what it compiles in; --explain prints the scene format with an example.
    Scene {
        /// Scene file to check.
        file: Option<PathBuf>,
        #[arg(long)]
        explain: bool,
    },
    /// Render a scene: a tone-mapped sRGB PNG per model, the comparison grid, difference heat maps against ggx
    /// and polar lobe plots, under --out (default results/scenes/<scene name>/).
    Render {
        #[arg(long)]
        scene: PathBuf,
        #[arg(long)]
        out: Option<PathBuf>,
        #[command(flatten)]
        device: DeviceArgs,
    },
    /// Time and measure the accuracy of many model specs in one interleaved run: table, JSON and a chart of
    /// error against cost with the Pareto frontier, under --out (default results/).
    Sweep {
        /// Specs to sweep (default: every D with its sensible Vis terms and Schlick, every Fresnel on ggx,
        /// the thesis models in fp16).
        #[command(flatten)]
        model: ModelArgs,
        #[command(flatten)]
        timing: TimingArgs,
        #[arg(long, default_value = "512x512")]
        size: String,
        #[arg(long, default_value_t = 1)]
        reps: usize,
        #[arg(long, default_value_t = 150.0)]
        budget: f64,
        /// CI half-width target: 1.5% resolves neighbours 3% apart.
        #[arg(long, default_value_t = 0.015)]
        target_ci: f64,
        /// Directory for sweep-<device>.md, .json and .png.
        #[arg(long, default_value = "results")]
        out: PathBuf,
        #[command(flatten)]
        device: DeviceArgs,
    },
    /// Run the hard-case catalogue, dense grids, reciprocity and energy checks on the GPU for every spec
    /// (default: every D x Vis and every Fresnel on ggx, fp32 and fp16). Exit 1 when any spec yields NaN, Inf
    /// or a negative value on a valid input.
    Stability {
        #[command(flatten)]
        model: ModelArgs,
        /// Skip the directional-albedo (energy) part.
        #[arg(long)]
        no_energy: bool,
        /// Directory for stability-<device>.md/.json and the furnace, albedo and failure PNGs.
        #[arg(long, default_value = "results")]
        out: PathBuf,
        #[command(flatten)]
        device: DeviceArgs,
    },
    /// Instruction counts of each model's specialised shading kernel: SPIR-V by class (glslang and
    /// spirv-opt -O), naga's analysis, driver statistics, and on lavapipe the CPU instructions executed per
    /// BRDF evaluation (callgrind).
    Inspect {
        #[command(flatten)]
        model: ModelArgs,
        #[command(flatten)]
        inspect: InspectArgs,
        /// JSON report path (default: results/inspect-<device>.json).
        #[arg(long)]
        json: Option<PathBuf>,
        /// Markdown report path (default: results/inspect-<device>.md).
        #[arg(long)]
        markdown: Option<PathBuf>,
        /// A `brdfprof profile` JSON report: adds callgrind's instructions per evaluation next to its ns per
        /// evaluation, with their rank correlation.
        #[arg(long)]
        profile: Option<PathBuf>,
        #[command(flatten)]
        device: DeviceArgs,
    },
    /// Measures the counts and a short timing run and compares them with a saved baseline: exit 0 no
    /// regression, 1 regression, 2 could not measure.
    Check {
        /// Baseline to compare with (from `check --save-baseline`).
        #[arg(long)]
        baseline: Option<PathBuf>,
        /// Write this run as a baseline (atomically), whatever the comparison found.
        #[arg(long)]
        save_baseline: Option<PathBuf>,
        /// Regression threshold of a statistic or a section, e.g. spirv/total=0.02, callgrind=0.005, timing=0.1
        /// (defaults: 0.01 for counts, 0.05 for timings).
        #[arg(long = "threshold")]
        thresholds: Vec<String>,
        /// Compare timings and callgrind counts even when the baseline comes from another environment.
        #[arg(long)]
        force: bool,
        /// Models (default: the baseline's, else the thesis models).
        #[command(flatten)]
        model: ModelArgs,
        #[command(flatten)]
        inspect: InspectArgs,
        #[command(flatten)]
        timing: CheckTimingArgs,
        #[command(flatten)]
        device: DeviceArgs,
    },
    #[command(name = "__callgrind-child", hide = true)]
    CallgrindChild { request: String },
}

#[derive(Args, Clone)]
struct InspectArgs {
    /// Directional lights per pixel (default 8; `check` defaults to the baseline's).
    #[arg(long)]
    lights: Option<u32>,
    /// Compile the kernels from this GLSL directory (a copy of glsl/, with its kernels.txt) with glslang
    /// instead of using the embedded SPIR-V.
    #[arg(long)]
    glsl: Option<PathBuf>,
    /// Skip the callgrind run.
    #[arg(long)]
    no_callgrind: bool,
    /// G-buffer of the callgrind dispatch, WIDTHxHEIGHT.
    #[arg(long, default_value = "64x64")]
    callgrind_size: String,
}

impl InspectArgs {
    fn kernels(&self) -> Result<KernelSet> {
        self.glsl.as_deref().map_or_else(|| Ok(KernelSet::embedded()), KernelSet::from_glsl)
    }

    /// How to run the callgrind child (None: --no-callgrind); it inherits validation from the parent.
    fn callgrind(&self, device: &DeviceArgs) -> Result<Option<CallgrindOptions>> {
        let (width, height) = parse_size(&self.callgrind_size).map_err(|e| anyhow!("--callgrind-{}", e.to_string().trim_start_matches("--")))?;
        let validate = device.validate || std::env::var("BRDFPROF_VALIDATION").is_ok_and(|v| !v.is_empty() && v != "0");
        Ok((!self.no_callgrind).then_some(CallgrindOptions { width, height, device: None, validate }))
    }
}

#[derive(Args, Clone)]
struct CheckTimingArgs {
    /// Interleaved timing rounds (at least 9 for the significance test; 0 skips timing).
    #[arg(long, default_value_t = 15)]
    rounds: usize,
    /// Timed dispatches of each kernel per round.
    #[arg(long, default_value_t = 3)]
    reps: usize,
    /// G-buffer of the timing run, WIDTHxHEIGHT.
    #[arg(long, default_value = "960x540")]
    timing_size: String,
    /// Keep Mesa's on-disk shader cache (timed runs switch it off by default; see `fresh_compilation`).
    #[arg(long)]
    shader_cache: bool,
}

/// Timed runs compile every pipeline afresh (MESA_SHADER_CACHE_DISABLE=true unless the user set it or asked
/// to keep the cache): with Mesa's on-disk shader cache a process runs binaries an earlier process compiled,
/// and on lavapipe that moved one scene effect's cost from 0.3 to 19 ns/pixel between runs, where fresh
/// compilation gave the same figure run after run. The variable is recorded in every report's environment.
fn fresh_compilation(keep_cache: bool) {
    if !keep_cache && std::env::var_os("MESA_SHADER_CACHE_DISABLE").is_none() {
        // SAFETY: called on the main thread before any other thread exists and before the Vulkan driver,
        // which reads the variable, is loaded.
        unsafe { std::env::set_var("MESA_SHADER_CACHE_DISABLE", "true") };
    }
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match run(cli) {
        Ok(code) => code,
        Err(e) => {
            eprintln!("brdfprof: error: {e:#}");
            ExitCode::from(2)
        }
    }
}

fn run(cli: Cli) -> Result<ExitCode> {
    match cli.command {
        Command::Devices => devices(),
        Command::Models => {
            print!("{}", models_text());
            Ok(ExitCode::SUCCESS)
        }
        Command::Eval { model, input, output, device } => {
            let specs = model.specs(&[])?;
            let [spec] = specs.as_slice() else {
                return Err(anyhow!("eval takes exactly one --model"));
            };
            let samples = io::read_samples_csv(&input)?;
            let gpu = device.open()?;
            let values = kernels::eval(&gpu, spec, &samples, kernels::RunLimits::default())?;
            gpu.check_validation()?;
            io::write_atomic(&output, io::format_rgb_csv(&values).as_bytes())?;
            eprintln!("brdfprof: {} rows of {} on {} -> {}", values.len(), spec, gpu.info.name, output.display());
            Ok(ExitCode::SUCCESS)
        }
        Command::Profile { scene: Some(path), timing, reps, budget, target_ci, json, device, .. } => {
            fresh_compilation(timing.shader_cache);
            let scene = scene::Scene::load(&path)?;
            let base = timing.options(Vec::new(), "1x1", reps, budget, target_ci)?;
            let options = scene::profile::SceneProfileOptions { protocol: base.protocol, target_rel_ci: target_ci, max_chunk: None, instances: base.instances };
            let gpu = device.open()?;
            let progress = progress_bar();
            let result = scene::profile::run(&gpu, &scene, &options, &progress);
            progress.finish_and_clear();
            let result = result?;
            gpu.check_validation()?;
            let path = json.unwrap_or_else(|| PathBuf::from(format!("results/scene-{}-{}.json", scene.name(), report::device_slug(&gpu.info))));
            report::write_json(&path, &result)?;
            println!("{}\n", result.summary());
            print!("{}", result.markdown());
            println!("\nJSON: {}", path.display());
            Ok(ExitCode::SUCCESS)
        }
        Command::Scene { file, explain } => {
            match (file, explain) {
                (_, true) => print!("{}", scene::explain()),
                (Some(f), false) => print!("{}", scene::check(&f)?),
                (None, false) => return Err(anyhow!("give a scene file to check, or --explain")),
            }
            Ok(ExitCode::SUCCESS)
        }
        Command::Render { scene: path, out, device } => {
            let scene = scene::Scene::load(&path)?;
            let out = out.unwrap_or_else(|| PathBuf::from("results/scenes").join(scene.name()));
            let gpu = device.open()?;
            let progress = progress_bar();
            let result = scene::render::render(&gpu, &scene, &out, &progress);
            progress.finish_and_clear();
            let result = result?;
            gpu.check_validation()?;
            for n in &result.notes {
                eprintln!("brdfprof: note: {n}");
            }
            println!("written: {}", result.files.iter().map(|p| p.display().to_string()).collect::<Vec<_>>().join(", "));
            Ok(ExitCode::SUCCESS)
        }
        Command::Profile { model, timing, size, reps, budget, target_ci, json, device, scene: None } => {
            fresh_compilation(timing.shader_cache);
            let options = timing.options(model.specs(&spec::THESIS_MODELS)?, &size, reps, budget, target_ci)?;
            let gpu = device.open()?;
            let progress = progress_bar();
            let result = profile::run(&gpu, &options, &progress);
            progress.finish_and_clear();
            let result = result?;
            gpu.check_validation()?;
            let path = json.unwrap_or_else(|| PathBuf::from(format!("results/profile-{}.json", report::device_slug(&gpu.info))));
            report::write_json(&path, &result)?;
            println!("{}\n", result.summary());
            print!("{}{}", result.table().markdown(), result.placement_notes());
            println!("\nJSON: {}", path.display());
            Ok(ExitCode::SUCCESS)
        }
        Command::Sweep { model, timing, size, reps, budget, target_ci, out, device } => {
            fresh_compilation(timing.shader_cache);
            let models = if model.models.is_empty() { sweep::default_specs() } else { model.specs(&[])? };
            let options = sweep::SweepOptions { profile: timing.options(models, &size, reps, budget, target_ci)? };
            let gpu = device.open()?;
            let progress = progress_bar();
            let result = sweep::run(&gpu, &options, &progress);
            progress.finish_and_clear();
            let result = result?;
            gpu.check_validation()?;
            let stem = out.join(format!("sweep-{}", report::device_slug(&gpu.info)));
            let (md, json, png) = (stem.with_extension("md"), stem.with_extension("json"), stem.with_extension("png"));
            report::write_json_compact(&json, &result)?;
            io::write_atomic(&md, result.markdown().as_bytes())?;
            result.chart(&png)?;
            print!("{}", result.markdown());
            println!("\nwritten: {}, {}, {}", md.display(), json.display(), png.display());
            Ok(ExitCode::SUCCESS)
        }
        Command::Stability { model, no_energy, out, device } => {
            let specs = if model.models.is_empty() { stability::default_specs() } else { model.specs(&[])? };
            let gpu = device.open()?;
            let progress = progress_bar();
            let result = stability::run(&gpu, &stability::StabilityOptions { specs, energy: !no_energy }, &progress);
            progress.finish_and_clear();
            let result = result?;
            gpu.check_validation()?;
            let stem = out.join(format!("stability-{}", report::device_slug(&gpu.info)));
            let mut written = vec![stem.with_extension("md"), stem.with_extension("json")];
            report::write_json_compact(&written[1], &result)?;
            io::write_atomic(&written[0], result.markdown().as_bytes())?;
            let entries = result.energy_entries();
            if !entries.is_empty() {
                let furnace = out.join(format!("furnace-{}.png", report::device_slug(&gpu.info)));
                let albedo = out.join(format!("albedo-{}.png", report::device_slug(&gpu.info)));
                stability::energy::furnace_png(&furnace, &entries)?;
                stability::energy::albedo_chart(&albedo, &entries)?;
                written.extend([furnace, albedo]);
            }
            let heat = out.join(format!("stability-{}-failures.png", report::device_slug(&gpu.info)));
            if result.heatmaps(&heat)? {
                written.push(heat);
            }
            print!("{}", result.markdown());
            println!("\nwritten: {}", written.iter().map(|p| p.display().to_string()).collect::<Vec<_>>().join(", "));
            let failing = result.failing();
            if failing.is_empty() {
                Ok(ExitCode::SUCCESS)
            } else {
                eprintln!("brdfprof: {} spec(s) give NaN, Inf or negative values on valid inputs", failing.len());
                Ok(ExitCode::from(1))
            }
        }
        Command::Inspect { model, inspect, json, markdown, profile, device } => {
            let lights = inspect.lights.unwrap_or(8);
            if lights == 0 {
                return Err(anyhow!("--lights must be at least 1"));
            }
            let options = InspectOptions { specs: model.specs(&spec::THESIS_MODELS)?, lights, callgrind: inspect.callgrind(&device)? };
            let kernels = inspect.kernels()?;
            let gpu = device.open()?;
            let mut result = inspect::run(&gpu, &kernels, &options)?;
            gpu.check_validation()?;
            if let Some(p) = &profile {
                result.vs_profile = Some(inspect::correlate::correlate(&result, p)?);
            }
            let slug = report::device_slug(&gpu.info);
            let json = json.unwrap_or_else(|| PathBuf::from(format!("results/inspect-{slug}.json")));
            let markdown = markdown.unwrap_or_else(|| PathBuf::from(format!("results/inspect-{slug}.md")));
            let text = format!("# brdfprof inspect\n\n{}\n\n{}", result.summary(), result.markdown());
            report::write_json(&json, &result)?;
            io::write_atomic(&markdown, text.as_bytes())?;
            print!("{text}");
            println!("JSON: {}\nMarkdown: {}", json.display(), markdown.display());
            Ok(ExitCode::SUCCESS)
        }
        Command::Check { baseline, save_baseline, thresholds, force, model, inspect, timing, device } => {
            fresh_compilation(timing.shader_cache);
            let (width, height) = parse_size(&timing.timing_size).map_err(|e| anyhow!("--timing-{}", e.to_string().trim_start_matches("--")))?;
            let options = CheckOptions {
                baseline,
                save: save_baseline,
                thresholds: Thresholds::parse(&thresholds)?,
                force,
                specs: model.specs(&[])?,
                lights: inspect.lights,
                callgrind: inspect.callgrind(&device)?,
                timing: TimingOptions { width, height, lights: 0, rounds: timing.rounds, reps: timing.reps, seed: 1 },
            };
            let outcome = check::run(&options, &inspect.kernels()?, || device.open())?;
            print!("{}", outcome.text);
            Ok(ExitCode::from(outcome.exit))
        }
        Command::CallgrindChild { request } => {
            inspect::callgrind::child_main(&request)?;
            Ok(ExitCode::SUCCESS)
        }
    }
}

fn parse_size(text: &str) -> Result<(u32, u32)> {
    let parse = || -> Option<(u32, u32)> {
        let (w, h) = text.split_once(['x', 'X'])?;
        Some((w.trim().parse().ok()?, h.trim().parse().ok()?))
    };
    match parse() {
        Some((w, h)) if w > 0 && h > 0 => Ok((w, h)),
        _ => Err(anyhow!("--size `{text}`: expected WIDTHxHEIGHT, e.g. 1920x1080")),
    }
}

fn devices() -> Result<ExitCode> {
    let infos = gpu::list_devices()?;
    let default = gpu::select_device(&infos, None)?;
    let mut t = report::Table::new([
        "index", "name", "type", "driver", "API", "timestampPeriod ns", "ts bits", "maxStorageBufferRange", "maxWorkGroupCount.x", "fp16", "fp64", "exec. stats",
    ]);
    for d in &infos {
        t.row([
            format!("{}{}", d.index, if d.index == default { " (default)" } else { "" }),
            d.name.clone(),
            d.device_type.clone(),
            format!("{} {} ({})", d.driver_name, d.driver_info, d.driver_version),
            d.api_version.clone(),
            d.timestamp_period.to_string(),
            d.timestamp_valid_bits.to_string(),
            d.max_storage_buffer_range.to_string(),
            d.max_compute_work_group_count[0].to_string(),
            d.shader_float16.to_string(),
            d.shader_float64.to_string(),
            d.pipeline_executable_properties.to_string(),
        ]);
    }
    print!("{}", t.markdown());
    Ok(ExitCode::SUCCESS)
}

fn models_text() -> String {
    let mut out = String::new();
    let mut section = |title: &str, rows: Vec<(String, String)>| {
        let mut t = report::Table::new(["name", "source"]);
        for (name, cite) in rows {
            t.row([name, cite]);
        }
        out += &format!("{title}\n\n{}\n", t.markdown());
    };
    section("D (d=)", D::ALL.iter().map(|t| (t.name().to_string(), t.citation().to_string())).collect());
    section("Visibility (vis=)", Vis::ALL.iter().map(|t| (t.name().to_string(), t.citation().to_string())).collect());
    section("Fresnel (f=)", {
        let mut rows: Vec<(String, String)> = F::ALL.iter().filter(|f| **f != F::Conductor).map(|t| (t.name().to_string(), t.citation().to_string())).collect();
        rows.extend(Metal::ALL.iter().map(|m| (format!("conductor-{}", m.name()), format!("{} {}", F::Conductor.citation(), m.citation()))));
        rows
    });
    section("Precision (precision=)", vec![("f32".into(), "fp32 arithmetic".into()), ("f16".into(), "fp16 arithmetic (needs shaderFloat16)".into())]);
    section(
        "Presets",
        spec::PRESETS.iter().map(|p| (p.name.to_string(), format!("{} = {}", p.source, ModelSpec::preset(p.name).unwrap().canonical()))).collect(),
    );
    out += "Parameters: gamma=G (GTR exponent, default 1.5), metal=NAME (f82 metal, default gold).\n";
    out
}
