//! Module-level constants as C expressions: literals that convert back to the same bits, composites through
//! their `mk_` constructors, and the OpSpecConstantOp forms spirv-opt leaves unfolded after freezing.

use super::TranslateError;
use super::ctypes::Scalar;
use super::module::{Constant, ModuleInfo, Type};
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
        Some(Constant::Composite { parts, .. })
            if parts.len() as u32 > super::ctypes::MAX_CONSTRUCTOR_MEMBERS || is_table(m, id) =>
        {
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
    let table = initializer(m, id).filter(|_| is_table(m, id));
    if parts.len() as u32 <= super::ctypes::MAX_CONSTRUCTOR_MEMBERS && table.is_none() {
        return Ok(());
    }
    let c = m.c_type(*ty)?;
    // A lookup table is also one constant object (BRDFPROF_CONST_TABLE: CUDA's and OpenCL's constant memory,
    // the host's static storage), which the function variables that only ever hold it read in place
    // (`body::tables`, through BRDFPROF_TABLE_SPACE pointers): built member by member into a copy at every use,
    // 16 lookups into a 64-entry table cost 515 STL.64 on sm_75.
    if let Some(init) = &table {
        out.push_str(&format!("#ifdef BRDFPROF_CONST_TABLE\nBRDFPROF_CONST_TABLE {c} k_{id}_v = {init};\n#endif\n"));
    }
    let sets = m
        .members(*ty)
        .iter()
        .zip(parts)
        .map(|((_, accessor), p)| Ok(format!(" r.{accessor} = {};", expr(m, *p)?)))
        .collect::<Result<String, TranslateError>>()?;
    out.push_str(&format!("BRDFPROF_FN {c} k_{id}(void) {{ {c} r;{sets} return r; }}\n"));
    Ok(())
}

/// Whether constant `id` is a lookup table: an array each scalar of which has a constant-expression literal.
pub fn is_table(m: &ModuleInfo, id: Word) -> bool {
    matches!(m.constants.get(&id), Some(Constant::Composite { ty, .. }) if matches!(m.ty(*ty), Type::Array { .. }))
        && initializer(m, id).is_some()
}

/// Constant `id` as a C aggregate initializer of its struct (`{ { e0, e1, ... } }` for the `c[N]` of a vector,
/// matrix or array, `{ f0, f1, ... }` for a struct), None where a scalar has no constant-expression literal
/// (half, booleans, non-finite floats: their literals are function calls or differ by dialect).
fn initializer(m: &ModuleInfo, id: Word) -> Option<String> {
    match m.constants.get(&id)? {
        Constant::Scalar { ty, bits } => {
            let s = m.scalar(*ty).ok()?;
            let exact = match s {
                Scalar::F32 => f32::from_bits(*bits as u32).is_finite(),
                Scalar::F64 => f64::from_bits(*bits).is_finite(),
                Scalar::I32 | Scalar::U32 => true,
                Scalar::Bool | Scalar::F16 => false,
            };
            exact.then(|| literal(s, *bits))
        }
        Constant::Composite { ty, parts } => {
            let parts = parts.iter().map(|p| initializer(m, *p)).collect::<Option<Vec<_>>>()?.join(", ");
            let array = matches!(m.ty(*ty), Type::Vector { .. } | Type::Matrix { .. } | Type::Array { .. });
            Some(if array { format!("{{ {{ {parts} }} }}") } else { format!("{{ {parts} }}") })
        }
        _ => None,
    }
}
