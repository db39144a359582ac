//! `--device adreno:FAMILY`: Qualcomm Adreno 6xx (the installed Mesa 22.3) and 7xx (bookworm-backports' Mesa
//! 25.0) through Mesa's Turnip driver and its ir3 compiler, on the freedreno noop drm-shim (`FD_GPU_ID`). Turnip's ir3 is what Linux and some Android systems run on Adreno;
//! stock phone drivers use Qualcomm's own compiler, so these are ir3's figures, not a phone driver's.
//!
//! ir3 states no cycle model; brdfprof prices the statistics ir3 computes itself (`collect_info` in
//! src/freedreno/ir3/ir3.c, Mesa 22.3 and 25.0 alike) under the one rule of `cost::schedule`:
//! - **pipes** (cycles one wave keeps each busy, one issue per instruction and repeat): ALU = cat1 (moves and
//!   conversions) + cat2 + cat3 (one- to three-source arithmetic); SFU = cat4 (transcendentals); texture = cat5;
//!   load/store = cat6; control = cat0 without the NOPs (ir3 counts each NOP, folded `(nopN)` ones too, under
//!   cat0) + cat7 (barriers). a6xx's and a7xx's base wave is 64 fibres (`threadsize_base = 64`,
//!   ir3_compiler.c); a wave ir3 doubles to 128 fibres passes each ALU instruction twice.
//! - **schedule latency**: one wave alone issues every slot, NOPs included (Instruction Count), and waits ir3's
//!   own estimates at its `(ss)` (SFU results) and `(sy)` (memory results) sync bits.
//! - **resident waves**: "Max Waves Per Core", ir3's figure from the registers the kernel uses.
//!
//! ir3 publishes no SFU, texture or load/store rate, so each of those instructions is one issue cycle of its
//! pipe: a lower bound on those pipes, whose results' waits the schedule latency carries.

use super::cost;
use super::mesa_noop::builds::{MESA_25_UNVALIDATED, MESA_BACKPORTS, MESA_DEBIAN};
use super::mesa_noop::shim::{Shim, ShimFamily};
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
    ShimFamily::on(&MESA_DEBIAN, name, gpu_id, "Adreno 6xx", products, detail)
}

/// An a7xx GPU: Mesa 22.3's Turnip has none; bookworm-backports' Mesa 25.0 compiles for them.
const fn family_a7xx(
    name: &'static str,
    gpu_id: &'static str,
    products: &'static str,
    detail: &'static str,
) -> ShimFamily {
    ShimFamily::on(&MESA_BACKPORTS, name, gpu_id, "Adreno 7xx", products, detail).unvalidated(MESA_25_UNVALIDATED)
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
    representation_stats: None,
};

/// The rule's figures of one wave (`ir3::schedule_of`), at the subgroup size the driver reported.
fn schedule_of(stats: &Stats) -> Option<(brdfprof_isa_cost::schedule::Schedule, f64)> {
    let fibres = stats.get(crate::schema::driver::SUBGROUP_SIZE).copied().filter(|s| *s > 0.0)?;
    brdfprof_isa_cost::ir3::schedule_of(stats, fibres)
}

type Stats = std::collections::BTreeMap<String, f64>;

fn cost_table(shim: &Shim, family: &ShimFamily, report: &InspectReport) -> Option<TargetCost> {
    let rule = format!(
        "{}; ir3's statistics: pipes ALU (cat1-3, twice at 128 fibres), SFU (cat4), texture (cat5), load/store (cat6), control (cat0 less NOPs, cat7), one issue each; latency = Instruction Count (NOPs included) + ir3's SS and SY stall estimates; waves = Max Waves Per Core; / (subgroupSize x lights per kernel)",
        cost::schedule::RULE
    );
    cost::schedule_table(report, shim.header(family, report, rule, "SP cycles", &SHOWN), schedule_of)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::schema::Row;

    #[test]
    fn ir3s_categories_are_pipes_and_its_stalls_the_latency_waves_hide() {
        // cat0 holds the NOPs; ALU is cat1-3.
        let row = |model: &str, cats: [f64; 8], nops: f64, ss: f64, waves: f64, fibres: f64| {
            let mut stats: std::collections::BTreeMap<String, f64> = [
                ("driver/CS/Instruction Count".to_string(), cats.iter().sum()),
                ("driver/CS/NOPs Count".to_string(), nops),
                ("driver/CS/Estimated cycles stalled on SS".to_string(), ss),
                ("driver/CS/Estimated cycles stalled on SY".to_string(), 0.0),
                ("driver/CS/Max Waves Per Core".to_string(), waves),
                (crate::schema::driver::SUBGROUP_SIZE.to_string(), fibres),
            ]
            .into();
            for (k, c) in cats.iter().enumerate() {
                stats.insert(format!("driver/CS/cat{k} instructions"), *c);
            }
            Row { model: model.into(), spec: None, stats, notes: Default::default() }
        };
        let mut report = crate::schema::tests::empty_report("Turnip Adreno (TM) 660");
        report.provenance["target"] = "adreno:a660".into();
        report.rows = vec![
            // 900 ALU issues; latency 1000 + 100 + 300 stalls over 10 waves = 140: ALU binds.
            row("ggx", [101.0, 10.0, 800.0, 90.0, 36.0, 1.0, 1.0, 0.0], 100.0, 300.0, 10.0, 64.0),
            // One wave's 400 cycles over 2 waves (200) exceed its 100 ALU issues: latency binds.
            row("chain", [201.0, 0.0, 100.0, 0.0, 0.0, 1.0, 1.0, 0.0], 200.0, 97.0, 2.0, 64.0),
            // At 128 fibres each ALU instruction is two passes.
            row(crate::model::BASELINE_LABEL, [1.0, 0.0, 100.0, 0.0, 0.0, 1.0, 1.0, 0.0], 0.0, 0.0, 16.0, 128.0),
        ];
        let t = super::super::Vendor::cost(&ADRENO, &report).unwrap();
        let lights = f64::from(t.lights_per_kernel);
        let r = |m: &str| t.row(m).unwrap();
        assert_eq!(t.target.as_deref(), Some("adreno:a660"));
        assert_eq!((r("ggx").cycles_per_eval, r("ggx").bound.as_deref()), (900.0 / (64.0 * lights), Some("ALU")));
        let chain = r("chain");
        assert_eq!(chain.cycles_per_eval, 400.0 / 2.0 / (64.0 * lights));
        assert_eq!(chain.bound.as_deref(), Some(crate::targets::cost::schedule::LATENCY_TERM));
        let base = r(crate::model::BASELINE_LABEL).cycles_per_eval;
        assert_eq!(base, 200.0 / (128.0 * lights));
        assert_eq!(r("ggx").net_cycles_per_eval, Some(900.0 / (64.0 * lights) - base));
        assert!(r("ggx").terms.iter().any(|(n, v)| n == "SFU" && *v == 36.0));
        // Another vendor's report is not Adreno's.
        report.provenance["target"] = "anv:tgl".into();
        assert!(super::super::Vendor::cost(&ADRENO, &report).is_none());
    }
}
