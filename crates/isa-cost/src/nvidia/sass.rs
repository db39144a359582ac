//! A SASS listing as ptxas scheduled it. From Volta on, every 128-bit SASS instruction carries the compiler's
//! own scheduling decisions in its control bits (Jia et al., "Dissecting the NVIDIA Volta GPU Architecture
//! via Microbenchmarking", arXiv:1804.06826, 2.1; the same layout on Turing, Ampere, Ada, Hopper and
//! Blackwell): bits 105-108 the stall count (cycles before the warp issues its next instruction), 109 the
//! yield hint, 110-112 the scoreboard a variable-latency result will release (7: none), 113-115 the one its
//! source reads will release, 116-121 the scoreboards the instruction waits for, 122-125 operand reuse.
//! `nvdisasm -hex` prints each instruction's two 64-bit words; bit 105 is bit 41 of the second.
//!
//! One warp's schedule latency is then ptxas' own schedule played through: each instruction issues after
//! its predecessor's stall count and once the scoreboards it waits for are released. Fixed-latency results
//! are inside the stall counts (ptxas computed them); a variable-latency result's wait needs a latency, which
//! no NVIDIA document gives, so `VARIABLE_LATENCY` states the figures brdfprof assumes and where each comes
//! from (memory: the family's measured DRAM latency where one was found, `Family::memory`, else ACO's figure).

use anyhow::{Result, anyhow, bail};

/// One instruction: its full opcode (`F2F.F32.F16`, `MUFU.EX2`, without its predicate) and its control bits.
#[derive(Clone, Debug, PartialEq)]
pub struct Instruction {
    pub opcode: String,
    pub control: Control,
    /// The source files and lines nvdisasm's `--print-line-info-inline` names for it, innermost first: each
    /// `//## File "F", line N inlined at "G", line M` line of its chain gives the inlined location, then the
    /// outermost one; empty where it names none.
    pub sources: Vec<(String, u32)>,
}

impl Instruction {
    /// The mnemonic before the first `.` (`MUFU`).
    pub fn mnemonic(&self) -> &str {
        self.opcode.split('.').next().unwrap_or(&self.opcode)
    }
}

/// The control bits of one instruction (sm_70 and later).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Control {
    pub stall: u32,
    pub yield_hint: bool,
    pub write_barrier: Option<u8>,
    pub read_barrier: Option<u8>,
    /// Bit k set: wait until scoreboard k is released.
    pub wait_mask: u8,
    pub reuse: u8,
}

impl Control {
    /// The control bits of an instruction's second (high) 64-bit word: bits 105-125 of the 128.
    pub fn decode(high: u64) -> Control {
        let bits = |from: u32, width: u32| ((high >> (from - 64)) & ((1 << width) - 1)) as u8;
        let barrier = |b: u8| (b != 7).then_some(b);
        Control {
            stall: u32::from(bits(105, 4)),
            yield_hint: bits(109, 1) == 1,
            write_barrier: barrier(bits(110, 3)),
            read_barrier: barrier(bits(113, 3)),
            wait_mask: bits(116, 6),
            reuse: bits(122, 4),
        }
    }
}

/// The address, opcode and first hex word of an nvdisasm `-hex` instruction line
/// (`/*0090*/  @!P0 LDG.E R4, [R2.64] ;  /* 0x0000000402047981 */`).
fn instruction_line(line: &str) -> Option<(u64, String, Option<u64>)> {
    let rest = line.trim_start().strip_prefix("/*")?;
    let (addr, rest) = rest.split_once("*/")?;
    if addr.is_empty() || !addr.chars().all(|c| c.is_ascii_hexdigit()) {
        return None;
    }
    let (code, hex) = rest.split_once(';').map_or((rest, ""), |(c, h)| (c, h));
    let mut words = code.split_whitespace().filter(|w| !w.starts_with('@'));
    let opcode = words.next()?.trim_end_matches(';').to_string();
    Some((u64::from_str_radix(addr, 16).ok()?, opcode, hex_word(hex)))
}

/// The 64-bit word of a `/* 0x000fe40000000f00 */` comment.
fn hex_word(text: &str) -> Option<u64> {
    let inner = text.trim().strip_prefix("/*")?.trim().strip_suffix("*/")?.trim();
    u64::from_str_radix(inner.strip_prefix("0x")?, 16).ok()
}

/// The instructions of an nvdisasm `-hex` listing up to the kernel's last EXIT (the padding after it left
/// out), NOPs included (a NOP's stall counts too).
pub fn instructions(listing: &str) -> Result<Vec<Instruction>> {
    let mut out = Vec::new();
    let mut sources: Vec<(String, u32)> = Vec::new();
    let mut in_chain = false;
    let mut lines = listing.lines().peekable();
    while let Some(line) = lines.next() {
        if let Some(s) = line_info(line) {
            // A chain's lines follow one another: the first starts a new one.
            if !in_chain {
                sources.clear();
            }
            sources.push(s);
            in_chain = true;
            continue;
        }
        in_chain = false;
        let Some((_, opcode, low)) = instruction_line(line) else { continue };
        let high = lines.peek().and_then(|l| hex_word(l));
        let (Some(_), Some(high)) = (low, high) else {
            bail!("nvdisasm's listing has no `-hex` words for `{}`", line.trim());
        };
        lines.next();
        out.push(Instruction { opcode, control: Control::decode(high), sources: sources.clone() });
    }
    let end = out.iter().rposition(|i| i.opcode == "EXIT").ok_or_else(|| anyhow!("a SASS listing without EXIT"))?;
    out.truncate(end + 1);
    Ok(out)
}

/// The file and line of nvdisasm's line comment (`\t//## File "/tmp/x.brdf", line 12`, perhaps followed by
/// ` inlined at "F", line M`: its caller, which the chain's next line names).
fn line_info(line: &str) -> Option<(String, u32)> {
    let rest = line.trim_start().strip_prefix("//## File \"")?;
    let (file, rest) = rest.split_once("\", line ")?;
    Some((file.to_string(), rest.split(|c: char| !c.is_ascii_digit()).next()?.parse().ok()?))
}

/// The latency brdfprof assumes for a variable-latency result (released through a scoreboard), in cycles,
/// with its source, by the producing instruction.
#[derive(Debug, PartialEq)]
pub struct VariableLatency {
    pub what: &'static str,
    pub cycles: f64,
    pub source: &'static str,
}

// Every figure is a finite constant: the equality is total (so `Family`, which names one, is `Eq`).
impl Eq for VariableLatency {}

/// Global and local memory loads, where no measurement of the family was found (`Family::memory`).
pub const MEMORY: VariableLatency = VariableLatency {
    what: "global/local memory load",
    cycles: 320.0,
    source: "ACO's vector-memory figure (Mesa's aco_statistics.cpp), for every family without a measured one",
};
/// Ada's (sm_89) global loads: the G-buffer streams from DRAM, each pixel's read once.
pub const MEMORY_SM89: VariableLatency = VariableLatency {
    what: "global/local memory load (DRAM)",
    cycles: 632.0,
    source: "M6: te42kyfo/gpu-benches gpu-latency/l40.txt, L40 pointer chase, DRAM ~632 cycles (L2 277)",
};
/// Hopper's (sm_90) global loads, as `MEMORY_SM89`.
pub const MEMORY_SM90: VariableLatency = VariableLatency {
    what: "global/local memory load (DRAM)",
    cycles: 484.0,
    source: "M5: Luo et al., arXiv 2501.12084, reproduced on an H100 (Johnsonms/NVIDIA-Hopper-Benchmark), DRAM 484 cycles (L2 272)",
};
/// Constant and uniform loads.
pub const CONSTANT: VariableLatency = VariableLatency {
    what: "constant/uniform load",
    cycles: 30.0,
    source: "ACO's scalar-memory figure for a likely cache hit (aco_statistics.cpp), used for every vendor's constant loads",
};
/// The special-function unit and the other variable-latency instructions (conversions, S2R, shuffles).
pub const SFU: VariableLatency = VariableLatency {
    what: "MUFU, conversions, S2R, shuffles",
    cycles: 21.0,
    source: "Accel-Sim's tuned SM75/SM86/SM89 configurations (-ptx_opcode_latency_sfu 21)",
};
/// A read scoreboard (the sources have been read, so their registers may be written again).
pub const SOURCES_READ: VariableLatency = VariableLatency {
    what: "sources read (read scoreboard)",
    cycles: 4.0,
    source: "assumed: the FP32 pipe latency (Accel-Sim's SM86 sp latency 4)",
};

/// The variable latency of `instruction`'s result, a memory load's `memory` (the family's).
pub fn variable_latency(instruction: &Instruction, memory: &'static VariableLatency) -> &'static VariableLatency {
    let m = instruction.mnemonic();
    if ["LDC", "ULDC", "LDCU"].contains(&m) {
        &CONSTANT
    } else if m.starts_with("LD")
        || m.starts_with("ATOM")
        || m.starts_with("RED")
        || m.starts_with("TEX")
        || m.starts_with("TLD")
        || m.starts_with("SULD")
    {
        memory
    } else {
        &SFU
    }
}

/// One warp's cycles through `instructions` alone: each issues `stall` cycles (at least one) after its
/// predecessor and not before the scoreboards it waits for are released; a result released through a
/// scoreboard takes `variable_latency`. Every instruction once (a branch's both sides; no loop repeated).
pub fn schedule_latency(instructions: &[Instruction], memory: &'static VariableLatency) -> f64 {
    let times = issue_times(instructions, memory);
    times.last().copied().unwrap_or(0.0)
}

/// The cycle each instruction issues at in `schedule_latency`'s schedule, and after them the cycle the warp
/// ends (the last instruction's issue plus its stall).
pub fn issue_times(instructions: &[Instruction], memory: &'static VariableLatency) -> Vec<f64> {
    let mut times = Vec::with_capacity(instructions.len() + 1);
    let mut released = [0.0f64; 6];
    let mut t = 0.0f64;
    for i in instructions {
        for (b, r) in released.iter().enumerate() {
            if i.control.wait_mask & (1 << b) != 0 {
                t = t.max(*r);
            }
        }
        if let Some(b) = i.control.write_barrier.filter(|b| *b < 6) {
            released[b as usize] = released[b as usize].max(t + variable_latency(i, memory).cycles);
        }
        if let Some(b) = i.control.read_barrier.filter(|b| *b < 6) {
            released[b as usize] = released[b as usize].max(t + SOURCES_READ.cycles);
        }
        times.push(t);
        t += f64::from(i.control.stall.max(1));
    }
    times.push(t);
    times
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn decodes_the_control_bits() {
        // IMAD.MOV.U32 R1, RZ, RZ, c[0x0][0x28]: stall 2, yield, no scoreboards.
        let c = Control::decode(0x000fe400078e00ff);
        assert_eq!(
            (c.stall, c.yield_hint, c.write_barrier, c.read_barrier, c.wait_mask, c.reuse),
            (2, true, None, None, 0, 0)
        );
        // Write scoreboard 0, wait on scoreboards 0 and 2, stall 4.
        let high = (4u64 << 41) | (0u64 << 46) | (7u64 << 49) | (0b101u64 << 52);
        let c = Control::decode(high);
        assert_eq!((c.stall, c.write_barrier, c.read_barrier, c.wait_mask), (4, Some(0), None, 0b101));
    }

    const LISTING: &str = "        /*0000*/                   MOV R1, c[0x0][0x28] ;                          /* 0x00000a0000017a02 */\n\
                                                                                       /* 0x000fe40000000f00 */\n\
        /*0010*/                   LDG.E R2, [R4.64] ;                             /* 0x0000000404027981 */\n\
                                                                                       /* 0x000ea200001ee900 */\n\
        /*0020*/              @!P0 MUFU.RCP R3, R0 ;                               /* 0x0000000000038308 */\n\
                                                                                       /* 0x000e240000001000 */\n\
        /*0030*/                   FADD R2, R2, R3 ;                               /* 0x0000000302027221 */\n\
                                                                                       /* 0x005fca0000000000 */\n\
        /*0040*/                   EXIT ;                                          /* 0x000000000000794d */\n\
                                                                                       /* 0x000fea0003800000 */\n\
        /*0050*/                   BRA 0x50;                                       /* 0xfffffff000007947 */\n\
                                                                                       /* 0x000fc0000383ffff */\n";

    #[test]
    fn plays_the_schedule_through_with_the_waits() {
        let is = instructions(LISTING).unwrap();
        assert_eq!(
            is.iter().map(|i| i.opcode.as_str()).collect::<Vec<_>>(),
            ["MOV", "LDG.E", "MUFU.RCP", "FADD", "EXIT"]
        );
        assert_eq!(is[1].control.write_barrier, Some(2));
        assert_eq!(is[2].control.write_barrier, Some(0));
        assert_eq!(is[3].control.wait_mask, 0b101);
        // MOV at 0 (stall 2), LDG at 2 (stall 1; scoreboard 2 at 2 + 320), MUFU at 3 (scoreboard 0 at
        // 3 + 21), FADD waits for both: 322, then stall 5, EXIT at 327 and its stall 5.
        assert_eq!(schedule_latency(&is, &MEMORY), 322.0 + 5.0 + 5.0);
        assert_eq!(schedule_latency(&is, &MEMORY_SM89), 634.0 + 5.0 + 5.0);
        assert!(instructions("/*0000*/ MOV R1, R2 ;\n").unwrap_err().to_string().contains("-hex"));
    }
}
