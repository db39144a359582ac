//! "A Mesa Vulkan driver on a device that only compiles, in a child process", written once for every driver
//! that runs so: RADV on its null winsys (`RADV_FORCE_FAMILY`), and Turnip (Adreno), PanVK (Mali) and ANV
//! (Intel) on Mesa's noop drm-shims (`LD_PRELOAD` of the shim, `VK_ICD_FILENAMES` naming the driver that
//! `make mesa` built, the GPU id in the driver's variable). Each driver is one file (`radv.rs`, `adreno.rs`,
//! `mali.rs`, `anv.rs`) implementing `NoopDriver`: its families, the environment that selects one, and how its
//! cost is read; this file runs the child, reads its report and contains its crashes.
//!
//! brdfprof runs itself as a child (`brdfprof __noop-child REQUEST`) with the driver's environment, so that the
//! Vulkan loader of that process, and only of it, sees the compile-only device; neither the user's environment
//! nor the parent's devices change. The child marks every device it opens compile-only (nothing is submitted,
//! timed or read back: a noop shim executes nothing), runs `inspect`'s analyses on it (no callgrind), optionally
//! writes the driver's internal representations of every kernel, and prints its report as one JSON line. The
//! child dies with brdfprof (cleanup::command).
//!
//! A compile-only device has no queue that executes work: `Gpu` never waits on it when nothing was submitted
//! (Mesa 22.3 RADV's vkDeviceWaitIdle calls through a null pointer there), and a child that still crashes after
//! printing its complete report is accepted with a note, so the user gets the report and exit 0.

pub mod cache;
pub mod shim;

use super::{Request, Run, Target, Vendor};
use crate::cleanup;
use crate::gpu::{CompilerLog, Gpu, GpuOptions, Kernel, RepresentationStats};
use crate::kernels::shade::{self, GBufferFormat, kernel_hash, shade_kernel, steady_block};
use crate::model::BASELINE_LABEL;
use crate::model::Model;
use crate::schema::InspectReport;
use crate::shaders::Shaders;
use anyhow::{Context, Result, anyhow, bail};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// A Mesa driver that compiles for a family of GPUs this machine does not have, in a child process.
pub trait NoopDriver: Vendor {
    /// The compiler's name in messages ("ACO", "ir3").
    fn compiler(&self) -> &'static str;
    /// The environment that makes the child's Vulkan loader offer `family`'s compile-only device (every value
    /// set, none removed); an error, naming what to run, where the driver is not built.
    fn environment(&self, family: usize) -> Result<Vec<(String, String)>>;
    /// The device the child opens (a name substring), None for the only one its environment offers.
    fn device(&self, _family: usize) -> Option<String> {
        None
    }
    /// The folder of a family's listings under `--isa DIR` (`Target::slug`, `adreno-a660`).
    fn isa_folder(&self, family: usize) -> String {
        format!("{}-{}", self.prefix(), self.families()[family].name)
    }
    /// What to do when the child finds no such device.
    fn install_hint(&self) -> String;
    /// A stderr line of the child that is the driver's or its shim's chatter, not a message for the user
    /// (beside the non-conformance banner every Mesa driver may print).
    fn is_noise(&self, _line: &str) -> bool {
        false
    }
    /// Why the Khronos validation layer cannot judge this driver's compilations, where it cannot (the child
    /// then runs without it and the report says so).
    fn without_validation(&self, _family: usize) -> Option<&'static str> {
        None
    }
    /// Statistics the compiler prints on stderr (drivers without VK_KHR_pipeline_executable_properties).
    fn compiler_log(&self) -> Option<CompilerLog> {
        None
    }
    /// Statistics read from one of the driver's internal representations (every pipeline captures them).
    fn representation_stats(&self) -> Option<RepresentationStats> {
        None
    }
}

/// The hidden subcommand the child runs.
pub const CHILD_COMMAND: &str = "__noop-child";

/// Set in the child's environment to the target it compiles for (`adreno:a660`): the child refuses to run
/// without it, so that a stray `__noop-child` never reads a user's devices as a target's.
pub const TARGET_VAR: &str = "BRDFPROF_NOOP_TARGET";

/// What the parent asks the child (one JSON argument).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct NoopRequest {
    /// The driver's `--device` prefix and the family's name.
    pub driver: String,
    pub family: String,
    /// Models by their spec text (`Model::name`, label included, which `Model::parse` reads back); the memory-only
    /// kernel is analysed after them.
    pub models: Vec<String>,
    pub lights: u32,
    pub validate: bool,
    pub glsl: Option<PathBuf>,
    /// Write each kernel's internal representations under DIR/<family>/.
    pub isa_dir: Option<PathBuf>,
    /// Kernels from outside the model set (`RawKernel`), compiled instead of the models when given.
    #[serde(default)]
    pub raw: Vec<RawSpirv>,
}

/// A raw kernel for the child: its frozen SPIR-V in a file (a scene kernel's words are more than one
/// command-line argument may carry) and its interface.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct RawSpirv {
    pub label: String,
    /// The model's spec text (`Model::name`), to check the family can compile it.
    pub model: String,
    pub path: PathBuf,
    pub storage_buffers: u32,
    pub push_bytes: u32,
}

/// What the child prints on its last stdout line.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct NoopReply {
    /// `adreno:a660`.
    pub target: String,
    pub report: InspectReport,
    /// Files written under the ISA directory.
    pub isa_files: Vec<PathBuf>,
}

/// The driver of a `--device` prefix.
fn driver_of(prefix: &str) -> Result<&'static dyn NoopDriver> {
    super::VENDORS
        .iter()
        .find_map(|v| v.noop().filter(|d| d.prefix() == prefix))
        .ok_or_else(|| anyhow!("`{prefix}` is not a driver brdfprof runs on a compile-only device"))
}

/// The child: compiles every kernel on the compile-only device its environment offers and reports.
pub fn child_main(request_json: &str) -> Result<()> {
    let req: NoopRequest = serde_json::from_str(request_json).context("bad compile-only child request")?;
    let driver = driver_of(&req.driver)?;
    let family = driver
        .families()
        .iter()
        .position(|f| f.name == req.family)
        .ok_or_else(|| anyhow!("unknown {} family `{}`", driver.name(), req.family))?;
    let target = Target { vendor: driver, family }.name();
    let environment = driver.environment(family)?;
    let set = |k: &str, v: &str| std::env::var(k).ok().as_deref() == Some(v);
    if !set(TARGET_VAR, &target) || !environment.iter().all(|(k, v)| set(k, v)) {
        let vars = environment.iter().map(|(k, v)| format!("{k}={v}")).collect::<Vec<_>>().join(" ");
        bail!(
            "`brdfprof {CHILD_COMMAND}` runs with {TARGET_VAR}={target} {vars}; `brdfprof inspect --device {target}` runs it so"
        );
    }
    crate::gpu::mark_compile_only_process();
    let models =
        req.models.iter().map(|s| Model::parse(s).map_err(|e| anyhow!("{s}: {e:#}"))).collect::<Result<Vec<_>>>()?;
    crash_if_asked(&models);
    let shaders = match &req.glsl {
        Some(dir) => Shaders::from_glsl(dir)?,
        None => Shaders::embedded(),
    };
    let wanted = driver.device(family);
    let unvalidated = driver.without_validation(family).filter(|_| req.validate);
    let options = GpuOptions {
        device: Some(wanted.clone().unwrap_or_else(|| "0".into())),
        validation: req.validate && unvalidated.is_none(),
        compiler_log: driver.compiler_log(),
        representation_stats: driver.representation_stats(),
    };
    let gpu = Gpu::new(&options).map_err(|e| {
        anyhow!(
            "{target}: the driver offered no compile-only device{} ({e:#}). {}",
            wanted.map_or_else(String::new, |w| format!(" `{w}`")),
            driver.install_hint()
        )
    })?;
    if !gpu.reports_statistics() {
        bail!("{target}: {} reports no compiler statistics (no VK_KHR_pipeline_executable_properties)", gpu.info.name);
    }
    // A driver without VK_KHR_pipeline_executable_properties (PanVK) returns no listing: --isa says so.
    // PanVK 25 has the extension but its statistics and no listing come through the compiler's log.
    let listings = gpu.has_executable_properties() && driver.compiler_log().is_none_or(|l| l.beside_properties);
    let isa_dir = req.isa_dir.as_ref().filter(|_| listings).map(|d| d.join(driver.isa_folder(family)));
    let (mut report, isa_files) = if req.raw.is_empty() {
        models_report(&gpu, &shaders, &req, &target, models, isa_dir.as_deref())?
    } else {
        raw_report(&gpu, &shaders, &req, &target, isa_dir.as_deref())?
    };
    report.provenance["target"] = serde_json::Value::String(target.clone());
    if req.isa_dir.is_some() && !listings {
        let why = if !gpu.has_executable_properties() {
            "has no VK_KHR_pipeline_executable_properties to return one"
        } else {
            "reports its compiler's statistics on stderr, not through pipeline executable properties"
        };
        add_driver_note(&mut report, format!("--isa: no listing for {target}: {} {why}", gpu.info.name));
    }
    if let Some(why) = unvalidated {
        add_driver_note(&mut report, format!("the Khronos validation layer was not run for {target}: {why}"));
    }
    gpu.check_validation()?;
    drop(gpu);
    reply(NoopReply { target, report, isa_files })
}

/// Adds a sentence to the driver section's notes.
fn add_driver_note(report: &mut InspectReport, note: String) {
    let joined = report.section_notes.get("driver/").map_or(note.clone(), |n| format!("{n}; {note}"));
    report.section_notes.insert("driver/".into(), joined);
}

/// The models' kernels and the memory-only one, as `inspect` reports them; a model this family cannot compile
/// (fp16 arithmetic where the device has no shaderFloat16) is left out and named in the driver section's
/// notes, so that one family does not stop a report of many.
fn models_report(
    gpu: &Gpu,
    shaders: &Shaders,
    req: &NoopRequest,
    target: &str,
    models: Vec<Model>,
    isa_dir: Option<&Path>,
) -> Result<(InspectReport, Vec<PathBuf>)> {
    let (models, skipped): (Vec<Model>, Vec<Model>) =
        models.into_iter().partition(|m| m.check_support(&gpu.info).is_ok());
    // The listings first: Turnip keeps each compiled kernel in its in-memory pipeline cache, and a capture
    // compiled after the same kernel without one would come back from there without its IR3 assembly.
    let mut isa_files = Vec::new();
    if let Some(dir) = isa_dir {
        let mut all: Vec<Option<&Model>> = models.iter().map(Some).collect();
        all.push(None);
        for model in all {
            isa_files.extend(write_isa(gpu, shaders, model, req.lights, dir)?);
        }
    }
    let mut report = crate::kernel_stats::device_report(gpu, shaders, &models, req.lights, None)?;
    // The target first: a driver's cost rule finds its family by it.
    report.provenance["target"] = serde_json::Value::String(target.to_string());
    report.cost = super::cost_of(&report);
    if let Some(cost) = &mut report.cost {
        cost.absent =
            skipped.iter().map(|m| (m.name(), format!("{:#}", m.check_support(&gpu.info).unwrap_err()))).collect();
    }
    if !skipped.is_empty() {
        let why = skipped
            .iter()
            .map(|m| format!("{} ({:#})", m.name(), m.check_support(&gpu.info).unwrap_err()))
            .collect::<Vec<_>>()
            .join("; ");
        report.section_notes.insert("driver/".into(), format!("not compiled for {target}: {why}"));
    }
    Ok((report, isa_files))
}

/// Prints the reply as the child's last stdout line.
fn reply(reply: NoopReply) -> Result<()> {
    println!("{}", serde_json::to_string(&reply)?);
    if test_hook(CRASH_AFTER_REPLY).is_some() {
        use std::io::Write;
        std::io::stdout().flush()?;
        crash();
    }
    Ok(())
}

/// Dies of SIGSEGV where `CRASH_ON_MODEL` names one of `models`.
fn crash_if_asked(models: &[Model]) {
    if let Some(label) = test_hook(CRASH_ON_MODEL)
        && models.iter().any(|m| std::ffi::OsStr::new(&m.label()) == label)
    {
        crash();
    }
}

/// Dies of SIGSEGV, as a driver that crashes does: for the tests of crash containment.
fn crash() {
    // SAFETY: raising a signal on this process; the test of crash containment asks for it.
    // The default action (Rust's own SIGSEGV handler is for stack overflows and would return).
    unsafe {
        libc::signal(libc::SIGSEGV, libc::SIG_DFL);
        libc::raise(libc::SIGSEGV);
    }
}

/// The request's raw kernels compiled on the compile-only device, one row each with the compiler's statistics, as one report
/// (with the request's lights per kernel, which the cost divides by); a kernel the family cannot compile is left
/// out and named in the driver section's notes.
fn raw_report(
    gpu: &Gpu,
    shaders: &Shaders,
    req: &NoopRequest,
    target: &str,
    isa_dir: Option<&Path>,
) -> Result<(InspectReport, Vec<PathBuf>)> {
    let mut rows = Vec::new();
    let mut skipped = Vec::new();
    let mut isa_files = Vec::new();
    for r in &req.raw {
        let model = Model::parse(&r.model).map_err(|e| anyhow!("{}: {e:#}", r.model))?;
        if let Err(e) = model.check_support(&gpu.info) {
            skipped.push(format!("{} ({e:#})", r.label));
            continue;
        }
        let bytes = crate::io::read_bounded(&r.path, crate::launch::MAX_OUTPUT_BYTES as u64)
            .with_context(|| format!("the {target} child cannot read {}", r.path.display()))?;
        let words: Vec<u32> = bytemuck::pod_collect_to_vec(&bytes);
        let kernel = Kernel::with_capture(
            gpu,
            &r.label,
            &words,
            &Default::default(),
            &crate::gpu::Binding::storage(r.storage_buffers),
            r.push_bytes,
            isa_dir.is_some(),
        )?;
        let mut row = crate::schema::Row {
            model: r.label.clone(),
            spec: None,
            stats: Default::default(),
            notes: Default::default(),
        };
        let executables =
            kernel.executables()?.ok_or_else(|| anyhow!("{} reports no pipeline statistics", gpu.info.name))?;
        if let Some(dir) = isa_dir {
            isa_files.extend(write_representations(gpu, &executables, &r.label, dir)?);
        }
        row.stats.extend(crate::schema::driver::executable_stats(executables));
        rows.push(row);
    }
    let provenance = serde_json::to_value(crate::export::json::Provenance::new(&gpu.info))?;
    let notes = if skipped.is_empty() {
        Default::default()
    } else {
        [("driver/".to_string(), format!("not compiled for {target}: {}", skipped.join("; ")))].into()
    };
    Ok((
        crate::kernel_stats::compiled_report(rows, provenance, req.lights, shaders, Default::default(), notes),
        isa_files,
    ))
}

/// Set in a child's environment, it dies of SIGSEGV after printing its report, as Mesa 22.3's teardown of
/// RADV's null device did (vkDeviceWaitIdle through a null pointer): the test that the parent contains such a crash.
pub const CRASH_AFTER_REPLY: &str = "BRDFPROF_TEST_NOOP_CHILD_CRASH";

/// A test hook's variable: read only in a build with the `test-hooks` feature (the tests'), inert otherwise.
fn test_hook(name: &str) -> Option<std::ffi::OsString> {
    if cfg!(feature = "test-hooks") { std::env::var_os(name) } else { None }
}

/// Set in a child's environment to a model's label, a child whose request holds that model dies of SIGSEGV
/// before it compiles anything, as a driver that crashes on one model's kernel would: the test that the other
/// models are still costed.
pub const CRASH_ON_MODEL: &str = "BRDFPROF_TEST_NOOP_CHILD_CRASH_ON";

/// Compiles one kernel with CAPTURE_INTERNAL_REPRESENTATIONS and writes each text representation
/// (RADV: NIR, ACO IR, disassembly; Turnip: NIR, IR3 assembly; ANV: NIR, GEN assembly) to
/// DIR/<kernel>.<representation>.txt.
fn write_isa(gpu: &Gpu, shaders: &Shaders, model: Option<&Model>, lights: u32, dir: &Path) -> Result<Vec<PathBuf>> {
    let label = model.map_or_else(|| BASELINE_LABEL.to_string(), Model::label);
    let (per_dispatch, accumulate) = steady_block(lights);
    let k = shade_kernel(model, GBufferFormat::Packed, per_dispatch, accumulate, shaders)?;
    let kernel = Kernel::with_capture(
        gpu,
        &k.spirv.name,
        &k.spirv.words,
        &k.constants,
        &shade::bindings(GBufferFormat::Packed),
        shade::PUSH_BYTES,
        true,
    )?;
    write_representations(gpu, &kernel.executables()?.unwrap_or_default(), &label, dir)
}

/// Each text representation of each executable to DIR/<kernel>.<representation>.txt.
fn write_representations(
    gpu: &Gpu,
    executables: &[crate::gpu::PipelineExecutable],
    label: &str,
    dir: &Path,
) -> Result<Vec<PathBuf>> {
    std::fs::create_dir_all(dir).with_context(|| format!("--isa: cannot create {}", dir.display()))?;
    let mut files = Vec::new();
    for exe in executables {
        for (name, text) in &exe.representations {
            let path = dir.join(format!("{}.{}.txt", super::file_slug(label), super::file_slug(name)));
            crate::io::write_output(
                &path,
                format!("; {label}: {} of {}, {}\n{text}", name, exe.name, gpu.info.name).as_bytes(),
            )?;
            files.push(path);
        }
    }
    if files.is_empty() {
        bail!(
            "{}: the driver returned no internal representation for {label}{}",
            gpu.info.name,
            if !gpu.has_executable_properties() {
                " (it has no VK_KHR_pipeline_executable_properties: --isa has nothing to write for it)"
            } else {
                ""
            }
        );
    }
    Ok(files)
}

/// What every child of one `compile` is asked (the parts of a `Request` a child reads).
struct Job<'a> {
    /// The shared part of every child's cache key (`cache::request_digest`); None: no child is cached.
    cache_digest: Option<String>,
    lights: u32,
    shaders: &'a Shaders,
    validate: bool,
    isa_dir: Option<&'a Path>,
    /// Each kernel's row label and hash (`kernel_hash`, packed) as this process composed it, which the key
    /// holds: a child reads the model files again, and a report of other kernels (a file edited during the
    /// run) is refused, neither used nor cached.
    kernels: Vec<(String, String)>,
}

/// One target's child: run, and its report read back.
struct ChildRun {
    report: InspectReport,
    isa_files: Vec<PathBuf>,
    /// Set when the child crashed after it had printed its complete report.
    teardown_note: Option<String>,
}

/// What the cache keeps of a child's run: its report and the messages it had for the user.
#[derive(Serialize, Deserialize)]
struct CachedChild {
    target: String,
    report: InspectReport,
    messages: Vec<String>,
}

/// Runs the child for one target and reads its report, or takes both from the kernel cache when nothing that
/// reaches the driver changed (`cache`); the child's messages reach the user either way.
fn run(
    driver: &'static dyn NoopDriver,
    family: usize,
    models: &[Model],
    raw: &[super::RawKernel],
    request: &Job,
) -> Result<ChildRun> {
    let name = Target { vendor: driver, family }.name();
    // The driver's environment first: a driver that is not built stops here, naming what to run.
    let environment = driver.environment(family)?;
    let key = request.cache_digest.as_deref().map(|digest| cache::key(digest, &name, &environment, request.validate));
    // A child that failed is not cached, nor is what isolating its models finds (a compile past the limit is
    // no property of the kernels), so a later run tries them again.
    let isolated = |first: anyhow::Error, environment| {
        if !isolable(&first, models, raw) {
            return Err(first);
        }
        let (run, messages) = isolate(driver, family, models, request, environment, first)?;
        messages.iter().for_each(|m| crate::messages::line(m));
        Ok(run)
    };
    let Some(key) = key else {
        return match spawn(driver, family, models, raw, request, environment.clone()) {
            Ok((run, messages)) => {
                messages.iter().for_each(|m| crate::messages::line(m));
                Ok(run)
            }
            Err(first) => isolated(first, environment),
        };
    };
    let store = crate::cache::Store::open_default();
    let what = format!("the report of the {name} child");
    let valid = |bytes: &[u8]| -> Result<()> {
        let cached: CachedChild = serde_json::from_slice(bytes)?;
        if cached.target != name {
            bail!("a report for {} under {name}'s key", cached.target);
        }
        Ok(())
    };
    let mut teardown_note = None;
    let mut built = false;
    let built_run = crate::cache::get_or_build(store.as_ref(), cache::KIND, &key, &what, valid, || {
        let (run, messages) = spawn(driver, family, models, raw, request, environment.clone())?;
        teardown_note = run.teardown_note;
        built = true;
        Ok(serde_json::to_vec(&CachedChild { target: name.clone(), report: run.report, messages })?)
    });
    let bytes = match built_run {
        Ok(bytes) => bytes,
        Err(first) => return isolated(first, environment),
    };
    let mut cached: CachedChild = serde_json::from_slice(&bytes)?;
    cached.messages.iter().for_each(|m| crate::messages::line(m));
    if let (false, Some(store)) = (built, &store) {
        cached.report.provenance["cache_entry"] =
            serde_json::Value::String(store.path(cache::KIND, &key).display().to_string());
    }
    Ok(ChildRun { report: cached.report, isa_files: Vec::new(), teardown_note })
}

/// Writes each raw SPIR-V kernel into `dir` for the child (`raw-K.spv`), as the child's request names it.
fn write_raw_spirv(dir: &Path, raw: &[super::RawKernel]) -> Result<Vec<RawSpirv>> {
    let mut raw_files = Vec::new();
    for (k, r) in raw.iter().enumerate() {
        let path = dir.join(format!("raw-{k}.spv"));
        std::fs::write(&path, bytemuck::cast_slice::<u32, u8>(&r.spirv))
            .with_context(|| format!("cannot write {}", path.display()))?;
        raw_files.push(RawSpirv {
            label: r.label.clone(),
            model: r.model.name(),
            path,
            storage_buffers: r.storage_buffers,
            push_bytes: r.push_bytes,
        });
    }
    Ok(raw_files)
}

/// What the child's exit `status` means: nothing where it replied and succeeded, a note where it crashed after
/// writing its complete report (in Mesa's teardown), else the error of a failed child with its last lines.
fn teardown_note(
    driver: &'static dyn NoopDriver,
    name: &str,
    replied: bool,
    status: std::process::ExitStatus,
    stderr: &str,
) -> Result<Option<String>> {
    Ok(match (replied, status.success()) {
        (true, true) => None,
        (true, false) if status.code().is_none() => Some(format!(
            "the {name} child crashed after writing its complete report ({}); the crash is in Mesa's teardown of the compile-only device, not in the figures",
            status
        )),
        _ => {
            let tail: Vec<&str> = stderr.lines().rev().take(15).collect::<Vec<_>>().into_iter().rev().collect();
            bail!(
                "{name}: the compile-only child failed ({}):\n{}\n{}",
                status,
                tail.join("\n"),
                driver.install_hint()
            );
        }
    })
}

/// Whether the child's failure `e` may be one model's: it ended without its report (not a report the parent
/// refused) and held several models and no raw kernel.
fn isolable(e: &anyhow::Error, models: &[Model], raw: &[super::RawKernel]) -> bool {
    models.len() > 1 && raw.is_empty() && e.downcast_ref::<ChildFailed>().is_some()
}

/// After the child of all `models` failed (`first`): one child per model finds those the driver fails on (a
/// crash, a compile past the limit, a validation message), the others are compiled together again, and the
/// failed ones are named in the report's cost (`failed`) with the child's error, so one model never stops the
/// others. `first` where every model alone succeeds (the failure is not one model's) or none does.
fn isolate(
    driver: &'static dyn NoopDriver,
    family: usize,
    models: &[Model],
    request: &Job,
    environment: Vec<(String, String)>,
    first: anyhow::Error,
) -> Result<(ChildRun, Vec<String>)> {
    let name = Target { vendor: driver, family }.name();
    crate::messages::progress(format!("{name}: the child failed; compiling each model in a child of its own"));
    let mut good = Vec::new();
    let mut failed = Vec::new();
    for m in models {
        match spawn(driver, family, std::slice::from_ref(m), &[], request, environment.clone()) {
            Ok(_) => good.push(m.clone()),
            // The driver is installed (the others compiled): its installation hint would mislead.
            Err(e) => failed.push((
                m.label(),
                format!("{e:#}").replace(&driver.install_hint(), "").trim().trim_end_matches(':').to_string(),
            )),
        }
    }
    if failed.is_empty() || good.is_empty() {
        return Err(first);
    }
    let (mut run, messages) = spawn(driver, family, &good, &[], request, environment)?;
    match &mut run.report.cost {
        Some(cost) => cost.failed.extend(failed),
        None => return Err(first),
    }
    Ok((run, messages))
}

/// A child that ended without its report (a crash, an error, the limit): what a model of its request may have
/// caused, unlike a report the parent refuses (another kernel than it composed), which no model alone explains.
#[derive(Debug)]
struct ChildFailed(String);

impl std::fmt::Display for ChildFailed {
    fn fmt(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for ChildFailed {}

fn child_failed(e: anyhow::Error) -> anyhow::Error {
    anyhow::Error::new(ChildFailed(format!("{e:#}")))
}

/// Runs the child for one target: its report, and the lines of its stderr meant for the user.
fn spawn(
    driver: &'static dyn NoopDriver,
    family: usize,
    models: &[Model],
    raw: &[super::RawKernel],
    request: &Job,
    environment: Vec<(String, String)>,
) -> Result<(ChildRun, Vec<String>)> {
    let target = Target { vendor: driver, family };
    let name = target.name();
    // The child writes its ISA files into its own TMPDIR; they become outputs of this process (staged with
    // its others) only once the child has succeeded.
    let mut cmd =
        cleanup::command(&std::env::current_exe().context("cannot find brdfprof's own executable")?.to_string_lossy());
    let tmp = cleanup::child_tmpdir(&mut cmd)?;
    let child_isa = request.isa_dir.map(|_| tmp.path().join("isa"));
    let raw_files = write_raw_spirv(tmp.path(), raw)?;
    let req = NoopRequest {
        driver: driver.prefix().to_string(),
        family: target.info().name.to_string(),
        models: models.iter().map(Model::name).collect(),
        lights: request.lights,
        validate: request.validate,
        glsl: request.shaders.glsl_dir().map(Path::to_path_buf),
        isa_dir: child_isa.clone(),
        raw: raw_files,
    };
    cmd.arg(CHILD_COMMAND)
        .arg(serde_json::to_string(&req)?)
        .env(TARGET_VAR, &name)
        .envs(environment)
        // The compiler's output, not a binary an earlier process cached, and no stale statistics.
        .env("MESA_SHADER_CACHE_DISABLE", "true");
    // The child compiles each kernel under the compile limit itself; the whole child gets one limit per
    // kernel (models, the memory-only kernel, their ISA captures) and a few seconds to start.
    crate::launch::export(&mut cmd);
    let kernels = (models.len() as u32 + 1 + raw.len() as u32) * if request.isa_dir.is_some() { 2 } else { 1 };
    let limit = crate::launch::limit() * kernels + std::time::Duration::from_secs(10);
    let what = format!("the kernels for {name} ({}, in a child process)", driver.compiler());
    let output = crate::launch::output_within(&mut cmd, &what, limit)
        .with_context(|| format!("cannot run brdfprof's {name} child"))
        .map_err(child_failed)?;
    let stdout = String::from_utf8_lossy(&output.stdout);
    let stderr = String::from_utf8_lossy(&output.stderr);
    let reply: Option<NoopReply> = stdout.lines().rev().find_map(|l| serde_json::from_str(l).ok());
    // Validation messages and warnings of the child reach the user as they are, but for the banner Mesa prints
    // for every driver it does not consider conformant (RADV's null device, PanVK) and the shims' notices.
    // (A failed child's last lines are in the error below.)
    let messages: Vec<String> = stderr
        .lines()
        .filter(|l| reply.is_some() && !is_banner(l) && !is_shim_notice(l) && !driver.is_noise(l))
        .map(str::to_string)
        .collect();
    let teardown_note = teardown_note(driver, &name, reply.is_some(), output.status, &stderr).map_err(child_failed)?;
    let reply = reply.expect("checked above");
    if reply.target != name {
        bail!("the compile-only child answered for {} instead of {name}", reply.target);
    }
    check_kernels(&reply.report, &request.kernels, models, &name)?;
    let isa_files = match (&child_isa, request.isa_dir) {
        (Some(from), Some(to)) => reply.isa_files.iter().map(|f| publish(f, from, to)).collect::<Result<Vec<_>>>()?,
        _ => Vec::new(),
    };
    Ok((ChildRun { report: reply.report, isa_files, teardown_note }, messages))
}

/// Refuses a child's report whose kernels are not the ones this process composed (`Job::kernels`).
fn check_kernels(report: &InspectReport, kernels: &[(String, String)], models: &[Model], target: &str) -> Result<()> {
    for (label, hash) in kernels {
        let row = report.rows.iter().find(|r| r.model == *label);
        let theirs = row.and_then(|r| r.notes.get(crate::schema::HASH_NOTE));
        if theirs.is_some_and(|h| h != hash) {
            let file = models.iter().find(|m| m.label() == *label).and_then(Model::file).map(|f| f.path.clone());
            bail!(
                "{}: the {target} child compiled another kernel than brdfprof composed for `{label}` (its file was read again by the child and had changed: was it edited during the run?); nothing was cached, run again",
                file.unwrap_or_else(|| label.clone())
            );
        }
    }
    Ok(())
}

/// Where a test makes the parent wait before it starts its children: set to a path P, the parent writes
/// P.waiting and waits (at most 120 s) until P exists, so that a test can edit a model file between the
/// parent's key and the child's compile.
pub const HOLD_BEFORE_CHILDREN: &str = "BRDFPROF_TEST_NOOP_HOLD";

fn hold_before_children() {
    let Some(path) = test_hook(HOLD_BEFORE_CHILDREN).map(PathBuf::from) else { return };
    let _ = std::fs::write(path.with_extension("waiting"), b"");
    let start = std::time::Instant::now();
    while !path.exists() && start.elapsed() < std::time::Duration::from_secs(120) {
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
}

/// A line the drm-shim prints for each ioctl or query its noop device does not answer (Mesa 25's Turnip:
/// `Unknown DRM_IOCTL_MSM_GET_PARAM 16`; ANV: `Unknown drm_i915_query_item id=...`): the driver falls back on
/// each, so they reach the user only in a failed child's error.
fn is_shim_notice(line: &str) -> bool {
    line.starts_with("Unknown DRM_IOCTL_") || line.starts_with("Unknown drm_")
}

/// The line Mesa prints on every start of a driver it calls non-conformant (RADV's null device, PanVK).
fn is_banner(line: &str) -> bool {
    line.starts_with("WARNING: ") && line.contains("not a conformant")
}

/// Writes a file the child wrote under `from` as this process' output under `to`.
fn publish(file: &Path, from: &Path, to: &Path) -> Result<PathBuf> {
    let rel = file
        .strip_prefix(from)
        .map_err(|_| anyhow!("the compile-only child wrote {} outside its ISA directory", file.display()))?;
    let bytes = crate::io::read_bounded(file, crate::launch::MAX_OUTPUT_BYTES as u64)
        .with_context(|| format!("cannot read the compile-only child's {}", file.display()))?;
    let path = to.join(rel);
    crate::io::write_output(&path, &bytes)?;
    Ok(path)
}

/// Every family of `families` compiled by `driver`'s children (the models, or the raw kernels when given), at
/// most as many children at once as the host has cores; results in order, with the driver's cost table.
pub fn compile(prefix: &str, families: &[usize], raw: &[super::RawKernel], request: &Request) -> Result<Vec<Run>> {
    let driver = driver_of(prefix)?;
    let models: &[Model] = if raw.is_empty() { request.models } else { &[] };
    // A child that writes files (--isa) or is asked to crash (the containment test) always runs; any other
    // report is cached under a key whose kernels' part is computed once here, for every family.
    let cache_digest = match request.isa_dir.is_some()
        || test_hook(CRASH_AFTER_REPLY).is_some()
        || test_hook(CRASH_ON_MODEL).is_some()
    {
        true => None,
        false => Some(cache::request_digest(models, raw, request.lights, request.validate, request.shaders)?),
    };
    let mut kernels = Vec::new();
    for model in models {
        kernels.push((model.label(), kernel_hash(Some(model), GBufferFormat::Packed, request.shaders)?));
    }
    let request = &Job {
        lights: request.lights,
        shaders: request.shaders,
        validate: request.validate,
        isa_dir: request.isa_dir,
        cache_digest,
        kernels,
    };
    hold_before_children();
    let workers = std::thread::available_parallelism().map_or(1, |n| n.get()).min(families.len()).max(1);
    let next = std::sync::atomic::AtomicUsize::new(0);
    let results: std::sync::Mutex<Vec<Option<Result<ChildRun>>>> =
        std::sync::Mutex::new((0..families.len()).map(|_| None).collect());
    // Each worker spawns and waits for its own children (PR_SET_PDEATHSIG follows the spawning thread).
    std::thread::scope(|s| {
        for _ in 0..workers {
            s.spawn(|| {
                loop {
                    let i = next.fetch_add(1, std::sync::atomic::Ordering::SeqCst);
                    if i >= families.len() {
                        break;
                    }
                    let r = run(driver, families[i], models, raw, request);
                    results.lock().unwrap_or_else(|e| e.into_inner())[i] = Some(r);
                }
            });
        }
    });
    let runs =
        results.into_inner().unwrap_or_else(|e| e.into_inner()).into_iter().map(|r| r.expect("every target ran"));
    runs.zip(families)
        .map(|(run, &family)| {
            let run = run?;
            let mut report = run.report;
            if let Some(note) = &run.teardown_note {
                add_driver_note(&mut report, note.clone());
            }
            // The cost is the parent's rule; the models the child could not compile, and those it failed on,
            // stay named under it.
            let (absent, failed) = report.cost.take().map(|c| (c.absent, c.failed)).unwrap_or_default();
            report.cost = driver.cost(&report);
            if let Some(cost) = &mut report.cost {
                cost.absent = absent;
                cost.failed = failed;
            }
            Ok(Run {
                target: Target { vendor: driver, family },
                report,
                isa_files: run.isa_files,
                note: run.teardown_note,
            })
        })
        .collect()
}

/// The family a report of `driver`'s children was made for (its provenance names the target).
pub fn family_of(driver: &dyn NoopDriver, report: &InspectReport) -> Option<usize> {
    let (prefix, family) = report.provenance["target"].as_str()?.split_once(':')?;
    (prefix == driver.prefix()).then(|| driver.families().iter().position(|f| f.name == family)).flatten()
}

/// What a compile-only device's statistics depend on: the device (the family) and the Mesa that compiled,
/// not the host.
pub fn fingerprint(report: &InspectReport) -> std::collections::BTreeMap<String, String> {
    let device = report.provenance["device"]["name"].as_str().unwrap_or("?");
    [("device".to_string(), device.to_string()), ("mesa".to_string(), driver_version(report))].into()
}

/// The Mesa version of a compile-only device's report: the provenance's, else the driver's info or version
/// (PanVK, a Vulkan 1.0 driver, states only its driverVersion).
pub fn driver_version(report: &InspectReport) -> String {
    let p = &report.provenance;
    let nonempty = |v: &serde_json::Value| v.as_str().filter(|s| !s.is_empty()).map(str::to_string);
    nonempty(&p["mesa_version"])
        .or_else(|| nonempty(&p["device"]["driver_info"]))
        .or_else(|| nonempty(&p["device"]["driver_version"]))
        .unwrap_or_else(|| "?".into())
}

/// A Mesa build `make mesa` makes (scripts/mesa-noop.sh), which some families' drivers load.
pub struct MesaBuild {
    /// Its tools folder (`tools::TOOLS`: `mesa`, a link into the build cache).
    pub link: &'static str,
    /// The variable that names another build directory instead.
    pub var: &'static str,
    /// What it is, for messages: "Debian 12's Mesa 22.3".
    pub what: &'static str,
    /// What `make mesa` builds in it, for messages.
    pub drivers: &'static str,
}

/// The installed Mesa's own source package (Debian 12: 22.3.6).
pub static MESA_DEBIAN: MesaBuild = MesaBuild {
    link: "mesa",
    var: "BRDFPROF_MESA_DIR",
    what: "the installed Mesa (Debian 12: 22.3)",
    drivers: "Turnip, PanVK and ANV from Debian's source package of the installed Mesa, ~8 minutes on 2 cores",
};

/// Why the validation layer does not run for Mesa 25.0's drivers.
pub const MESA_25_UNVALIDATED: &str = "Debian 12's validation layer warns, on Mesa 25.0's Turnip, PanVK and NVK only, that the kernels' texel-buffer fetch (GLSL usamplerBuffer: an OpTypeSampledImage of Dim Buffer) should not be a sampled image; the same SPIR-V 1.3 kernels pass the layer on lavapipe, RADV and Mesa 22.3's drivers, so brdfprof compiles them unvalidated there and says so";

/// bookworm-backports' Mesa (25.0): Adreno 7xx and Mali Valhall.
pub static MESA_BACKPORTS: MesaBuild = MesaBuild {
    link: "mesa25",
    var: "BRDFPROF_MESA25_DIR",
    what: "bookworm-backports' Mesa 25.0",
    drivers: "Turnip and PanVK from Debian's bookworm-backports source package of Mesa 25.0, ~12 minutes on 2 cores",
};

/// The same Mesa 25.0 source again, its NVK alone (NAK is Rust, so this build needs cargo-installed bindgen and
/// cbindgen and Mesa's Rust subprojects): NVIDIA Turing and Ampere.
pub static MESA_NVK: MesaBuild = MesaBuild {
    link: "mesa25-nvk",
    var: "BRDFPROF_MESA25_NVK_DIR",
    what: "bookworm-backports' Mesa 25.0 (NVK)",
    drivers: "NVK from Debian's bookworm-backports source package of Mesa 25.0, ~12 minutes on 2 cores after ~7 minutes of cargo install for bindgen and cbindgen",
};

impl MesaBuild {
    /// Its directory (`tools::locate`: `$VAR`, beside the binary, the data directory, the build checkout; each
    /// a link `make mesa` makes into its build cache).
    pub fn dir(&self) -> PathBuf {
        crate::tools::dir(self.link)
    }

    /// A file of the build, or an error naming what is missing and what to run.
    pub fn file(&self, driver: &str, relative: &str) -> Result<PathBuf> {
        let path = self.dir().join(relative);
        if !path.is_file() {
            bail!(
                "{driver} is not built: {} is missing. Run `make mesa` (as root: it builds Mesa's drivers and their noop kernel shims once per machine; \
                 here {}), or set {} to such a build of {}",
                path.display(),
                self.drivers,
                self.var,
                self.what
            );
        }
        Ok(path)
    }
}

/// The directory of the installed Mesa's build (`MESA_DEBIAN`).
pub fn build_dir() -> PathBuf {
    MESA_DEBIAN.dir()
}

/// The variable that names the installed Mesa's build directory.
pub const BUILD_DIR_VAR: &str = "BRDFPROF_MESA_DIR";

/// The environment of a driver on a noop drm-shim: the loader sees only `icd` (the driver's devenv ICD file,
/// which names `library` in the build), `shim` answers the kernel's ioctls, and `extra` selects the GPU. Each
/// file must be in the build, or the error names it and `make mesa`.
pub fn shim_environment(
    driver: &str,
    build: &MesaBuild,
    icd: &str,
    library: &str,
    shim: &str,
    extra: &[(&str, String)],
) -> Result<Vec<(String, String)>> {
    let icd = build.file(driver, icd)?;
    build.file(driver, library)?;
    let shim = build.file(driver, shim)?;
    let mut env = vec![
        ("VK_ICD_FILENAMES".to_string(), icd.display().to_string()),
        ("VK_DRIVER_FILES".to_string(), icd.display().to_string()),
        ("LD_PRELOAD".to_string(), shim.display().to_string()),
    ];
    env.extend(extra.iter().map(|(k, v)| (k.to_string(), v.clone())));
    Ok(env)
}
