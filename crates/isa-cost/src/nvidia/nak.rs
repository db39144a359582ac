//! NAK's assembly (Mesa's NVK compiler, `NAK_DEBUG=print`) read as SASS instructions with the control bits NAK
//! encodes, so that ptxas' SASS and NAK's code are priced by one rule (`nvidia::SassStats`).

use super::sass;
use anyhow::{Result, anyhow, bail};

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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::nvidia::{FAMILIES, SassStats};

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
        let sm86 = FAMILIES.iter().find(|f| f.name == "sm_86").unwrap();
        let s = SassStats::of_instructions(&is, sm86);
        let pipes = s.pipes(sm86).unwrap();
        let pipe = |n: &str| pipes.iter().find(|p| p.0 == n).map(|p| p.1);
        assert_eq!((pipe("FMA"), pipe("XU (MUFU, conversions)")), (Some(0.5), Some(2.0)));
        // S2R at 0 (scoreboard 0 at 21), LDC at 1 (scoreboard 1 at 31), the first FFMA waits for both (31),
        // then 6, 6, 1: the load at 44 (scoreboard 4 at 364); EXIT waits for 2 and 4 at 364, then 5.
        assert_eq!(s.schedule_latency, 364.0 + 5.0);
        assert!(instructions("   r0 = ffma r1 r2 r3 // delay=6 wr:7\n").unwrap_err().to_string().contains("6"));
        assert!(instructions("   R0 = FFMA r1\n").is_err());
    }
}
