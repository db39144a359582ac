//! `--device anv:FAMILY`: Intel GPUs through ANV, Intel's Linux Vulkan driver in Mesa, and its compiler (brw),
//! on Mesa's intel noop drm-shim (`INTEL_STUB_GPU_PLATFORM`). It compiles the very SPIR-V lavapipe runs, with no
//! translation: a second Intel production compiler beside IGC (`intel:`, which compiles the OpenCL C
//! translation).
//!
//! brw's listing (INTEL_DEBUG=cs: it prints each program's assembly on stderr, which the child captures per
//! pipeline, `gpu::GpuOptions::compiler_log`) is priced exactly as IGC's is (`intel::IsaStats`, `intel::brw`):
//! each pipe's busy cycles at the lanes per clock of Intel's documents, one thread's latency in brw's
//! instruction order at IGC's scheduler latencies, and the threads an EU holds (brw allocates 128 registers,
//! so the family's full count), under the one rule of `cost::schedule`; cycles/eval divides by the listing's
//! SIMD width and the lights per kernel. IGC and brw then differ only where their code does.
//!
//! brw's own static estimate, "Cycle Count" (`performance::latency`, "estimate of the runtime of the whole
//! program in cycle units assuming uncontended execution", brw_ir_performance.h; Mesa 22.3), is one thread's
//! critical path with no other thread hiding it: kept as a column of its own, not the cost.

use super::cost;
use super::mesa_noop::builds::MESA_DEBIAN;
use super::mesa_noop::shim::{Shim, ShimFamily};
use crate::gpu::{CompilerLog, DriverStat};
use crate::schema::InspectReport;
use crate::schema::cost::TargetCost;
use anyhow::{Result, anyhow, bail};
use cost::schedule::Schedule;

/// The statistics shown beside cycles/eval (ANV's names).
const SHOWN: [&str; 5] = ["Instruction Count", "SEND Count", "Cycle Count", "Spill Count", "Fill Count"];

/// The statistic of the listing's SIMD width (the lanes of one thread).
const LISTING_SIMD: &str = "Listing SIMD Width";

/// The `intel:` family whose rates and latencies price an ANV family's listing.
fn intel_family(anv: &str) -> Option<&'static super::intel::Family> {
    let name = match anv {
        "skl" => "gen9",
        "icl" => "gen11",
        "tgl" | "adl" => "gen12lp",
        "dg2" => "xe-hpg",
        _ => return None,
    };
    super::intel::FAMILIES.iter().find(|f| f.name == name)
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
    // The runtime's in-memory pipeline cache off: a kernel compiled twice in one child (`--isa`, then the
    // statistics) would come back from it the second time without brw printing its listing.
    extra_env: &[("INTEL_DEBUG", "cs"), ("VK_ENABLE_PIPELINE_CACHE", "0")],
    families: &[
        ShimFamily::on(
            &MESA_DEBIAN,
            "skl",
            "skl",
            "Gen9",
            "Skylake HD/Iris Graphics 5xx",
            "INTEL_STUB_GPU_PLATFORM=skl, Gen9",
        ),
        ShimFamily::on(&MESA_DEBIAN, "icl", "icl", "Gen11", "Ice Lake Iris Plus", "INTEL_STUB_GPU_PLATFORM=icl, Gen11"),
        ShimFamily::on(
            &MESA_DEBIAN,
            "tgl",
            "tgl",
            "Gen12LP (Xe-LP)",
            "Tiger Lake Iris Xe",
            "INTEL_STUB_GPU_PLATFORM=tgl, Gen12LP",
        ),
        ShimFamily::on(
            &MESA_DEBIAN,
            "adl",
            "adl",
            "Gen12LP (Xe-LP)",
            "Alder Lake UHD/Iris Xe",
            "INTEL_STUB_GPU_PLATFORM=adl, Gen12LP",
        ),
        ShimFamily::on(
            &MESA_DEBIAN,
            "dg2",
            "dg2",
            "Xe-HPG (Gen12.5)",
            "Arc A-series (Alchemist)",
            "INTEL_STUB_GPU_PLATFORM=dg2, Gen12.5",
        ),
    ],
    cost: cost_table,
    compiler_log: Some(CompilerLog { read: read_listing, beside_properties: true }),
    representation_stats: None,
};

/// One pipeline's stderr under INTEL_DEBUG=cs: its program's listing priced for the family the shim emulates
/// (the child's `INTEL_STUB_GPU_PLATFORM`); the lines passed on are the driver's own messages, not the dump.
pub fn read_listing(log: &str) -> Result<(Vec<DriverStat>, Vec<String>)> {
    let platform = std::env::var(ANV.gpu_var).map_err(|_| anyhow!("{} is not set in the ANV child", ANV.gpu_var))?;
    let family = intel_family(&platform).ok_or_else(|| anyhow!("no Intel rates for ANV platform `{platform}`"))?;
    let (simd, listing) = super::intel::brw::last_program(log, family.grf_bytes)
        .map_err(|e| anyhow!("brw's listing (INTEL_DEBUG=cs): {e:#}"))?;
    if listing.is_empty() || ![8, 16, 32].contains(&simd) {
        bail!("brw's listing has {} instructions at SIMD{simd}: not a program brdfprof can price", listing.len());
    }
    let stats = super::intel::IsaStats::of_listing(simd, BRW_REGISTERS, listing);
    let mut out = vec![(LISTING_SIMD.to_string(), f64::from(simd))];
    out.extend(stats.rule_stats(family)?);
    let stat = |(name, value): (String, f64)| DriverStat {
        executable: crate::gpu::LOGGED_EXECUTABLE.into(),
        description: format!("brw's listing (INTEL_DEBUG=cs) priced by IGC's rates: {name}"),
        name,
        value,
    };
    let passed = log.lines().filter(|l| l.starts_with("drm-shim") || l.to_ascii_lowercase().contains("error"));
    Ok((out.into_iter().map(stat).collect(), passed.map(str::to_string).collect()))
}

/// brw's register file per thread (Mesa 22.3 has no large-GRF mode): the family's full thread count resides.
const BRW_REGISTERS: u32 = 128;

fn cost_table(shim: &Shim, family: &ShimFamily, report: &InspectReport) -> Option<TargetCost> {
    let rule = format!(
        "{}; brw's listing (INTEL_DEBUG=cs) priced as IGC's: pipes at THROUGHPUT's lanes per clock, latency in brw's instruction order at IGC's scheduler latencies, threads per EU at 128 registers; / (listing SIMD width x lights per kernel); Cycle Count: brw's own one-thread critical path, beside it",
        cost::schedule::RULE
    );
    let schedule_of = |stats: &std::collections::BTreeMap<String, f64>| {
        let lanes = cost::driver_stat(stats, LISTING_SIMD).filter(|s| *s > 0.0)?;
        Some((Schedule::of(stats)?, lanes))
    };
    cost::schedule_table(report, shim.header(family, report, rule, "EU cycles", &SHOWN), schedule_of)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::schema::Row;

    #[test]
    fn brws_listing_is_priced_by_igcs_rates_under_the_one_rule() {
        let tgl = intel_family("tgl").unwrap();
        assert_eq!(
            (tgl.name, intel_family("dg2").unwrap().name, intel_family("adl").unwrap().name),
            ("gen12lp", "xe-hpg", "gen12lp")
        );
        // Sixteen SIMD16 multiplies: two EU cycles each on Xe-LP's FP pipe (8 lanes per clock).
        let listing: String = (0..16)
            .map(|k| format!("mul(16)  g{}<1>F  g2<8,8,1>F  g4<8,8,1>F  {{ align1 1H }};\n", 20 + 2 * k))
            .collect();
        let (simd, is) =
            crate::targets::intel::brw::last_program(&format!("SIMD16 shader: 16 instructions.\n{listing}"), 32)
                .unwrap();
        let stats = crate::targets::intel::IsaStats::of_listing(simd, BRW_REGISTERS, is);
        let rule: std::collections::BTreeMap<String, f64> = stats.rule_stats(tgl).unwrap().into_iter().collect();
        assert_eq!(rule["Pipe: ALU (FP, integer)"], 32.0);
        assert_eq!(rule[crate::targets::cost::schedule::RESIDENT_WAVES], 7.0);
        let row = |model: &str, alu: f64, latency: f64| Row {
            model: model.into(),
            spec: None,
            stats: [
                ("driver/Compute Shader/Cycle Count".to_string(), 9999.0),
                (format!("driver/Compute Shader/{LISTING_SIMD}"), 16.0),
                ("driver/Compute Shader/Pipe: ALU (FP, integer)".to_string(), alu),
                ("driver/Compute Shader/Schedule Latency".to_string(), latency),
                ("driver/Compute Shader/Resident Waves".to_string(), 7.0),
            ]
            .into(),
            notes: Default::default(),
        };
        let mut report = crate::schema::tests::empty_report("Intel(R) Xe Graphics (TGL GT2)");
        report.provenance["target"] = "anv:tgl".into();
        // brw's Cycle Count (9999, one thread's critical path) is not the cost: 7 threads hide 2100 cycles.
        report.rows = vec![row("ggx", 400.0, 2100.0), row(crate::model::BASELINE_LABEL, 100.0, 700.0)];
        let t = super::super::Vendor::cost(&ANV, &report).unwrap();
        let lights = f64::from(t.lights_per_kernel);
        assert_eq!(t.family.as_deref(), Some("tgl"));
        assert_eq!(t.rows[0].cycles_per_eval, 400.0 / (16.0 * lights));
        assert_eq!(t.rows[0].net_cycles_per_eval, Some(300.0 / (16.0 * lights)));
        assert_eq!(t.rows[0].stats["Cycle Count"], 9999.0);
        assert_eq!(super::super::Vendor::family_of(&ANV, &report), Some(2));
    }
}
