//! brw's assembly listing, as Mesa's Intel compiler prints it with INTEL_DEBUG=cs (brw_disasm.c, Mesa 22.3:
//! `mad(16)  g12<1>F  g4<8,8,1>F ... { align1 1H @2 };`), read into `gen_isa`'s instructions, so that ANV's
//! kernels are priced by the very pipes, rates and latencies that price IGC's (`intel::IsaStats`): two
//! compilers under one rule.

use super::gen_isa::{Instruction, registers};
use anyhow::{Result, anyhow, bail};

/// The SIMD width and instructions of the last program in `log` (`SIMD16 shader: N instructions. ...` and the
/// blocks after it), read strictly: every line of its blocks an instruction, as many as the header states.
pub fn last_program(log: &str, grf: u32) -> Result<(u32, Vec<Instruction>)> {
    let mut program: Option<(&str, Vec<String>)> = None;
    let mut inside = false;
    for line in log.lines() {
        if line.starts_with("SIMD") && line.contains(" shader: ") {
            program = Some((line, Vec::new()));
            inside = true;
            continue;
        }
        let Some((_, lines)) = program.as_mut().filter(|_| inside) else { continue };
        let t = line.trim();
        // Blocks are apart by blank lines and labels; the next dump (NIR, another program) ends the program.
        if t.starts_with("NIR ") || t.starts_with("Native code") {
            inside = false;
        } else if t.is_empty() {
        } else if t.contains("MsgDesc:") {
            // A send's message descriptor continues the line before it.
            if let Some(last) = lines.last_mut() {
                last.push(DESCRIPTOR);
                last.push_str(t);
            }
        } else if !(t.starts_with("START B") || t.starts_with("END B") || t.ends_with(':')) {
            lines.push(line.to_string());
        }
    }
    let (header, lines) = program.ok_or_else(|| anyhow!("no `SIMDn shader:` program listing"))?;
    let number = |text: &str| text.trim().parse::<u32>().map_err(|_| anyhow!("unreadable program header `{header}`"));
    let (width, rest) = header.strip_prefix("SIMD").and_then(|r| r.split_once(" shader: ")).unwrap_or_default();
    let (width, stated) = (number(width)?, number(rest.split_once(" instructions").unwrap_or_default().0)?);
    let instructions = lines
        .iter()
        .map(|l| instruction(l, grf).ok_or_else(|| anyhow!("not an instruction brdfprof can read: `{}`", l.trim())))
        .collect::<Result<Vec<_>>>()?;
    if instructions.len() != stated as usize {
        bail!("{} instructions read where the header `{header}` states {stated}", instructions.len());
    }
    Ok((width, instructions))
}

/// Joins a send's descriptor line to its instruction line.
const DESCRIPTOR: char = '\u{1f}';

/// The control-flow mnemonics, whose operands are labels and not a destination.
const CONTROL: [&str; 12] =
    ["if", "else", "endif", "while", "break", "cont", "halt", "jmpi", "call", "ret", "goto", "join"];

/// One line of brw's listing (a send with its descriptor joined), None where it is not an instruction.
pub fn instruction(line: &str, grf: u32) -> Option<Instruction> {
    let (code, desc) = line.split_once(DESCRIPTOR).unwrap_or((line, ""));
    let code = strip_comments(code.split('{').next().unwrap_or(""));
    let mut words = code.split_whitespace().peekable();
    let mut reads = Vec::new();
    if let Some(p) = words.next_if(|w| w.starts_with('(') && w.ends_with(')')) {
        // `(+f0.0)`, `(-f1.0.any16h)`: the flag it reads.
        let flag = p.trim_matches(['(', ')']).trim_start_matches(['+', '-']);
        reads.extend(flag_register(flag, 1, grf));
    }
    let op = words.next()?;
    let (name, mut exec) = split_width(op);
    let mut function = String::new();
    if exec.is_none() {
        // `math inv(16)`, `sync nop(1)`: the function carries the width; a bare `nop` has neither.
        if let Some(f) = words.next_if(|w| w.contains('(')) {
            let (f, e) = split_width(f);
            function = f.to_string();
            exec = e;
        }
    }
    let exec_size = exec.unwrap_or(1);
    let mut parts = name.split('.');
    let mnemonic = parts.next()?.to_string();
    if mnemonic.is_empty() || !mnemonic.chars().all(|c| c.is_ascii_alphanumeric()) {
        return None;
    }
    // `cmp.ge.f0.0`, `and.nz.f0.0`: the flag the conditional modifier writes.
    let modifiers: Vec<&str> = parts.collect();
    let mut writes = Vec::new();
    if let Some(k) = modifiers.iter().position(|m| m.len() == 2 && m.starts_with('f')) {
        let flag = format!("{}.{}", modifiers[k], modifiers.get(k + 1).unwrap_or(&"0"));
        writes.extend(flag_register(&flag, exec_size, grf));
    }
    let is_send = mnemonic.starts_with("send");
    let lengths = if is_send { send_lengths(desc) } else { [None; 3] };
    let mut dst_type = String::new();
    let control = CONTROL.contains(&mnemonic.as_str());
    let operands: Vec<String> = words.filter_map(operand).collect();
    for (k, o) in operands.iter().enumerate() {
        if k == 0 && !control {
            writes.extend(registers(o, exec_size, grf, lengths[0].filter(|_| is_send), true));
            dst_type = o.rsplit_once(':').map_or(String::new(), |(_, t)| t.to_string());
        } else if k > 0 && !control {
            let length = if is_send { lengths.get(k).copied().flatten() } else { None };
            reads.extend(registers(o, exec_size, grf, length, false));
        }
    }
    let constant = is_send && reads_constant_data(desc);
    Some(Instruction { mnemonic, function, exec_size, dst_type, reads, writes, constant })
}

/// Whether a send's descriptor (`const MsgDesc: (bti 4, ...)`) reads constant data: the constant cache's
/// messages (SFID `const`: uniform blocks, the lights), LSC's transposed block loads (`ugm MsgDesc: ( load, a32,
/// d32, V16, transpose, ...`: one block for every lane, how Xe-HPG reads a uniform block), and A64 reads (`DC A64
/// untyped surface read`, LSC's `ugm MsgDesc: ( load_cmask, a64, ...`), which in brdfprof's kernels read only
/// the shader's constant data: ANV 22.3 moves a constant array indexed at run time into it
/// (`load_global_constant` in the final NIR), while the G-buffer is sampled and the output written as an image.
fn reads_constant_data(desc: &str) -> bool {
    let (sfid, message) = desc.split_once("MsgDesc:").map_or(("", ""), |(s, m)| (s.trim(), m));
    let lsc: Vec<&str> = message.trim_start().trim_start_matches('(').split(',').map(str::trim).collect();
    let lsc_load = sfid == "ugm" && lsc.first().is_some_and(|op| op.starts_with("load"));
    sfid == "const"
        || desc.contains("A64 untyped surface read")
        || (lsc_load && (lsc.contains(&"transpose") || lsc.contains(&"a64")))
}

/// `mad(16)` as ("mad", Some(16)); `math` as ("math", None).
fn split_width(word: &str) -> (&str, Option<u32>) {
    match word.split_once('(') {
        Some((name, rest)) => (name, rest.trim_end_matches(')').parse().ok()),
        None => (word, None),
    }
}

fn strip_comments(code: &str) -> String {
    let mut out = String::new();
    let mut rest = code;
    while let Some((before, after)) = rest.split_once("/*") {
        out.push_str(before);
        rest = after.split_once("*/").map_or("", |(_, a)| a);
    }
    out.push_str(rest);
    out
}

/// A flag sub-register (`f0.0`, `f1.1`) in IGA's spelling, for `registers`.
fn flag_register(flag: &str, exec: u32, grf: u32) -> Vec<super::gen_isa::Reg> {
    let mut parts = flag.split('.');
    let (Some(f), Some(sub)) = (parts.next(), parts.next()) else { return Vec::new() };
    if !f.starts_with('f') {
        return Vec::new();
    }
    registers(&format!("{f}.{sub}"), exec, grf, None, false)
}

/// A register operand in IGA's spelling (`-(abs)g39<8,8,1>F` as `r39.0<8;8,1>:f`, `g93UD` as `r93.0:ud`);
/// None for immediates and labels.
fn operand(word: &str) -> Option<String> {
    let w = word.trim_start_matches('-').trim_start_matches('~').trim_start_matches("(abs)");
    let name_end = w.find(|c: char| !c.is_ascii_alphabetic())?;
    let (name, rest) = w.split_at(name_end);
    if name.is_empty() || !rest.starts_with(|c: char| c.is_ascii_digit()) && name != "null" {
        return None;
    }
    let name = match name {
        "g" => "r",
        "JIP" | "UIP" | "LABEL" => return None,
        other => other,
    };
    let digits_end = rest.find(|c: char| !c.is_ascii_digit() && c != '.').unwrap_or(rest.len());
    let (number, tail) = rest.split_at(digits_end);
    let (region, ty) = match tail.split_once('<') {
        Some((_, r)) => r.split_once('>').map_or(("", r), |(reg, t)| (reg, t)),
        None => ("", tail),
    };
    let number = if number.contains('.') { number.to_string() } else { format!("{number}.0") };
    let region = if region.is_empty() { String::new() } else { format!("<{}>", region.replacen(',', ";", 1)) };
    Some(format!("{name}{number}{region}:{}", ty.to_ascii_lowercase()))
}

/// A send's payload lengths in registers from its descriptor: (destination, source 0, source 1), brw's
/// `mlen`, `ex_mlen`, `rlen` or the LSC messages' `dst_len`, `src0_len`, `src1_len`.
fn send_lengths(desc: &str) -> [Option<u32>; 3] {
    let words: Vec<&str> = desc.split([' ', ',', '(', ')']).filter(|w| !w.is_empty() && *w != "=").collect();
    let field = |key: &str| {
        words.iter().position(|w| *w == key).and_then(|k| words.get(k + 1)).and_then(|v| v.parse::<u32>().ok())
    };
    [
        field("rlen").or_else(|| field("dst_len")).map(|n| n.max(1)),
        field("mlen").or_else(|| field("src0_len")).map(|n| n.max(1)),
        field("ex_mlen").or_else(|| field("src1_len")).map(|n| n.max(1)),
    ]
}

#[cfg(test)]
mod tests {
    use super::super::gen_isa::Reg;
    use super::*;

    #[test]
    fn brws_operands_give_the_registers_read_and_written() {
        let m = instruction(
            "mad(16)         g6<1>F          g4<8,8,1>F      g125<8,8,1>F    g125<1,1,1>F { align1 1H @4 compacted };",
            32,
        )
        .unwrap();
        assert_eq!((m.mnemonic.as_str(), m.exec_size, m.dst_type.as_str()), ("mad", 16, "f"));
        assert_eq!(m.writes, vec![Reg::Grf(6), Reg::Grf(7)]);
        assert_eq!(m.reads[..2], [Reg::Grf(4), Reg::Grf(5)]);
        let c =
            instruction("cmp.ge.f0.0(16) null<1>F        g39<8,8,1>F     0x0F  /* 0F */  { align1 1H compacted };", 32)
                .unwrap();
        assert_eq!(
            (c.mnemonic.as_str(), c.writes.clone(), c.reads.clone()),
            ("cmp", vec![Reg::Flag(0)], vec![Reg::Grf(39), Reg::Grf(40)])
        );
        let s = instruction(
            "(+f0.0) sel(16) g49<1>F         -g47<8,8,1>F    (abs)g47<8,8,1>F     { align1 1H @5 compacted };",
            32,
        )
        .unwrap();
        assert_eq!(s.reads[0], Reg::Flag(0));
        let p = instruction("math pow(16)    g8<1>F   g2<8,8,1>F   g4<8,8,1>F  { align1 1H @2 $5 };", 32).unwrap();
        assert_eq!((p.mnemonic.as_str(), p.function.as_str(), p.exec_size), ("math", "pow", 16));
        let n =
            instruction("sync nop(1)                     null<0,1,0>UB                   { align1 WE_all 1N @3 };", 32)
                .unwrap();
        assert_eq!((n.mnemonic.as_str(), n.function.as_str(), n.writes.len()), ("sync", "nop", 0));
        assert!(instruction("LABEL1:", 32).is_none());
    }

    #[test]
    fn a_sends_descriptor_gives_its_payload_lengths() {
        let log = "NIR (final form) for compute shader:\n\tblock block_0:\n\n\
Native code for unnamed compute shader (null)\n\
SIMD16 shader: 4 instructions. 0 loops. 100 cycles. 0:0 spills:fills, 1 sends\n   START B0 (100 cycles)\n\
send(16)        g105UD          g2UD            g111UD          0x0465a002                0x00000080\n\
                            sampler MsgDesc: ld_lz SIMD16 Surface = 2 Sampler = 0 mlen 2 ex_mlen 2 rlen 6 { align1 1H @1 $0 };\n\
send(1)         g1UD            g91UD           nullUD          0x0280f500                0x00000000\n\
                            ugm MsgDesc: ( load, a32, d32, V64, transpose, L1STATE_L3MOCS dst_len = 8, src0_len = 1, src1_len = 0 flat ) base_offset 0  { align1 WE_all 1N $0 };\n\
(+f0.0) if(16)  JIP:  LABEL1          UIP:  LABEL0              { align1 1H };\n   END B0 ->B1\n\nLABEL1:\n   START B1 <-B0 (10 cycles)\n\
mul(16)         g20<1>F         g105<8,8,1>F    0x40000000F  /* 2F */ { align1 1H $0.dst };\n   END B1\n\n\
NIR (from SPIR-V) for MESA_SHADER_COMPUTE shader:\n\tmul(16) g1<1>F g2<8,8,1>F g3<8,8,1>F\n";
        let (width, is) = last_program(log, 32).unwrap();
        assert_eq!((width, is.len()), (16, 4));
        assert_eq!((is[2].mnemonic.as_str(), is[2].reads.clone(), is[2].writes.len()), ("if", vec![Reg::Flag(0)], 0));
        assert_eq!(is[0].writes, (105..111).map(Reg::Grf).collect::<Vec<_>>());
        assert_eq!(is[0].reads, [Reg::Grf(2), Reg::Grf(3), Reg::Grf(111), Reg::Grf(112)]);
        assert_eq!(is[1].writes, (1..9).map(Reg::Grf).collect::<Vec<_>>());
        assert_eq!(is[3].reads, [Reg::Grf(105), Reg::Grf(106)]);
        assert!(last_program("no program here", 32).is_err());
        // Garbage among the instructions, or a count other than the header's, is refused.
        assert!(
            last_program(&log.replace("mul(16)         g20", "??? g20"), 32).unwrap_err().to_string().contains("???")
        );
        assert!(
            last_program(&log.replace("4 instructions", "5 instructions"), 32)
                .unwrap_err()
                .to_string()
                .contains("states 5")
        );
    }

    #[test]
    fn a_send_reads_constant_data_through_the_constant_cache_or_an_a64_read() {
        let send = |desc: &str| {
            let line = format!(
                "send(16)        g118UD          g25UD           nullUD          0x02280304                0x00000000{DESCRIPTOR}{desc}"
            );
            instruction(&line, 32).unwrap()
        };
        let family = super::super::FAMILIES.iter().find(|f| f.name == "gen12lp").unwrap();
        let ubo = send(
            "const MsgDesc: (bti 4, msg_ctrl 3, msg_type 0, write_commit 0) mlen 1 ex_mlen 0 rlen 2 { align1 WE_all 1H @1 $8 };",
        );
        let table = send(
            "dp data 1 MsgDesc: (DC A64 untyped surface read, Surface = 253, SIMD16, Mask = 0xe) mlen 4 ex_mlen 0 rlen 2 { align1 1H @1 $10 };",
        );
        let gbuffer =
            send("sampler MsgDesc: ld_lz SIMD16 Surface = 2 Sampler = 0 mlen 2 ex_mlen 2 rlen 6 { align1 1H @1 $0 };");
        let block = send(
            "ugm MsgDesc: ( load, a32, d32, V16, transpose, L1STATE_L3MOCS dst_len = 2, src0_len = 1, src1_len = 0 bti ) BTI 4 base_offset 0  { align1 WE_all 1N $0 };",
        );
        let lsc_table = send(
            "ugm MsgDesc: ( load_cmask, a64, d32, x, L1STATE_L3MOCS dst_len = 2, src0_len = 4, src1_len = 0 flat ) base_offset 0  { align1 1H $1 };",
        );
        let per_lane = send(
            "ugm MsgDesc: ( load, a32, d32, V1, L1STATE_L3MOCS dst_len = 2, src0_len = 2, src1_len = 0 bti ) BTI 5 base_offset 0  { align1 1H $2 };",
        );
        let store = send(
            "ugm MsgDesc: ( store, a64, d32, V1, L1STATE_L3MOCS dst_len = 0, src0_len = 4, src1_len = 2 flat ) base_offset 0  { align1 1H $3 };",
        );
        assert!(ubo.constant && table.constant && block.constant && lsc_table.constant);
        assert!(!gbuffer.constant && !per_lane.constant && !store.constant);
        let cycles = |i: &Instruction| super::super::latency(i, family);
        assert_eq!([cycles(&ubo), cycles(&table), cycles(&gbuffer)], [30.0, 30.0, 320.0]);
    }
}
