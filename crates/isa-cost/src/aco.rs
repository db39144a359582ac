//! ACO's own schedule of a kernel, instruction by instruction: with `ACO_DEBUG=perfinfo` ACO prints each program
//! after register allocation with the clocks its cycle estimator (`aco_statistics.cpp`, BlockCycleEstimator)
//! gives every instruction (dependency stalls, waits on its counters, the resource it issues to), then the
//! block-weighted totals behind its Latency and Inverse Throughput statistics (usage per resource, latency,
//! waves). The totals weigh each block by ACO's guesses (a loop 8 times, each side of a divergent branch 0.75,
//! a uniform branch 0.5); brdfprof re-adds the same per-instruction figures with every instruction once, as it
//! counts NVIDIA's and Intel's listings (`cost::schedule`): the clocks summed give the schedule latency,
//! and each instruction's class (ACO's `aco_opcodes.py`, `CLASSES` below) gives its resource usage by ACO's
//! own table (`get_perf_info`). On a kernel without branches or loops both agree with ACO's totals exactly
//! (tested).

use crate::Stat;
use anyhow::{Result, bail};

/// An instruction class of ACO's (`instr_class` in aco_opcodes.py), as far as its cost model distinguishes
/// them (`get_perf_info`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Class {
    Valu32,
    ValuFma,
    Valu64,
    ValuQuarterRate32,
    ValuTranscendental32,
    ValuDouble,
    ValuDoubleAdd,
    ValuDoubleConvert,
    ValuDoubleTranscendental,
    Salu,
    SMem,
    Branch,
    Sendmsg,
    Ds,
    Export,
    VMem,
    /// Waits, barriers and pseudo-instructions: no resource.
    Other,
}

impl Class {
    pub const ALL: [Class; 17] = [
        Class::Valu32,
        Class::ValuFma,
        Class::Valu64,
        Class::ValuQuarterRate32,
        Class::ValuTranscendental32,
        Class::ValuDouble,
        Class::ValuDoubleAdd,
        Class::ValuDoubleConvert,
        Class::ValuDoubleTranscendental,
        Class::Salu,
        Class::SMem,
        Class::Branch,
        Class::Sendmsg,
        Class::Ds,
        Class::Export,
        Class::VMem,
        Class::Other,
    ];

    /// aco_opcodes.py's name of the class.
    pub fn name(self) -> &'static str {
        match self {
            Class::Valu32 => "valu32",
            Class::ValuFma => "valu_fma",
            Class::Valu64 => "valu64",
            Class::ValuQuarterRate32 => "valu_quarter_rate32",
            Class::ValuTranscendental32 => "valu_transcendental32",
            Class::ValuDouble => "valu_double",
            Class::ValuDoubleAdd => "valu_double_add",
            Class::ValuDoubleConvert => "valu_double_convert",
            Class::ValuDoubleTranscendental => "valu_double_transcendental",
            Class::Salu => "salu",
            Class::SMem => "smem",
            Class::Branch => "branch",
            Class::Sendmsg => "sendmsg",
            Class::Ds => "ds",
            Class::Export => "exp",
            Class::VMem => "vmem",
            Class::Other => "other",
        }
    }

    /// Whether ACO issues it to the vector pipes (`is_vector`: dual-issued as two halves for wave64 on GFX10+).
    pub fn is_vector(self) -> bool {
        !matches!(self, Class::Salu | Class::SMem | Class::Branch | Class::Sendmsg | Class::Other)
    }
}

/// The opcodes whose class is not their encoding's default (aco_opcodes.py of Mesa 22.3: SOP* encodings
/// are salu, SMEM smem, VOP* valu32, MUBUF/MTBUF/MIMG/FLAT/GLOBAL/SCRATCH vmem, DS ds; these are the
/// exceptions the cost model prices differently).
const CLASSES: &[(Class, &[&str])] = &[
    (
        Class::ValuTranscendental32,
        &[
            "v_cos_f16",
            "v_cos_f32",
            "v_exp_f16",
            "v_exp_f32",
            "v_exp_legacy_f32",
            "v_log_clamp_f32",
            "v_log_f16",
            "v_log_f32",
            "v_log_legacy_f32",
            "v_rcp_clamp_f32",
            "v_rcp_f16",
            "v_rcp_f32",
            "v_rcp_iflag_f32",
            "v_rcp_legacy_f32",
            "v_rsq_clamp_f32",
            "v_rsq_f16",
            "v_rsq_f32",
            "v_rsq_legacy_f32",
            "v_sin_f16",
            "v_sin_f32",
            "v_sqrt_f16",
            "v_sqrt_f32",
        ],
    ),
    (Class::ValuQuarterRate32, &["v_mul_hi_i32", "v_mul_hi_u32", "v_mul_lo_i32", "v_mul_lo_u32"]),
    (Class::ValuFma, &["v_fma_f32", "v_fma_legacy_f16", "v_fma_legacy_f32"]),
    (
        Class::Valu64,
        &[
            "v_ashr_i64",
            "v_ashrrev_i64",
            "v_lshl_b64",
            "v_lshlrev_b64",
            "v_lshr_b64",
            "v_lshrrev_b64",
            "v_mad_i64_i32",
            "v_mad_u64_u32",
        ],
    ),
    (Class::ValuDoubleAdd, &["v_add_f64"]),
    (
        Class::ValuDoubleConvert,
        &["v_cvt_f32_f64", "v_cvt_f64_f32", "v_cvt_f64_i32", "v_cvt_f64_u32", "v_cvt_i32_f64", "v_cvt_u32_f64"],
    ),
    (Class::ValuDoubleTranscendental, &["v_rcp_clamp_f64", "v_rcp_f64", "v_rsq_clamp_f64", "v_rsq_f64", "v_sqrt_f64"]),
    (
        Class::ValuDouble,
        &[
            "v_ceil_f64",
            "v_floor_f64",
            "v_fract_f64",
            "v_frexp_exp_i32_f64",
            "v_frexp_mant_f64",
            "v_rndne_f64",
            "v_trunc_f64",
            "v_div_fmas_f64",
            "v_div_scale_f64",
            "v_fma_f64",
            "v_ldexp_f64",
            "v_max_f64",
            "v_min_f64",
            "v_mul_f64",
            "v_trig_preop_f64",
        ],
    ),
    (
        Class::Branch,
        &[
            "s_branch",
            "s_cbranch_scc0",
            "s_cbranch_scc1",
            "s_cbranch_vccz",
            "s_cbranch_vccnz",
            "s_cbranch_execz",
            "s_cbranch_execnz",
            "s_cbranch_cdbgsys",
            "s_cbranch_cdbguser",
            "s_cbranch_cdbgsys_or_user",
            "s_cbranch_cdbgsys_and_user",
            "s_trap",
            "s_setpc_b64",
            "s_swappc_b64",
            "s_rfe_b64",
            "s_cbranch_join",
            "s_cbranch_g_fork",
            "s_rfe_restore_b64",
            "s_call_b64",
            "s_cbranch_i_fork",
            "s_subvector_loop_begin",
            "s_subvector_loop_end",
        ],
    ),
    (Class::Sendmsg, &["s_sendmsg", "s_sendmsghalt"]),
    (
        Class::Other,
        &[
            "s_waitcnt",
            "s_waitcnt_vscnt",
            "s_waitcnt_vmcnt",
            "s_waitcnt_expcnt",
            "s_waitcnt_lgkmcnt",
            "s_barrier",
            "exp",
        ],
    ),
];

/// SMEM opcodes: every scalar memory access (`Format.SMEM`).
const SMEM_PREFIXES: [&str; 10] = [
    "s_load_",
    "s_buffer_",
    "s_store_",
    "s_scratch_",
    "s_atomic_",
    "s_dcache_",
    "s_memtime",
    "s_memrealtime",
    "s_atc_probe",
    "s_gl1_inv",
];
/// Vector memory encodings (MUBUF, MTBUF, MIMG, FLAT, GLOBAL, SCRATCH).
const VMEM_PREFIXES: [&str; 6] = ["buffer_", "tbuffer_", "image_", "flat_", "global_", "scratch_"];

/// The class of an ACO mnemonic.
pub fn class(mnemonic: &str) -> Class {
    if let Some((c, _)) = CLASSES.iter().find(|(_, ops)| ops.contains(&mnemonic)) {
        return if mnemonic == "exp" { Class::Export } else { *c };
    }
    if SMEM_PREFIXES.iter().any(|p| mnemonic.starts_with(p)) {
        Class::SMem
    } else if VMEM_PREFIXES.iter().any(|p| mnemonic.starts_with(p)) {
        Class::VMem
    } else if mnemonic.starts_with("ds_") || mnemonic.starts_with("lds_") {
        Class::Ds
    } else if mnemonic.starts_with("v_") {
        Class::Valu32
    } else if mnemonic.starts_with("s_") {
        Class::Salu
    } else {
        Class::Other
    }
}

/// ACO's resources (BlockCycleEstimator::resource), the pipes of the rule.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Resource {
    Scalar,
    BranchSendmsg,
    Valu,
    ValuComplex,
    Lds,
    ExportGds,
    VMem,
}

impl Resource {
    pub const ALL: [Resource; 7] = [
        Resource::Valu,
        Resource::ValuComplex,
        Resource::Scalar,
        Resource::BranchSendmsg,
        Resource::VMem,
        Resource::Lds,
        Resource::ExportGds,
    ];

    /// The pipe's name in reports, and ACO's perfinfo name of its usage.
    pub fn name(self) -> &'static str {
        match self {
            Resource::Valu => "VALU",
            Resource::ValuComplex => "VALU transcendental",
            Resource::Scalar => "SALU/SMEM",
            Resource::BranchSendmsg => "branch",
            Resource::VMem => "VMEM",
            Resource::Lds => "LDS",
            Resource::ExportGds => "export",
        }
    }

    pub fn perfinfo(self) -> &'static str {
        match self {
            Resource::Valu => "valu_usage",
            Resource::ValuComplex => "valu_complex_usage",
            Resource::Scalar => "salu_smem_usage",
            Resource::BranchSendmsg => "branch_sendmsg_usage",
            Resource::VMem => "vmem_usage",
            Resource::Lds => "lds_usage",
            Resource::ExportGds => "export_gds_usage",
        }
    }
}

/// What ACO's cost model distinguishes between families.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Arch {
    /// GFX10 (RDNA) or later: the other resource table, and wave64 vector instructions issued twice.
    pub gfx10: bool,
    /// Full-rate v_fma_f32 before GFX10 (`has_fast_fma32`: GFX9, and Tahiti, Hawaii, Carrizo).
    pub fast_fma: bool,
}

/// The resources one instruction of `class` occupies and for how many cycles (`get_perf_info` of Mesa 22.3).
pub fn usage(class: Class, arch: Arch) -> Vec<(Resource, f64)> {
    use Resource::*;
    if arch.gfx10 {
        return match class {
            Class::Valu32 | Class::ValuFma => vec![(Valu, 1.0)],
            Class::Valu64 => vec![(Valu, 2.0), (ValuComplex, 2.0)],
            Class::ValuQuarterRate32 => vec![(Valu, 4.0), (ValuComplex, 4.0)],
            Class::ValuTranscendental32 => vec![(Valu, 1.0), (ValuComplex, 4.0)],
            Class::ValuDouble | Class::ValuDoubleAdd | Class::ValuDoubleConvert | Class::ValuDoubleTranscendental => {
                vec![(Valu, 16.0), (ValuComplex, 16.0)]
            }
            Class::Salu | Class::SMem => vec![(Scalar, 1.0)],
            Class::Branch | Class::Sendmsg => vec![(BranchSendmsg, 1.0)],
            Class::Ds => vec![(Lds, 1.0)],
            Class::Export => vec![(ExportGds, 1.0)],
            Class::VMem => vec![(VMem, 1.0)],
            Class::Other => Vec::new(),
        };
    }
    let valu = |c: f64| vec![(Valu, c)];
    match class {
        Class::Valu32 => valu(4.0),
        Class::ValuFma => valu(if arch.fast_fma { 4.0 } else { 16.0 }),
        Class::Valu64 => valu(8.0),
        Class::ValuQuarterRate32 | Class::ValuTranscendental32 | Class::ValuDoubleConvert => valu(16.0),
        Class::ValuDouble | Class::ValuDoubleTranscendental => valu(64.0),
        Class::ValuDoubleAdd => valu(32.0),
        Class::Salu | Class::SMem => vec![(Scalar, 4.0)],
        Class::Branch => vec![(BranchSendmsg, 8.0)],
        Class::Ds => vec![(Lds, 4.0)],
        Class::Export => vec![(ExportGds, 16.0)],
        Class::VMem => vec![(VMem, 4.0)],
        Class::Sendmsg | Class::Other => Vec::new(),
    }
}

/// One program as perfinfo prints it: each instruction's clocks and mnemonic, and ACO's weighted totals
/// (`num_waves`, `valu_usage`, ..., `latency`) by name.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Program {
    pub instructions: Vec<(f64, String)>,
    pub totals: Vec<(String, f64)>,
}

/// The last line of a program's totals.
const LAST_TOTAL: &str = "wave64_per_cycle";

/// The programs perfinfo printed in `log` (every one ACO compiled meanwhile) and the other lines.
pub fn split(log: &str) -> (Vec<Program>, Vec<String>) {
    let (mut programs, mut rest) = (Vec::new(), Vec::new());
    let mut current: Option<Program> = None;
    for line in log.lines() {
        let inside = current.is_some();
        if line == "After RA:" || (inside && is_listing_line(line)) {
            current.get_or_insert_with(Program::default);
            if let Some((clk, mnemonic)) = instruction(line) {
                current.as_mut().expect("just set").instructions.push((clk, mnemonic));
            }
        } else if let (true, Some((name, value))) =
            (inside, line.split_once(": ").and_then(|(n, v)| Some((n, v.trim().parse::<f64>().ok()?))))
        {
            current.as_mut().expect("inside").totals.push((name.to_string(), value));
            if name == LAST_TOTAL {
                programs.extend(current.take());
            }
        } else {
            rest.push(line.to_string());
        }
    }
    (programs, rest)
}

/// Whether a line is one perfinfo prints (a program or its totals), for the programs ACO compiles outside a
/// kernel's pipeline creation (RADV's internal shaders when its device opens), which are not the user's.
pub fn is_printed_line(line: &str) -> bool {
    line == "After RA:"
        || is_listing_line(line)
        || line.split_once(": ").is_some_and(|(n, v)| TOTALS.contains(&n) && v.trim().parse::<f64>().is_ok())
}

/// The totals perfinfo prints after a program (Mesa 22.3's `collect_preasm_stats`).
const TOTALS: [&str; 12] = [
    "num_waves",
    "salu_smem_usage",
    "branch_sendmsg_usage",
    "valu_usage",
    "valu_complex_usage",
    "lds_usage",
    "export_gds_usage",
    "vmem_usage",
    "latency",
    "parallelism",
    "max_utilization",
    LAST_TOTAL,
];

/// A line of the printed program before its totals: stage, block headers, instructions, blank lines.
fn is_listing_line(line: &str) -> bool {
    line.is_empty()
        || line.starts_with("ACO shader stage:")
        || line.starts_with("BB")
        || line.starts_with("/*")
        || line.starts_with('\t')
        || line.starts_with('[')
}

/// `\t(  2 clk)   v0 = v_lshl_add_u32 ...`: the clocks and the mnemonic (the word after ` = `, or the first).
fn instruction(line: &str) -> Option<(f64, String)> {
    let rest = line.trim_start().strip_prefix('(')?;
    let (clk, code) = rest.split_once("clk)")?;
    let code = code.trim();
    let op = code.split_once(" = ").map_or(code, |(_, op)| op);
    Some((clk.trim().parse().ok()?, op.split_whitespace().next()?.to_string()))
}

/// Statistic names of the figures `read` takes from perfinfo.
pub const CLOCKS: &str = "perfinfo: clocks, every instruction once";
pub const WAVES: &str = "perfinfo: num_waves";

/// The statistics name of a class's instruction count.
pub fn count_name(class: Class) -> String {
    format!("perfinfo: {} instructions", class.name())
}

/// A `CompilerLog` for RADV with ACO_DEBUG=perfinfo: the one program compiled in this pipeline creation as
/// statistics (clocks summed, waves, instructions per class, and ACO's own weighted totals as
/// `perfinfo: weighted <name>`), and the lines that are not perfinfo's.
pub fn read(log: &str) -> Result<(Vec<Stat>, Vec<String>)> {
    let (programs, rest) = split(log);
    let program = match programs.as_slice() {
        [one] => one,
        [] => bail!("ACO printed no perfinfo program (is ACO_DEBUG=perfinfo reaching RADV?)"),
        many => bail!("ACO printed {} perfinfo programs for one pipeline", many.len()),
    };
    let stat = |name: String, value: f64| Stat { description: format!("ACO_DEBUG=perfinfo: {name}"), name, value };
    let mut stats = vec![stat(CLOCKS.into(), program.instructions.iter().map(|(c, _)| c).sum())];
    for c in Class::ALL {
        stats.push(stat(count_name(c), program.instructions.iter().filter(|(_, m)| class(m) == c).count() as f64));
    }
    for (name, value) in &program.totals {
        stats.push(stat(if name == "num_waves" { WAVES.into() } else { format!("perfinfo: weighted {name}") }, *value));
    }
    if !stats.iter().any(|s| s.name == WAVES) {
        bail!("ACO's perfinfo totals carry no num_waves");
    }
    Ok((stats, rest))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two programs as Mesa 22.3's perfinfo prints them (abridged), with a driver line between.
    const LOG: &str = "After RA:\nACO shader stage: compute_cs\nBB0\n/* logical preds: / linear preds: / kind: uniform, top-level, */\n\
\t(  1 clk)   s0 = s_mov_b32 s3\n\t(  2 clk)   s[8-11] = s_load_dwordx4 s[2-3], 0\n\t( 23 clk)   s_waitcnt lgkmcnt(0)\n\
\t(  2 clk)   v[4-7] = buffer_load_dwordx4 s[8-11], v0, 0 offen storage:buffer\n\t(321 clk)   s_waitcnt vmcnt(0)\n\
\t(  5 clk)   (precise)v5 = v_rcp_f32 v5\n\t(  2 clk)   v5, vcc = v_addc_co_u32 v7, v1, vcc\n\t(321 clk)   s_endpgm\n\n\
num_waves: 16\nsalu_smem_usage: 3.000000\nbranch_sendmsg_usage: 0.000000\nvalu_usage: 4.000000\nvalu_complex_usage: 8.000000\n\
lds_usage: 0.000000\nexport_gds_usage: 0.000000\nvmem_usage: 2.000000\nlatency: 677.000000\nparallelism: 16.000000\n\
max_utilization: 1.000000\nwave64_per_cycle: 0.023088\n\nradv: a driver message\n";

    #[test]
    fn reads_one_programs_schedule_and_passes_the_rest_on() {
        let (programs, rest) = split(LOG);
        assert_eq!(programs.len(), 1);
        assert_eq!(programs[0].instructions.len(), 8);
        assert_eq!(programs[0].instructions[5], (5.0, "v_rcp_f32".to_string()));
        assert_eq!(rest.iter().filter(|l| !l.is_empty()).collect::<Vec<_>>(), ["radv: a driver message"]);
        let (stats, _) = read(LOG).unwrap();
        let get = |n: &str| stats.iter().find(|s| s.name == n).map(|s| s.value);
        assert_eq!((get(CLOCKS), get(WAVES)), (Some(677.0), Some(16.0)));
        assert_eq!(
            (
                get(&count_name(Class::ValuTranscendental32)),
                get(&count_name(Class::Valu32)),
                get(&count_name(Class::SMem)),
                get(&count_name(Class::Other))
            ),
            (Some(1.0), Some(1.0), Some(1.0), Some(2.0))
        );
        assert_eq!(get("perfinfo: weighted valu_complex_usage"), Some(8.0));
        assert!(read(&format!("{LOG}{LOG}")).unwrap_err().to_string().contains("2 perfinfo programs"));
        assert!(read("radv: nothing\n").unwrap_err().to_string().contains("no perfinfo program"));
        assert!(LOG.lines().filter(|l| *l != "radv: a driver message").all(is_printed_line));
        assert!(!is_printed_line("radv: a driver message") && !is_printed_line("Validation Error: [ VUID-x ]"));
    }

    #[test]
    fn classes_and_costs_are_acos() {
        assert_eq!(
            [
                class("v_rcp_f32"),
                class("v_fma_f32"),
                class("v_add_f32"),
                class("s_load_dwordx4"),
                class("s_buffer_load_dword"),
                class("buffer_store_format_xyz"),
                class("global_load_dword"),
                class("s_cbranch_execz"),
                class("s_waitcnt"),
                class("s_mov_b32"),
                class("exp")
            ],
            [
                Class::ValuTranscendental32,
                Class::ValuFma,
                Class::Valu32,
                Class::SMem,
                Class::SMem,
                Class::VMem,
                Class::VMem,
                Class::Branch,
                Class::Other,
                Class::Salu,
                Class::Export
            ]
        );
        let rdna = Arch { gfx10: true, fast_fma: true };
        assert_eq!(usage(Class::ValuTranscendental32, rdna), vec![(Resource::Valu, 1.0), (Resource::ValuComplex, 4.0)]);
        let polaris = Arch { gfx10: false, fast_fma: false };
        assert_eq!(
            (usage(Class::ValuFma, polaris), usage(Class::ValuFma, Arch { fast_fma: true, ..polaris })),
            (vec![(Resource::Valu, 16.0)], vec![(Resource::Valu, 4.0)])
        );
    }
}
