//! IGA's listing of an Intel GPU kernel as IGC scheduled it: each instruction with the registers it reads and
//! writes, so that one hardware thread's schedule latency can be played through in IGC's instruction order
//! at the latencies of IGC's own scheduler (`visa/LocalScheduler/LatencyTable.h` and `.cpp`: the Gen9/Gen11
//! "legacy" table and the Xe table), and each pipe's busy cycles summed.
//!
//! Dependencies are the registers themselves (what Gen9/Gen11's scoreboard tracks; on Gen12 and later the
//! SWSB annotations IGC writes encode the same dependencies): an instruction starts once the results it reads
//! or overwrites are ready, one cycle after its predecessor, and once its pipe is free. Memory results take
//! `sass::MEMORY`'s latency, the one figure brdfprof uses for every vendor's memory loads.

use anyhow::Result;

/// A register file an operand lives in, with the unit the dependency tracking uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Reg {
    /// A general register (by number).
    Grf(u32),
    /// An accumulator (acc0, acc2, ...).
    Acc(u32),
    /// A flag sub-register (f0.0 = 0, f0.1 = 1, f1.0 = 2, ...).
    Flag(u32),
    /// The address register and other architecture registers (one unit each by name).
    Arf(u32),
}

/// One instruction of the listing.
#[derive(Clone, Debug, PartialEq)]
pub struct Instruction {
    pub mnemonic: String,
    /// What follows the mnemonic's first `.` (`math.pow`: `pow`), empty if nothing.
    pub function: String,
    pub exec_size: u32,
    /// The destination's type (`f`, `hf`, `d`, ...), empty where it has none.
    pub dst_type: String,
    pub reads: Vec<Reg>,
    pub writes: Vec<Reg>,
    /// A send that reads constant data, which every invocation reads and the cache holds: priced at the rule's
    /// constant-load latency, not a memory load's (`intel::latency`). Only brw's listing names it (`brw`); IGA's
    /// data-cache sends do not say what they read, so IGC's are all memory loads.
    pub constant: bool,
}

/// Bytes of a type.
fn type_bytes(t: &str) -> u32 {
    match t {
        "b" | "ub" => 1,
        "w" | "uw" | "hf" | "bf" => 2,
        "q" | "uq" | "df" => 8,
        _ => 4,
    }
}

/// The registers an operand covers: a general register's bytes from its sub-register over its region for
/// `exec` channels (`grf` bytes a register), or `length` whole registers for a send's payload; accumulators,
/// flags and others as one unit each (a SIMD32 flag two).
pub(super) fn registers(operand: &str, exec: u32, grf: u32, length: Option<u32>, dst: bool) -> Vec<Reg> {
    let o = operand.trim_start_matches(['-', '~']).trim_start_matches("(abs)");
    let (name, rest) = o.split_at(o.find(|c: char| !c.is_ascii_alphabetic()).unwrap_or(o.len()));
    let number: u32 = rest.split(|c: char| !c.is_ascii_digit()).next().and_then(|n| n.parse().ok()).unwrap_or(0);
    let sub: u32 = rest
        .split_once('.')
        .and_then(|(_, s)| s.split(|c: char| !c.is_ascii_digit()).next()?.parse().ok())
        .unwrap_or(0);
    let ty = o.rsplit_once(':').map_or("ud", |(_, t)| t);
    let size = type_bytes(ty);
    match name {
        "r" => {
            let span = match length {
                Some(n) => n.max(1) * grf,
                None => region_bytes(o, exec, size, dst),
            };
            let start = number * grf + sub * size;
            (start / grf..=(start + span - 1) / grf).map(Reg::Grf).collect()
        }
        "acc" => vec![Reg::Acc(number)],
        "f" => (0..if exec > 16 { 2 } else { 1 }).map(|k| Reg::Flag(number * 2 + sub + k)).collect(),
        "null" | "" => Vec::new(),
        other => vec![Reg::Arf(other.bytes().fold(number, |h, b| h.wrapping_mul(31).wrapping_add(u32::from(b))))],
    }
}

/// Bytes an operand's region spans: `<H>` (destination), `<V;W,H>` or the ternary `<V;H>` (sources).
fn region_bytes(operand: &str, exec: u32, size: u32, dst: bool) -> u32 {
    let region = operand.split_once('<').and_then(|(_, r)| r.split_once('>')).map_or("1", |(r, _)| r);
    let nums: Vec<u32> = region.split([';', ',']).filter_map(|n| n.trim().parse().ok()).collect();
    let last = match (dst, nums.as_slice()) {
        (true, [h, ..]) => (exec - 1) * h,
        (_, [v, w, h]) if *w > 0 => (exec / w).max(1).saturating_sub(1) * v + (w - 1) * h,
        (_, [v, h]) => (exec - 1) * if *h > 0 { *h } else { (*v).min(1) },
        (_, [h]) => (exec - 1) * h,
        _ => 0,
    };
    last * size + size
}

/// A send's payload lengths from IGA's comment (`wr:2+0, rd:6`; `1h` is half a register): (src0, src1, dst).
fn send_lengths(comment: &str) -> (Option<u32>, Option<u32>, Option<u32>) {
    let number = |s: &str| s.trim().trim_end_matches('h').parse::<u32>().ok().map(|n| n.max(1));
    let field = |key: &str| comment.split(|c| c == ',' || c == ';').find_map(|f| f.trim().strip_prefix(key));
    let (src0, src1) =
        field("wr:").and_then(|w| w.split_once('+')).map_or((None, None), |(a, b)| (number(a), number(b)));
    (src0, src1, field("rd:").and_then(number))
}

/// Parses one line of IGA's listing (`(W&f0.0) sel (16|M0) (lt)f1.0 r39.0<1>:f r4.1<0;1,0>:f 1.0:f`); None
/// for labels, comments and blank lines. `grf` is the family's register size in bytes.
pub fn instruction(line: &str, grf: u32) -> Option<Instruction> {
    let (code, comment) = line.split_once("//").unwrap_or((line, ""));
    let code = code.split('{').next()?.trim();
    if code.is_empty() || code.ends_with(':') {
        return None;
    }
    let mut words = code.split_whitespace().peekable();
    let mut reads = Vec::new();
    if let Some(predicate) = words.next_if(|w| w.starts_with('(')) {
        if let Some(f) =
            predicate.trim_matches(['(', ')']).split('&').find(|p| p.trim_start_matches('~').starts_with('f'))
        {
            reads.extend(registers(f.trim_start_matches('~'), 1, grf, None, false));
        }
    }
    let op = words.next()?;
    let (mnemonic, function) = op.split_once('.').map_or((op, ""), |(m, f)| (m, f.split('.').next().unwrap_or(f)));
    if mnemonic.is_empty() || !mnemonic.chars().all(|c| c.is_ascii_alphanumeric()) {
        return None;
    }
    let exec_size = words
        .next_if(|w| w.starts_with('(') && w.contains('|'))
        .and_then(|w| w.trim_start_matches('(').split('|').next()?.parse().ok())
        .unwrap_or(1);
    let mut writes = Vec::new();
    if let Some(cond) = words.next_if(|w| w.starts_with('(') && w.contains(")f")) {
        writes.extend(registers(cond.split_once(')').map_or("", |(_, f)| f), exec_size, grf, None, true));
    }
    let operands: Vec<&str> = words
        .filter(|w| w.starts_with(['r', 'a', 'f', 'n', 'c', 's', 't', '-', '~', '(']) && !w.starts_with("0x"))
        .collect();
    let is_send = mnemonic.starts_with("send");
    let (src0, src1, dst_len) = if is_send { send_lengths(comment) } else { (None, None, None) };
    let mut dst_type = String::new();
    for (k, o) in operands.iter().enumerate() {
        if k == 0
            && ![
                "if", "else", "endif", "while", "jmpi", "goto", "join", "break", "cont", "call", "ret", "halt", "brd",
                "brc", "nop",
            ]
            .contains(&mnemonic)
        {
            writes.extend(registers(o, exec_size, grf, dst_len.filter(|_| is_send), true));
            dst_type = o.rsplit_once(':').map_or(String::new(), |(_, t)| t.to_string());
        } else if k > 0 {
            let length = if is_send { if k == 1 { src0 } else { src1 } } else { None };
            reads.extend(registers(o, exec_size, grf, length.filter(|_| is_send), false));
        }
    }
    Some(Instruction {
        mnemonic: mnemonic.into(),
        function: function.into(),
        exec_size,
        dst_type,
        reads,
        writes,
        constant: false,
    })
}

/// Every instruction of a listing.
pub fn instructions(listing: &str, grf: u32) -> Vec<Instruction> {
    listing.lines().filter_map(|l| instruction(l, grf)).collect()
}

/// Every instruction of IGC's own listing (its shader dump, compiled with `-g`) with the source file and line
/// its `// File: F` and `// Line N` comments name; None before the first.
pub fn sourced_instructions(listing: &str, grf: u32) -> Vec<(Instruction, Option<(String, u32)>)> {
    let mut file: Option<String> = None;
    let mut line: Option<u32> = None;
    let mut out = Vec::new();
    for l in listing.lines() {
        let t = l.trim();
        if let Some(f) = t.strip_prefix("// File: ") {
            file = Some(f.trim().to_string());
        } else if let Some(n) = t.strip_prefix("// Line ") {
            line = n.split(|c: char| !c.is_ascii_digit()).next().and_then(|n| n.parse().ok());
        } else if let Some(i) = instruction(l, grf) {
            out.push((i, file.clone().zip(line)));
        }
    }
    out
}

/// Where an instruction's result takes a latency and a pipe occupancy in the schedule.
pub struct Timing {
    /// Cycles from its start until its result can be read.
    pub latency: f64,
    /// The pipe it occupies (an index the caller chose) and for how long; None: no pipe but the issue.
    pub pipe: Option<(usize, f64)>,
}

/// One hardware thread's cycles through `instructions` alone: each starts one cycle after its predecessor
/// at the earliest, once the registers it reads or writes are ready and its pipe is free (`timing` gives
/// both); the thread ends when its last instruction (the end-of-thread send) issues.
pub fn schedule_latency(instructions: &[Instruction], timing: impl Fn(&Instruction) -> Result<Timing>) -> Result<f64> {
    Ok(issue_times(instructions, timing)?.last().copied().unwrap_or(0.0))
}

/// The cycle each instruction starts at in `schedule_latency`'s schedule, and after them the cycle the
/// thread ends.
pub fn issue_times(instructions: &[Instruction], timing: impl Fn(&Instruction) -> Result<Timing>) -> Result<Vec<f64>> {
    let mut times = Vec::with_capacity(instructions.len() + 1);
    let mut ready: std::collections::HashMap<Reg, f64> = std::collections::HashMap::new();
    let mut pipe_free: Vec<f64> = Vec::new();
    let mut t = -1.0f64;
    for i in instructions {
        let tm = timing(i)?;
        let mut start = t + 1.0;
        for r in i.reads.iter().chain(&i.writes) {
            start = start.max(ready.get(r).copied().unwrap_or(0.0));
        }
        if let Some((p, busy)) = tm.pipe {
            if pipe_free.len() <= p {
                pipe_free.resize(p + 1, 0.0);
            }
            start = start.max(pipe_free[p]);
            pipe_free[p] = start + busy;
        }
        for r in &i.writes {
            ready.insert(*r, start + tm.latency);
        }
        times.push(start);
        t = start;
    }
    times.push(t + 1.0);
    Ok(times)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn operands_give_the_registers_read_and_written() {
        let i =
            instruction("(W&f0.0)  sel (16|M0)   (lt)f1.0   r39.0<1>:f    r4.1<0;1,0>:f     1.0:f   {Compacted}", 32)
                .unwrap();
        assert_eq!((i.mnemonic.as_str(), i.exec_size, i.dst_type.as_str()), ("sel", 16, "f"));
        assert_eq!(i.reads, vec![Reg::Flag(0), Reg::Grf(4)]);
        assert_eq!(i.writes, vec![Reg::Flag(2), Reg::Grf(39), Reg::Grf(40)]);
        let m = instruction(
            "        mad (16|M0)   acc0.0<1>:f   acc0.0<8;1>:f     r28.0<8;1>:f      r28.0<1>:f       {@6}",
            32,
        )
        .unwrap();
        assert_eq!(m.writes, vec![Reg::Acc(0)]);
        assert_eq!(m.reads, vec![Reg::Acc(0), Reg::Grf(28), Reg::Grf(29), Reg::Grf(28), Reg::Grf(29)]);
        let s = instruction("        send.dc1 (16|M0)         r10      r2      null    0x0            0x04605800           {@2,$0} // wr:2+0, rd:6; untyped surface read with xyz", 32).unwrap();
        assert_eq!(s.writes, (10..16).map(Reg::Grf).collect::<Vec<_>>());
        assert_eq!(s.reads, vec![Reg::Grf(2), Reg::Grf(3)]);
        let p =
            instruction("        math.pow (16|M0)         r8.0<1>:f     r2.0<1;1,0>:f     r4.0<1;1,0>:f  {F@1}", 32)
                .unwrap();
        assert_eq!((p.mnemonic.as_str(), p.function.as_str()), ("math", "pow"));
        assert!(instruction("L640:", 32).is_none() && instruction("// a comment", 32).is_none());
        let c =
            instruction("(f0.0)  if (32|M0)                           L944                  L992                ", 32)
                .unwrap();
        assert_eq!((c.reads.clone(), c.writes.clone()), (vec![Reg::Flag(0)], vec![]));
    }

    #[test]
    fn the_thread_waits_for_what_it_reads_and_for_its_pipe() {
        let is = instructions(
            "        send.dc1 (16|M0)  r10  r2  null  0x0  0x04605800  // wr:2+0, rd:2\n\
                     mul (16|M0)  r20.0<1>:f  r10.0<8;8,1>:f  2.0:f\n\
                     mul (16|M0)  r30.0<1>:f  r40.0<8;8,1>:f  2.0:f\n\
                     add (16|M0)  r22.0<1>:f  r20.0<8;8,1>:f  r30.0<8;8,1>:f\n",
            32,
        );
        let timing = |i: &Instruction| {
            Ok(if i.mnemonic == "send" {
                Timing { latency: 320.0, pipe: None }
            } else {
                Timing { latency: 10.0, pipe: Some((0, 2.0)) }
            })
        };
        // send at 0; the first mul waits for r10 (320); the second for the pipe (322); add for r30 (332).
        assert_eq!(schedule_latency(&is, timing).unwrap(), 333.0);
        assert_eq!(issue_times(&is, timing).unwrap(), [0.0, 320.0, 322.0, 332.0, 333.0]);
    }

    #[test]
    fn igcs_file_and_line_comments_name_the_instructions_after_them() {
        let listing = "(W)     mov (8|M0)  r59.0<1>:ud  r0.0<1;1,0>:ud  // $1\n// File: /tmp/a.brdf\n// Line 20\n        shl (16|M0)  r64.0<1>:d  r64.0<8;8,1>:d  2:w  // $18\n// Line 11\n        math.exp (16|M0)  r60.0<1>:f  r108.0<8;8,1>:f  {$1}  // $28\n";
        let got: Vec<(String, Option<(String, u32)>)> =
            sourced_instructions(listing, 32).into_iter().map(|(i, s)| (i.mnemonic, s)).collect();
        let a = |n| Some(("/tmp/a.brdf".to_string(), n));
        assert_eq!(got, [("mov".to_string(), None), ("shl".to_string(), a(20)), ("math".to_string(), a(11))]);
    }
}
