//! `--device nvidia:sm_XX`: NVIDIA's production compiler (NVRTC and ptxas, `nvrtc`) on the kernels' CUDA C++
//! translation (`translate`), for five GPU generations, with no NVIDIA GPU or driver. Per kernel: ptxas'
//! registers, stack and spills, the SASS nvdisasm lists counted by class, the cubin's size, occupancy, and a
//! documented cost model: issue-limited SM cycles from the throughput table of NVIDIA's CUDA C++ Programming
//! Guide (`THROUGHPUT`, the one place those figures live). These are "NVIDIA's CUDA compiler (ptxas), same
//! maths" figures: NVIDIA's Vulkan driver compiles SPIR-V with its own front end, and no public comparison of
//! the two exists.

use super::nvrtc;
use crate::gpu::DriverStat;
use anyhow::{bail, Result};
use std::collections::BTreeMap;

/// One NVIDIA GPU generation, as a compute capability.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Family {
    /// `-arch=` and `--device nvidia:` name.
    pub name: &'static str,
    pub compute_capability: (u32, u32),
    pub architecture: &'static str,
    pub products: &'static str,
    /// Column of `THROUGHPUT`.
    column: usize,
    /// Resident warps per SM at most (Programming Guide, "Technical Specifications per Compute Capability").
    pub max_warps: u32,
}

pub const FAMILIES: [Family; 5] = [
    Family { name: "sm_75", compute_capability: (7, 5), architecture: "Turing", products: "GeForce RTX 20 / GTX 16 series, T4", column: 0, max_warps: 32 },
    Family { name: "sm_86", compute_capability: (8, 6), architecture: "Ampere (GA10x)", products: "GeForce RTX 30 series, RTX A6000", column: 1, max_warps: 48 },
    Family { name: "sm_89", compute_capability: (8, 9), architecture: "Ada Lovelace", products: "GeForce RTX 40 series, L4, L40", column: 2, max_warps: 48 },
    Family { name: "sm_90", compute_capability: (9, 0), architecture: "Hopper", products: "H100, H200", column: 3, max_warps: 64 },
    Family { name: "sm_120", compute_capability: (12, 0), architecture: "Blackwell (GB20x)", products: "GeForce RTX 50 series, RTX PRO 6000", column: 4, max_warps: 48 },
];

/// The compute capabilities of `THROUGHPUT`'s columns.
pub const COLUMNS: [&str; 5] = ["7.5", "8.6", "8.9", "9.0", "12.0"];

/// A row of the guide's table "Throughput of Native Arithmetic Instructions (Number of Results per Clock
/// Cycle per Multiprocessor)": its label as the guide writes it and its figure per column.
pub struct Rate {
    pub row: &'static str,
    pub per_clock: [u32; 5],
}

/// The rows the cost model uses, as published in the CUDA C++ Programming Guide (see README, "NVIDIA
/// targets", for the version and section); tests tie every figure to the cited table.
pub const THROUGHPUT: &[Rate] = &[];

/// Instructions one SM issues per clock: four warp schedulers, one warp instruction each (Programming Guide,
/// the compute-capability sections: "4 warp schedulers"), i.e. 128 results per clock: the rate of every
/// instruction the table does not list (moves, predicates, branches, loads and stores).
pub const ISSUE_PER_CLOCK: u32 = 128;

/// What a SASS instruction is counted as in the report.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Class {
    Fp32,
    Fp16,
    Fp64,
    Mufu,
    Integer,
    Conversion,
    Memory,
    Control,
    Move,
}

impl Class {
    pub const ALL: [Class; 9] = [Class::Fp32, Class::Fp16, Class::Fp64, Class::Mufu, Class::Integer, Class::Conversion, Class::Memory, Class::Control, Class::Move];

    pub fn name(self) -> &'static str {
        match self {
            Class::Fp32 => "FP32 (FMA, MUL, ADD, compare)",
            Class::Fp16 => "FP16",
            Class::Fp64 => "FP64",
            Class::Mufu => "MUFU (special functions)",
            Class::Integer => "Integer",
            Class::Conversion => "Conversion",
            Class::Memory => "Memory",
            Class::Control => "Control",
            Class::Move => "Move and predicate",
        }
    }
}

/// The report class of a SASS opcode (its mnemonic before the first `.`) and the `THROUGHPUT` row it issues
/// at (None: the issue rate).
pub fn classify(opcode: &str) -> (Class, Option<&'static str>) {
    const FP32: &str = "32-bit floating-point add, multiply, multiply-add";
    const CMP: &str = "compare, minimum, maximum";
    const CVT: &str = "all other type conversions";
    match opcode {
        "FADD" | "FMUL" | "FFMA" | "FADD32I" | "FMUL32I" | "FFMA32I" | "FSWZADD" => (Class::Fp32, Some(FP32)),
        "FMNMX" | "FSETP" | "FSET" | "FSEL" | "FCHK" => (Class::Fp32, Some(CMP)),
        "HADD2" | "HMUL2" | "HFMA2" | "HADD2_32I" | "HMUL2_32I" | "HFMA2_32I" => (Class::Fp16, Some("16-bit floating-point add, multiply, multiply-add")),
        "HSETP2" | "HSET2" | "HMNMX2" => (Class::Fp16, Some(CMP)),
        "DADD" | "DMUL" | "DFMA" => (Class::Fp64, Some("64-bit floating-point add, multiply, multiply-add")),
        "DSETP" | "DMNMX" => (Class::Fp64, Some(CMP)),
        "MUFU" => (Class::Mufu, Some("32-bit floating-point reciprocal, reciprocal square root, base-2 logarithm (__log2f), base 2 exponential (exp2f), sine (__sinf), cosine (__cosf)")),
        "IADD3" | "IADD" | "IADD32I" | "VIADD" | "LEA" | "IABS" => (Class::Integer, Some("32-bit integer add, extended-precision add, subtract, extended-precision subtract")),
        "IMAD" | "IMUL" | "IMAD32I" | "IMUL32I" | "IMADSP" | "XMAD" | "IDP" | "IDP4A" => (Class::Integer, Some("32-bit integer multiply, multiply-add, extended-precision multiply-add")),
        "SHF" | "SHL" | "SHR" => (Class::Integer, Some("32-bit integer shift")),
        "ISETP" | "IMNMX" | "VIMNMX" | "ISET" | "ICMP" => (Class::Integer, Some(CMP)),
        "LOP3" | "LOP" | "LOP32I" => (Class::Integer, Some("32-bit bitwise AND, OR, XOR")),
        "BREV" => (Class::Integer, Some("32-bit integer bit reverse")),
        "BFE" | "BFI" | "SGXT" | "BMSK" => (Class::Integer, Some("Bit field extract/insert")),
        "FLO" => (Class::Integer, Some("count of leading zeros, most significant non-sign bit")),
        "POPC" => (Class::Integer, Some("population count")),
        "SHFL" => (Class::Move, Some("warp shuffle")),
        "F2F" | "F2I" | "I2F" | "I2FP" | "F2FP" | "F2IP" | "FRND" | "I2I" | "I2IP" => (Class::Conversion, Some(CVT)),
        op if op.starts_with("LD") || op.starts_with("ST") || op.starts_with("ATOM") || op.starts_with("RED") || op.starts_with("TEX") || op.starts_with("TLD") || op.starts_with("SU") || op.starts_with("ULDC") => (Class::Memory, None),
        "BRA" | "BRX" | "JMP" | "JMX" | "EXIT" | "RET" | "CALL" | "BSSY" | "BSYNC" | "BREAK" | "BMOV" | "BPT" | "WARPSYNC" | "BAR" | "YIELD" | "KILL" | "NANOSLEEP" => (Class::Control, None),
        op if op.starts_with('U') => (Class::Integer, None),
        _ => (Class::Move, None),
    }
}

/// The throughput of row `row` on `family` (results per clock per SM).
pub fn rate(row: &str, family: &Family) -> Option<u32> {
    THROUGHPUT.iter().find(|r| r.row == row).map(|r| r.per_clock[family.column])
}

/// One kernel's SASS, counted.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SassStats {
    pub instructions: u32,
    pub by_class: BTreeMap<Class, u32>,
    /// Instructions per `THROUGHPUT` row (None: issue-limited).
    pub by_row: BTreeMap<Option<&'static str>, u32>,
    pub registers: u32,
    pub stack_bytes: u32,
    pub spill_bytes: u32,
    pub cubin_bytes: u32,
}

/// The opcode of one nvdisasm line (`/*0090*/  @!P0 LDG.E.CONSTANT R4, [R2.64] ;`), None for other lines.
fn opcode(line: &str) -> Option<&str> {
    let rest = line.trim_start().strip_prefix("/*")?;
    let (addr, rest) = rest.split_once("*/")?;
    if addr.is_empty() || !addr.chars().all(|c| c.is_ascii_hexdigit()) {
        return None;
    }
    let mut words = rest.split_whitespace();
    let mut first = words.next()?;
    if first.starts_with('@') {
        first = words.next()?;
    }
    let op = first.trim_end_matches(';');
    Some(op.split('.').next().unwrap_or(op))
}

/// The figure before `what` in ptxas' `-v` report ("Used 40 registers", "0 bytes spill stores"), the largest
/// where several functions report one; 0 when absent.
fn ptxas_figure(log: &str, what: &str) -> u32 {
    log.lines()
        .flat_map(|l| l.split(','))
        .filter_map(|part| part.trim().strip_suffix(what)?.split_whitespace().last()?.parse().ok())
        .max()
        .unwrap_or(0)
}

impl SassStats {
    /// Counts the listing: every instruction up to the kernel's last EXIT (nvdisasm pads the section with a
    /// branch to itself and NOPs after it).
    pub fn of(listing: &str, ptxas_log: &str, cubin_bytes: usize) -> Self {
        let ops: Vec<&str> = listing.lines().filter_map(opcode).collect();
        let end = ops.iter().rposition(|o| *o == "EXIT").map_or(ops.len(), |i| i + 1);
        let mut s = SassStats { cubin_bytes: cubin_bytes as u32, ..Default::default() };
        for op in ops[..end].iter().filter(|o| **o != "NOP") {
            let (class, row) = classify(op);
            s.instructions += 1;
            *s.by_class.entry(class).or_default() += 1;
            *s.by_row.entry(row).or_default() += 1;
        }
        s.registers = ptxas_figure(ptxas_log, "registers");
        s.stack_bytes = ptxas_figure(ptxas_log, "bytes stack frame");
        s.spill_bytes = ptxas_figure(ptxas_log, "bytes spill stores") + ptxas_figure(ptxas_log, "bytes spill loads");
        s
    }

    /// SM cycles one warp's instructions take at the table's rates: the sum over rows of
    /// count x 32 / (results per clock), the issue rate for every unlisted instruction.
    pub fn issue_cycles(&self, family: &Family) -> Result<f64> {
        let mut cycles = 0.0;
        for (row, n) in &self.by_row {
            let per_clock = match row {
                Some(r) => rate(r, family).ok_or_else(|| anyhow::anyhow!("the throughput table has no row `{r}`"))?,
                None => ISSUE_PER_CLOCK,
            };
            if per_clock == 0 {
                bail!("`{}` has no native throughput on {}", row.unwrap_or("?"), family.name);
            }
            cycles += f64::from(*n) * 32.0 / f64::from(per_clock.min(ISSUE_PER_CLOCK));
        }
        Ok(cycles)
    }

    /// Resident warps per SM the register count allows: 65,536 registers per SM allocated per warp in units
    /// of 256 (occupancy calculator), two warps per 64-thread workgroup, at most the family's warps.
    pub fn warps_per_sm(&self, family: &Family) -> u32 {
        const REGISTERS_PER_SM: u32 = 65_536;
        const ALLOCATION_UNIT: u32 = 256;
        let per_warp = (self.registers.max(1) * 32).div_ceil(ALLOCATION_UNIT) * ALLOCATION_UNIT;
        let warps = (REGISTERS_PER_SM / per_warp) / 2 * 2;
        warps.min(family.max_warps)
    }

    /// The statistics as driver statistics of the executable "SASS" (their names line up with the aliases
    /// of `inspect::driver`, so that the gate reads registers, instructions, spills and code size as for any
    /// driver).
    pub fn driver_stats(&self, family: &Family) -> Result<Vec<DriverStat>> {
        let stat = |name: &str, value: f64| DriverStat { executable: "SASS".into(), name: name.into(), description: String::new(), value };
        let mut out = vec![
            stat("Instruction Count", f64::from(self.instructions)),
            stat("Register Count", f64::from(self.registers)),
            stat("Spill Count", f64::from(self.spill_bytes)),
            stat("Scratch Memory Size", f64::from(self.stack_bytes)),
            stat("Binary Size", f64::from(self.cubin_bytes)),
            stat("Warps per SM", f64::from(self.warps_per_sm(family))),
            stat("Issue Cycles", self.issue_cycles(family)?),
        ];
        for c in Class::ALL {
            out.push(stat(c.name(), f64::from(self.by_class.get(&c).copied().unwrap_or(0))));
        }
        Ok(out)
    }
}

/// NVRTC's options: the architecture, ptxas' resource report, no warnings, and (unless `precise`)
/// `-use_fast_math`, which gives NVIDIA the precision freedom a Vulkan driver has (approximate division and
/// square root, exp2/log2-based transcendentals, denormals flushed: `--ftz=true --prec-div=false
/// --prec-sqrt=false --fmad=true`).
pub fn options(family: &Family, precise: bool) -> Vec<String> {
    let mut o = vec![format!("-arch={}", family.name), "--ptxas-options=-v".into(), "-w".into()];
    if !precise {
        o.push("-use_fast_math".into());
    }
    o
}

/// A kernel compiled for `family`: the SASS listing, ptxas' log and the cubin's size.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize, PartialEq)]
pub struct Sass {
    pub listing: String,
    pub log: String,
    pub cubin_bytes: usize,
}

/// Compiles the CUDA C++ `source` for `family` and disassembles it.
pub fn compile(source: &str, family: &Family, precise: bool) -> Result<Sass> {
    let tools = nvrtc::tools()?;
    let compiled = tools.compile(source, "brdfprof_kernel.cu", &options(family, precise))?;
    let listing = tools.disassemble(&compiled.cubin)?;
    Ok(Sass { listing, log: compiled.log, cubin_bytes: compiled.cubin.len() })
}
