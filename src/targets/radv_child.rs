//! `--device radv:FAMILY`: the kernels compiled by Mesa RADV's ACO for an AMD GPU family that this machine
//! does not have. brdfprof runs itself as a child (`brdfprof __radv-child REQUEST`) with
//! `RADV_FORCE_FAMILY=<family>` in its environment, so that the Vulkan loader of that process (and only of
//! it) sees RADV's compile-only "Null hardware" device. The child opens that device, runs `inspect`'s
//! analyses on it (no callgrind: nothing executes), optionally writes ACO's internal representations of
//! every kernel, and prints its report as one JSON line. The child dies with brdfprof (cleanup::command).
//!
//! The null device has no queue that executes work: `Gpu` never waits on it when nothing was submitted
//! (Mesa 22.3's vkDeviceWaitIdle calls through a null pointer there), and a child that still crashes after
//! printing its complete report is accepted with a note, so the user gets the report and exit 0.

use crate::inspect::{InspectOptions, InspectReport};
use crate::cleanup;
use super::radv_families::{self as targets, Family};
use crate::gpu::{Gpu, GpuOptions, Kernel};
use crate::model::Model;
use crate::kernels::shade::{self, shade_kernel, steady_block, GBufferFormat};
use crate::model::BASELINE_LABEL;
use crate::shaders::Shaders;
use anyhow::{anyhow, bail, Context, Result};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

/// The hidden subcommand the child runs.
pub const CHILD_COMMAND: &str = "__radv-child";

/// What the parent asks the child (one JSON argument).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct RadvRequest {
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
pub struct RadvReply {
    pub family: String,
    pub report: InspectReport,
    /// Files written under the ISA directory.
    pub isa_files: Vec<PathBuf>,
}

/// One target's result in the parent.
#[derive(Clone, Debug)]
pub struct RadvRun {
    pub target: &'static Family,
    pub report: InspectReport,
    pub isa_files: Vec<PathBuf>,
    /// Set when the child crashed after it had printed its complete report.
    pub teardown_note: Option<String>,
}

/// The child: compiles every kernel on the null device of `RADV_FORCE_FAMILY` and reports.
pub fn child_main(request_json: &str) -> Result<()> {
    let req: RadvRequest = serde_json::from_str(request_json).context("bad radv child request")?;
    let target = targets::lookup(&req.family)?;
    if std::env::var(targets::FORCE_FAMILY_VAR).ok().as_deref() != Some(target.family) {
        bail!("`brdfprof {CHILD_COMMAND}` runs with {}={}; `brdfprof inspect --device radv:{}` runs it so", targets::FORCE_FAMILY_VAR, target.family, target.family);
    }
    let models = req.models.iter().map(|s| Model::parse(s).map_err(|e| anyhow!("{s}: {e:#}"))).collect::<Result<Vec<_>>>()?;
    let shaders = match &req.glsl {
        Some(dir) => Shaders::from_glsl(dir)?,
        None => Shaders::embedded(),
    };
    let name = targets::null_device_name(target);
    let gpu = Gpu::new(&GpuOptions { device: Some(name.clone()), validation: req.validate }).map_err(|e| {
        anyhow!(
            "RADV offered no compile-only device `{name}` ({e:#}). Is Mesa's AMD Vulkan driver installed? On Debian/Ubuntu as \
             root: `apt-get install mesa-vulkan-drivers` (it ships /usr/share/vulkan/icd.d/radeon_icd.*.json), or run `make setup`"
        )
    })?;
    if !gpu.info.compile_only() {
        bail!("{} is not RADV's compile-only device", gpu.info.name);
    }
    if !req.raw.is_empty() {
        let isa_dir = req.isa_dir.as_ref().map(|d| d.join(target.family));
        let (report, isa_files) = raw_report(&gpu, &shaders, &req, target.family, isa_dir.as_deref())?;
        gpu.check_validation()?;
        drop(gpu);
        return reply(RadvReply { family: target.family.to_string(), report, isa_files });
    }
    // A model this family cannot compile (fp16 arithmetic where the device has no shaderFloat16) is left out
    // and named in the driver section's notes, so that one family does not stop a report of many.
    let (models, skipped): (Vec<Model>, Vec<Model>) = models.into_iter().partition(|m| m.check_support(&gpu.info).is_ok());
    let mut report = super::inspect_device(&gpu, &shaders, &InspectOptions { models: models.clone(), lights: req.lights, callgrind: None })?;
    if !skipped.is_empty() {
        let why = skipped.iter().map(|m| format!("{} ({:#})", m.name(), m.check_support(&gpu.info).unwrap_err())).collect::<Vec<_>>().join("; ");
        report.section_notes.insert("driver/".into(), format!("not compiled for {}: {why}", target.family));
    }
    let mut isa_files = Vec::new();
    if let Some(dir) = &req.isa_dir {
        let dir = dir.join(target.family);
        std::fs::create_dir_all(&dir).with_context(|| format!("--isa: cannot create {}", dir.display()))?;
        let mut all: Vec<Option<&Model>> = models.iter().map(Some).collect();
        all.push(None);
        for model in all {
            isa_files.extend(write_isa(&gpu, &shaders, model, req.lights, &dir)?);
        }
    }
    gpu.check_validation()?;
    drop(gpu);
    reply(RadvReply { family: target.family.to_string(), report, isa_files })
}

/// Prints the reply as the child's last stdout line.
fn reply(reply: RadvReply) -> Result<()> {
    println!("{}", serde_json::to_string(&reply)?);
    if std::env::var_os(CRASH_AFTER_REPLY).is_some() {
        use std::io::Write;
        std::io::stdout().flush()?;
        // SAFETY: raising a signal on this process; the test of crash containment asks for it.
        // The default action (Rust's own SIGSEGV handler is for stack overflows and would return).
        unsafe {
            libc::signal(libc::SIGSEGV, libc::SIG_DFL);
            libc::raise(libc::SIGSEGV);
        }
    }
    Ok(())
}

/// The request's raw kernels compiled on the null device, one row each with ACO's statistics, as one report
/// (with the request's lights per kernel, which the cost divides by); a kernel the family cannot compile is left
/// out and named in the driver section's notes.
fn raw_report(gpu: &Gpu, shaders: &Shaders, req: &RadvRequest, family: &str, isa_dir: Option<&Path>) -> Result<(InspectReport, Vec<PathBuf>)> {
    let mut rows = Vec::new();
    let mut skipped = Vec::new();
    let mut isa_files = Vec::new();
    for r in &req.raw {
        let model = Model::parse(&r.model).map_err(|e| anyhow!("{}: {e:#}", r.model))?;
        if let Err(e) = model.check_support(&gpu.info) {
            skipped.push(format!("{} ({e:#})", r.label));
            continue;
        }
        let bytes = crate::io::read_bounded(&r.path, crate::compile_limit::MAX_OUTPUT_BYTES as u64).with_context(|| format!("the radv child cannot read {}", r.path.display()))?;
        let words: Vec<u32> = bytemuck::pod_collect_to_vec(&bytes);
        let kernel = Kernel::with_capture(gpu, &r.label, &words, &Default::default(), &crate::gpu::Binding::storage(r.storage_buffers), r.push_bytes, isa_dir.is_some())?;
        let mut row = crate::inspect::Row { model: r.label.clone(), spec: None, stats: Default::default(), notes: Default::default() };
        let executables = kernel.executables()?.ok_or_else(|| anyhow!("{} reports no pipeline statistics", gpu.info.name))?;
        if let Some(dir) = isa_dir {
            isa_files.extend(write_representations(gpu, &executables, &r.label, dir)?);
        }
        row.stats.extend(crate::inspect::driver::stats(&executables.into_iter().flat_map(|e| e.stats).collect::<Vec<_>>()));
        rows.push(row);
    }
    let provenance = serde_json::to_value(crate::results::Provenance::new(&gpu.info))?;
    let notes = if skipped.is_empty() { Default::default() } else { [("driver/".to_string(), format!("not compiled for {family}: {}", skipped.join("; ")))].into() };
    Ok((crate::inspect::compiled_report(rows, provenance, req.lights, shaders, Default::default(), notes), isa_files))
}

/// Set in a child's environment, it dies of SIGSEGV after printing its report, as Mesa 22.3's teardown of the
/// null device did (vkDeviceWaitIdle through a null pointer): the test that the parent contains such a crash.
pub const CRASH_AFTER_REPLY: &str = "BRDFPROF_TEST_RADV_CHILD_CRASH";

/// Compiles one kernel with CAPTURE_INTERNAL_REPRESENTATIONS and writes each text representation
/// (RADV: NIR, ACO IR, disassembly) to DIR/<kernel>.<representation>.txt.
fn write_isa(gpu: &Gpu, shaders: &Shaders, model: Option<&Model>, lights: u32, dir: &Path) -> Result<Vec<PathBuf>> {
    let label = model.map_or_else(|| BASELINE_LABEL.to_string(), Model::label);
    let (per_dispatch, accumulate) = steady_block(lights);
    let k = shade_kernel(model, GBufferFormat::Packed, per_dispatch, accumulate, shaders)?;
    let kernel = Kernel::with_capture(gpu, &k.spirv.name, &k.spirv.words, &k.constants, &shade::bindings(GBufferFormat::Packed), shade::PUSH_BYTES, true)?;
    write_representations(gpu, &kernel.executables()?.unwrap_or_default(), &label, dir)
}

/// Each text representation of each executable (RADV: NIR, ACO IR, disassembly) to DIR/<kernel>.<representation>.txt.
fn write_representations(gpu: &Gpu, executables: &[crate::gpu::PipelineExecutable], label: &str, dir: &Path) -> Result<Vec<PathBuf>> {
    std::fs::create_dir_all(dir).with_context(|| format!("--isa: cannot create {}", dir.display()))?;
    let mut files = Vec::new();
    for exe in executables {
        for (name, text) in &exe.representations {
            let path = dir.join(format!("{}.{}.txt", super::file_slug(label), super::file_slug(name)));
            crate::io::write_output(&path, format!("; {label}: {} of {}, {}\n{text}", name, exe.name, gpu.info.name).as_bytes())?;
            files.push(path);
        }
    }
    if files.is_empty() {
        bail!("{}: the driver returned no internal representation for {label}", gpu.info.name);
    }
    Ok(files)
}

/// Runs the child for one target and reads its report.
pub fn run(target: &'static Family, models: &[Model], raw: &[super::RawKernel], lights: u32, shaders: &Shaders, validate: bool, isa_dir: Option<&Path>) -> Result<RadvRun> {
    // The child writes its ISA files into its own TMPDIR; they become outputs of this process (staged with
    // its others) only once the child has succeeded.
    let mut cmd = cleanup::command(&std::env::current_exe().context("cannot find brdfprof's own executable")?.to_string_lossy());
    let tmp = cleanup::child_tmpdir(&mut cmd)?;
    let child_isa = isa_dir.map(|_| tmp.path().join("isa"));
    let mut raw_files = Vec::new();
    for (k, r) in raw.iter().enumerate() {
        let path = tmp.path().join(format!("raw-{k}.spv"));
        std::fs::write(&path, bytemuck::cast_slice::<u32, u8>(&r.spirv)).with_context(|| format!("cannot write {}", path.display()))?;
        raw_files.push(RawSpirv { label: r.label.clone(), model: r.model.name(), path, storage_buffers: r.storage_buffers, push_bytes: r.push_bytes });
    }
    let req = RadvRequest {
        family: target.family.to_string(),
        models: models.iter().map(Model::name).collect(),
        lights,
        validate,
        glsl: shaders.glsl_dir().map(Path::to_path_buf),
        isa_dir: child_isa.clone(),
        raw: raw_files,
    };
    cmd.arg(CHILD_COMMAND)
        .arg(serde_json::to_string(&req)?)
        .env(targets::FORCE_FAMILY_VAR, target.family)
        // ACO's output, not a binary an earlier process cached, and no stale statistics.
        .env("MESA_SHADER_CACHE_DISABLE", "true");
    // The child compiles each kernel under the compile limit itself; the whole child gets one limit per
    // kernel (models, the memory-only kernel, their ISA captures) and a few seconds to start.
    crate::compile_limit::export(&mut cmd);
    let kernels = (models.len() as u32 + 1 + raw.len() as u32) * if isa_dir.is_some() { 2 } else { 1 };
    let limit = crate::compile_limit::limit() * kernels + std::time::Duration::from_secs(10);
    let what = format!("the kernels for radv:{} (ACO, in a child process)", target.family);
    let output = crate::compile_limit::output_within(&mut cmd, &what, limit).context("cannot run brdfprof's radv child")?;
    let stdout = String::from_utf8_lossy(&output.stdout);
    let stderr = String::from_utf8_lossy(&output.stderr);
    // Validation messages and warnings of the child reach the user as they are, but for the banner RADV prints
    // for every device it does not know to be conformant (its null device among them).
    let reply: Option<RadvReply> = stdout.lines().rev().find_map(|l| serde_json::from_str(l).ok());
    // (A failed child's last lines are in the error below.)
    for line in stderr.lines().filter(|l| reply.is_some() && !l.starts_with("WARNING: radv is not a conformant Vulkan implementation")) {
        crate::messages::line(line);
    }
    let teardown_note = match (&reply, output.status.success()) {
        (Some(_), true) => None,
        (Some(_), false) if output.status.code().is_none() => Some(format!(
            "the radv:{} child crashed after writing its complete report ({}); the crash is in Mesa's teardown of the null device, not in the figures",
            target.family, output.status
        )),
        _ => {
            let tail: Vec<&str> = stderr.lines().rev().take(15).collect::<Vec<_>>().into_iter().rev().collect();
            bail!("radv:{}: the compile-only child failed ({}):\n{}", target.family, output.status, tail.join("\n"));
        }
    };
    let reply = reply.expect("checked above");
    if reply.family != target.family {
        bail!("radv child answered for {} instead of {}", reply.family, target.family);
    }
    let isa_files = match (&child_isa, isa_dir) {
        (Some(from), Some(to)) => reply.isa_files.iter().map(|f| publish(f, from, to)).collect::<Result<Vec<_>>>()?,
        _ => Vec::new(),
    };
    Ok(RadvRun { target, report: reply.report, isa_files, teardown_note })
}

/// Writes a file the child wrote under `from` as this process' output under `to`.
fn publish(file: &Path, from: &Path, to: &Path) -> Result<PathBuf> {
    let rel = file.strip_prefix(from).map_err(|_| anyhow!("the radv child wrote {} outside its ISA directory", file.display()))?;
    let bytes = crate::io::read_bounded(file, crate::compile_limit::MAX_OUTPUT_BYTES as u64).with_context(|| format!("cannot read the radv child's {}", file.display()))?;
    let path = to.join(rel);
    crate::io::write_output(&path, &bytes)?;
    Ok(path)
}

/// `run` for every target, at most as many children at once as the host has cores; results in order.
pub fn run_all(targets: &[&'static Family], models: &[Model], raw: &[super::RawKernel], lights: u32, shaders: &Shaders, validate: bool, isa_dir: Option<&Path>) -> Result<Vec<RadvRun>> {
    let workers = std::thread::available_parallelism().map_or(1, |n| n.get()).min(targets.len()).max(1);
    let next = std::sync::atomic::AtomicUsize::new(0);
    let results: std::sync::Mutex<Vec<Option<Result<RadvRun>>>> = std::sync::Mutex::new((0..targets.len()).map(|_| None).collect());
    // Each worker spawns and waits for its own children (PR_SET_PDEATHSIG follows the spawning thread).
    std::thread::scope(|s| {
        for _ in 0..workers {
            s.spawn(|| loop {
                let i = next.fetch_add(1, std::sync::atomic::Ordering::SeqCst);
                if i >= targets.len() {
                    break;
                }
                let r = run(targets[i], models, raw, lights, shaders, validate, isa_dir);
                results.lock().unwrap_or_else(|e| e.into_inner())[i] = Some(r);
            });
        }
    });
    results.into_inner().unwrap_or_else(|e| e.into_inner()).into_iter().map(|r| r.expect("every target ran")).collect()
}
