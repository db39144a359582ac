//! Module-level constants as C expressions: literals that convert back to the same bits, composites through
//! their `mk_` constructors, and the OpSpecConstantOp forms spirv-opt leaves unfolded after freezing.

use super::TranslateError;
use super::ctypes::Scalar;
use super::module::{Constant, ModuleInfo};
use rspirv::spirv::{Op, Word};

/// A C literal of the scalar `bits` of type `s` that the C compiler reads back exactly.
pub fn literal(s: Scalar, bits: u64) -> String {
    match s {
        Scalar::Bool => (if bits != 0 { "true" } else { "false" }).into(),
        Scalar::U32 => format!("{}u", bits as u32),
        Scalar::I32 => match bits as u32 as i32 {
            i32::MIN => "(-2147483647 - 1)".into(),
            v if v < 0 => format!("({v})"),
            v => v.to_string(),
        },
        Scalar::F16 => format!("h_from_bits({}u)", bits as u16),
        Scalar::F32 => {
            let x = f32::from_bits(bits as u32);
            // Rust's shortest representation converts back to the same float under correct rounding.
            if x.is_finite() { format!("{x:?}f") } else { format!("f32_from_bits({}u)", bits as u32) }
        }
        Scalar::F64 => {
            let x = f64::from_bits(bits);
            if x.is_finite() { format!("{x:?}") } else { format!("f64_from_bits({bits}ull)") }
        }
    }
}

/// The C expression of constant `id`.
pub fn expr(m: &ModuleInfo, id: Word) -> Result<String, TranslateError> {
    match m.constants.get(&id) {
        Some(Constant::Scalar { ty, bits }) => Ok(literal(m.scalar(*ty)?, *bits)),
        Some(Constant::Bool { value, .. }) => Ok(value.to_string()),
        Some(Constant::Composite { parts, .. }) if parts.len() as u32 > super::ctypes::MAX_CONSTRUCTOR_MEMBERS => {
            Ok(format!("k_{id}()"))
        }
        Some(Constant::Composite { ty, parts }) => {
            let parts = parts.iter().map(|p| expr(m, *p)).collect::<Result<Vec<_>, _>>()?;
            Ok(format!("mk_{}({})", m.c_type(*ty)?, parts.join(", ")))
        }
        Some(Constant::Zero { ty }) => m.zero(*ty),
        Some(Constant::Op { ty, op, operands, literals }) => spec_op(m, *ty, *op, operands, literals),
        None => Err(TranslateError::new(format!("a reference to constant %{id}, which the module does not define"))),
    }
}

/// An OpSpecConstantOp on frozen operands (scalars: the forms glslang emits for conversions and selectors).
fn spec_op(m: &ModuleInfo, ty: Word, op: Op, operands: &[Word], literals: &[u32]) -> Result<String, TranslateError> {
    let a = |k: usize| expr(m, operands.get(k).copied().unwrap_or(0));
    let to = m.scalar(m.scalar_of(ty))?;
    if m.components(ty) != 1 {
        if op == Op::CompositeExtract || op == Op::VectorShuffle {
            return Err(TranslateError::new(format!("a vector-valued OpSpecConstantOp {op:?}")));
        }
    }
    Ok(match op {
        Op::FConvert => {
            let from = m.scalar(m.scalar_of(m.type_of(operands[0]).unwrap_or(0)))?;
            convert_float(from, to, &a(0)?)
        }
        Op::IAdd => format!("({} + {})", a(0)?, a(1)?),
        Op::ISub => format!("({} - {})", a(0)?, a(1)?),
        Op::IMul => format!("({} * {})", a(0)?, a(1)?),
        Op::SNegate => format!("(-{})", a(0)?),
        Op::Select => format!("({} ? {} : {})", a(0)?, a(1)?, a(2)?),
        Op::IEqual | Op::LogicalEqual => format!("({} == {})", a(0)?, a(1)?),
        Op::INotEqual | Op::LogicalNotEqual => format!("({} != {})", a(0)?, a(1)?),
        Op::LogicalAnd => format!("({} && {})", a(0)?, a(1)?),
        Op::LogicalOr => format!("({} || {})", a(0)?, a(1)?),
        Op::LogicalNot => format!("(!{})", a(0)?),
        Op::SLessThan | Op::ULessThan => format!("({} < {})", a(0)?, a(1)?),
        Op::SGreaterThan | Op::UGreaterThan => format!("({} > {})", a(0)?, a(1)?),
        Op::CompositeExtract => {
            let mut e = a(0)?;
            for l in literals {
                e = format!("({e}).c[{l}]");
            }
            e
        }
        other => return Err(TranslateError::new(format!("the specialisation-constant operation {other:?}"))),
    })
}

/// A float converted between widths.
pub fn convert_float(from: Scalar, to: Scalar, e: &str) -> String {
    match (from, to) {
        (a, b) if a == b => e.to_string(),
        (Scalar::F16, Scalar::F32) => format!("h_to_f32({e})"),
        (Scalar::F16, _) => format!("(double)h_to_f32({e})"),
        (_, Scalar::F16) => format!("h_from_f32((float)({e}))"),
        (_, Scalar::F32) => format!("(float)({e})"),
        _ => format!("(double)({e})"),
    }
}

/// The functions that build the composite constants too large for a `mk_` constructor (a lookup table of
/// more than `MAX_CONSTRUCTOR_MEMBERS` elements), each `k_ID()`, member by member; those a constant's
/// members need come first.
pub fn large_composites(m: &ModuleInfo) -> Result<String, TranslateError> {
    let mut ids: Vec<Word> = m.constants.keys().copied().collect();
    ids.sort_unstable();
    let mut out = String::new();
    let mut done = std::collections::HashSet::new();
    for id in ids {
        define_large(m, id, &mut done, &mut out)?;
    }
    Ok(out)
}

fn define_large(
    m: &ModuleInfo,
    id: Word,
    done: &mut std::collections::HashSet<Word>,
    out: &mut String,
) -> Result<(), TranslateError> {
    let Some(Constant::Composite { ty, parts }) = m.constants.get(&id) else { return Ok(()) };
    if !done.insert(id) {
        return Ok(());
    }
    for p in parts {
        define_large(m, *p, done, out)?;
    }
    if parts.len() as u32 <= super::ctypes::MAX_CONSTRUCTOR_MEMBERS {
        return Ok(());
    }
    let c = m.c_type(*ty)?;
    let sets = m
        .members(*ty)
        .iter()
        .zip(parts)
        .map(|((_, accessor), p)| Ok(format!(" r.{accessor} = {};", expr(m, *p)?)))
        .collect::<Result<String, TranslateError>>()?;
    out.push_str(&format!("BRDFPROF_FN {c} k_{id}(void) {{ {c} r;{sets} return r; }}\n"));
    Ok(())
}
