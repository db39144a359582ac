//! The argument types several commands share: device, models, timing, counts and `--html`, and the value
//! parsers of the flags more than one command takes (ranges, sizes, budgets, devices, references, the compile
//! limit).

use super::{command_started, compiles_only_error};
use anyhow::{Result, anyhow, bail};
use brdfprof::gpu::{Gpu, GpuOptions};
use brdfprof::inspect::callgrind::CallgrindOptions;
use brdfprof::io;
use brdfprof::measure::protocol::ProtocolOptions;
use brdfprof::model::{self, Model};
use brdfprof::profile::ProfileOptions;
use brdfprof::report::{self, Input};
use brdfprof::shaders::Shaders;
use brdfprof::targets;
use clap::Args;
use std::path::PathBuf;
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
pub fn roughness_range(text: &str) -> Result<(f64, f64), String> {
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

/// `--reference SPEC`: a built-in spec (it has the f64 twin a reference needs).
pub fn reference_spec(text: &str) -> Result<brdfprof::brdf::ModelSpec, String> {
    brdfprof::brdf::ModelSpec::parse(text)
        .map_err(|e| format!("{e} (a reference is a built-in spec: a preset or D/Vis/F terms, which have an f64 twin)"))
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
        let gpu =
            Gpu::new(&GpuOptions { device: self.device.clone(), validation: self.validation(), ..Default::default() })?;
        if gpu.info.compile_only() && !compile_only_ok {
            return Err(compiles_only_error(&format!("{} ({})", self.device.as_deref().unwrap_or("?"), gpu.info.name)));
        }
        Ok(gpu)
    }
}

#[derive(Args, Clone)]
pub struct ModelArgs {
    /// Model spec: a preset (ggx, blinn, cook-torrance, burley, ue-default-lit, filament-high, filament-low)
    /// or d=..,vis=..,f=..,precision=..; see `brdfprof models`. Or a model file,
    /// PATH[,NAME=VALUE|@roughness|@alpha|@f0|@basecolor|@metallic...]: a BRDF Explorer .brdf file (its shader
    /// in GLSL, HLSL, Slang or WGSL), or a plain HLSL (.hlsl, .hlsli, .ush, .usf), Slang (.slang) or WGSL
    /// (.wgsl) shader file.
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
    /// A directory a shader's `#include` (GLSL, HLSL, Slang), a Slang shader's `import` and a WGSL shader's
    /// `#import` search, after the model file's own (repeatable, in order; `include=DIR` in the model's spec;
    /// docs/hlsl.md, docs/slang.md, docs/wgsl.md).
    #[arg(long = "include-dir", value_name = "DIR")]
    pub include_dirs: Vec<String>,
    /// A virtual include prefix and the directory it stands for, e.g. /Engine=UE/Engine/Shaders: `#include
    /// "/Engine/Private/BRDF.ush"` reads UE/Engine/Shaders/Private/BRDF.ush (`include-map=` in the spec).
    #[arg(long = "include-map", value_name = "VIRTUAL=DIR")]
    pub include_maps: Vec<String>,
    /// A file used wherever the shader includes NAME, beside the including file or through the search path
    /// (repeatable; `include-override=NAME=FILE` in the spec): a stub for an engine's globals header.
    #[arg(long = "include-override", value_name = "NAME=FILE")]
    pub include_overrides: Vec<String>,
    /// Which front end compiles an HLSL shader: glslang, and Slang's slangc where glslang refuses or crashes
    /// (auto); or one of them alone (`hlsl-front-end=` in the model's spec; docs/hlsl.md).
    #[arg(long = "hlsl-front-end", value_name = "auto|glslang|slang", value_parser = ["auto", "glslang", "slang"])]
    pub hlsl_front_end: Option<String>,
}

impl ModelArgs {
    /// The models asked for, or `default` when none.
    pub fn models(&self, default: &[&str]) -> Result<Vec<Model>> {
        let mut items = String::new();
        for (flag, key, values) in [
            ("--define", model::file_model::DEFINE, &self.defines),
            ("--include-dir", model::file_model::INCLUDE, &self.include_dirs),
            ("--include-map", model::file_model::INCLUDE_MAP, &self.include_maps),
            ("--include-override", model::file_model::INCLUDE_OVERRIDE, &self.include_overrides),
            ("--hlsl-front-end", model::file_model::HLSL_FRONT_END, &self.hlsl_front_end.iter().cloned().collect()),
        ] {
            if let Some(v) = values.iter().find(|v| v.contains(',')) {
                bail!(
                    "{flag} {v}: a comma would end the value in the model's spec; rename the directory or give the value without one"
                );
            }
            items += &values.iter().map(|v| format!(",{key}={v}")).collect::<String>();
        }
        if items.is_empty() {
            return model::models_from_args(&self.models, &self.params, default);
        }
        // The options join each shader file model's text, so that its shader is prepared once, with them (a
        // file may `#error` without its defines, or include what only these directories hold).
        if !self.models.iter().any(|m| model::file_model::names_a_file(m)) {
            let flag = [
                ("--define", &self.defines),
                ("--include-dir", &self.include_dirs),
                ("--include-map", &self.include_maps),
                ("--include-override", &self.include_overrides),
                ("--hlsl-front-end", &self.hlsl_front_end.iter().cloned().collect()),
            ]
            .into_iter()
            .find_map(|(f, v)| v.first().map(|v| format!("{f} {v}")))
            .unwrap_or_default();
            bail!(
                "{flag}: it is for a shader file's model, and no --model is a .brdf file, nor an .hlsl, .ush, .slang or .wgsl file"
            );
        }
        let with: Vec<String> = self
            .models
            .iter()
            .map(|m| if model::file_model::names_a_file(m) { format!("{m}{items}") } else { m.clone() })
            .collect();
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
    /// one JIT compilation landing badly placed (docs/measurement.md, the lavapipe hazards).
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
        let off = m
            .twin()
            .filter(|s| s.guards != brdfprof::brdf::guards::GuardSet::NONE)
            .map(|s| Model::spec(brdfprof::brdf::ModelSpec { guards: brdfprof::brdf::guards::GuardSet::NONE, ..*s }));
        out.push(m);
        out.extend(off);
    }
    let mut seen = Vec::new();
    out.retain(|m| {
        if seen.contains(m) {
            false
        } else {
            seen.push(m.clone());
            true
        }
    });
    out
}

impl TimingArgs {
    pub fn options(
        &self,
        models: Vec<Model>,
        size: &str,
        reps: usize,
        budget: f64,
        target_ci: f64,
    ) -> Result<ProfileOptions> {
        let (width, height) = parse_size("--size", size)?;
        use brdfprof::measure::workload::MAX_LIGHTS;
        if self.lights.iter().any(|&l| l == 0 || l > MAX_LIGHTS) {
            bail!(
                "--lights {}: each count must be 1 to {MAX_LIGHTS}",
                self.lights.iter().map(u32::to_string).collect::<Vec<_>>().join(",")
            );
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
    pub fn shaders(&self) -> Result<Shaders> {
        self.glsl.as_deref().map_or_else(|| Ok(Shaders::embedded()), Shaders::from_glsl)
    }

    /// How to run the callgrind child (None: --no-callgrind); it inherits validation from the parent.
    pub fn callgrind(&self, validate: bool) -> Result<Option<CallgrindOptions>> {
        let (width, height) = parse_size("--callgrind-size", &self.callgrind_size)?;
        Ok((!self.no_callgrind).then_some(CallgrindOptions { width, height, device: None, validate }))
    }
}

/// `--bench-json FILE`, shared by profile, inspect and sweep.
#[derive(Args, Clone, Default)]
pub struct BenchArg {
    /// Also write the figures as github-action-benchmark's `customSmallerIsBetter` list (name, unit, value,
    /// range from the interval where there is one), for a benchmark dashboard's trend (docs/ci.md).
    #[arg(long, value_name = "FILE")]
    pub bench_json: Option<PathBuf>,
    /// The list's format: `github` (github-action-benchmark's customSmallerIsBetter list) or `bmf` (Bencher's
    /// Metric Format, an object keyed by benchmark).
    #[arg(long, value_name = "FORMAT", default_value = "github", value_parser = brdfprof::export::bench::FORMATS)]
    pub bench_format: String,
}

impl BenchArg {
    /// Refuses a bad path before anything is measured.
    pub fn check(&self) -> Result<()> {
        self.bench_json.as_deref().map_or(Ok(()), |p| io::check_output_path("--bench-json", p))
    }

    pub fn write(&self, entries: &[brdfprof::export::bench::Entry]) -> Result<()> {
        let Some(path) = &self.bench_json else { return Ok(()) };
        brdfprof::export::bench::write(path, entries, &self.bench_format)?;
        brdfprof::messages::progress(format!("benchmark JSON: {} ({} entries)", path.display(), entries.len()));
        Ok(())
    }
}

/// `--html FILE`: the flag's help, shared by the commands that take it.
#[derive(Args, Clone, Default)]
pub struct HtmlArg {
    /// Also write the results as one self-contained HTML page (as `brdfprof report` draws it).
    #[arg(long, value_name = "FILE")]
    pub html: Option<PathBuf>,
}

impl HtmlArg {
    /// Refuses a bad path before anything is measured.
    pub fn check(&self) -> Result<()> {
        self.html.as_deref().map_or(Ok(()), |p| io::check_output_path("--html", p))
    }

    /// Writes the page of `inputs` (lobes and spheres on `gpu`) where asked; returns its path.
    pub fn write(&self, inputs: &[Input], gpu: Option<&Gpu>) -> Result<Option<PathBuf>> {
        let Some(path) = &self.html else { return Ok(None) };
        let bytes = report::write(inputs, path, gpu)?;
        brdfprof::messages::progress(format!("HTML report: {} ({bytes} bytes)", path.display()));
        Ok(Some(path.clone()))
    }
}
