//! A module's loops at a fixed count of passes: each loop's exit tests read a pass counter instead of their own
//! condition, so every compiler knows the trip count and makes the code it makes for a loop of that length
//! (unrolled, in practice, for the 2 and 3 passes `targets::trips` asks for). The kernel computes something
//! else then: it is compiled for its cost, never run for its results.

use anyhow::{Result, anyhow, bail};
use rspirv::dr::{Block, Instruction, Module, Operand};
use rspirv::spirv::{Op, Word};

/// `words` with every loop running `passes` header passes per entry (its exit tests: `counter < passes - 1`, the
/// counter the header's pass, from 0), and the number of loops set. `unroll` marks each loop Unroll, for
/// spirv-opt's `--loop-unroll` to write out (a module that keeps its loops is left unmarked: spirv-opt's
/// preparations for the host translation would unroll them).
pub fn at_passes(words: &[u32], passes: u32, unroll: bool) -> Result<(Vec<u32>, usize)> {
    if passes == 0 {
        bail!("a loop runs its header at least once per entry");
    }
    let mut module = rspirv::dr::load_words(words).map_err(|e| anyhow!("rspirv cannot parse the module: {e}"))?;
    let header = module.header.as_mut().ok_or_else(|| anyhow!("the module has no header"))?;
    let mut next = header.bound;
    let mut fresh = || {
        next += 1;
        next - 1
    };
    let (uint, boolean) =
        (scalar_type(&mut module, Op::TypeInt, &mut fresh), scalar_type(&mut module, Op::TypeBool, &mut fresh));
    let mut constant = |value: u32| {
        let id = fresh();
        module.types_global_values.push(Instruction::new(
            Op::Constant,
            Some(uint),
            Some(id),
            vec![Operand::LiteralBit32(value)],
        ));
        id
    };
    let (zero, one, last) = (constant(0), constant(1), constant(passes - 1));
    let mut set = 0;
    for function in &mut module.functions {
        let headers: Vec<(usize, Word)> =
            function.blocks.iter().enumerate().filter_map(|(k, b)| loop_merge(b).map(|merge| (k, merge))).collect();
        for (at, merge) in headers {
            set_loop(&mut function.blocks, at, merge, Ids { uint, boolean, zero, one, last }, &mut fresh)?;
            if unroll {
                let control = function.blocks[at].instructions.iter_mut().find(|i| i.class.opcode == Op::LoopMerge);
                let merge = control.expect("a loop header");
                // Unroll takes no literal: a control's parameters (DependencyLength, ...) go with it.
                merge.operands.truncate(2);
                merge.operands.push(Operand::LoopControl(rspirv::spirv::LoopControl::UNROLL));
            }
            set += 1;
        }
    }
    module.header.as_mut().expect("checked above").bound = next;
    Ok((rspirv::binary::Assemble::assemble(&module), set))
}

/// The loops of a module.
pub fn count(words: &[u32]) -> Result<usize> {
    let module = rspirv::dr::load_words(words).map_err(|e| anyhow!("rspirv cannot parse the module: {e}"))?;
    Ok(module.functions.iter().flat_map(|f| &f.blocks).filter(|b| loop_merge(b).is_some()).count())
}

/// The ids a loop's counter uses.
#[derive(Clone, Copy)]
struct Ids {
    uint: Word,
    boolean: Word,
    zero: Word,
    one: Word,
    last: Word,
}

/// The merge block of a loop header.
fn loop_merge(block: &Block) -> Option<Word> {
    let merge = block.instructions.iter().find(|i| i.class.opcode == Op::LoopMerge)?;
    match merge.operands.first() {
        Some(Operand::IdRef(id)) => Some(*id),
        _ => None,
    }
}

/// The blocks a block's terminator branches to.
fn successors(block: &Block) -> Vec<Word> {
    let Some(last) = block.instructions.last() else { return Vec::new() };
    let ids = last.operands.iter().filter_map(|o| if let Operand::IdRef(id) = o { Some(*id) } else { None });
    match last.class.opcode {
        Op::Branch => ids.collect(),
        Op::BranchConditional => ids.skip(1).collect(),
        Op::Switch => ids.skip(1).collect(),
        _ => Vec::new(),
    }
}

/// The loop headed by `blocks[at]` counts its passes (a phi from 0, one more on each back edge) and leaves where
/// any of its exit tests (a conditional branch to `merge`) finds the count at `last`. Structured blocks come in
/// dominance order: a predecessor after the header is a back edge.
fn set_loop(blocks: &mut [Block], at: usize, merge: Word, ids: Ids, fresh: &mut impl FnMut() -> Word) -> Result<()> {
    let header = blocks[at].label_id().ok_or_else(|| anyhow!("a block without a label"))?;
    let counter = fresh();
    let mut phi = Vec::new();
    let mut exits = 0;
    for k in 0..blocks.len() {
        let label = blocks[k].label_id().ok_or_else(|| anyhow!("a block without a label"))?;
        if successors(&blocks[k]).contains(&header) {
            let value = if k < at {
                ids.zero
            } else {
                add_before_end(&mut blocks[k], Op::IAdd, ids.uint, counter, ids.one, fresh)
            };
            phi.extend([Operand::IdRef(value), Operand::IdRef(label)]);
        }
        let Some(end) = blocks[k].instructions.last() else { continue };
        if end.class.opcode != Op::BranchConditional {
            continue;
        }
        let leaves_when = match end.operands.as_slice() {
            [_, Operand::IdRef(t), Operand::IdRef(f), ..] if *t == merge => true,
            [_, Operand::IdRef(_), Operand::IdRef(f), ..] if *f == merge => false,
            _ => continue,
        };
        let test = if leaves_when { Op::UGreaterThanEqual } else { Op::ULessThan };
        let cond = add_before_end(&mut blocks[k], test, ids.boolean, counter, ids.last, fresh);
        let end = blocks[k].instructions.last_mut().expect("a terminator");
        end.operands[0] = Operand::IdRef(cond);
        exits += 1;
    }
    if exits == 0 {
        bail!("a loop (header %{header}) leaves only through a switch or a nested branch: its passes cannot be set");
    }
    let phi = Instruction::new(Op::Phi, Some(ids.uint), Some(counter), phi);
    let first = blocks[at].instructions.iter().take_while(|i| i.class.opcode == Op::Phi).count();
    blocks[at].instructions.insert(first, phi);
    Ok(())
}

/// `result = op(a, b)` of `ty`, placed before the block's terminator (and a merge instruction before it).
fn add_before_end(block: &mut Block, op: Op, ty: Word, a: Word, b: Word, fresh: &mut impl FnMut() -> Word) -> Word {
    let id = fresh();
    let n = block.instructions.len();
    let merges = |i: &Instruction| matches!(i.class.opcode, Op::LoopMerge | Op::SelectionMerge);
    let at = if n >= 2 && merges(&block.instructions[n - 2]) { n - 2 } else { n - 1 };
    block.instructions.insert(at, Instruction::new(op, Some(ty), Some(id), vec![Operand::IdRef(a), Operand::IdRef(b)]));
    id
}

/// The module's 32-bit unsigned integer (`Op::TypeInt`) or boolean type, declared if it has none.
fn scalar_type(module: &mut Module, op: Op, fresh: &mut impl FnMut() -> Word) -> Word {
    let operands =
        if op == Op::TypeInt { vec![Operand::LiteralBit32(32), Operand::LiteralBit32(0)] } else { Vec::new() };
    let found = module.types_global_values.iter().find(|i| i.class.opcode == op && i.operands == operands);
    if let Some(id) = found.and_then(|i| i.result_id) {
        return id;
    }
    let id = fresh();
    module.types_global_values.push(Instruction::new(op, None, Some(id), operands));
    id
}
