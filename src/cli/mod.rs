//! What every command shares: the device, model and timing arguments, and the one sequence that opens the
//! device, shows progress, runs the work and checks the validation layer.

pub mod cache;
pub mod compare;
pub mod counts;
pub mod diff;
pub mod eval;
pub mod info;
pub mod measure;
pub mod report;
pub mod scene;

use anyhow::{anyhow, bail, Result};
use brdfprof::gpu::{Gpu, GpuOptions};
use brdfprof::targets;
use brdfprof::io;
use brdfprof::model::{self, Model};
use brdfprof::profile::protocol::ProtocolOptions;
use brdfprof::profile::ProfileOptions;
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};
use std::path::Path;
use std::time::Duration;

#[derive(Args, Clone)]
pub struct DeviceArgs {
    /// Device index (see `brdfprof devices`) or a case-insensitive substring of its name.
    /// Default: the first discrete or integrated GPU, else lavapipe.
    #[arg(long, value_parser = device_name)]
    pub device: Option<String>,
    /// Run under the Khronos validation layer and fail on any message (also BRDFPROF_VALIDATION=1).
    #[arg(long)]
    pub validate: bool,
}

/// `--roughness MIN..MAX`: 0 <= MIN <= MAX <= 1.
fn roughness_range(text: &str) -> Result<(f64, f64), String> {
    let fail = || format!("`{text}`: give MIN..MAX with 0 <= MIN <= MAX <= 1 (e.g. 0.0525..1)");
    let (lo, hi) = text.split_once("..").ok_or_else(fail)?;
    let (lo, hi): (f64, f64) = (lo.trim().parse().map_err(|_| fail())?, hi.trim().parse().map_err(|_| fail())?);
    if !(0.0..=1.0).contains(&lo) || !(0.0..=1.0).contains(&hi) || lo > hi {
        return Err(fail());
    }
    Ok((lo, hi))
}

/// `--nov MIN..MAX`, `--nol MIN..MAX`: a cosine range, 0 <= MIN <= MAX <= 1.
pub fn cosine_range(text: &str) -> Result<(f64, f64), String> {
    roughness_range(text).map_err(|_| format!("`{text}`: give MIN..MAX with 0 <= MIN <= MAX <= 1 (e.g. 0.05..1)"))
}

/// One range of the default samples: the flag's, else the intersection of `default` with the models' declared
/// domains (named in the words returned), else `default`; models whose domains do not meet are refused.
fn range_of(flag: (&str, Option<(f64, f64)>), default: (f64, f64), declared: Vec<(String, (f64, f64))>, what: &str) -> Result<((f64, f64), String)> {
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
        bail!("the models' {what} domains do not meet within [{}, {}] ({names}); give {} MIN..MAX to compare them anyway", default.0, default.1, flag.0);
    }
    Ok(((lo, hi), format!(" (the models' declared domain: {names})")))
}

/// The sample ranges of a command (its `--roughness`, `--nov`, `--nol` flags, else the models' declared domains
/// within `d`, else `d`), and the words saying where each comes from.
pub fn sample_domain(flags: [Option<(f64, f64)>; 3], d: brdfprof::diff::SampleDomain, models: &[&Model]) -> Result<(brdfprof::diff::SampleDomain, [String; 3])> {
    let declared = |pick: &dyn Fn(&Model) -> Option<(f64, f64)>| models.iter().filter_map(|m| pick(m).map(|r| (m.label(), r))).collect::<Vec<_>>();
    let (roughness, rw) = range_of(("--roughness", flags[0]), d.roughness, declared(&|m| m.roughness_domain()), "roughness")?;
    let (nov, vw) = range_of(("--nov", flags[1]), d.nov, declared(&|m| m.cosine_domains().0), "N.V")?;
    let (nol, lw) = range_of(("--nol", flags[2]), d.nol, declared(&|m| m.cosine_domains().1), "N.L")?;
    Ok((brdfprof::diff::SampleDomain { roughness, nov, nol }, [rw, vw, lw]))
}

/// `--reference SPEC`: a built-in spec (it has the f64 twin a reference needs).
pub fn reference_spec(text: &str) -> Result<brdfprof::brdf::ModelSpec, String> {
    brdfprof::brdf::ModelSpec::parse(text).map_err(|e| format!("{e} (a reference is a built-in spec: a preset or D/Vis/F terms, which have an f64 twin)"))
}

/// `--device`: an empty or blank name would match every device (a substring of each), so it is refused; a
/// compile-only target must name known families (`targets`).
pub fn device_name(text: &str) -> Result<String, String> {
    if text.trim().is_empty() {
        return Err("empty; give an index or a name substring (see `brdfprof devices`)".into());
    }
    targets::parse(text).map_err(|e| format!("{e:#}"))?;
    Ok(text.to_string())
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

impl DeviceArgs {
    /// Validation asked for by the flag or the environment.
    pub fn validation(&self) -> bool {
        self.validate || std::env::var("BRDFPROF_VALIDATION").is_ok_and(|v| !v.is_empty() && v != "0")
    }

    /// Opens the device for a command that executes kernels: a compile-only device is refused.
    pub fn open(&self) -> Result<Gpu> {
        self.open_with(false)
    }

    /// Opens the device; `compile_only_ok`: the command only compiles (inspect, check), so RADV's null device
    /// (the user's own RADV_FORCE_FAMILY and an explicit `--device`) will do. A compile-only target is never
    /// opened here: the commands that take it compile through `targets`.
    pub fn open_with(&self, compile_only_ok: bool) -> Result<Gpu> {
        if self.device.as_deref().is_some_and(|d| d.trim().is_empty()) {
            bail!("--device: empty; give an index or a name substring (see `brdfprof devices`)");
        }
        if let Some(d) = self.device.as_deref().filter(|d| targets::is_compile_only(d)) {
            return Err(compiles_only_error(d));
        }
        let gpu = Gpu::new(&GpuOptions { device: self.device.clone(), validation: self.validation(), ..Default::default() })?;
        if gpu.info.compile_only() && !compile_only_ok {
            return Err(compiles_only_error(&format!("{} ({})", self.device.as_deref().unwrap_or("?"), gpu.info.name)));
        }
        Ok(gpu)
    }
}

/// Opens the device, runs `work` with a progress bar, and fails if the validation layer said anything.
pub fn on_device<T>(device: &DeviceArgs, work: impl FnOnce(&Gpu, &ProgressBar) -> Result<T>) -> Result<(Gpu, T)> {
    on_device_with(device, false, work)
}

/// `on_device`; `compile_only_ok`: the work only compiles, so a compile-only device will do.
pub fn on_device_with<T>(device: &DeviceArgs, compile_only_ok: bool, work: impl FnOnce(&Gpu, &ProgressBar) -> Result<T>) -> Result<(Gpu, T)> {
    let gpu = device.open_with(compile_only_ok)?;
    let progress = ProgressBar::new(0).with_style(ProgressStyle::with_template("{spinner} {elapsed} {pos} {msg}").expect("valid progress template"));
    progress.enable_steady_tick(Duration::from_millis(200));
    let bar = progress.clone();
    let messages = brdfprof::messages::ProgressGuard::new(move |print| bar.suspend(print));
    let result = work(&gpu, &progress);
    drop(messages);
    progress.finish_and_clear();
    let result = result?;
    gpu.check_validation()?;
    Ok((gpu, result))
}

#[derive(Args, Clone)]
pub struct ModelArgs {
    /// Model spec: a preset (ggx, blinn, cook-torrance, burley, ue-default-lit, filament-high, filament-low)
    /// or d=..,vis=..,f=..,precision=..; see `brdfprof models`. Or a model file,
    /// PATH[,NAME=VALUE|@roughness|@alpha|@f0|@basecolor|@metallic...]: a BRDF Explorer .brdf file (its shader
    /// in GLSL, HLSL or WGSL), or a plain HLSL (.hlsl, .hlsli, .ush, .usf) or WGSL (.wgsl) shader file.
    #[arg(long = "model")]
    pub models: Vec<String>,
    /// Parameter override applied to every model that takes it, e.g. gamma=1.5 (GTR exponent), metal=copper,
    /// precision=f16; for a model file one of its parameters (a colour as r,g,b) or a binding such as
    /// roughness=@roughness.
    #[arg(long = "param")]
    pub params: Vec<String>,
    /// A macro for every model file's shader (.brdf, .hlsl, .ush, .wgsl, ...), NAME or NAME=VALUE: glslang's -D
    /// for GLSL and HLSL, a naga_oil shader def for WGSL (whose `#ifdef` asks only whether NAME is defined); the
    /// same as `define=NAME=VALUE` in the file's spec (docs/brdf-files.md, docs/wgsl.md).
    #[arg(long = "define", value_name = "NAME[=VALUE]")]
    pub defines: Vec<String>,
    /// A directory an HLSL shader's `#include` and a WGSL shader's `#import` search, after the model file's
    /// own (repeatable, in order; `include=DIR` in the model's spec; docs/hlsl.md, docs/wgsl.md).
    #[arg(long = "include-dir", value_name = "DIR")]
    pub include_dirs: Vec<String>,
    /// A virtual include prefix and the directory it stands for, e.g. /Engine=UE/Engine/Shaders: `#include
    /// "/Engine/Private/BRDF.ush"` reads UE/Engine/Shaders/Private/BRDF.ush (`include-map=` in the spec).
    #[arg(long = "include-map", value_name = "VIRTUAL=DIR")]
    pub include_maps: Vec<String>,
}

impl ModelArgs {
    /// The models asked for, or `default` when none.
    pub fn models(&self, default: &[&str]) -> Result<Vec<Model>> {
        let mut items = String::new();
        for (flag, key, values) in [("--define", model::file_model::DEFINE, &self.defines), ("--include-dir", model::file_model::INCLUDE, &self.include_dirs), ("--include-map", model::file_model::INCLUDE_MAP, &self.include_maps)] {
            if let Some(v) = values.iter().find(|v| v.contains(',')) {
                bail!("{flag} {v}: a comma would end the value in the model's spec; rename the directory or give the value without one");
            }
            items += &values.iter().map(|v| format!(",{key}={v}")).collect::<String>();
        }
        if items.is_empty() {
            return model::models_from_args(&self.models, &self.params, default);
        }
        // The options join each shader file model's text, so that its shader is prepared once, with them (a
        // file may `#error` without its defines, or include what only these directories hold).
        if !self.models.iter().any(|m| model::file_model::names_a_file(m)) {
            let flag = [("--define", &self.defines), ("--include-dir", &self.include_dirs), ("--include-map", &self.include_maps)].into_iter().find_map(|(f, v)| v.first().map(|v| format!("{f} {v}"))).unwrap_or_default();
            bail!("{flag}: it is for a shader file's model, and no --model is a .brdf file, nor an .hlsl, .ush or .wgsl file");
        }
        let with: Vec<String> = self.models.iter().map(|m| if model::file_model::names_a_file(m) { format!("{m}{items}") } else { m.clone() }).collect();
        model::models_from_args(&with, &self.params, default)
    }
}

/// Size and protocol of a timed run, shared by `profile` and `sweep`.
#[derive(Args, Clone)]
pub struct TimingArgs {
    /// Directional lights per pixel (run in blocks of 8 per dispatch, each block's loop unrolled). A
    /// comma-separated list (e.g. 1,8,64) times every count in the same interleaved rounds.
    #[arg(long, value_delimiter = ',', default_value = "8")]
    pub lights: Vec<u32>,
    /// G-buffer layout: packed as engines store it (octahedral normal, RGBA8 material and base colour, V from
    /// the pixel and the camera, R11G11B10F out: 16 bytes in, 4 out), or float (48 bytes in, 16 out).
    #[arg(long, value_enum, default_value = "packed")]
    pub gbuffer: brdfprof::kernels::shade::GBufferFormat,
    /// Minimum and maximum number of interleaved rounds.
    #[arg(long, default_value_t = 12)]
    pub min_rounds: usize,
    #[arg(long, default_value_t = 400)]
    pub max_rounds: usize,
    /// Seed of the interleaving order.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Independently compiled pipelines per kernel, all timed every round (the faster counts): guards against
    /// one JIT compilation landing badly placed, seen to double a kernel's time on lavapipe.
    #[arg(long, default_value_t = 2)]
    pub instances: usize,
    /// Keep Mesa's on-disk shader cache (timed runs switch it off by default; see `fresh_compilation`).
    #[arg(long)]
    pub shader_cache: bool,
    /// Compile the shading kernels from this GLSL directory (a copy of glsl/, with its kernels.txt) with
    /// glslang instead of using the embedded SPIR-V: time an edited kernel against the built-in one.
    #[arg(long)]
    pub glsl: Option<std::path::PathBuf>,
    /// Also time each spec without brdfprof's guards (`guards=off`, docs/guards.md), listed next to it and
    /// timed in the same interleaved rounds.
    #[arg(long)]
    pub unguarded: bool,
}

/// `models` with, after each built-in spec that keeps a guard, the same spec with `guards=off` (a `.brdf`
/// file has no brdfprof guards to remove), when `unguarded`.
pub fn with_unguarded(models: Vec<Model>, unguarded: bool) -> Vec<Model> {
    if !unguarded {
        return models;
    }
    let mut out = Vec::with_capacity(2 * models.len());
    for m in models {
        let off = m.twin().filter(|s| s.guards != brdfprof::brdf::guards::GuardSet::NONE).map(|s| Model::spec(brdfprof::brdf::ModelSpec { guards: brdfprof::brdf::guards::GuardSet::NONE, ..*s }));
        out.push(m);
        out.extend(off);
    }
    let mut seen = Vec::new();
    out.retain(|m| if seen.contains(m) { false } else { seen.push(m.clone()); true });
    out
}

impl TimingArgs {
    pub fn options(&self, models: Vec<Model>, size: &str, reps: usize, budget: f64, target_ci: f64) -> Result<ProfileOptions> {
        let (width, height) = parse_size("--size", size)?;
        use brdfprof::profile::workload::MAX_LIGHTS;
        if self.lights.iter().any(|&l| l == 0 || l > MAX_LIGHTS) {
            bail!("--lights {}: each count must be 1 to {MAX_LIGHTS}", self.lights.iter().map(u32::to_string).collect::<Vec<_>>().join(","));
        }
        let mut seen = std::collections::BTreeSet::new();
        if let Some(l) = self.lights.iter().find(|l| !seen.insert(**l)) {
            bail!("--lights: {l} is given twice");
        }
        let min_rounds = self.min_rounds.max(1);
        Ok(ProfileOptions {
            models: with_unguarded(models, self.unguarded),
            width,
            height,
            lights: self.lights.clone(),
            format: self.gbuffer,
            protocol: ProtocolOptions {
                min_rounds,
                max_rounds: self.max_rounds.max(min_rounds),
                reps: reps.max(1),
                budget: parse_budget(budget)?,
                started: command_started(),
                seed: self.seed,
            },
            target_rel_ci: target_ci,
            max_chunk: None,
            instances: self.instances.max(1),
            glsl: self.glsl.clone(),
        })
    }
}

/// `--compile-timeout`: seconds, more than 0 and at most a day.
pub fn compile_timeout(text: &str) -> Result<Duration, String> {
    brdfprof::launch::parse(text)
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
    brdfprof::host::memory_limit()?;
    if !child {
        brdfprof::targets::radv_env::sanitise()?;
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

/// `--budget` in seconds: positive and finite.
pub fn parse_budget(seconds: f64) -> Result<Duration> {
    if !(seconds.is_finite() && seconds > 0.0 && seconds <= 86_400.0) {
        bail!("--budget {seconds}: give seconds, more than 0 and at most 86400");
    }
    Ok(Duration::from_secs_f64(seconds))
}

/// `WIDTHxHEIGHT`, both at least 1; `flag` names the option in errors.
pub fn parse_size(flag: &str, text: &str) -> Result<(u32, u32)> {
    let parse = || -> Option<(u32, u32)> {
        let (w, h) = text.split_once(['x', 'X'])?;
        Some((w.trim().parse().ok()?, h.trim().parse().ok()?))
    };
    match parse() {
        Some((w, h)) if w > 0 && h > 0 => Ok((w, h)),
        Some((w, h)) => Err(anyhow!("{flag} `{text}`: width and height must be at least 1 (got {w}x{h})")),
        None => Err(anyhow!("{flag} `{text}`: expected WIDTHxHEIGHT, e.g. 1920x1080")),
    }
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
        Some(p) => io::check_output_path(flag, p),
        None => {
            io::check_output_dir(&format!("{flag} (default {default_dir}/{default_name})"), Path::new(default_dir))?;
            // The device is not known yet: a `<device>` name is refused where git tracks it for any device.
            io::refuse_tracked_default(flag, Path::new(default_dir), &[default_name.replace("<device>", "*")])
        }
    }
}

/// "written: a, b, c" for a command's outputs.
pub fn written(paths: &[std::path::PathBuf]) -> String {
    format!("written: {}", paths.iter().map(|p| p.display().to_string()).collect::<Vec<_>>().join(", "))
}
