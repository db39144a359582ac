//! NVIDIA's rates and SASS counted under the one rule: the five GPU generations brdfprof prices, the throughput
//! table of NVIDIA's CUDA C++ Programming Guide (`THROUGHPUT`, the one place those figures live), each
//! instruction's class and pipe, and a kernel's SASS counted (`SassStats`). ptxas' listing (`sass`) and NAK's
//! assembly (`nak`) are read alike.

pub mod nak;
pub mod sass;

use crate::Stat;
use crate::schedule::{LATENCY, PIPE_PREFIX, RESIDENT_WAVES};
use anyhow::{Result, bail};
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
    /// Resident blocks (workgroups) per SM at most (the same table).
    pub max_blocks: u32,
    /// A global load's latency: the family's measured DRAM figure where one was found (docs/measured.md).
    pub memory: &'static sass::VariableLatency,
}

pub const FAMILIES: [Family; 5] = [
    Family {
        name: "sm_75",
        compute_capability: (7, 5),
        architecture: "Turing",
        products: "GeForce RTX 20 / GTX 16 series, T4",
        column: 0,
        max_warps: 32,
        max_blocks: 16,
        memory: &sass::MEMORY,
    },
    Family {
        name: "sm_86",
        compute_capability: (8, 6),
        architecture: "Ampere (GA10x)",
        products: "GeForce RTX 30 series, RTX A6000",
        column: 1,
        max_warps: 48,
        max_blocks: 16,
        memory: &sass::MEMORY,
    },
    Family {
        name: "sm_89",
        compute_capability: (8, 9),
        architecture: "Ada Lovelace",
        products: "GeForce RTX 40 series, L4, L40",
        column: 2,
        max_warps: 48,
        max_blocks: 24,
        memory: &sass::MEMORY_SM89,
    },
    Family {
        name: "sm_90",
        compute_capability: (9, 0),
        architecture: "Hopper",
        products: "H100, H200",
        column: 3,
        max_warps: 64,
        max_blocks: 32,
        memory: &sass::MEMORY_SM90,
    },
    Family {
        name: "sm_120",
        compute_capability: (12, 0),
        architecture: "Blackwell (GB20x)",
        products: "GeForce RTX 50 series, RTX PRO 6000",
        column: 4,
        max_warps: 48,
        max_blocks: 32,
        memory: &sass::MEMORY,
    },
];

/// The compute capabilities of `THROUGHPUT`'s columns.
pub const COLUMNS: [&str; 5] = ["7.5", "8.6", "8.9", "9.0", "12.0"];

/// A row of the guide's table "Throughput of Native Arithmetic Instructions (Number of Results per Clock
/// Cycle per Multiprocessor)": its label as the guide writes it and its figure per column.
pub struct Rate {
    pub row: &'static str,
    pub per_clock: [u32; 5],
}

/// The rows the cost model uses, with the guide's labels and figures (CUDA C++ Programming Guide v12.x,
/// 5.4.1, for 7.5 to 9.0; CUDA C++ Best Practices Guide v13.x, 12.1.1, for 12.0; sources and their copies in
/// docs/targets/nvidia.md). `crates/isa-cost/fixtures/nvidia-throughput.tsv` transcribes the same table with its citation, and
/// a test ties every entry here to it.
pub const THROUGHPUT: &[Rate] = &[
    Rate { row: FP16, per_clock: [128, 256, 128, 256, 128] },
    Rate { row: FP32, per_clock: [64, 128, 128, 128, 128] },
    Rate { row: FP64, per_clock: [2, 2, 2, 64, 2] },
    Rate { row: MUFU, per_clock: [16, 16, 16, 16, 16] },
    Rate { row: IADD, per_clock: [64, 64, 64, 64, 128] },
    Rate { row: IMAD, per_clock: [64, 64, 64, 64, 64] },
    Rate { row: SHIFT, per_clock: [64, 64, 64, 64, 64] },
    Rate { row: CMP, per_clock: [64, 64, 64, 64, 64] },
    Rate { row: INT_MINMAX, per_clock: [64, 64, 64, 64, 128] },
    Rate { row: LOGIC, per_clock: [64, 64, 64, 64, 64] },
    Rate { row: SHUFFLE, per_clock: [32, 32, 32, 32, 32] },
    Rate { row: CVT_F2I, per_clock: [16, 16, 16, 16, 2] },
    Rate { row: CVT_F16_F32, per_clock: [16, 16, 16, 16, 64] },
    Rate { row: CVT, per_clock: [16, 16, 16, 16, 16] },
];

const FP16: &str = "16-bit floating-point add, multiply, multiply-add";
const FP32: &str = "32-bit floating-point add, multiply, multiply-add";
const FP64: &str = "64-bit floating-point add, multiply, multiply-add";
const MUFU: &str = "32-bit floating-point reciprocal, reciprocal square root, base-2 logarithm (__log2f), base 2 exponential (exp2f), sine (__sinf), cosine (__cosf)";
const IADD: &str = "32-bit integer add, extended-precision add, subtract, extended-precision subtract";
const IMAD: &str = "32-bit integer multiply, multiply-add, extended-precision multiply-add";
const SHIFT: &str = "32-bit integer shift";
const CMP: &str = "compare, minimum, maximum";
/// The 13.x guide gives 12.0 its own integer minimum/maximum rate; before, the compare row's.
const INT_MINMAX: &str = "32-bit integer minimum, maximum";
const LOGIC: &str = "32-bit bitwise AND, OR, XOR";
const SHUFFLE: &str = "warp shuffle";
/// The 13.x guide's 12.0 conversions rows (footnote: "2 for float->32-bit integer type (SM > 10.0)"); before
/// 12.0 both are "all other type conversions".
const CVT_F2I: &str = "32-bit floating-point to 32-bit integer conversion";
const CVT_F16_F32: &str = "16-bit to 32-bit floating-point conversion";
const CVT: &str = "all other type conversions";

/// Results one instruction of a row computes per thread: the 16-bit row counts both halves of an
/// HFMA2/HADD2/HMUL2, which the translation's scalar halves issue one instruction each for.
fn results_per_instruction(row: &str) -> u32 {
    if row == FP16 { 2 } else { 1 }
}

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
    pub const ALL: [Class; 9] = [
        Class::Fp32,
        Class::Fp16,
        Class::Fp64,
        Class::Mufu,
        Class::Integer,
        Class::Conversion,
        Class::Memory,
        Class::Control,
        Class::Move,
    ];

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

/// The SM's execution pipes as NVIDIA's Nsight Compute Kernel Profiling Guide (2.3.6 "Pipelines") names them,
/// each instruction on the one the guide assigns it to (`classify`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Pipe {
    /// FP32 arithmetic, IMAD/IMUL; FP16x2 from GA10x on.
    Fma,
    /// "On Volta, Turing and NVIDIA GA100, the FP16 pipeline performs paired FP16 instructions."
    Fp16,
    Fp64,
    /// Integer add, shift, logic, compare; FP32 compare, min, max and select (not named by the guide: here, as
    /// integer compares are); fast FP32-to-FP16 and integer-to-FP32 conversion (F2FP, I2FP).
    Alu,
    /// Special functions (MUFU) and the int-to-float / float-to-int conversions.
    Xu,
    /// Loads, stores, special-register reads, shuffles.
    Lsu,
    /// Constant loads.
    Adu,
    /// Branches and convergence barriers.
    Cbu,
    /// The uniform datapath.
    Uniform,
}

impl Pipe {
    pub const ALL: [Pipe; 9] =
        [Pipe::Fma, Pipe::Fp16, Pipe::Fp64, Pipe::Alu, Pipe::Xu, Pipe::Lsu, Pipe::Adu, Pipe::Cbu, Pipe::Uniform];

    pub fn name(self) -> &'static str {
        match self {
            Pipe::Fma => "FMA",
            Pipe::Fp16 => "FP16",
            Pipe::Fp64 => "FP64",
            Pipe::Alu => "ALU",
            Pipe::Xu => "XU (MUFU, conversions)",
            Pipe::Lsu => "LSU",
            Pipe::Adu => "ADU",
            Pipe::Cbu => "CBU",
            Pipe::Uniform => "uniform",
        }
    }

    /// The pipe on `family`: GA10x and later run FP16x2 on the FMA pipe.
    pub fn on(self, family: &Family) -> Pipe {
        if self == Pipe::Fp16 && family.compute_capability >= (8, 6) { Pipe::Fma } else { self }
    }
}

/// The report class of a SASS opcode (`F2F.F32.F16`; its mnemonic before the first `.` decides, and for
/// conversions its types), the `THROUGHPUT` row it issues at (None: the issue rate) and its pipe (None: the
/// issue slot alone: moves, predicates, NOPs).
pub fn classify(opcode: &str) -> (Class, Option<&'static str>, Option<Pipe>) {
    let mnemonic = opcode.split('.').next().unwrap_or(opcode);
    match mnemonic {
        "FADD" | "FMUL" | "FFMA" | "FADD32I" | "FMUL32I" | "FFMA32I" | "FSWZADD" => {
            (Class::Fp32, Some(FP32), Some(Pipe::Fma))
        }
        "FMNMX" | "FSETP" | "FSET" | "FSEL" | "FCHK" => (Class::Fp32, Some(CMP), Some(Pipe::Alu)),
        "HADD2" | "HMUL2" | "HFMA2" | "HADD2_32I" | "HMUL2_32I" | "HFMA2_32I" => {
            (Class::Fp16, Some(FP16), Some(Pipe::Fp16))
        }
        "HSETP2" | "HSET2" | "HMNMX2" => (Class::Fp16, Some(CMP), Some(Pipe::Fp16)),
        "DADD" | "DMUL" | "DFMA" => (Class::Fp64, Some(FP64), Some(Pipe::Fp64)),
        "DSETP" | "DMNMX" => (Class::Fp64, Some(CMP), Some(Pipe::Fp64)),
        "MUFU" => (Class::Mufu, Some(MUFU), Some(Pipe::Xu)),
        "IADD3" | "IADD" | "IADD32I" | "VIADD" | "LEA" | "IABS" => (Class::Integer, Some(IADD), Some(Pipe::Alu)),
        "IMAD" | "IMUL" | "IMAD32I" | "IMUL32I" | "IMADSP" | "XMAD" => (Class::Integer, Some(IMAD), Some(Pipe::Fma)),
        "SHF" | "SHL" | "SHR" => (Class::Integer, Some(SHIFT), Some(Pipe::Alu)),
        "ISETP" | "ISET" | "ICMP" => (Class::Integer, Some(CMP), Some(Pipe::Alu)),
        "IMNMX" | "VIMNMX" => (Class::Integer, Some(INT_MINMAX), Some(Pipe::Alu)),
        "LOP3" | "LOP" | "LOP32I" => (Class::Integer, Some(LOGIC), Some(Pipe::Alu)),
        "SHFL" => (Class::Move, Some(SHUFFLE), Some(Pipe::Lsu)),
        "F2FP" | "I2FP" => (Class::Conversion, Some(LOGIC), Some(Pipe::Alu)),
        "F2I" | "F2IP" => (Class::Conversion, Some(CVT_F2I), Some(Pipe::Xu)),
        "F2F" if opcode.starts_with("F2F.F32.F16") => (Class::Conversion, Some(CVT_F16_F32), Some(Pipe::Xu)),
        "F2F" | "I2F" | "FRND" | "I2I" | "I2IP" => (Class::Conversion, Some(CVT), Some(Pipe::Xu)),
        "LDC" | "ULDC" | "LDCU" => (Class::Memory, None, Some(Pipe::Adu)),
        "S2R" | "S2UR" | "CS2R" => (Class::Move, None, Some(Pipe::Lsu)),
        op if ["LD", "ST", "ATOM", "RED", "TEX", "TLD", "SULD", "SUST"].iter().any(|p| op.starts_with(p)) => {
            (Class::Memory, None, Some(Pipe::Lsu))
        }
        "BRA" | "BRX" | "JMP" | "JMX" | "EXIT" | "RET" | "CALL" | "BSSY" | "BSYNC" | "BREAK" | "BMOV" | "BPT"
        | "WARPSYNC" | "BAR" | "YIELD" | "KILL" | "NANOSLEEP" => (Class::Control, None, Some(Pipe::Cbu)),
        // The uniform datapath's own instructions (UIADD3, ULOP3, UMOV, ...) and bit operations the table
        // has no row for: the issue rate.
        op if op.starts_with('U') => (Class::Integer, None, Some(Pipe::Uniform)),
        op if ["BREV", "BMSK", "SGXT", "FLO", "POPC", "IDP", "IDP4A"].contains(&op) => (Class::Integer, None, None),
        _ => (Class::Move, None, None),
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
    /// Instructions per (`THROUGHPUT` row, pipe) (None: issue-limited; no pipe but the issue slot).
    pub by_row: BTreeMap<(Option<&'static str>, Option<Pipe>), u32>,
    /// One warp's cycles alone by ptxas' schedule (`sass::schedule_latency`).
    pub schedule_latency: f64,
    pub registers: u32,
    pub stack_bytes: u32,
    pub spill_bytes: u32,
    pub cubin_bytes: u32,
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
    /// Counts the `-hex` listing: every instruction up to the kernel's last EXIT (nvdisasm pads the section
    /// with a branch to itself and NOPs after it), NOPs left out of the counts (not of the schedule).
    pub fn of(listing: &str, ptxas_log: &str, cubin_bytes: usize, family: &Family) -> Result<Self> {
        let mut s = Self::of_instructions(&sass::instructions(listing)?, family);
        s.cubin_bytes = cubin_bytes as u32;
        s.registers = ptxas_figure(ptxas_log, "registers");
        s.stack_bytes = ptxas_figure(ptxas_log, "bytes stack frame");
        s.spill_bytes = ptxas_figure(ptxas_log, "bytes spill stores") + ptxas_figure(ptxas_log, "bytes spill loads");
        Ok(s)
    }

    /// The counts and the schedule latency of one warp's instructions in issue order, whichever compiler
    /// scheduled them (ptxas' SASS, NAK's assembly), NOPs left out of the counts (not of the schedule); no
    /// registers, stack or code size.
    pub fn of_instructions(instructions: &[sass::Instruction], family: &Family) -> Self {
        let schedule_latency = sass::schedule_latency(instructions, family.memory);
        let mut s = SassStats { schedule_latency, ..Default::default() };
        for i in instructions.iter().filter(|i| i.mnemonic() != "NOP") {
            let (class, row, pipe) = classify(&i.opcode);
            s.instructions += 1;
            *s.by_class.entry(class).or_default() += 1;
            *s.by_row.entry((row, pipe)).or_default() += 1;
        }
        s
    }

    /// SM cycles per warp of each of `n` instructions of `row`: 32 x (results per instruction) / (results per
    /// clock per SM), at most the issue rate's.
    pub fn cycles_per_instruction(row: Option<&'static str>, family: &Family) -> Result<f64> {
        let per_clock = match row {
            Some(r) => rate(r, family).ok_or_else(|| anyhow::anyhow!("the throughput table has no row `{r}`"))?,
            None => ISSUE_PER_CLOCK,
        };
        if per_clock == 0 {
            bail!("`{}` has no native throughput on {}", row.unwrap_or("?"), family.name);
        }
        let results = row.map_or(1, results_per_instruction);
        Ok(32.0 * f64::from(results) / f64::from(per_clock.min(ISSUE_PER_CLOCK * results)))
    }

    /// SM cycles one warp's instructions take at the table's rates if no two overlapped (the serial sum,
    /// reported as a column of its own): the sum over rows of count x 32 / (results per clock), the issue rate
    /// for every unlisted instruction.
    pub fn issue_cycles(&self, family: &Family) -> Result<f64> {
        let mut cycles = 0.0;
        for ((row, _), n) in &self.by_row {
            cycles += f64::from(*n) * Self::cycles_per_instruction(*row, family)?;
        }
        Ok(cycles)
    }

    /// SM cycles per warp each pipe is busy (its instructions at their rows' rates), and the issue slots
    /// (every instruction at 32 / 128: four schedulers, one warp instruction each per clock).
    pub fn pipes(&self, family: &Family) -> Result<Vec<(String, f64)>> {
        let mut busy: BTreeMap<Pipe, f64> = BTreeMap::new();
        for ((row, pipe), n) in &self.by_row {
            if let Some(p) = pipe {
                *busy.entry(p.on(family)).or_default() += f64::from(*n) * Self::cycles_per_instruction(*row, family)?;
            }
        }
        let mut out: Vec<(String, f64)> = busy.into_iter().map(|(p, c)| (p.name().to_string(), c)).collect();
        out.push(("issue".to_string(), f64::from(self.instructions) * 32.0 / f64::from(ISSUE_PER_CLOCK)));
        Ok(out)
    }

    /// Resident warps per SM under every limit the kernels meet: 65,536 registers per SM allocated per warp
    /// in units of 256 (occupancy calculator), whole 64-thread workgroups of two warps, the family's resident
    /// warps and resident blocks per SM (Programming Guide, "Technical Specifications per Compute
    /// Capability"); no shared memory is used, so its limit never binds.
    pub fn warps_per_sm(&self, family: &Family) -> u32 {
        const REGISTERS_PER_SM: u32 = 65_536;
        const ALLOCATION_UNIT: u32 = 256;
        const WARPS_PER_BLOCK: u32 = 2;
        let per_warp = (self.registers.max(1) * 32).div_ceil(ALLOCATION_UNIT) * ALLOCATION_UNIT;
        let warps = (REGISTERS_PER_SM / per_warp) / WARPS_PER_BLOCK * WARPS_PER_BLOCK;
        warps.min(family.max_warps).min(family.max_blocks * WARPS_PER_BLOCK)
    }

    /// The statistics, as the driver statistics of the executable "SASS" (their names line up with the aliases
    /// of `schema::driver`, so that the gate reads registers, instructions, spills and code size as for any
    /// driver).
    pub fn driver_stats(&self, family: &Family) -> Result<Vec<Stat>> {
        let stat = |name: &str, value: f64| Stat::new(name, "", value);
        let mut out = vec![
            stat("Instruction Count", f64::from(self.instructions)),
            stat("Register Count", f64::from(self.registers)),
            // ptxas reports spill stores in bytes, not a count of spilled values.
            stat("Spill Bytes", f64::from(self.spill_bytes)),
            stat("Scratch Memory Size", f64::from(self.stack_bytes)),
            stat("Binary Size", f64::from(self.cubin_bytes)),
            stat("Warps per SM", f64::from(self.warps_per_sm(family))),
            stat(RESIDENT_WAVES, f64::from(self.warps_per_sm(family))),
        ];
        out.extend(self.rule_stats(family)?.into_iter().map(|(n, v)| stat(&n, v)));
        Ok(out)
    }

    /// What the rule reads of the instructions alone, named as `cost::schedule` reads them: the classes, each
    /// pipe's busy cycles, the schedule latency and the serial sum ("Issue Cycles"); not the resident warps,
    /// which need the registers.
    pub fn rule_stats(&self, family: &Family) -> Result<Vec<(String, f64)>> {
        let mut out = vec![
            ("Issue Cycles".to_string(), self.issue_cycles(family)?),
            (LATENCY.to_string(), self.schedule_latency),
        ];
        for c in Class::ALL {
            out.push((c.name().to_string(), f64::from(self.by_class.get(&c).copied().unwrap_or(0))));
        }
        for (pipe, cycles) in self.pipes(family)? {
            out.push((format!("{PIPE_PREFIX}{pipe}"), cycles));
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn resident_warps_meet_the_register_warp_and_block_limits() {
        let family = |name: &str| FAMILIES.iter().find(|f| f.name == name).unwrap();
        let with = |registers: u32| SassStats { registers, ..Default::default() };
        // 32 registers allow 64 warps; Ampere GA10x holds 48 warps but only 16 blocks (32 warps of 64 threads).
        assert_eq!(with(32).warps_per_sm(family("sm_86")), 32);
        // Ada holds 24 blocks: its 48 warps.
        assert_eq!(with(32).warps_per_sm(family("sm_89")), 48);
        // 128 registers: 16 warps, whatever the other limits.
        assert_eq!(with(128).warps_per_sm(family("sm_90")), 16);
    }

    #[test]
    fn every_rate_is_the_fixtures() {
        let text = include_str!("../../fixtures/nvidia-throughput.tsv");
        let rows: Vec<Vec<&str>> = text
            .lines()
            .filter(|l| !l.starts_with('#') && !l.trim().is_empty() && !l.starts_with("ratio"))
            .map(|l| l.split('\t').collect())
            .collect();
        for r in &rows {
            let rate =
                THROUGHPUT.iter().find(|t| t.row == r[0]).unwrap_or_else(|| panic!("the code has no row `{}`", r[0]));
            let figures: Vec<u32> = r[1..].iter().map(|v| v.parse().unwrap()).collect();
            assert_eq!(rate.per_clock.to_vec(), figures, "{}", r[0]);
        }
        assert_eq!(rows.len(), THROUGHPUT.len(), "every row of the code is in the fixture once");
        // FP64 is FP32 over Table 30's ratio.
        let ratio: Vec<u32> = text
            .lines()
            .find(|l| l.starts_with("ratio"))
            .unwrap()
            .split('\t')
            .skip(1)
            .map(|v| v.parse().unwrap())
            .collect();
        for (k, r) in ratio.iter().enumerate() {
            assert_eq!(rate(FP32, &FAMILIES[k]).unwrap() / r, rate(FP64, &FAMILIES[k]).unwrap(), "{}", COLUMNS[k]);
        }
    }

    #[test]
    fn instructions_go_to_their_pipes_at_their_rates() {
        assert_eq!(classify("MUFU.EX2").2, Some(Pipe::Xu));
        assert_eq!(classify("F2FP.PACK_AB").2, Some(Pipe::Alu));
        assert_eq!(classify("IMAD.MOV.U32").2, Some(Pipe::Fma));
        assert_eq!(classify("F2F.F32.F16").1, Some(CVT_F16_F32));
        assert_eq!(classify("F2I.FTZ.U32.TRUNC.NTZ").1, Some(CVT_F2I));
        assert_eq!(classify("MOV").2, None);
        let sm = |n: &str| FAMILIES.iter().find(|f| f.name == n).unwrap();
        let mut s = SassStats { instructions: 8, ..Default::default() };
        s.by_row.insert((Some(FP32), Some(Pipe::Fma)), 4);
        s.by_row.insert((Some(MUFU), Some(Pipe::Xu)), 2);
        s.by_row.insert((Some(CVT_F2I), Some(Pipe::Xu)), 1);
        s.by_row.insert((None, None), 1);
        let pipes = |n: &str| s.pipes(sm(n)).unwrap().into_iter().collect::<BTreeMap<String, f64>>();
        // sm_89: FFMA 32/128 each, MUFU 32/16, F2I 32/16; every instruction 32/128 on the issue slot.
        assert_eq!(
            (pipes("sm_89")["FMA"], pipes("sm_89")["XU (MUFU, conversions)"], pipes("sm_89")["issue"]),
            (1.0, 6.0, 2.0)
        );
        // sm_120: F2I at 2 per clock; sm_75: FP32 at 64.
        assert_eq!((pipes("sm_120")["XU (MUFU, conversions)"], pipes("sm_75")["FMA"]), (4.0 + 16.0, 2.0));
        // The serial sum adds them all: 1 + 4 + 2 + 0.25 on sm_89.
        assert_eq!(s.issue_cycles(sm("sm_89")).unwrap(), 1.0 + 4.0 + 2.0 + 0.25);
    }
}
