//! `--device nak:FAMILY`: NVIDIA GPUs through NVK, Mesa's Vulkan driver for them, and its compiler (NAK), on
//! Mesa's nouveau noop drm-shim (`NOUVEAU_CHIPSET`). It compiles the very SPIR-V lavapipe runs, with no
//! translation: a second NVIDIA compiler beside ptxas (`nvidia:`, which compiles the CUDA C++ translation).
//!
//! NAK keeps its assembly as an internal representation ("NAK assembly": SASS-like text, each instruction with
//! the control bits NAK encodes, `// delay=6 wt=000001 rd:0 wr:1`: the stall count, the scoreboards waited for,
//! the read and write scoreboards). Each instruction is priced exactly as ptxas' SASS is (`nvidia::classify`,
//! `nvidia::SassStats`): its pipe at the CUDA guide's throughput, one warp's schedule played through NAK's own
//! stall counts and scoreboards (`nvidia::sass::schedule_latency`), resident warps from NAK's register count
//! under the family's limits; cycles/eval divides by 32 lanes and the lights per kernel. ptxas and NAK then
//! differ only where their code does. Mesa 25.0's NAK charges 6 cycles for every register result
//! (calc_instr_deps.rs, `instr_latency`) where ptxas' tables give 4 for FP32: its stall counts are its own,
//! and the hardware honours them as written.

use super::cost;
use super::mesa_noop::builds::{MESA_25_UNVALIDATED, MESA_NVK};
use super::mesa_noop::shim::{Shim, ShimFamily};
use super::nvidia::{self, SassStats, nak::instructions};
use crate::gpu::RepresentationStats;
use crate::schema::InspectReport;
use crate::schema::cost::TargetCost;
use anyhow::{Result, anyhow, bail};
use cost::schedule::Schedule;

/// The statistics shown beside cycles/eval (NVK's names, then the rule's).
const SHOWN: [&str; 5] =
    ["Instruction count", "Number of GPRs", "SLM Size", "MUFU (special functions)", "Issue Cycles"];

/// NVK's register statistic: the registers the hardware allocates per thread (NAK adds the reserved ones).
const REGISTERS: &str = "Number of GPRs";

/// The internal representation NAK's assembly comes as.
pub const ASSEMBLY: &str = "NAK assembly";

pub static NAK: Shim = Shim {
    prefix: "nak",
    vendor: "NVIDIA",
    title: "NVIDIA (NVK): Mesa's Vulkan driver for NVIDIA GPUs (NAK compiler) on the nouveau noop drm-shim, in a child process (it compiles, nothing executes)",
    driver: "NVK",
    compiler: "NAK",
    icd: "src/nouveau/vulkan/nouveau_devenv_icd.x86_64.json",
    library: "src/nouveau/vulkan/libvulkan_nouveau.so",
    shim: "src/nouveau/drm-shim/libnouveau_noop_drm_shim.so",
    gpu_var: "NOUVEAU_CHIPSET",
    extra_env: &[],
    // Chip ids the stock shim enumerates (Mesa 25.0.7): Turing TU104 and Ampere GA102. Ada and later need a
    // patched shim (its class tables stop at 0x17x).
    families: &[
        ShimFamily::on(&MESA_NVK, "sm_75", "164", "Turing", "GeForce RTX 2080 (TU104)", "NOUVEAU_CHIPSET=164, SM 7.5")
            .unvalidated(MESA_25_UNVALIDATED),
        ShimFamily::on(
            &MESA_NVK,
            "sm_86",
            "172",
            "Ampere (GA10x)",
            "GeForce RTX 3080/3090 (GA102)",
            "NOUVEAU_CHIPSET=172, SM 8.6",
        )
        .unvalidated(MESA_25_UNVALIDATED),
    ],
    cost: cost_table,
    compiler_log: None,
    representation_stats: Some(RepresentationStats { name: ASSEMBLY, read: read_assembly }),
};

/// The `nvidia:` family whose rates, limits and pipes price a NAK family's code.
fn nvidia_family(nak: &str) -> Option<&'static nvidia::Family> {
    nvidia::FAMILIES.iter().find(|f| f.name == nak)
}

/// The family the child's shim emulates (its `NOUVEAU_CHIPSET`).
fn child_family() -> Result<&'static nvidia::Family> {
    let chip = std::env::var(NAK.gpu_var).map_err(|_| anyhow!("{} is not set in the NVK child", NAK.gpu_var))?;
    let f = NAK.families.iter().find(|f| f.gpu_id == chip).ok_or_else(|| anyhow!("no NAK family for chip {chip}"))?;
    nvidia_family(f.name).ok_or_else(|| anyhow!("no NVIDIA rates for {}", f.name))
}

/// One kernel's NAK assembly priced for the child's family: the rule's statistics (`SassStats::rule_stats`).
fn read_assembly(text: &str) -> Result<Vec<(String, f64)>> {
    let instructions = instructions(text)?;
    if instructions.is_empty() {
        bail!("NAK's assembly has no instruction");
    }
    let mut out = vec![("Assembly Instructions".to_string(), instructions.len() as f64)];
    let family = child_family()?;
    out.extend(SassStats::of_instructions(&instructions, family).rule_stats(family)?);
    Ok(out)
}

fn cost_table(shim: &Shim, family: &ShimFamily, report: &InspectReport) -> Option<TargetCost> {
    let nvidia = nvidia_family(family.name)?;
    let rule = format!(
        "{}; NAK's assembly priced as ptxas' SASS: pipes at the CUDA guide's throughputs (Nsight Compute's pipe assignment), latency by NAK's own delays and scoreboards, warps per SM from NVK's Number of GPRs; / (32 x lights per kernel); Issue Cycles: the serial sum",
        cost::schedule::RULE
    );
    let schedule_of = |stats: &std::collections::BTreeMap<String, f64>| {
        let registers = cost::driver_stat(stats, REGISTERS).filter(|r| *r > 0.0)?;
        let warps = SassStats { registers: registers as u32, ..Default::default() }.warps_per_sm(nvidia);
        let schedule = Schedule { resident_waves: Some(f64::from(warps)), ..Schedule::of(stats)? };
        Some((schedule, 32.0))
    };
    cost::schedule_table(report, shim.header(family, report, rule, "SM cycles", &SHOWN), schedule_of)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_family_is_an_nvidia_family() {
        for f in NAK.families {
            assert!(nvidia_family(f.name).is_some(), "{}", f.name);
        }
    }
}
