//! `--device adreno:FAMILY`: Qualcomm Adreno 6xx (the installed Mesa 22.3) and 7xx (bookworm-backports' Mesa
//! 25.0) through Mesa's Turnip driver and its ir3 compiler, on the freedreno noop drm-shim (`FD_GPU_ID`). Turnip's ir3 is what Linux and some Android systems run on Adreno;
//! stock phone drivers use Qualcomm's own compiler, so these are ir3's figures, not a phone driver's.
//!
//! ir3 states no cycle model, so brdfprof's rule is built from the statistics ir3 computes itself
//! (`collect_info` in src/freedreno/ir3/ir3.c, Mesa 22.3 and 25.0 alike): "Instruction Count" counts every issue slot of one
//! wave (each instruction `1 + repeat + nop`, so the NOPs it folds into `(nopN)` and plain `nop`s are already in
//! it), and "Estimated cycles stalled on SS/SY" are its own estimates of the cycles a wave waits for SFU
//! (transcendental) and memory results at the `(ss)`/`(sy)` sync bits. One wave's issue cycles are their sum; a
//! wave holds `subgroupSize` fibres (64, or 128 where ir3 doubles the thread size), so
//! `cycles/eval = (Instruction Count + SS stall + SY stall) / (subgroupSize x lights per kernel)`. It assumes
//! one instruction issued per wave per cycle and no other wave hiding the stalls; "Max Waves Per Core" (from
//! registers) is beside it to say how much latency other waves could hide.

use super::cost;
use super::mesa_noop::shim::{Shim, ShimFamily};
use super::mesa_noop::{MESA_25_UNVALIDATED, MESA_BACKPORTS, MESA_DEBIAN};
use crate::schema::InspectReport;
use crate::schema::cost::TargetCost;

/// The statistics shown beside cycles/eval (Turnip's names).
const SHOWN: [&str; 6] = [
    "Instruction Count",
    "NOPs Count",
    "Estimated cycles stalled on SS",
    "Estimated cycles stalled on SY",
    "Registers used",
    "Max Waves Per Core",
];

const fn family(name: &'static str, gpu_id: &'static str, products: &'static str, detail: &'static str) -> ShimFamily {
    ShimFamily {
        name,
        gpu_id,
        architecture: "Adreno 6xx",
        products,
        detail,
        default: true,
        build: &MESA_DEBIAN,
        without_validation: None,
    }
}

/// An a7xx GPU: Mesa 22.3's Turnip has none; bookworm-backports' Mesa 25.0 compiles for them.
const fn family_a7xx(
    name: &'static str,
    gpu_id: &'static str,
    products: &'static str,
    detail: &'static str,
) -> ShimFamily {
    ShimFamily {
        name,
        gpu_id,
        architecture: "Adreno 7xx",
        products,
        detail,
        default: true,
        build: &MESA_BACKPORTS,
        without_validation: Some(MESA_25_UNVALIDATED),
    }
}

pub static ADRENO: Shim = Shim {
    prefix: "adreno",
    vendor: "Qualcomm",
    title: "Qualcomm Adreno: Mesa's Turnip driver (ir3 compiler) on the freedreno noop drm-shim, in a child process (it compiles, nothing executes)",
    driver: "Turnip",
    compiler: "ir3",
    icd: "src/freedreno/vulkan/freedreno_devenv_icd.x86_64.json",
    library: "src/freedreno/vulkan/libvulkan_freedreno.so",
    shim: "src/freedreno/drm-shim/libfreedreno_noop_drm_shim.so",
    gpu_var: "FD_GPU_ID",
    extra_env: &[],
    // The a6xx GPUs Mesa 22.3's shim accepts (650 and 690 it refuses), and the a7xx ones Mesa 25.0's does.
    families: &[
        family("a618", "618", "Snapdragon 730/730G/732G", "FD_GPU_ID=618, a6xx gen 1"),
        family("a630", "630", "Snapdragon 845", "FD_GPU_ID=630, a6xx gen 1"),
        family("a660", "660", "Snapdragon 888", "FD_GPU_ID=660, a6xx gen 4"),
        family_a7xx("a730", "730", "Snapdragon 8 Gen 1", "FD_GPU_ID=730, a7xx gen 1, Mesa 25.0"),
        family_a7xx("a740", "740", "Snapdragon 8 Gen 2", "FD_GPU_ID=740, a7xx gen 2, Mesa 25.0"),
        family_a7xx("a750", "750", "Snapdragon 8 Gen 3", "FD_GPU_ID=750, a7xx gen 3, Mesa 25.0"),
    ],
    cost: cost_table,
    compiler_log: None,
};

/// One wave's issue cycles per fibre and light (the module's rule).
fn cycles_per_eval(stats: &std::collections::BTreeMap<String, f64>, lights: u32) -> Option<f64> {
    let instructions = cost::driver_stat(stats, "Instruction Count")?;
    let stalls = cost::driver_stat(stats, "Estimated cycles stalled on SS").unwrap_or(0.0)
        + cost::driver_stat(stats, "Estimated cycles stalled on SY").unwrap_or(0.0);
    let fibres = stats.get(crate::schema::driver::SUBGROUP_SIZE).copied().filter(|s| *s > 0.0)?;
    Some((instructions + stalls) / (fibres * f64::from(lights)))
}

fn cost_table(shim: &Shim, family: &ShimFamily, report: &InspectReport) -> Option<TargetCost> {
    let rule = "cycles/eval = (Instruction Count, NOPs included + Estimated cycles stalled on SS + on SY) / (subgroupSize x lights per kernel): one wave's issue slots and ir3's own stall estimates (ir3.c collect_info), one instruction per wave per cycle, no latency hidden by other waves (Max Waves Per Core beside it)";
    cost::table(
        report,
        shim.header(family, report, rule.into(), "wave issue cycles per fibre", &SHOWN),
        cycles_per_eval,
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::schema::Row;

    #[test]
    fn issue_cycles_are_instructions_plus_stalls_per_fibre_and_light() {
        let row = |model: &str, instructions: f64, ss: f64, sy: f64, fibres: f64| Row {
            model: model.into(),
            spec: None,
            stats: [
                ("driver/CS/Instruction Count".to_string(), instructions),
                ("driver/CS/Estimated cycles stalled on SS".to_string(), ss),
                ("driver/CS/Estimated cycles stalled on SY".to_string(), sy),
                (crate::schema::driver::SUBGROUP_SIZE.to_string(), fibres),
            ]
            .into(),
            notes: Default::default(),
        };
        let mut report = crate::schema::tests::empty_report("Turnip Adreno (TM) 660");
        report.provenance["target"] = "adreno:a660".into();
        report.rows =
            vec![row("ggx", 1000.0, 20.0, 4.0, 64.0), row(crate::model::BASELINE_LABEL, 300.0, 0.0, 20.0, 128.0)];
        let t = super::super::Vendor::cost(&ADRENO, &report).unwrap();
        let lights = f64::from(t.lights_per_kernel);
        assert_eq!(t.target.as_deref(), Some("adreno:a660"));
        assert_eq!(t.rows[0].cycles_per_eval, 1024.0 / (64.0 * lights));
        assert_eq!(t.rows[1].cycles_per_eval, 320.0 / (128.0 * lights));
        assert_eq!(t.rows[0].net_cycles_per_eval, Some(1024.0 / (64.0 * lights) - 320.0 / (128.0 * lights)));
        // Another vendor's report is not Adreno's.
        report.provenance["target"] = "anv:tgl".into();
        assert!(super::super::Vendor::cost(&ADRENO, &report).is_none());
    }
}
