//! The parent: runs one child per family (at most as many at once as the host has cores), each under the
//! compile limit and with the driver's environment, reads its report back or takes it from the kernel cache,
//! contains a child's crash and isolates a model a driver fails on.

use super::cache;
use super::{
    CHILD_COMMAND, CRASH_AFTER_REPLY, CRASH_ON_MODEL, HOLD_BEFORE_CHILDREN, NoopDriver, NoopReply, NoopRequest,
    RawSpirv, TARGET_VAR, add_driver_note, driver_of, test_hook,
};
use crate::cleanup;
use crate::kernels::shade::{GBufferFormat, kernel_hash};
use crate::model::Model;
use crate::schema::InspectReport;
use crate::shaders::Shaders;
use crate::targets::{RawKernel, Request, Run, Target};
use anyhow::{Context, Result, anyhow, bail};
use serde::{Deserialize, Serialize};
use std::path::{Path, PathBuf};

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
    raw: &[RawKernel],
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
fn write_raw_spirv(dir: &Path, raw: &[RawKernel]) -> Result<Vec<RawSpirv>> {
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
fn isolable(e: &anyhow::Error, models: &[Model], raw: &[RawKernel]) -> bool {
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
    raw: &[RawKernel],
    request: &Job,
    environment: Vec<(String, String)>,
) -> Result<(ChildRun, Vec<String>)> {
    let target = Target { vendor: driver, family };
    let name = target.name();
    // The child writes its ISA files into its own TMPDIR; they become outputs of this process (staged with
    // its others) only once the child has succeeded.
    let mut cmd = cleanup::self_command(CHILD_COMMAND)?;
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
    cmd.arg(serde_json::to_string(&req)?)
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
pub fn compile(prefix: &str, families: &[usize], raw: &[RawKernel], request: &Request) -> Result<Vec<Run>> {
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
