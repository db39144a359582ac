//! `--device anv:FAMILY`: Intel GPUs through ANV, Intel's Linux Vulkan driver in Mesa, and its compiler (brw),
//! on Mesa's intel noop drm-shim (`INTEL_STUB_GPU_PLATFORM`). It compiles the very SPIR-V lavapipe runs, with no
//! translation: a second Intel production compiler beside IGC (`intel:`, which compiles the OpenCL C
//! translation).
//!
//! brw states its own static estimate, "Cycle Count": `performance::latency`, "estimate of the runtime of the
//! whole program in cycle units assuming uncontended execution" (brw_ir_performance.h; set in
//! brw_fs_generator.cpp, Mesa 22.3), one hardware thread of SIMD width N. One thread evaluates N invocations, so
//! `cycles/eval = Cycle Count / (SIMD width x lights per kernel)`, the SIMD width being the executable's
//! subgroupSize (ANV reports the dispatch width there).

use super::cost;
use super::mesa_noop::shim::{Shim, ShimFamily};
use crate::schema::InspectReport;
use crate::schema::cost::TargetCost;

/// The statistics shown beside cycles/eval (ANV's names).
const SHOWN: [&str; 5] = ["Instruction Count", "SEND Count", "Cycle Count", "Spill Count", "Fill Count"];

const fn family(
    name: &'static str,
    gpu_id: &'static str,
    architecture: &'static str,
    products: &'static str,
    detail: &'static str,
) -> ShimFamily {
    ShimFamily {
        name,
        gpu_id,
        architecture,
        products,
        detail,
        default: true,
        build: &super::mesa_noop::MESA_DEBIAN,
        without_validation: None,
    }
}

pub static ANV: Shim = Shim {
    prefix: "anv",
    vendor: "Intel",
    title: "Intel (ANV): Mesa's Intel Vulkan driver (brw compiler) on the intel noop drm-shim, in a child process (it compiles, nothing executes)",
    driver: "ANV",
    compiler: "brw",
    icd: "src/intel/vulkan/intel_devenv_icd.x86_64.json",
    library: "src/intel/vulkan/libvulkan_intel.so",
    shim: "src/intel/tools/libintel_noop_drm_shim.so",
    gpu_var: "INTEL_STUB_GPU_PLATFORM",
    extra_env: &[],
    families: &[
        family("skl", "skl", "Gen9", "Skylake HD/Iris Graphics 5xx", "INTEL_STUB_GPU_PLATFORM=skl, Gen9"),
        family("icl", "icl", "Gen11", "Ice Lake Iris Plus", "INTEL_STUB_GPU_PLATFORM=icl, Gen11"),
        family("tgl", "tgl", "Gen12LP (Xe-LP)", "Tiger Lake Iris Xe", "INTEL_STUB_GPU_PLATFORM=tgl, Gen12LP"),
        family("adl", "adl", "Gen12LP (Xe-LP)", "Alder Lake UHD/Iris Xe", "INTEL_STUB_GPU_PLATFORM=adl, Gen12LP"),
        family("dg2", "dg2", "Xe-HPG (Gen12.5)", "Arc A-series (Alchemist)", "INTEL_STUB_GPU_PLATFORM=dg2, Gen12.5"),
    ],
    cost: cost_table,
    // The shim's line for each ioctl query it does not emulate (Mesa 22.3's i915 shim: DG2's memory regions).
    compiler_log: None,
};

/// brw's Cycle Count per invocation and light (the module's rule).
fn cycles_per_eval(stats: &std::collections::BTreeMap<String, f64>, lights: u32) -> Option<f64> {
    let cycles = cost::driver_stat(stats, "Cycle Count")?;
    let simd = stats.get(crate::schema::driver::SUBGROUP_SIZE).copied().filter(|s| *s > 0.0)?;
    Some(cycles / (simd * f64::from(lights)))
}

fn cost_table(shim: &Shim, family: &ShimFamily, report: &InspectReport) -> Option<TargetCost> {
    let rule = "cycles/eval = Cycle Count / (SIMD width x lights per kernel): brw's own static estimate of one thread's EU cycles, per invocation (SIMD width = the executable's subgroupSize)";
    cost::table(report, shim.header(family, report, rule.into(), "EU cycles", &SHOWN), cycles_per_eval)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::schema::Row;

    #[test]
    fn cycles_per_eval_is_cycle_count_per_lane_and_light() {
        let row = |model: &str, cycles: f64, simd: f64| Row {
            model: model.into(),
            spec: None,
            stats: [
                ("driver/Compute Shader/Cycle Count".to_string(), cycles),
                (crate::schema::driver::SUBGROUP_SIZE.to_string(), simd),
            ]
            .into(),
            notes: Default::default(),
        };
        let mut report = crate::schema::tests::empty_report("Intel(R) Xe Graphics (TGL GT2)");
        report.provenance["target"] = "anv:tgl".into();
        report.rows = vec![row("ggx", 5286.0, 16.0), row(crate::model::BASELINE_LABEL, 1994.0, 16.0)];
        let t = super::super::Vendor::cost(&ANV, &report).unwrap();
        let lights = f64::from(t.lights_per_kernel);
        assert_eq!(t.family.as_deref(), Some("tgl"));
        assert_eq!(t.rows[0].cycles_per_eval, 5286.0 / (16.0 * lights));
        assert_eq!(t.rows[0].net_cycles_per_eval, Some((5286.0 - 1994.0) / (16.0 * lights)));
        assert_eq!(super::super::Vendor::family_of(&ANV, &report), Some(2));
    }
}
