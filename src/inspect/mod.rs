//! `brdfprof inspect`: what each model's specialised shading kernel is made of and what it executes.
//! Per model spec: SPIR-V instruction counts by class (glslang's output specialised, and after
//! `spirv-opt -O`), naga's analysis, the driver's own statistics where it reports them, and on lavapipe the
//! CPU instructions its JIT code executes per BRDF evaluation (callgrind), with the cost table the device's
//! statistics give (`targets::cost_of`). The per-kernel rows are `kernel_stats`'s, shared with the compile-only
//! targets. `check` turns these counts (and a short timing run) into a regression gate against a saved baseline.

pub mod callgrind;
pub mod correlate;
pub mod devices;

use crate::gpu::Gpu;
use crate::kernel_stats;
use crate::model::Model;
use crate::schema::callgrind::CallgrindRun;
use crate::schema::{InspectReport, Row};
use crate::shaders::Shaders;
use anyhow::Result;
use callgrind::CallgrindOptions;
use std::collections::BTreeMap;

pub use crate::model::BASELINE_LABEL;

#[derive(Clone, Debug)]
pub struct InspectOptions {
    pub models: Vec<Model>,
    pub lights: u32,
    /// None: no callgrind run.
    pub callgrind: Option<CallgrindOptions>,
}

/// Runs every analysis for every model and the baseline kernel, with the cost table its vendor's model gives,
/// if any (a real RADV GPU reports ACO's statistics).
pub fn run(gpu: &Gpu, shaders: &Shaders, options: &InspectOptions) -> Result<InspectReport> {
    let mut report = match &options.callgrind {
        Some(cg) => {
            let mut measure =
                |rows: &mut [Row], notes: &mut BTreeMap<String, String>, setup: &mut BTreeMap<String, String>| {
                    measure_callgrind(gpu, shaders, options, cg, rows, notes, setup)
                };
            kernel_stats::device_report(gpu, shaders, &options.models, options.lights, Some(&mut measure))?
        }
        None => kernel_stats::device_report(gpu, shaders, &options.models, options.lights, None)?,
    };
    report.cost = crate::targets::cost_of(&report);
    Ok(report)
}

/// The callgrind figures, on lavapipe only; a failure is reported in the section notes, not fatal.
fn measure_callgrind(
    gpu: &Gpu,
    shaders: &Shaders,
    options: &InspectOptions,
    cg: &CallgrindOptions,
    rows: &mut [Row],
    notes: &mut BTreeMap<String, String>,
    setup: &mut BTreeMap<String, String>,
) -> Option<CallgrindRun> {
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
