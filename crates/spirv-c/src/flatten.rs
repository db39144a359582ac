//! Side-effect-free selections flattened into OpSelect, as Mesa's NIR does before RADV's and lavapipe's
//! backends (`nir_opt_peephole_select` with a limit of 8 instructions per side, as `radv_optimize_nir` and
//! lavapipe's `optimize` call it): an `if`/`else` (or an `if` alone) whose every side is one block of at most
//! `SIDE_LIMIT` instructions, none of which can trap, read or write memory or call, has both sides computed in
//! its header and each OpPhi of its merge block becomes an OpSelect on the branch's condition. Every value is
//! the one the branch computed (the speculated side's results are unused where it was not taken), so the
//! translation's results do not change (tested bit for bit on the host); what changes is that a value a
//! branch computed once per light (Burley's `expm1_over_t`) is now straight-line code that CSE, in spirv-opt
//! (`--redundancy-elimination`) and in the target's own compiler, computes once per invocation, as ACO's does.
//!
//! Not speculated: loads, stores, calls, image and atomic operations, integer division and remainder (a
//! zero divisor traps on the CPUs that run the translation), float-to-integer conversions (out of range, C
//! leaves them undefined), and a selection marked `[[dont_flatten]]`. A phi of a type OpSelect cannot take in
//! SPIR-V 1.0 (a struct, an array, a matrix) leaves its selection as it is.

use rspirv::dr::{Block, Function, Instruction, Module, Operand};
use rspirv::spirv::{GlslStd450Op, Op, SelectionControl, Word};

/// The most instructions a side may have to be computed speculatively: nir_opt_peephole_select's `limit` as
/// RADV calls it (`nir_opt_peephole_select, 8, true, true` in `radv_optimize_nir`).
pub const SIDE_LIMIT: usize = 8;

/// `words` with every flattenable selection flattened (repeatedly: an inner one first, then the one that
/// contains it).
pub fn flatten(words: &[u32]) -> anyhow::Result<Vec<u32>> {
    use rspirv::binary::Assemble;
    let mut module =
        rspirv::dr::load_words(words).map_err(|e| anyhow::anyhow!("rspirv cannot parse the module: {e}"))?;
    let glsl: Vec<Word> = module
        .ext_inst_imports
        .iter()
        .filter(|i| matches!(i.operands.first(), Some(Operand::LiteralString(s)) if s == "GLSL.std.450"))
        .filter_map(|i| i.result_id)
        .collect();
    let mut functions = std::mem::take(&mut module.functions);
    for f in &mut functions {
        while let Some(site) = find_site(f, &module, &glsl) {
            apply(f, &mut module, site);
        }
    }
    module.functions = functions;
    Ok(module.assemble())
}

/// A selection to flatten: its header block, condition, merge block and sides (None: the branch goes
/// straight to the merge block).
struct Site {
    header: usize,
    condition: Word,
    merge: Word,
    sides: [Option<Word>; 2],
    /// For each vector phi width, the bool vector type its splatted condition takes.
    bool_vectors: Vec<(u32, Word)>,
}

fn label(b: &Block) -> Word {
    b.label_id().unwrap_or(0)
}

fn id(i: &Instruction, k: usize) -> Word {
    match i.operands.get(k) {
        Some(Operand::IdRef(v)) => *v,
        _ => 0,
    }
}

/// The blocks each branch instruction of `f` targets, by the block that branches.
fn successors(b: &Block) -> Vec<Word> {
    let Some(t) = b.instructions.last() else { return Vec::new() };
    match t.class.opcode {
        Op::Branch => vec![id(t, 0)],
        Op::BranchConditional => vec![id(t, 1), id(t, 2)],
        Op::Switch => {
            t.operands.iter().skip(1).filter_map(|o| if let Operand::IdRef(v) = o { Some(*v) } else { None }).collect()
        }
        _ => Vec::new(),
    }
}

fn predecessors(f: &Function, block: Word) -> usize {
    f.blocks.iter().map(|b| successors(b).iter().filter(|s| **s == block).count()).sum()
}

/// The opcodes `speculatable` takes as they are: pure arithmetic, conversions, composites, comparisons and
/// logic, none of which touches memory, calls, traps or is undefined in C.
const SPECULATABLE: &[Op] = &[
    Op::Line,
    Op::NoLine,
    Op::FAdd,
    Op::FSub,
    Op::FMul,
    Op::FDiv,
    Op::FRem,
    Op::FMod,
    Op::FNegate,
    Op::IAdd,
    Op::ISub,
    Op::IMul,
    Op::SNegate,
    Op::Dot,
    Op::VectorTimesScalar,
    Op::MatrixTimesScalar,
    Op::VectorTimesMatrix,
    Op::MatrixTimesVector,
    Op::MatrixTimesMatrix,
    Op::OuterProduct,
    Op::Transpose,
    Op::ConvertSToF,
    Op::ConvertUToF,
    Op::FConvert,
    Op::UConvert,
    Op::SConvert,
    Op::Bitcast,
    Op::QuantizeToF16,
    Op::CompositeConstruct,
    Op::CompositeExtract,
    Op::CompositeInsert,
    Op::VectorShuffle,
    Op::VectorExtractDynamic,
    Op::VectorInsertDynamic,
    Op::CopyObject,
    Op::Select,
    Op::IEqual,
    Op::INotEqual,
    Op::UGreaterThan,
    Op::SGreaterThan,
    Op::UGreaterThanEqual,
    Op::SGreaterThanEqual,
    Op::ULessThan,
    Op::SLessThan,
    Op::ULessThanEqual,
    Op::SLessThanEqual,
    Op::FOrdEqual,
    Op::FUnordEqual,
    Op::FOrdNotEqual,
    Op::FUnordNotEqual,
    Op::FOrdLessThan,
    Op::FUnordLessThan,
    Op::FOrdGreaterThan,
    Op::FUnordGreaterThan,
    Op::FOrdLessThanEqual,
    Op::FUnordLessThanEqual,
    Op::FOrdGreaterThanEqual,
    Op::FUnordGreaterThanEqual,
    Op::IsNan,
    Op::IsInf,
    Op::LogicalEqual,
    Op::LogicalNotEqual,
    Op::LogicalOr,
    Op::LogicalAnd,
    Op::LogicalNot,
    Op::ShiftRightLogical,
    Op::ShiftRightArithmetic,
    Op::ShiftLeftLogical,
    Op::BitwiseOr,
    Op::BitwiseXor,
    Op::BitwiseAnd,
    Op::Not,
    Op::Any,
    Op::All,
];

/// Whether `i` may be executed where its block was not taken: no memory, no call, no trap, no undefined
/// behaviour in C.
fn speculatable(i: &Instruction, glsl: &[Word]) -> bool {
    match i.class.opcode {
        op if SPECULATABLE.contains(&op) => true,
        Op::ExtInst => {
            glsl.contains(&id(i, 0))
                && !matches!(i.operands.get(1), Some(Operand::LiteralExtInstInteger(op)) if pointer_argument(*op))
        }
        _ => false,
    }
}

/// GLSL.std.450 functions that write through a pointer or read an interpolant.
fn pointer_argument(op: u32) -> bool {
    use GlslStd450Op as G;
    [G::Modf, G::Frexp, G::InterpolateAtCentroid, G::InterpolateAtSample, G::InterpolateAtOffset]
        .iter()
        .any(|g| *g as u32 == op)
}

/// The side block `target` of a selection with header `header` merging at `merge`: its index when it is one
/// block of at most `SIDE_LIMIT` speculatable instructions that only `header` enters and that branches to
/// `merge`.
fn side(f: &Function, target: Word, merge: Word, glsl: &[Word]) -> Option<Option<usize>> {
    if target == merge {
        return Some(None);
    }
    let k = f.blocks.iter().position(|b| label(b) == target)?;
    let b = &f.blocks[k];
    let (body, last) = b.instructions.split_at(b.instructions.len().checked_sub(1)?);
    let ok = last[0].class.opcode == Op::Branch && id(&last[0], 0) == merge && predecessors(f, target) == 1;
    let counted = body.iter().filter(|i| !matches!(i.class.opcode, Op::Line | Op::NoLine)).count();
    (ok && counted <= SIDE_LIMIT && body.iter().all(|i| speculatable(i, glsl))).then_some(Some(k))
}

/// The first selection of `f` that can be flattened.
fn find_site(f: &Function, module: &Module, glsl: &[Word]) -> Option<Site> {
    (0..f.blocks.len()).find_map(|h| site_at(f, module, glsl, h))
}

fn site_at(f: &Function, module: &Module, glsl: &[Word], h: usize) -> Option<Site> {
    let ins = &f.blocks[h].instructions;
    let (merge_inst, branch) = (ins.get(ins.len().checked_sub(2)?)?, ins.last()?);
    if merge_inst.class.opcode != Op::SelectionMerge || branch.class.opcode != Op::BranchConditional {
        return None;
    }
    let control = match merge_inst.operands.get(1) {
        Some(Operand::SelectionControl(c)) => *c,
        _ => SelectionControl::NONE,
    };
    let (merge, t, e) = (id(merge_inst, 0), id(branch, 1), id(branch, 2));
    if control.contains(SelectionControl::DONT_FLATTEN) || t == e || predecessors(f, merge) != 2 {
        return None;
    }
    let sides = [side(f, t, merge, glsl)?, side(f, e, merge, glsl)?];
    let m = f.blocks.iter().find(|b| label(b) == merge)?;
    let mut bool_vectors = Vec::new();
    for phi in m.instructions.iter().filter(|i| i.class.opcode == Op::Phi) {
        match select_type(module, phi.result_type?)? {
            0 => {}
            n if bool_vectors.iter().any(|(w, _)| *w == n) => {}
            n => bool_vectors.push((n, bool_vector(module, n)?)),
        }
    }
    Some(Site {
        header: h,
        condition: id(branch, 0),
        merge,
        sides: sides.map(|s| s.map(|k| label(&f.blocks[k]))),
        bool_vectors,
    })
}

/// How OpSelect takes a value of type `ty` in SPIR-V 1.0: 0 with a scalar condition (scalars), n with a
/// splatted bool vector of n components (vectors); None if it cannot (structs, arrays, matrices; pointers,
/// which Vulkan's logical addressing selects only with VariablePointers).
fn select_type(module: &Module, ty: Word) -> Option<u32> {
    let t = module.types_global_values.iter().find(|i| i.result_id == Some(ty))?;
    match t.class.opcode {
        Op::TypeBool | Op::TypeInt | Op::TypeFloat => Some(0),
        Op::TypeVector => match t.operands.get(1) {
            Some(Operand::LiteralBit32(n)) => Some(*n),
            _ => None,
        },
        _ => None,
    }
}

/// The module's `bvecN` type, if it declares one.
fn bool_vector(module: &Module, n: u32) -> Option<Word> {
    let bool_ty = module.types_global_values.iter().find(|i| i.class.opcode == Op::TypeBool)?.result_id?;
    module
        .types_global_values
        .iter()
        .find(|i| {
            i.class.opcode == Op::TypeVector
                && id(i, 0) == bool_ty
                && matches!(i.operands.get(1), Some(Operand::LiteralBit32(k)) if *k == n)
        })
        .and_then(|i| i.result_id)
}

/// A fresh result id.
fn fresh(module: &mut Module) -> Word {
    let header = module.header.as_mut().expect("a parsed module has a header");
    header.bound += 1;
    header.bound - 1
}

/// Flattens `site`: the sides' instructions into the header, the merge block's phis into selects, the merge
/// block appended to the header when nothing else names it.
fn apply(f: &mut Function, module: &mut Module, site: Site) {
    let header_label = label(&f.blocks[site.header]);
    let mut moved = Vec::new();
    for s in site.sides.iter().flatten() {
        let k = f.blocks.iter().position(|b| label(b) == *s).expect("a side block");
        let b = f.blocks.remove(k);
        moved.extend(b.instructions.into_iter().filter(|i| i.class.opcode != Op::Branch));
    }
    let mut splats = Vec::new();
    for (n, ty) in &site.bool_vectors {
        let v = fresh(module);
        splats.push((*n, v));
        moved.push(Instruction::new(
            Op::CompositeConstruct,
            Some(*ty),
            Some(v),
            vec![Operand::IdRef(site.condition); *n as usize],
        ));
    }
    let h = f.blocks.iter().position(|b| label(b) == header_label).expect("the header");
    let ins = &mut f.blocks[h].instructions;
    ins.truncate(ins.len() - 2);
    ins.extend(moved);
    ins.push(Instruction::new(Op::Branch, None, None, vec![Operand::IdRef(site.merge)]));
    let edge = |k: usize| site.sides[k].unwrap_or(header_label);
    let (on_true, on_false) = (edge(0), edge(1));
    let m = f.blocks.iter().position(|b| label(b) == site.merge).expect("the merge block");
    for phi in f.blocks[m].instructions.iter_mut().filter(|i| i.class.opcode == Op::Phi) {
        let value = |from: Word| {
            phi.operands
                .chunks(2)
                .find(|p| p.get(1) == Some(&Operand::IdRef(from)))
                .and_then(|p| if let Operand::IdRef(v) = p[0] { Some(v) } else { None })
                .unwrap_or(0)
        };
        let (t, e) = (value(on_true), value(on_false));
        let n = select_type(module, phi.result_type.unwrap_or(0)).unwrap_or(0);
        let condition = splats.iter().find(|(w, _)| *w == n).map_or(site.condition, |(_, v)| *v);
        *phi = Instruction::new(
            Op::Select,
            phi.result_type,
            phi.result_id,
            vec![Operand::IdRef(condition), Operand::IdRef(t), Operand::IdRef(e)],
        );
    }
    join(f, header_label, site.merge);
}

/// Appends block `merge` to block `header` (which now branches only to it) when no merge or continue
/// instruction names it; its successors' phis then name `header` as the edge they come from.
fn join(f: &mut Function, header: Word, merge: Word) {
    let named = f.blocks.iter().flat_map(|b| &b.instructions).any(|i| {
        matches!(i.class.opcode, Op::SelectionMerge | Op::LoopMerge)
            && i.operands.iter().any(|o| *o == Operand::IdRef(merge))
    });
    if named || predecessors(f, merge) != 1 {
        return;
    }
    let m = f.blocks.iter().position(|b| label(b) == merge).expect("the merge block");
    let block = f.blocks.remove(m);
    let h = f.blocks.iter().position(|b| label(b) == header).expect("the header");
    f.blocks[h].instructions.pop();
    f.blocks[h].instructions.extend(block.instructions);
    for i in f.blocks.iter_mut().flat_map(|b| b.instructions.iter_mut()).filter(|i| i.class.opcode == Op::Phi) {
        for (k, o) in i.operands.iter_mut().enumerate() {
            if k % 2 == 1 && *o == Operand::IdRef(merge) {
                *o = Operand::IdRef(header);
            }
        }
    }
}
