//! `brdfprof inspect`: what each model's specialised shading kernel is made of and what it executes.
//! Per model spec: SPIR-V instruction counts by class (glslang's output specialised, and after
//! `spirv-opt -O`), naga's analysis, the driver's own statistics where it reports them, and on lavapipe the
//! CPU instructions its JIT code executes per BRDF evaluation (callgrind). `check` turns these counts (and
//! a short timing run) into a regression gate against a saved baseline.

pub mod callgrind;
pub mod cost;
pub mod correlate;
pub mod driver;
pub mod lines;
pub mod naga_info;
pub mod schedule;
pub mod timing;

use crate::spirv;
use crate::gpu::Gpu;
use crate::model::{Model, ModelKernel};
use crate::kernels::shade::{self, shade_kernel, steady_block, GBufferFormat};
use crate::export::json::Provenance;
use crate::export::markdown::{self, Table};
use crate::shaders::Shaders;
use anyhow::{Context, Result};
use callgrind::{CallgrindOptions, CallgrindRun};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

pub use crate::model::BASELINE_LABEL;


/// Key of a row's kernel hash in `inspect::Row::notes`.
pub const HASH_NOTE: &str = "kernel-sha256";

/// Statistic sections, in report order: key prefix and title.
pub const SECTIONS: [(&str, &str); 5] = [
    ("spirv/", "SPIR-V instructions, glslang's output specialised (frozen spec constants, dead code removed)"),
    ("spirv-O/", "SPIR-V instructions after spirv-opt -O (the [[unroll]] light loop unrolled: about NUM_LIGHTS copies of the BRDF)"),
    ("naga/", "naga (SPIR-V front end and validator) on the specialised float-G-buffer kernel (same BRDF; naga 30 reads no texel buffers)"),
    ("driver/", "Driver statistics (VK_KHR_pipeline_executable_properties)"),
    ("callgrind/", "Executed CPU instructions (Ir) per BRDF evaluation of lavapipe's JIT code, under callgrind"),
];

#[derive(Clone, Debug)]
pub struct InspectOptions {
    pub models: Vec<Model>,
    pub lights: u32,
    /// None: no callgrind run.
    pub callgrind: Option<CallgrindOptions>,
}

/// One kernel's statistics.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct Row {
    /// The spec's name, or "baseline" for the memory-only kernel.
    pub model: String,
    /// Canonical spec (None for the baseline kernel).
    pub spec: Option<String>,
    /// Statistic key (`section/name`) -> value.
    pub stats: BTreeMap<String, f64>,
    /// Section -> text that is not a number (naga's verdict, why a section is missing).
    pub notes: BTreeMap<String, String>,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct InspectReport {
    /// Where it was measured (json::Provenance, kept as JSON so that baselines read back whatever it holds).
    pub provenance: serde_json::Value,
    /// Where the SPIR-V came from.
    pub kernels: String,
    pub lights: u32,
    /// Tool versions (spirv-opt, glslang, valgrind).
    pub tools: BTreeMap<String, String>,
    /// Statistic keys in report order.
    pub columns: Vec<String>,
    pub rows: Vec<Row>,
    /// Notes about a whole section (e.g. "not available on this device").
    pub section_notes: BTreeMap<String, String>,
    pub callgrind: Option<CallgrindRun>,
    /// How callgrind was run (workload, valgrind version), recorded even when the run failed; empty when it
    /// was not attempted.
    #[serde(default)]
    pub callgrind_setup: BTreeMap<String, String>,
    /// Callgrind figures next to a profile's timings (`inspect --profile FILE`).
    #[serde(default)]
    pub vs_profile: Option<correlate::Correlation>,
    /// The compiler's cost model applied to the kernels (set by `targets::cost_of`: ACO's on RADV, NVIDIA's issue
    /// model on `nvidia:` targets), where the device's statistics have one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cost: Option<cost::TargetCost>,
    /// Cost per source line (`inspect --lines`), per model, where the compiler names lines.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub lines: Vec<lines::KernelLines>,
}

/// SPIR-V statistics of one specialised kernel, and naga's of `naga_kernel` (the same BRDF over the float
/// G-buffer: naga's SPIR-V front end has no texel buffers, which the packed kernel reads).
fn static_stats(kernel: &ModelKernel, naga_kernel: &ModelKernel, row: &mut Row) -> Result<()> {
    let model = row.model.clone();
    let frozen = spirv::specialise(&kernel.spirv.words, &kernel.constants).with_context(|| model.clone())?;
    row.stats.extend(spirv::count(&frozen)?.stats("spirv"));
    row.stats.extend(spirv::count(&spirv::optimise(&frozen).with_context(|| model.clone())?)?.stats("spirv-O"));
    let naga = naga_info::analyse(&spirv::specialise(&naga_kernel.spirv.words, &naga_kernel.constants).with_context(|| model.clone())?);
    row.stats.extend(naga.stats());
    row.notes.insert("naga".into(), naga.verdict());
    Ok(())
}

/// Driver statistics of the kernel's pipeline, where the device reports them.
fn driver_stats(gpu: &Gpu, kernel: &ModelKernel, row: &mut Row) -> Result<()> {
    if !gpu.reports_statistics() {
        return Ok(());
    }
    let pipeline = crate::gpu::Kernel::new(gpu, &kernel.spirv.name, &kernel.spirv.words, &kernel.constants, &shade::bindings(GBufferFormat::Packed), shade::PUSH_BYTES)?;
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
/// The row note that names a file's parameters compiled in as constants (`FileModel::folded`).
pub const FOLDED_NOTE: &str = "folded";

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
        let note = format!("parameters compiled in as constants, so the figures are for these values (the compiler may fold them): {}; bind one to an input (NAME=@roughness, ...) to cost it as one", folded.join(", "));
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

/// The tools every report names: spirv-opt, and glslang when the kernels were compiled at run time.
fn tool_versions(shaders: &Shaders) -> BTreeMap<String, String> {
    let mut tools = BTreeMap::new();
    tools.insert("spirv-opt".into(), spirv::spirv_opt_version().unwrap_or_else(|| "not found".into()));
    if shaders.glsl_dir().is_some() {
        tools.insert("glslang".into(), crate::shaders::glslang_version().unwrap_or_else(|| "not found".into()));
    }
    // An HLSL or WGSL model's front end (docs/hlsl.md, docs/wgsl.md).
    tools.extend(crate::model::front::used().into_iter().map(|(path, front)| (format!("front end of {path}"), front)));
    tools
}

/// The report of a compile-only target that compiles in this process (no Vulkan device of its own): the
/// static rows with the target compiler's statistics added under `driver/`, nothing executed.
pub fn compiled_report(mut rows: Vec<Row>, provenance: serde_json::Value, lights: u32, shaders: &Shaders, mut tools: BTreeMap<String, String>, section_notes: BTreeMap<String, String>) -> InspectReport {
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
    }
}

/// Runs every analysis for every model and the baseline kernel.
pub fn run(gpu: &Gpu, shaders: &Shaders, options: &InspectOptions) -> Result<InspectReport> {
    let mut rows = kernels_of(&options.models).into_iter().map(|model| kernel_row(gpu, shaders, model, options.lights)).collect::<Result<Vec<_>>>()?;
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
    let callgrind = measure_callgrind(gpu, shaders, options, &mut rows, &mut section_notes, &mut callgrind_setup);
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
        lights: options.lights,
        tools,
        columns: ordered_columns(&rows, &emitted),
        rows,
        section_notes,
        callgrind,
        callgrind_setup,
        vs_profile: None,
        cost: None,
        lines: Vec::new(),
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

/// The callgrind figures, on lavapipe only; a failure is reported in the section notes, not fatal.
fn measure_callgrind(
    gpu: &Gpu,
    shaders: &Shaders,
    options: &InspectOptions,
    rows: &mut [Row],
    notes: &mut BTreeMap<String, String>,
    setup: &mut BTreeMap<String, String>,
) -> Option<CallgrindRun> {
    let Some(cg) = &options.callgrind else {
        notes.insert("callgrind/".into(), "not measured (--no-callgrind)".into());
        return None;
    };
    if !is_lavapipe(&gpu.info) {
        notes.insert("callgrind/".into(), format!("not applicable: {} is not lavapipe (llvmpipe)", gpu.info.name));
        return None;
    }
    let mut cg = cg.clone();
    cg.device = Some(gpu.info.index.to_string());
    setup.insert("workload".into(), format!("{}x{} pixels x {} lights", cg.width, cg.height, options.lights));
    setup.insert("valgrind".into(), callgrind::valgrind_version().unwrap_or_else(|_| "not found".into()));
    match callgrind::run(&options.models, options.lights, shaders, &cg) {
        Ok(run) => {
            for row in rows.iter_mut() {
                row.stats.extend(run.stats(&row.model));
            }
            notes.insert(
                "callgrind/".into(),
                format!("{}x{} pixels x {} lights = {} evaluations per dispatch, LP_NUM_THREADS=0, MESA_SHADER_CACHE_DISABLE=true", cg.width, cg.height, options.lights, run.evaluations),
            );
            Some(run)
        }
        Err(e) => {
            notes.insert("callgrind/".into(), format!("could not measure: {e:#}"));
            None
        }
    }
}

/// lavapipe reports itself as "llvmpipe (LLVM ...)", a CPU device.
pub fn is_lavapipe(info: &crate::gpu::DeviceInfo) -> bool {
    info.is_cpu() && info.name.starts_with("llvmpipe")
}

/// Formats a statistic: whole numbers as integers, others with 4 significant digits.
pub fn format_value(v: f64) -> String {
    if v.fract() == 0.0 && v.abs() < 1e15 { format!("{}", v as i64) } else { markdown::sig(v, 4) }
}

impl InspectReport {
    pub fn row(&self, model: &str) -> Option<&Row> {
        self.rows.iter().find(|r| r.model == model)
    }

    /// One table per section (one row per kernel, one column per statistic, a statistic equal on every kernel
    /// folded into a line below it), with the section's notes.
    pub fn markdown(&self) -> String {
        let mut out = String::new();
        for (prefix, title) in SECTIONS {
            let columns: Vec<&String> = self.columns.iter().filter(|c| c.starts_with(prefix)).collect();
            out += &format!("### {title}\n\n");
            if let Some(note) = self.section_notes.get(prefix) {
                out += &format!("{note}\n\n");
            }
            let with_notes = prefix == "naga/";
            if columns.is_empty() && !with_notes {
                continue;
            }
            let (columns, constant) = fold_constant(&columns, |c| self.rows.iter().map(|r| r.stats.get(*c).copied()).collect());
            let mut headers = vec!["model".to_string()];
            headers.extend(columns.iter().map(|c| c[prefix.len()..].to_string()));
            if with_notes {
                headers.push("result".into());
            }
            let mut t = Table::new(headers);
            for row in &self.rows {
                let mut cells = vec![row.model.clone()];
                cells.extend(columns.iter().map(|c| row.stats.get(*c).map_or("-".into(), |v| format_value(*v))));
                if with_notes {
                    cells.push(row.notes.get("naga").cloned().unwrap_or_default());
                }
                t.row(cells);
            }
            out += &t.markdown();
            out += &constant_note(constant.iter().map(|(c, v)| (&c[prefix.len()..], *v)));
            out += "\n";
        }
        if let Some(a) = &self.cost {
            out += &a.markdown();
            out += "\n";
        }
        out += &self.lines_markdown();
        for row in &self.rows {
            if let Some(note) = row.notes.get(FOLDED_NOTE) {
                out += &format!("{}: {note}.\n\n", row.model);
            }
        }
        if let Some(c) = &self.vs_profile {
            out += &format!("### Instructions vs time per evaluation\n\n{}\n", c.markdown());
        }
        out
    }

    /// Cost per source line (`inspect --lines`): each model's costliest lines, where the report has them.
    pub fn lines_markdown(&self) -> String {
        if self.lines.is_empty() {
            return String::new();
        }
        let unit = self.cost.as_ref().map_or("cycles", |c| c.unit.as_str());
        let mut out = "### Cost per source line

Each instruction of the kernel compiled with line information, attributed to the line of the `.brdf` file or of glsl/ it came from; per line its cycles on the kernel's binding pipe (the share of what binds), and the schedule cycles spent issuing it (waits and stalls), per wave. The ten costliest lines of each model:\n\n".replace("\\n", "\n");
        for k in &self.lines {
            out += &k.markdown(10, unit);
            if !k.note.is_empty() {
                out += &format!("\n{}: {}\n", k.model, k.note);
            }
            out += "\n";
        }
        out
    }

    /// One line saying what was inspected.
    pub fn summary(&self) -> String {
        let device = self.provenance["device"]["name"].as_str().unwrap_or("?");
        format!("{device}; shade kernel, {} lights; SPIR-V {}; tools: {}", self.lights, self.kernels, self.tools.iter().map(|(k, v)| format!("{k} = {v}")).collect::<Vec<_>>().join(", "))
    }
}

/// The columns whose value differs between rows (kept), and those equal on every one of three or more rows
/// with that value (folded: a column that never changes says nothing per row). `values` gives a column's.
pub fn fold_constant<'a, C: Copy>(columns: &'a [C], values: impl Fn(&C) -> Vec<Option<f64>>) -> (Vec<C>, Vec<(C, f64)>) {
    let (mut kept, mut folded) = (Vec::new(), Vec::new());
    for c in columns {
        let v = values(c);
        match v.first() {
            Some(&Some(x)) if v.len() >= 3 && v.iter().all(|y| *y == Some(x)) => folded.push((*c, x)),
            _ => kept.push(*c),
        }
    }
    (kept, folded)
}

/// The line under a table that lists its folded columns, or nothing.
pub fn constant_note<'a>(folded: impl Iterator<Item = (&'a str, f64)>) -> String {
    let items: Vec<String> = folded.map(|(name, v)| format!("{name} {}", format_value(v))).collect();
    if items.is_empty() { String::new() } else { format!("\nThe same on every kernel (not listed per row): {}.\n", items.join(", ")) }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// A report of `device` with no rows, for tests of what reads reports.
    pub fn empty_report(device: &str) -> InspectReport {
        InspectReport {
            provenance: serde_json::json!({"device": {"name": device}}),
            kernels: String::new(),
            lights: 8,
            tools: BTreeMap::new(),
            columns: vec![],
            rows: vec![],
            section_notes: BTreeMap::new(),
            callgrind: None,
            callgrind_setup: BTreeMap::new(),
            vs_profile: None,
            cost: None,
            lines: vec![],
        }
    }
}
