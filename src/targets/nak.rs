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
use super::nvidia::{self, SassStats, sass};
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
    out.extend(SassStats::of_instructions(&instructions).rule_stats(child_family()?)?);
    Ok(out)
}

/// The instructions of NAK's assembly in order (`Function`'s Display in nak/ir.rs): blocks
/// (`block 0 L0 [] -> {` ... `} -> [1]`), one instruction a line, `[@[!]pN] [dsts =] op srcs [// deps]`, where
/// deps are ` delay=N`, ` wt=BBBBBB` (bit k from the right: wait for scoreboard k), ` rd:N`, ` wr:N`,
/// ` reuse=...`, ` yld`; annotation lines are comments. Each becomes an instruction with SASS's upper-case
/// opcode and the control bits NAK encodes (no delay printed: the minimum, 1).
pub fn instructions(text: &str) -> Result<Vec<sass::Instruction>> {
    let mut out = Vec::new();
    for (n, line) in text.lines().enumerate() {
        let t = line.trim();
        if t.is_empty() || t.starts_with("//") || t.starts_with("block") || t.starts_with('}') {
            continue;
        }
        let (code, deps) = t.split_once("//").unwrap_or((t, ""));
        let op = code.split_once(" = ").map_or(code, |(_, op)| op);
        let op = op.split_whitespace().find(|w| !w.starts_with('@')).ok_or_else(|| anyhow!("line {}: `{t}`", n + 1))?;
        if !op.starts_with(|c: char| c.is_ascii_lowercase()) {
            bail!("line {}: `{t}` is not an instruction NAK prints", n + 1);
        }
        let control = control(deps).map_err(|e| anyhow!("line {}: `{t}`: {e}", n + 1))?;
        out.push(sass::Instruction { opcode: op.to_ascii_uppercase(), control, sources: Vec::new() });
    }
    Ok(out)
}

/// The control bits of an instruction's deps text (` delay=6 wt=000001 rd:0 wr:1 yld`).
fn control(deps: &str) -> Result<sass::Control> {
    let mut c = sass::Control { stall: 1, write_barrier: None, read_barrier: None, ..Default::default() };
    let scoreboard = |v: &str| -> Result<Option<u8>> {
        let b: u8 = v.parse().map_err(|_| anyhow!("scoreboard `{v}`"))?;
        if b >= 6 {
            bail!("scoreboard {b} (there are 6)");
        }
        Ok(Some(b))
    };
    for word in deps.split_whitespace() {
        if let Some(v) = word.strip_prefix("delay=") {
            c.stall = v.parse().map_err(|_| anyhow!("delay `{v}`"))?;
        } else if let Some(v) = word.strip_prefix("wt=") {
            c.wait_mask = u8::from_str_radix(v, 2).map_err(|_| anyhow!("wait mask `{v}`"))?;
        } else if let Some(v) = word.strip_prefix("rd:") {
            c.read_barrier = scoreboard(v)?;
        } else if let Some(v) = word.strip_prefix("wr:") {
            c.write_barrier = scoreboard(v)?;
        } else if let Some(v) = word.strip_prefix("reuse=") {
            c.reuse = u8::from_str_radix(v, 2).map_err(|_| anyhow!("reuse mask `{v}`"))?;
        } else if word == "yld" {
            c.yield_hint = true;
        } else {
            bail!("`{word}` is not a dependency NAK prints");
        }
    }
    Ok(c)
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

    /// NAK's assembly as `Function`'s Display prints it (our own kernel, in its layout).
    const ASM: &str = "block 0 L0 [] -> {\n\
        \x20  r0 = s2r sr_tid.x                  // delay=1 wr:0\n\
        \x20  r1 = ldc.b32 c[0x0][0x8]           // delay=1 wr:1\n\
        \x20  r2 = ffma r0 r1 r1                 // delay=6 wt=000011\n\
        \x20  r3 = ffma r2 r2 r1                 // delay=6\n\
        \x20  r4 = mufu.rcp r3                   // delay=1 wr:2\n\
        @p0 r2..4 = ld.global.a64.strong.gpu [r2] // delay=1 rd:3 wr:4\n\
        \n// an annotation\n\
        \x20      exit                           // delay=5 wt=010100 yld\n\
        } -> []\n";

    #[test]
    fn reads_naks_assembly_into_sass_instructions_and_their_control_bits() {
        let is = instructions(ASM).unwrap();
        let ops: Vec<&str> = is.iter().map(|i| i.opcode.as_str()).collect();
        assert_eq!(ops, ["S2R", "LDC.B32", "FFMA", "FFMA", "MUFU.RCP", "LD.GLOBAL.A64.STRONG.GPU", "EXIT"]);
        assert_eq!((is[2].control.stall, is[2].control.wait_mask), (6, 0b11));
        assert_eq!((is[5].control.read_barrier, is[5].control.write_barrier), (Some(3), Some(4)));
        assert_eq!((is[6].control.wait_mask, is[6].control.yield_hint), (0b010100, true));
        // The same rule as ptxas' SASS: FFMA on the FMA pipe, MUFU on XU, the load on the LSU.
        let s = SassStats::of_instructions(&is);
        let pipes = s.pipes(nvidia_family("sm_86").unwrap()).unwrap();
        let pipe = |n: &str| pipes.iter().find(|p| p.0 == n).map(|p| p.1);
        assert_eq!((pipe("FMA"), pipe("XU (MUFU, conversions)")), (Some(0.5), Some(2.0)));
        // S2R at 0 (scoreboard 0 at 21), LDC at 1 (scoreboard 1 at 31), the first FFMA waits for both (31),
        // then 6, 6, 1: the load at 44 (scoreboard 4 at 364); EXIT waits for 2 and 4 at 364, then 5.
        assert_eq!(s.schedule_latency, 364.0 + 5.0);
        assert!(instructions("   r0 = ffma r1 r2 r3 // delay=6 wr:7\n").unwrap_err().to_string().contains("6"));
        assert!(instructions("   R0 = FFMA r1\n").is_err());
    }

    #[test]
    fn every_family_is_an_nvidia_family() {
        for f in NAK.families {
            assert!(nvidia_family(f.name).is_some(), "{}", f.name);
        }
    }
}
