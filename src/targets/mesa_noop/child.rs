//! The child (`brdfprof __noop-child REQUEST`): compiles every kernel on the compile-only device its
//! environment offers, optionally writes the driver's internal representations, and prints its report as one
//! JSON line.

use super::{
    CHILD_COMMAND, CRASH_AFTER_REPLY, CRASH_ON_MODEL, NoopReply, NoopRequest, TARGET_VAR, add_driver_note, driver_of,
    test_hook,
};
use crate::gpu::{Gpu, GpuOptions, Kernel};
use crate::kernels::shade::{self, GBufferFormat, shade_kernel, steady_block};
use crate::model::BASELINE_LABEL;
use crate::model::Model;
use crate::schema::InspectReport;
use crate::shaders::Shaders;
use crate::targets::Target;
use anyhow::{Context, Result, anyhow, bail};
use std::path::{Path, PathBuf};

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
    report.cost = crate::targets::cost_of(&report);
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
            let path =
                dir.join(format!("{}.{}.txt", crate::targets::file_slug(label), crate::targets::file_slug(name)));
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
