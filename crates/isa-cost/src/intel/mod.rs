//! Intel's rates and IGA's listing counted under the one rule: the families brdfprof prices (Gen9 to Xe-HPC), the
//! lanes per clock of Intel's public architecture documents and IGC's own scheduling model (`THROUGHPUT`, the one
//! place those figures live), the pipes and latencies of IGC's scheduler, and a kernel's binary counted
//! (`IsaStats`: SIMD width, GRF count, scratch, instructions by class). IGC's listing (`gen_isa`) and Mesa brw's
//! (`brw`) are read alike.

pub mod brw;
pub mod gen_isa;

use crate::Stat;
use crate::schedule::{LATENCY, PIPE_PREFIX, RESIDENT_WAVES};
use anyhow::{Result, anyhow, bail};
use std::collections::BTreeMap;

/// One Intel GPU generation, as ocloc names a device of it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Family {
    /// The `--device intel:` name.
    pub name: &'static str,
    /// ocloc's `-device` (one product of the family).
    pub device: &'static str,
    pub architecture: &'static str,
    pub products: &'static str,
    /// Column of `THROUGHPUT`.
    column: usize,
    /// Bytes of a general register (Xe-HPC: 64).
    pub grf_bytes: u32,
    /// Hardware threads an EU (vector engine) holds with 128 registers each; half of them in large-GRF mode.
    pub threads: u32,
    pub pipes: Pipes,
    /// IGC's scheduler latencies: its Gen8-Gen11 ("legacy") table, or its Xe table.
    pub legacy_latency: bool,
}

/// How an EU's instructions reach its pipes: the pipes of the throughput bound and of the schedule.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Pipes {
    /// Gen9, Gen11: two SIMD-4 FPUs both run FP and integer work, one of them extended math too (Gen9
    /// whitepaper, 5.3.2).
    TwoFpus,
    /// Xe-LP: one in-order pipe for FP and integer work (IGA's one SWSB distance pipe; Mesa: "On TGL all
    /// instructions that use the RegDist synchronization mechanism are considered to be executed as a single
    /// in-order pipeline") and the extended-math pipe.
    OneAlu,
    /// Xe-HPG, Xe-HPC: float, integer and long (64-bit) in-order pipes (IGA's SWSB distance pipes F@, I@,
    /// L@; which instruction goes where as Mesa's `inferred_exec_pipe`) and the extended-math pipe.
    ThreePipes,
}

pub const FAMILIES: [Family; 5] = [
    Family {
        name: "gen9",
        device: "skl",
        architecture: "Gen9",
        products: "HD/UHD Graphics 5xx-6xx (Skylake to Comet Lake)",
        column: 0,
        grf_bytes: 32,
        threads: 7,
        pipes: Pipes::TwoFpus,
        legacy_latency: true,
    },
    Family {
        name: "gen11",
        device: "icllp",
        architecture: "Gen11",
        products: "Iris Plus / UHD (Ice Lake)",
        column: 1,
        grf_bytes: 32,
        threads: 7,
        pipes: Pipes::TwoFpus,
        legacy_latency: true,
    },
    Family {
        name: "gen12lp",
        device: "tgllp",
        architecture: "Xe-LP (Gen12LP)",
        products: "Iris Xe / UHD (Tiger Lake to Raptor Lake), Iris Xe MAX",
        column: 2,
        grf_bytes: 32,
        threads: 7,
        pipes: Pipes::OneAlu,
        legacy_latency: false,
    },
    Family {
        name: "xe-hpg",
        device: "dg2",
        architecture: "Xe-HPG",
        products: "Arc A-series (Alchemist, ACM-G10)",
        column: 3,
        grf_bytes: 32,
        threads: 8,
        pipes: Pipes::ThreePipes,
        legacy_latency: false,
    },
    Family {
        name: "xe-hpc",
        device: "pvc",
        architecture: "Xe-HPC",
        products: "Data Center GPU Max (Ponte Vecchio)",
        column: 4,
        grf_bytes: 64,
        threads: 8,
        pipes: Pipes::ThreePipes,
        legacy_latency: false,
    },
];

/// The families of `THROUGHPUT`'s columns.
pub const COLUMNS: [&str; 5] = ["gen9", "gen11", "gen12lp", "xe-hpg", "xe-hpc"];

/// A rate of the cost model: lanes one EU (Xe-HPG/HPC: one vector engine) completes per clock for a kind of
/// instruction, per family, with the document it is taken from.
pub struct Rate {
    pub row: &'static str,
    pub lanes_per_clock: [u32; 5],
}

/// Lanes per clock per EU/vector engine (sources per row and column in `crates/isa-cost/fixtures/intel-throughput.tsv`,
/// which transcribes the documents with their sections and the figures each rate is computed from; a test
/// ties every entry here to it and recomputes it; docs/targets/intel.md says which figures are stated and which
/// derived).
pub const THROUGHPUT: &[Rate] = &[
    Rate { row: FP32, lanes_per_clock: [8, 8, 8, 8, 16] },
    Rate { row: FP16, lanes_per_clock: [16, 16, 16, 16, 32] },
    Rate { row: INT32, lanes_per_clock: [8, 4, 8, 8, 16] },
    Rate { row: EM, lanes_per_clock: [2, 2, 2, 2, 2] },
    Rate { row: EM_TWO_SOURCE, lanes_per_clock: [1, 1, 2, 2, 2] },
];

const FP32: &str = "FP32 add, multiply, multiply-add";
const FP16: &str = "FP16 add, multiply, multiply-add";
const INT32: &str = "INT32 operations";
const EM: &str = "extended math (math.inv, sqt, rsqt, exp, log, sin, cos, iqot, irem)";
const EM_TWO_SOURCE: &str = "extended math, pow and fdiv (math.pow, math.fdiv)";
/// The math functions IGC's Gen8-11 scheduling model issues at half the other functions' rate.
const TWO_SOURCE_FUNCTIONS: [&str; 2] = ["pow", "fdiv"];

/// What an instruction is counted as in the report.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Class {
    Fma,
    Alu,
    ExtendedMath,
    Send,
    Control,
    Move,
}

impl Class {
    pub const ALL: [Class; 6] = [Class::Fma, Class::Alu, Class::ExtendedMath, Class::Send, Class::Control, Class::Move];

    pub fn name(self) -> &'static str {
        match self {
            Class::Fma => "FMA and arithmetic (add, mul, mad)",
            Class::Alu => "Compare, select, logic",
            Class::ExtendedMath => "Extended math",
            Class::Send => "Send",
            Class::Control => "Control",
            Class::Move => "Move",
        }
    }
}

/// The report class of a Gen ISA mnemonic (before its first `.`).
pub fn classify(mnemonic: &str) -> Class {
    match mnemonic {
        "add" | "add3" | "mul" | "mad" | "mac" | "mach" | "macl" | "madm" | "lrp" | "dp2" | "dp3" | "dp4" | "dph"
        | "dp4a" | "line" | "pln" | "avg" | "frc" | "rndd" | "rnde" | "rndu" | "rndz" | "sad2" | "sada2" | "addc"
        | "subb" => Class::Fma,
        "math" => Class::ExtendedMath,
        "send" | "sendc" | "sends" | "sendsc" => Class::Send,
        "if" | "else" | "endif" | "while" | "break" | "cont" | "goto" | "join" | "jmpi" | "call" | "calla" | "ret"
        | "halt" | "brd" | "brc" | "wait" | "sync" | "nop" | "illegal" => Class::Control,
        "mov" | "movi" | "smov" => Class::Move,
        _ => Class::Alu,
    }
}

/// The `THROUGHPUT` row an instruction issues at (None: one issue cycle, whatever its width: sends, whose
/// latency the model leaves out, and control), from its class, destination type and math function.
fn row_of(class: Class, dst_type: &str, function: &str) -> Option<&'static str> {
    match class {
        Class::Send | Class::Control => None,
        Class::ExtendedMath if TWO_SOURCE_FUNCTIONS.contains(&function) => Some(EM_TWO_SOURCE),
        Class::ExtendedMath => Some(EM),
        _ if dst_type == "hf" => Some(FP16),
        _ if dst_type == "f" || dst_type == "df" => Some(FP32),
        _ => Some(INT32),
    }
}

/// The pipe an instruction issues to on `family` (`Pipes`).
fn pipe_of(i: &gen_isa::Instruction, family: &Family) -> Pipe {
    match classify(&i.mnemonic) {
        Class::Send => Pipe::Send,
        Class::Control => Pipe::Branch,
        Class::ExtendedMath => Pipe::ExtendedMath,
        _ if family.pipes != Pipes::ThreePipes => Pipe::Alu,
        // Mesa's inferred_exec_pipe: 64-bit types and dword integer multiplies on the long pipe, float
        // destinations on the float pipe, the rest on the integer pipe.
        _ if ["df", "q", "uq"].contains(&i.dst_type.as_str())
            || (["mul", "mad", "mach"].contains(&i.mnemonic.as_str())
                && ["d", "ud"].contains(&i.dst_type.as_str())) =>
        {
            Pipe::Long
        }
        _ if ["f", "hf", "bf"].contains(&i.dst_type.as_str()) => Pipe::Float,
        _ => Pipe::Int,
    }
}

/// The pipe an instruction occupies and for how many EU cycles: its execution size over its row's lanes per
/// clock, at least one cycle; None for sends, control and sync, which take one issue cycle.
pub fn occupancy(i: &gen_isa::Instruction, family: &Family) -> Result<Option<(Pipe, f64)>> {
    let Some(row) = row_of(classify(&i.mnemonic), &i.dst_type, &i.function) else { return Ok(None) };
    let lanes = rate(row, family).ok_or_else(|| anyhow!("the throughput table has no row `{row}`"))?;
    Ok(Some((pipe_of(i, family), (f64::from(i.exec_size) / f64::from(lanes)).max(1.0))))
}

/// The EU cycles per thread an instruction keeps each pipe busy (`IsaStats::pipes` sums them): its occupancy,
/// sends and branches one cycle on their own; sync and nop none. Gen9/Gen11's two FPUs (`Pipes::TwoFpus`) both
/// take FP and integer work, only FPU1 extended math: an ALU instruction's occupancy counts in full on the pair,
/// extended math half of it there besides its own.
pub fn pipe_cycles(i: &gen_isa::Instruction, family: &Family) -> Result<Vec<(Pipe, f64)>> {
    if ["sync", "nop"].contains(&i.mnemonic.as_str()) {
        return Ok(Vec::new());
    }
    let (pipe, cycles) = occupancy(i, family)?.unwrap_or((pipe_of(i, family), 1.0));
    Ok(match (family.pipes, pipe) {
        (Pipes::TwoFpus, Pipe::ExtendedMath) => vec![(pipe, cycles), (Pipe::Alu, cycles / 2.0)],
        _ => vec![(pipe, cycles)],
    })
}

/// Cycles until an instruction's result can be read, by IGC's scheduler tables (`XE_*`, `LEGACY_*`); a send's, the
/// memory load's latency or, where it reads constant data, the constant load's, as on every vendor (`sass::MEMORY`,
/// `sass::CONSTANT`).
pub fn latency(i: &gen_isa::Instruction, family: &Family) -> f64 {
    let class = classify(&i.mnemonic);
    let two_source = TWO_SOURCE_FUNCTIONS.contains(&i.function.as_str());
    if class == Class::Send {
        let v = if i.constant { &crate::nvidia::sass::CONSTANT } else { &crate::nvidia::sass::MEMORY };
        return v.cycles;
    }
    if family.legacy_latency {
        return match class {
            Class::ExtendedMath if two_source => LEGACY_MATH_TWO_SOURCE,
            Class::ExtendedMath => LEGACY_MATH,
            _ => LEGACY_PIPELINE,
        };
    }
    let scale = match i.exec_size {
        0..=8 => 0.0,
        16 => 1.0,
        _ => 3.0,
    };
    let writes_arf = i.writes.iter().any(|r| matches!(r, gen_isa::Reg::Flag(_) | gen_isa::Reg::Arf(_)));
    match class {
        Class::ExtendedMath => XE_MATH + XE_DELTA_MATH * scale,
        _ if writes_arf => XE_ARF,
        Class::Fma if i.writes.iter().any(|r| matches!(r, gen_isa::Reg::Acc(_))) => XE_FPU_ACC + XE_DELTA * scale,
        Class::Fma => XE_FPU + XE_DELTA * scale,
        _ => XE_FPU,
    }
}

/// The rate of row `row` on `family` (lanes per clock per EU).
pub fn rate(row: &str, family: &Family) -> Option<u32> {
    THROUGHPUT.iter().find(|r| r.row == row).map(|r| r.lanes_per_clock[family.column])
}

/// The u32 words of every patch token in ocloc's PTM.txt dump, by token number (a token present twice keeps
/// its first).
fn patch_tokens(ptm: &str) -> BTreeMap<u32, Vec<u32>> {
    let mut tokens: BTreeMap<u32, Vec<u32>> = BTreeMap::new();
    let mut current: Option<u32> = None;
    let mut bytes: Vec<u8> = Vec::new();
    let mut flush = |current: Option<u32>, bytes: &mut Vec<u8>| {
        if let Some(t) = current {
            let words = bytes.chunks_exact(4).map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]])).collect();
            tokens.entry(t).or_insert(words);
        }
        bytes.clear();
    };
    for line in ptm.lines().map(str::trim) {
        if let Some(t) = line.strip_prefix("4 Token ") {
            flush(current, &mut bytes);
            current = t.trim().parse().ok();
        } else if let Some(hex) = line.strip_prefix("Hex ") {
            bytes.extend(hex.split_whitespace().filter_map(|b| u8::from_str_radix(b, 16).ok()));
        } else if !line.starts_with("4 Size") {
            flush(current, &mut bytes);
            current = None;
        }
    }
    flush(current, &mut bytes);
    tokens
}

/// The kernel's ISA size in bytes (`KernelUnpaddedSize` of the kernel's binary header): the device binary
/// ocloc writes also carries the program's SPIR-V and its state heaps.
/// Bytes of an IGA instruction: 8 compacted, 16 otherwise.
fn instruction_bytes(line: &str) -> u64 {
    if line.split("//").next().is_some_and(|c| c.contains("Compacted")) { 8 } else { 16 }
}

/// Whether IGA's `listing` is the whole kernel: it reaches the thread's end (a send with EOT) and its
/// instructions fill the kernel's code (`code_bytes`, the binary's unpadded kernel size) exactly.
pub fn check_listing(listing: &str, code_bytes: Option<usize>) -> std::result::Result<(), String> {
    let lines: Vec<&str> = listing.lines().filter(|l| gen_isa::instruction(l, 32).is_some()).collect();
    if !lines.iter().any(|l| l.split("//").next().is_some_and(|c| c.contains("EOT"))) {
        return Err(format!("{} instructions and no end of thread (EOT)", lines.len()));
    }
    let listed: u64 = lines.iter().map(|l| instruction_bytes(l)).sum();
    match code_bytes {
        Some(code) if listed != code as u64 => {
            Err(format!("{} instructions of {listed} bytes, where the kernel's code holds {code} bytes", lines.len()))
        }
        _ => Ok(()),
    }
}

fn kernel_bytes(ptm: &str) -> Option<usize> {
    ptm.lines().find_map(|l| l.trim().strip_prefix("4 KernelUnpaddedSize ")?.trim().parse().ok())
}

/// IGC's patch tokens brdfprof reads (IGC's `patch_list.h`): the execution environment and the scratch space
/// of the two scratch slots.
const EXECUTION_ENVIRONMENT: u32 = 23;
const MEDIA_VFE_STATE: u32 = 18;
const MEDIA_VFE_STATE_SLOT1: u32 = 55;
/// Words of `SPatchExecutionEnvironment` after its header: LargestCompiledSIMDSize and NumGRFRequired.
const SIMD_WORD: usize = 3;
const GRF_WORD: usize = 20;

/// One kernel's binary, counted.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct IsaStats {
    pub simd: u32,
    pub grf: u32,
    /// Per-thread scratch bytes (register spills and private memory; IGC allocates them together).
    pub scratch_bytes: u32,
    pub instructions: u32,
    pub by_class: BTreeMap<Class, u32>,
    /// Lanes per `THROUGHPUT` row (None: instructions issued in one cycle each).
    pub by_row: BTreeMap<Option<&'static str>, Vec<u32>>,
    pub binary_bytes: u32,
    /// The listing's instructions with their registers (`gen_isa`).
    pub listing: Vec<gen_isa::Instruction>,
}

/// A pipe of `Pipes`, as the bound and the schedule count it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Pipe {
    /// FP and integer work: Xe-LP's one pipe, or Gen9/Gen11's two FPUs together.
    Alu,
    Float,
    Int,
    Long,
    ExtendedMath,
    Send,
    Branch,
}

impl Pipe {
    pub fn name(self, pipes: Pipes) -> &'static str {
        match (self, pipes) {
            (Pipe::Alu, Pipes::TwoFpus) => "FPU0 + FPU1 (FP, integer, extended math)",
            (Pipe::Alu, _) => "ALU (FP, integer)",
            (Pipe::Float, _) => "FP",
            (Pipe::Int, _) => "integer",
            (Pipe::Long, _) => "long (64-bit)",
            (Pipe::ExtendedMath, Pipes::TwoFpus) => "FPU1 (extended math)",
            (Pipe::ExtendedMath, _) => "extended math",
            (Pipe::Send, _) => "send",
            (Pipe::Branch, _) => "branch",
        }
    }
}

/// IGC's Xe scheduler latencies (visa/LocalScheduler/LatencyTable.h, LatenciesXe): FPU 10, FPU with an
/// accumulator destination 6, extended math 17, flag and address destinations 16, each plus its per-width
/// delta (1 and 4 cycles x 0/1/3 for SIMD8/16/32); the legacy (Gen8-11) table: every pipe 14, math 22, pow and
/// fdiv 30.
const XE_FPU: f64 = 10.0;
const XE_FPU_ACC: f64 = 6.0;
const XE_MATH: f64 = 17.0;
const XE_ARF: f64 = 16.0;
const XE_DELTA: f64 = 1.0;
const XE_DELTA_MATH: f64 = 4.0;
const LEGACY_PIPELINE: f64 = 14.0;
const LEGACY_MATH: f64 = 22.0;
const LEGACY_MATH_TWO_SOURCE: f64 = 30.0;

impl IsaStats {
    /// A kernel ocloc compiled: its patch tokens (`PTM.txt`), IGA's `listing` and the binary's size in bytes.
    pub fn of(ptm: &str, listing: &str, bytes: usize, family: &Family) -> Result<Self> {
        let tokens = patch_tokens(ptm);
        let env = tokens
            .get(&EXECUTION_ENVIRONMENT)
            .filter(|w| w.len() > GRF_WORD)
            .ok_or_else(|| anyhow!("ocloc's patch tokens carry no execution environment (SIMD width, GRF count)"))?;
        let scratch = |t: u32| tokens.get(&t).and_then(|w| w.get(1).copied()).unwrap_or(0);
        let mut s = IsaStats {
            simd: env[SIMD_WORD],
            grf: env[GRF_WORD],
            scratch_bytes: scratch(MEDIA_VFE_STATE) + scratch(MEDIA_VFE_STATE_SLOT1),
            binary_bytes: kernel_bytes(ptm).unwrap_or(bytes) as u32,
            ..Default::default()
        };
        s.count(listing, family.grf_bytes);
        if s.instructions == 0 || ![8, 16, 32].contains(&s.simd) {
            bail!(
                "IGA's listing has {} instructions and the binary says SIMD{}: not a kernel brdfprof can count",
                s.instructions,
                s.simd
            );
        }
        check_listing(listing, kernel_bytes(ptm)).map_err(|why| {
            anyhow!(
                "ocloc disasm's listing is not the kernel's code ({why}); reinstall Intel's compiler with `make setup`"
            )
        })?;
        Ok(s)
    }

    /// Another compiler's listing (brw's, `brw`) of SIMD width `simd` with `grf` registers, counted as IGC's.
    pub fn of_listing(simd: u32, grf: u32, listing: Vec<gen_isa::Instruction>) -> Self {
        let mut s = IsaStats { simd, grf, ..Default::default() };
        s.count_instructions(listing);
        s
    }

    /// Counts IGA's listing: instructions by class, and their execution sizes by `THROUGHPUT` row.
    fn count(&mut self, listing: &str, grf_bytes: u32) {
        self.count_instructions(gen_isa::instructions(listing, grf_bytes));
    }

    fn count_instructions(&mut self, listing: Vec<gen_isa::Instruction>) {
        self.listing = listing;
        for i in &self.listing {
            let class = classify(&i.mnemonic);
            self.instructions += 1;
            *self.by_class.entry(class).or_default() += 1;
            // sync waits on a scoreboard (a latency the model leaves out) and issues no work.
            if i.mnemonic != "sync" {
                self.by_row.entry(row_of(class, &i.dst_type, &i.function)).or_default().push(i.exec_size);
            }
        }
    }

    /// EU cycles of one hardware thread if no two instructions overlapped (the serial sum, reported as a column
    /// of its own): each instruction its execution size over its row's lanes per clock, at least one cycle;
    /// sends and control one issue cycle each.
    pub fn issue_cycles(&self, family: &Family) -> Result<f64> {
        let mut cycles = 0.0;
        for i in self.listing.iter().filter(|i| i.mnemonic != "sync") {
            cycles += occupancy(i, family)?.map_or(1.0, |(_, c)| c);
        }
        Ok(cycles)
    }

    /// EU cycles per thread each pipe of the family is busy (`Pipes`): every instruction its execution size
    /// over its row's lanes per clock (at least one cycle), sends and branches one cycle each on their own.
    pub fn pipes(&self, family: &Family) -> Result<Vec<(String, f64)>> {
        let mut busy: BTreeMap<Pipe, f64> = BTreeMap::new();
        for i in &self.listing {
            for (pipe, cycles) in pipe_cycles(i, family)? {
                *busy.entry(pipe).or_default() += cycles;
            }
        }
        Ok(busy.into_iter().map(|(p, c)| (p.name(family.pipes).to_string(), c)).collect())
    }

    /// One thread's cycles alone in IGC's instruction order at IGC's scheduler latencies (`gen_isa`).
    pub fn schedule_latency(&self, family: &Family) -> Result<f64> {
        gen_isa::schedule_latency(&self.listing, |i| {
            let pipe = occupancy(i, family)?.map(|(p, c)| (p as usize, c));
            Ok(gen_isa::Timing { latency: latency(i, family), pipe })
        })
    }

    /// Threads an EU holds: the family's, half of them where IGC chose more than 128 registers (large GRF).
    pub fn resident_threads(&self, family: &Family) -> u32 {
        if self.grf > 128 { family.threads / 2 } else { family.threads }
    }

    /// The statistics as driver statistics of the executable "IGC" (names lined up with `schema::driver`'s
    /// aliases, so that the gate reads registers, instructions, spills and code size as for any driver).
    pub fn driver_stats(&self, family: &Family) -> Result<Vec<Stat>> {
        let stat = |name: &str, value: f64| Stat::new(name, "", value);
        let mut out = vec![
            stat("SIMD Width", f64::from(self.simd)),
            stat("Register Count", f64::from(self.grf)),
            stat("Large GRF Mode", if self.grf > 128 { 1.0 } else { 0.0 }),
            stat("Instruction Count", f64::from(self.instructions)),
            // IGC's scratch is its spill space (and private arrays), in bytes: one statistic, not a count.
            stat("Scratch Memory Size", f64::from(self.scratch_bytes)),
            stat("Binary Size", f64::from(self.binary_bytes)),
        ];
        for c in Class::ALL {
            out.push(stat(c.name(), f64::from(self.by_class.get(&c).copied().unwrap_or(0))));
        }
        out.extend(self.rule_stats(family)?.into_iter().map(|(n, v)| stat(&n, v)));
        Ok(out)
    }

    /// The figures of the one rule (`cost::schedule`): each pipe's busy cycles, the schedule latency and the
    /// resident threads, and the old serial sum beside them.
    pub fn rule_stats(&self, family: &Family) -> Result<Vec<(String, f64)>> {
        let mut out = vec![
            ("Issue Cycles".to_string(), self.issue_cycles(family)?),
            (LATENCY.to_string(), self.schedule_latency(family)?),
            (RESIDENT_WAVES.to_string(), f64::from(self.resident_threads(family))),
        ];
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
    fn iga_lines_give_mnemonic_width_type_and_row() {
        let i = gen_isa::instruction(
            "        math.inv (32|M0)         r6.0<1>:f     r2.0<1;1,0>:f                    {F@1}",
            32,
        )
        .unwrap();
        assert_eq!((i.mnemonic.as_str(), i.exec_size, classify(&i.mnemonic)), ("math", 32, Class::ExtendedMath));
        assert_eq!(row_of(classify(&i.mnemonic), &i.dst_type, &i.function), Some(EM));
        let h = gen_isa::instruction(
            "        mad (16|M0)              r5.0<1>:hf    r1.0<1;0>:hf   r2.0<1;0>:hf   r3.0<1;0>:hf",
            32,
        )
        .unwrap();
        assert_eq!(row_of(classify(&h.mnemonic), &h.dst_type, &h.function), Some(FP16));
        let p = gen_isa::instruction(
            "        math.pow (16|M0)         r8.0<1>:f     r2.0<1;1,0>:f     r4.0<1;1,0>:f  {F@1}",
            32,
        )
        .unwrap();
        assert_eq!(row_of(classify(&p.mnemonic), &p.dst_type, &p.function), Some(EM_TWO_SOURCE));
        let s = gen_isa::instruction(
            "        sync.nop                             null                             {Compacted,$6.dst}",
            32,
        )
        .unwrap();
        assert_eq!((s.mnemonic.as_str(), s.exec_size), ("sync", 1));
    }

    #[test]
    fn pipes_follow_the_family() {
        let family = |n: &str| FAMILIES.iter().find(|f| f.name == n).unwrap();
        let i = |l: &str| gen_isa::instruction(l, 32).unwrap();
        let (fmul, imul, iadd) = (
            i("mul (16|M0) r5.0<1>:f r1.0<8;8,1>:f r2.0<8;8,1>:f"),
            i("mul (16|M0) r5.0<1>:d r1.0<8;8,1>:d r2.0<8;8,1>:d"),
            i("add (16|M0) r5.0<1>:d r1.0<8;8,1>:d r2.0<8;8,1>:d"),
        );
        assert_eq!([&fmul, &imul, &iadd].map(|x| pipe_of(x, family("xe-hpg"))), [Pipe::Float, Pipe::Long, Pipe::Int]);
        assert_eq!([&fmul, &imul, &iadd].map(|x| pipe_of(x, family("gen12lp"))), [Pipe::Alu; 3]);
        // Xe latencies: an FPU result at SIMD16 10 + 1; a SIMD16 math 17 + 4; the legacy table 14 and 22.
        let math = i("math.inv (16|M0) r6.0<1>:f r2.0<8;8,1>:f");
        assert_eq!((latency(&fmul, family("gen12lp")), latency(&math, family("gen12lp"))), (11.0, 21.0));
        assert_eq!((latency(&fmul, family("gen9")), latency(&math, family("gen9"))), (14.0, 22.0));
    }

    #[test]
    fn patch_tokens_read_simd_grf_and_scratch() {
        let ptm = "Kernel #0\nUnidentified PatchToken:\n\t4 Token 18\n\t4 Size 16\n\tHex 0 0 0 0 0 80 0 0\nUnidentified PatchToken:\n\t4 Token 23\n\t4 Size 96\n\tHex 40 0 0 0 1 0 0 0 1 0 0 0 10 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 1 0 0 0 0 0 0 0 80 0 0 0\n";
        let t = patch_tokens(ptm);
        assert_eq!(t[&23][SIMD_WORD], 16);
        assert_eq!(t[&23][GRF_WORD], 128);
        assert_eq!(t[&18][1], 0x8000);
    }
}

#[cfg(test)]
mod throughput_fixture {
    use super::*;

    /// One fixture line: the rate, where it comes from and the source's figures it is computed from.
    struct Entry {
        row: String,
        family: String,
        lanes: u32,
        basis: String,
        source: String,
        figures: String,
    }

    fn fixture() -> Vec<Entry> {
        include_str!("../../fixtures/intel-throughput.tsv")
            .lines()
            .filter(|l| !l.starts_with('#') && !l.trim().is_empty())
            .map(|l| {
                let f: Vec<&str> = l.split('\t').collect();
                assert!(
                    f.len() == 7 && !f[6].trim().is_empty(),
                    "a fixture line needs row, family, lanes, basis, source, figures and note: {l}"
                );
                Entry {
                    row: f[0].into(),
                    family: f[1].into(),
                    lanes: f[2].parse().unwrap(),
                    basis: f[3].into(),
                    source: f[4].into(),
                    figures: f[5].into(),
                }
            })
            .collect()
    }

    /// `a/b*c...` over integers, left to right, exact (a division that leaves a remainder is refused).
    fn evaluate(figures: &str) -> u32 {
        let mut value: Option<u32> = None;
        let mut op = '*';
        let mut number = String::new();
        for c in figures.chars().chain(std::iter::once('\0')) {
            if c.is_ascii_digit() {
                number.push(c);
                continue;
            }
            let n: u32 = number.parse().unwrap_or_else(|_| panic!("`{figures}`: a number expected before `{c}`"));
            number.clear();
            value = Some(match (value, op) {
                (None, _) => n,
                (Some(v), '*') => v * n,
                (Some(v), _) => {
                    assert_eq!(v % n, 0, "`{figures}` does not divide exactly");
                    v / n
                }
            });
            assert!(matches!(c, '*' | '/' | '\0'), "`{figures}`: only integers, * and /");
            op = c;
        }
        value.unwrap()
    }

    #[test]
    fn every_rate_is_the_fixtures_computed_from_its_cited_figures() {
        let rows = fixture();
        let header = include_str!("../../fixtures/intel-throughput.tsv");
        for e in &rows {
            let what = format!("{} on {}", e.row, e.family);
            assert!(
                ["stated", "derived"].contains(&e.basis.as_str()),
                "{what}: basis `{}` (a rate is the source's figure or computed from it)",
                e.basis
            );
            assert!(
                header.contains(&format!("# [{}]", e.source)),
                "{what}: source `{}` is not cited in the header",
                e.source
            );
            assert_eq!(evaluate(&e.figures), e.lanes, "{what}: the figures `{}` do not give the rate", e.figures);
            if e.basis == "stated" {
                assert!(
                    e.figures.chars().all(|c| c.is_ascii_digit()),
                    "{what}: a stated rate is the figure itself, not `{}`",
                    e.figures
                );
            }
            let column =
                COLUMNS.iter().position(|c| *c == e.family).unwrap_or_else(|| panic!("unknown family {}", e.family));
            let rate =
                THROUGHPUT.iter().find(|r| r.row == e.row).unwrap_or_else(|| panic!("the code has no row `{}`", e.row));
            assert_eq!(rate.lanes_per_clock[column], e.lanes, "{what}");
        }
        assert_eq!(rows.len(), THROUGHPUT.len() * COLUMNS.len(), "every rate of every family is in the fixture once");
        for (k, f) in FAMILIES.iter().enumerate() {
            assert_eq!((COLUMNS[f.column], f.column), (f.name, k));
        }
        assert_eq!(evaluate("256/8/2"), 16);
    }

    /// The cost model by hand: a SIMD16 thread of two mads, a math.inv, a math.pow, a send and a sync.
    #[test]
    fn issue_cycles_by_hand() {
        let listing = "        mad (16|M0)   r5.0<1>:f  r1.0<1;0>:f  r2.0<1;0>:f  r3.0<1;0>:f\n\
                       (W)     mad (16|M0)   r6.0<1>:f  r1.0<1;0>:f  r2.0<1;0>:f  r3.0<1;0>:f\n\
                               math.inv (16|M0)  r7.0<1>:f  r5.0<1;1,0>:f\n\
                               math.pow (16|M0)  r8.0<1>:f  r5.0<1;1,0>:f  r6.0<1;1,0>:f\n\
                               send.ugm (16|M0)  r9  r10  null:0  0x0  0x08200580  {$1}\n\
                               sync.nop  null  {$1.dst}\n";
        let mut s = IsaStats::default();
        s.count(listing, 32);
        assert_eq!((s.instructions, s.by_class[&Class::ExtendedMath], s.by_class[&Class::Control]), (6, 2, 1));
        let family = |n: &str| FAMILIES.iter().find(|f| f.name == n).unwrap();
        // gen9: mads 16/8 = 2 each, inv 16/2 = 8, pow 16/1 = 16, send 1.
        assert_eq!(s.issue_cycles(family("gen9")).unwrap(), 2.0 + 2.0 + 8.0 + 16.0 + 1.0);
        // gen12lp: pow at the other functions' rate, 16/2 = 8.
        assert_eq!(s.issue_cycles(family("gen12lp")).unwrap(), 2.0 + 2.0 + 8.0 + 8.0 + 1.0);
        // xe-hpc: mads 16/16 = 1, math 16/2 = 8 (IGC's model counts 8-lane passes there too).
        assert_eq!(s.issue_cycles(family("xe-hpc")).unwrap(), 1.0 + 1.0 + 8.0 + 8.0 + 1.0);
        // The pipes on gen9: the mads on either FPU (2 x 2 FPU-cycles each), the math on FPU1 (8 + 16):
        // FPU1 binds at 24; on gen12lp the ALU has 4, extended math 16.
        let pipes = |f: &str| s.pipes(family(f)).unwrap().into_iter().collect::<BTreeMap<String, f64>>();
        assert_eq!(
            (pipes("gen9")["FPU0 + FPU1 (FP, integer, extended math)"], pipes("gen9")["FPU1 (extended math)"]),
            ((8.0 + 24.0) / 2.0, 24.0)
        );
        assert_eq!(
            (pipes("gen12lp")["ALU (FP, integer)"], pipes("gen12lp")["extended math"], pipes("gen12lp")["send"]),
            (4.0, 16.0, 1.0)
        );
    }
}
