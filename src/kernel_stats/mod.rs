//! What every report holds of the shading kernels themselves: per kernel its SPIR-V instruction counts (glslang's
//! output specialised, and after `spirv-opt -O`), naga's analysis, its hash, and on a Vulkan device the driver's
//! statistics, as report rows in report order. `inspect` and the compile-only targets both build their reports
//! here: a device's (`device_report`, callgrind's figures added by the caller that measures them) or a compiled
//! target's (`compiled_report`).

pub mod naga_info;

use crate::export::json::Provenance;
use crate::gpu::Gpu;
use crate::kernels::shade::{self, GBufferFormat, shade_kernel, steady_block};
use crate::model::{BASELINE_LABEL, Model, ModelKernel};
use crate::schema::callgrind::CallgrindRun;
use crate::schema::{FOLDED_NOTE, HASH_NOTE, InspectReport, Row, SECTIONS, driver};
use crate::shaders::Shaders;
use crate::spirv;
use anyhow::{Context, Result};
use std::collections::BTreeMap;

/// SPIR-V statistics of one specialised kernel, and naga's of `naga_kernel` (the same BRDF over the float
/// G-buffer: naga's SPIR-V front end has no texel buffers, which the packed kernel reads).
fn static_stats(kernel: &ModelKernel, naga_kernel: &ModelKernel, row: &mut Row) -> Result<()> {
    let model = row.model.clone();
    let frozen = spirv::specialise(&kernel.spirv.words, &kernel.constants).with_context(|| model.clone())?;
    row.stats.extend(spirv::count(&frozen)?.stats("spirv"));
    row.stats.extend(spirv::count(&spirv::optimise(&frozen).with_context(|| model.clone())?)?.stats("spirv-O"));
    let naga = naga_info::analyse(
        &spirv::specialise(&naga_kernel.spirv.words, &naga_kernel.constants).with_context(|| model.clone())?,
    );
    row.stats.extend(naga.stats());
    row.notes.insert("naga".into(), naga.verdict());
    Ok(())
}

/// Driver statistics of the kernel's pipeline, where the device reports them.
fn driver_stats(gpu: &Gpu, kernel: &ModelKernel, row: &mut Row) -> Result<()> {
    if !gpu.reports_statistics() {
        return Ok(());
    }
    let pipeline = crate::gpu::Kernel::new(
        gpu,
        &kernel.spirv.name,
        &kernel.spirv.words,
        &kernel.constants,
        &shade::bindings(GBufferFormat::Packed),
        shade::PUSH_BYTES,
    )?;
    if let Some(executables) = pipeline.executables()? {
        row.stats.extend(driver::executable_stats(executables));
    }
    Ok(())
}

/// Statistic keys in report order: sections in order, and within one, keys in the order rows first gave them.
fn ordered_columns(rows: &[Row], emitted: &[String]) -> Vec<String> {
    let mut columns = Vec::new();
    for (prefix, _) in SECTIONS {
        for key in emitted.iter().filter(|k| k.starts_with(prefix)) {
            if !columns.contains(key) && rows.iter().any(|r| r.stats.contains_key(key)) {
                columns.push(key.clone());
            }
        }
    }
    columns
}

/// One kernel's device-independent statistics (None: the baseline kernel): SPIR-V and naga counts, and the
/// kernel's hash.
pub fn static_row(shaders: &Shaders, model: Option<&Model>, lights: u32) -> Result<Row> {
    let mut row = Row {
        model: model.map_or_else(|| BASELINE_LABEL.to_string(), Model::label),
        spec: model.map(Model::canonical),
        stats: BTreeMap::new(),
        notes: BTreeMap::new(),
    };
    let (per_dispatch, accumulate) = steady_block(lights);
    let kernel = shade_kernel(model, GBufferFormat::Packed, per_dispatch, accumulate, shaders)?;
    let float_kernel = shade_kernel(model, GBufferFormat::Float, per_dispatch, accumulate, shaders)?;
    row.notes.insert(HASH_NOTE.into(), shade::kernel_hash(model, GBufferFormat::Packed, shaders)?);
    if let Some(folded) = model.and_then(Model::file).map(|f| f.folded()).filter(|f| !f.is_empty()) {
        let note = format!(
            "parameters compiled in as constants, so the figures are for these values (the compiler may fold them): {}; bind one to an input (NAME=@roughness, ...) to cost it as one",
            folded.join(", ")
        );
        crate::messages::note_once(format!("{}: {note}", row.model));
        row.notes.insert(FOLDED_NOTE.into(), note);
    }
    static_stats(&kernel, &float_kernel, &mut row)?;
    Ok(row)
}

/// One kernel's SPIR-V, naga and driver statistics (None: the baseline kernel).
fn kernel_row(gpu: &Gpu, shaders: &Shaders, model: Option<&Model>, lights: u32) -> Result<Row> {
    if let Some(m) = model {
        m.check_support(&gpu.info)?;
    }
    let mut row = static_row(shaders, model, lights)?;
    let (per_dispatch, accumulate) = steady_block(lights);
    let kernel = shade_kernel(model, GBufferFormat::Packed, per_dispatch, accumulate, shaders)?;
    driver_stats(gpu, &kernel, &mut row)?;
    Ok(row)
}

/// The models' kernels and then the memory-only one (None).
pub fn kernels_of(models: &[Model]) -> Vec<Option<&Model>> {
    let mut all: Vec<Option<&Model>> = models.iter().map(Some).collect();
    all.push(None);
    all
}

/// Statistic keys in the order rows give them (the SPIR-V counts first, in their own order), after filling
/// in the SPIR-V classes and extended instructions a kernel lacks as 0.
fn emitted_keys(rows: &mut [Row]) -> Vec<String> {
    let mut emitted: Vec<String> = Vec::new();
    for row in rows.iter() {
        for key in spirv_key_order(row).into_iter().chain(row.stats.keys().cloned()) {
            if !emitted.contains(&key) {
                emitted.push(key);
            }
        }
    }
    for key in emitted.iter().filter(|k| k.starts_with("spirv")) {
        for row in rows.iter_mut() {
            row.stats.entry(key.clone()).or_insert(0.0);
        }
    }
    emitted
}

/// The tools every report names: spirv-opt and glslang (which compiles a shader file's kernels, and with
/// `--glsl DIR` every kernel, at run time; a baseline records it, so that its counts are not compared with
/// another glslang's unseen).
fn tool_versions(_shaders: &Shaders) -> BTreeMap<String, String> {
    let mut tools = BTreeMap::new();
    tools.insert("spirv-opt".into(), spirv::spirv_opt_version().unwrap_or_else(|| "not found".into()));
    tools.insert("glslang".into(), crate::shaders::glslang_version().unwrap_or_else(|| "not found".into()));
    // An HLSL or WGSL model's front end (docs/hlsl.md, docs/wgsl.md).
    tools.extend(crate::model::front::used().into_iter().map(|(path, front)| (format!("front end of {path}"), front)));
    tools
}

/// The report of a compile-only target that compiles in this process (no Vulkan device of its own): the
/// static rows with the target compiler's statistics added under `driver/`, nothing executed.
pub fn compiled_report(
    mut rows: Vec<Row>,
    provenance: serde_json::Value,
    lights: u32,
    shaders: &Shaders,
    mut tools: BTreeMap<String, String>,
    section_notes: BTreeMap<String, String>,
) -> InspectReport {
    let emitted = emitted_keys(&mut rows);
    tools.extend(tool_versions(shaders));
    InspectReport {
        provenance,
        kernels: shaders.describe(),
        lights,
        tools,
        columns: ordered_columns(&rows, &emitted),
        rows,
        section_notes,
        callgrind: None,
        callgrind_setup: BTreeMap::new(),
        vs_profile: None,
        cost: None,
        lines: Vec::new(),
        loop_trips: Vec::new(),
    }
}

/// A callgrind measurement of a device report's kernels: it adds its figures to the rows and says how it went
/// in the section notes and the setup.
pub type Callgrind<'a> =
    &'a mut dyn FnMut(&mut [Row], &mut BTreeMap<String, String>, &mut BTreeMap<String, String>) -> Option<CallgrindRun>;

/// A Vulkan device's report of the models' kernels and the memory-only one: every static statistic, the
/// driver's, and callgrind's where `callgrind` measures them (None: not measured).
pub fn device_report(
    gpu: &Gpu,
    shaders: &Shaders,
    models: &[Model],
    lights: u32,
    callgrind: Option<Callgrind>,
) -> Result<InspectReport> {
    let mut rows = kernels_of(models)
        .into_iter()
        .map(|model| kernel_row(gpu, shaders, model, lights))
        .collect::<Result<Vec<_>>>()?;
    let mut emitted = emitted_keys(&mut rows);
    let mut section_notes = BTreeMap::new();
    if !gpu.reports_statistics() {
        section_notes.insert(
            "driver/".into(),
            format!("not available on this device ({} has no VK_KHR_pipeline_executable_properties)", gpu.info.name),
        );
    }
    let mut tools = tool_versions(shaders);
    let mut callgrind_setup = BTreeMap::new();
    let callgrind = match callgrind {
        Some(measure) => measure(&mut rows, &mut section_notes, &mut callgrind_setup),
        None => {
            section_notes.insert("callgrind/".into(), "not measured (--no-callgrind)".into());
            None
        }
    };
    if let Some(v) = callgrind_setup.get("valgrind") {
        tools.insert("valgrind".into(), v.clone());
    }
    for key in ["callgrind/ir-per-eval", "callgrind/net-ir-per-eval"] {
        if !emitted.iter().any(|k| k == key) {
            emitted.push(key.to_string());
        }
    }
    let report = InspectReport {
        provenance: serde_json::to_value(Provenance::new(&gpu.info))?,
        kernels: shaders.describe(),
        lights,
        tools,
        columns: ordered_columns(&rows, &emitted),
        rows,
        section_notes,
        callgrind,
        callgrind_setup,
        vs_profile: None,
        cost: None,
        lines: Vec::new(),
        loop_trips: Vec::new(),
    };
    Ok(report)
}

/// The SPIR-V keys of a row in the order `Counts::stats` gives them.
fn spirv_key_order(row: &Row) -> Vec<String> {
    let mut keys = Vec::new();
    for prefix in ["spirv", "spirv-O"] {
        keys.push(format!("{prefix}/total"));
        keys.push(format!("{prefix}/functions"));
        keys.extend(spirv::CLASSES.iter().map(|c| format!("{prefix}/{c}")));
        keys.extend(row.stats.keys().filter(|k| k.starts_with(&format!("{prefix}/glsl."))).cloned());
    }
    keys
}
