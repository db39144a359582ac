//! SPIR-V's value operations as C expressions: arithmetic, conversions, comparisons, composites and the matrix
//! forms, component by component for vectors (`mk_T(a.c[0] + b.c[0], ...)`). Integer arithmetic that C leaves
//! undefined (signed overflow, a shift by the width or more, a division by zero) goes through unsigned forms or
//! the prelude's `m_` functions, which give SPIR-V's wrapping results.

use super::TranslateError;
use super::body::FunctionWriter;
use super::constants::convert_float;
use super::ctypes::Scalar;
use super::module::Type;
use rspirv::dr::{Instruction, Operand};
use rspirv::spirv::{Op, Word};
use std::fmt::Write;

/// `e`'s component `k` when it has `n` (a scalar is its own component).
pub fn comp(e: &str, n: u32, k: u32) -> String {
    if n > 1 { format!("{e}.c[{k}]") } else { e.to_string() }
}

/// `a op b` in scalar kind `s` (halves through the prelude's `h_` functions).
pub fn fbin(s: Scalar, op: &str, a: &str, b: &str) -> String {
    match (s, op) {
        (Scalar::F16, "+") => format!("h_add({a}, {b})"),
        (Scalar::F16, "-") => format!("h_sub({a}, {b})"),
        (Scalar::F16, "*") => format!("h_mul({a}, {b})"),
        (Scalar::F16, _) => format!("h_div({a}, {b})"),
        (Scalar::F32, "/") => format!("m_fdiv({a}, {b})"),
        _ => format!("({a} {op} {b})"),
    }
}

/// A comparison of two halves with the prelude's ordered `h_lt`, `h_le`, `h_gt`, `h_ge` and `h_eq` (the unordered
/// forms are the negated ordered ones).
pub fn half_compare(op: Op, a: &str, b: &str) -> String {
    match op {
        Op::FOrdEqual => format!("h_eq({a}, {b})"),
        Op::FUnordEqual => format!("(!(h_lt({a}, {b}) || h_gt({a}, {b})))"),
        Op::FOrdNotEqual => format!("(h_lt({a}, {b}) || h_gt({a}, {b}))"),
        Op::FUnordNotEqual => format!("(!h_eq({a}, {b}))"),
        Op::FOrdLessThan => format!("h_lt({a}, {b})"),
        Op::FUnordLessThan => format!("(!h_ge({a}, {b}))"),
        Op::FOrdGreaterThan => format!("h_gt({a}, {b})"),
        Op::FUnordGreaterThan => format!("(!h_le({a}, {b}))"),
        Op::FOrdLessThanEqual => format!("h_le({a}, {b})"),
        Op::FUnordLessThanEqual => format!("(!h_gt({a}, {b}))"),
        Op::FOrdGreaterThanEqual => format!("h_ge({a}, {b})"),
        _ => format!("(!h_lt({a}, {b}))"),
    }
}

/// A scalar float as f32 (exact from f16) for the operations the translation does in f32.
pub fn as_f32(s: Scalar, e: &str) -> String {
    if s == Scalar::F16 { format!("h_to_f32({e})") } else { e.to_string() }
}

impl FunctionWriter<'_> {
    fn ty_of(&self, id: Word) -> Word {
        self.m.type_of(id).unwrap_or(0)
    }

    /// The scalar kind of a scalar, vector or matrix type (a matrix's: its columns').
    fn scalar_kind(&self, ty: Word) -> Result<Scalar, TranslateError> {
        let ty = match self.m.ty(ty) {
            Type::Matrix { column, .. } => *column,
            _ => ty,
        };
        self.m.scalar(self.m.scalar_of(ty)).map_err(|e| self.err(e.construct))
    }

    /// A value of type `ty` from its components (a scalar is its one component).
    pub fn build(&self, ty: Word, parts: Vec<String>) -> Result<String, TranslateError> {
        if matches!(self.m.ty(ty), Type::Vector { .. }) {
            Ok(format!("mk_{}({})", self.m.c_type(ty)?, parts.join(", ")))
        } else {
            Ok(parts.into_iter().next().unwrap_or_default())
        }
    }

    /// The result of `f(component k of each operand)` for every component of the result.
    fn each(&mut self, inst: &Instruction, f: impl Fn(&[String]) -> String) -> Result<String, TranslateError> {
        let ty = inst.result_type.unwrap_or(0);
        let n = self.m.components(ty);
        let operands: Vec<(String, u32)> = (0..inst.operands.len())
            .map(|k| {
                let id = Self::id(inst, k);
                Ok((self.v(id)?, self.m.components(self.ty_of(id))))
            })
            .collect::<Result<_, TranslateError>>()?;
        let parts = (0..n).map(|k| f(&operands.iter().map(|(e, m)| comp(e, *m, k)).collect::<Vec<_>>())).collect();
        self.build(ty, parts)
    }

    /// The C expression of a value instruction.
    pub fn operation(&mut self, inst: &Instruction) -> Result<String, TranslateError> {
        use Op::*;
        let op = inst.class.opcode;
        let ty = inst.result_type.unwrap_or(0);
        match op {
            FAdd | FSub | FMul | FDiv | FRem | FMod | FNegate => self.float_arith(inst),
            IAdd | ISub | IMul | UDiv | SDiv | UMod | SRem | SMod | ShiftLeftLogical | ShiftRightLogical
            | ShiftRightArithmetic | BitwiseAnd | BitwiseOr | BitwiseXor | Not | SNegate => self.int_arith(inst),
            ConvertFToS | ConvertFToU | ConvertSToF | ConvertUToF | FConvert | UConvert | SConvert | Bitcast
            | QuantizeToF16 => self.conversion(inst),
            FOrdEqual
            | FUnordEqual
            | FOrdNotEqual
            | FUnordNotEqual
            | FOrdLessThan
            | FUnordLessThan
            | FOrdGreaterThan
            | FUnordGreaterThan
            | FOrdLessThanEqual
            | FUnordLessThanEqual
            | FOrdGreaterThanEqual
            | FUnordGreaterThanEqual => self.float_compare(inst),
            IEqual | INotEqual | SLessThan | SLessThanEqual | SGreaterThan | SGreaterThanEqual | ULessThan
            | ULessThanEqual | UGreaterThan | UGreaterThanEqual => self.int_compare(inst),
            LogicalAnd => self.each(inst, |o| format!("({} && {})", o[0], o[1])),
            LogicalOr => self.each(inst, |o| format!("({} || {})", o[0], o[1])),
            LogicalEqual => self.each(inst, |o| format!("({} == {})", o[0], o[1])),
            LogicalNotEqual => self.each(inst, |o| format!("({} != {})", o[0], o[1])),
            LogicalNot => self.each(inst, |o| format!("(!{})", o[0])),
            Select => self.select(inst),
            Any | All => {
                let v = Self::id(inst, 0);
                let (e, n) = (self.v(v)?, self.m.components(self.ty_of(v)));
                let join = if op == Any { " || " } else { " && " };
                Ok(format!("({})", (0..n).map(|k| comp(&e, n, k)).collect::<Vec<_>>().join(join)))
            }
            IsNan | IsInf => {
                let s = self.scalar_kind(self.ty_of(Self::id(inst, 0)))?;
                let f = if op == IsNan { "m_isnan" } else { "m_isinf" };
                self.each(inst, |o| format!("{f}({})", as_f32(s, &o[0])))
            }
            CompositeConstruct => self.construct(inst),
            CompositeExtract => {
                let base = self.v(Self::id(inst, 0))?;
                let path = self.member_path(
                    self.ty_of(Self::id(inst, 0)),
                    &(1..inst.operands.len()).map(|k| Self::lit(inst, k)).collect::<Vec<_>>(),
                )?;
                Ok(format!("{base}{path}"))
            }
            VectorExtractDynamic => {
                let v = Self::id(inst, 0);
                let n = self.m.components(self.ty_of(v));
                Ok(format!("{}.c[{}]", self.v(v)?, self.index(Self::id(inst, 1), n)?))
            }
            VectorShuffle => self.shuffle(inst),
            CopyObject | CopyLogical => self.v(Self::id(inst, 0)),
            Undef => self.m.zero(ty),
            Dot | VectorTimesScalar => self.vector_product(inst),
            MatrixTimesScalar | MatrixTimesVector | VectorTimesMatrix | MatrixTimesMatrix | OuterProduct
            | Transpose => self.matrix(inst),
            other => Err(self.err(format!("the instruction Op{other:?}"))),
        }
    }

    /// OpDot and OpVectorTimesScalar.
    fn vector_product(&mut self, inst: &Instruction) -> Result<String, TranslateError> {
        let ty = inst.result_type.unwrap_or(0);
        if inst.class.opcode == Op::Dot {
            let (a, b) = (Self::id(inst, 0), Self::id(inst, 1));
            let (ea, eb, n) = (self.v(a)?, self.v(b)?, self.m.components(self.ty_of(a)));
            let s = self.scalar_kind(ty)?;
            return Ok(self.dot(s, &ea, &eb, n));
        }
        let s = self.scalar_kind(ty)?;
        let scalar = self.v(Self::id(inst, 1))?;
        let v = self.v(Self::id(inst, 0))?;
        let n = self.m.components(ty);
        self.build(ty, (0..n).map(|k| fbin(s, "*", &comp(&v, n, k), &scalar)).collect())
    }

    pub fn dot(&self, s: Scalar, a: &str, b: &str, n: u32) -> String {
        let mut e = fbin(s, "*", &comp(a, n, 0), &comp(b, n, 0));
        for k in 1..n {
            e = fbin(s, "+", &e, &fbin(s, "*", &comp(a, n, k), &comp(b, n, k)));
        }
        e
    }

    fn float_arith(&mut self, inst: &Instruction) -> Result<String, TranslateError> {
        let s = self.scalar_kind(inst.result_type.unwrap_or(0))?;
        let op = inst.class.opcode;
        self.each(inst, |o| match op {
            Op::FAdd => fbin(s, "+", &o[0], &o[1]),
            Op::FSub => fbin(s, "-", &o[0], &o[1]),
            Op::FMul => fbin(s, "*", &o[0], &o[1]),
            Op::FDiv => fbin(s, "/", &o[0], &o[1]),
            Op::FNegate if s == Scalar::F16 => format!("h_neg({})", o[0]),
            Op::FNegate => format!("(-{})", o[0]),
            // FRem takes the sign of the dividend (C's fmod), FMod the divisor's (GLSL's mod).
            Op::FRem => convert_float(Scalar::F32, s, &format!("m_fmod({}, {})", as_f32(s, &o[0]), as_f32(s, &o[1]))),
            _ => convert_float(Scalar::F32, s, &format!("m_glsl_mod({}, {})", as_f32(s, &o[0]), as_f32(s, &o[1]))),
        })
    }

    fn int_arith(&mut self, inst: &Instruction) -> Result<String, TranslateError> {
        let t = self.scalar_kind(inst.result_type.unwrap_or(0))?;
        let c = t.c_name();
        let op = inst.class.opcode;
        self.each(inst, |o| {
            let (a, b) = (o[0].as_str(), o.get(1).map_or("", String::as_str));
            match op {
                Op::IAdd => format!("({c})((u32)({a}) + (u32)({b}))"),
                Op::ISub => format!("({c})((u32)({a}) - (u32)({b}))"),
                Op::IMul => format!("({c})((u32)({a}) * (u32)({b}))"),
                Op::SNegate => format!("({c})(0u - (u32)({a}))"),
                Op::UDiv => format!("({c})m_udiv((u32)({a}), (u32)({b}))"),
                Op::UMod => format!("({c})m_umod((u32)({a}), (u32)({b}))"),
                Op::SDiv => format!("({c})m_sdiv((i32)({a}), (i32)({b}))"),
                Op::SRem => format!("({c})m_srem((i32)({a}), (i32)({b}))"),
                Op::SMod => format!("({c})m_smod((i32)({a}), (i32)({b}))"),
                Op::ShiftLeftLogical => format!("({c})((u32)({a}) << ((u32)({b}) & 31u))"),
                Op::ShiftRightLogical => format!("({c})((u32)({a}) >> ((u32)({b}) & 31u))"),
                Op::ShiftRightArithmetic => format!("({c})((i32)({a}) >> ((u32)({b}) & 31u))"),
                Op::BitwiseAnd => format!("({c})((u32)({a}) & (u32)({b}))"),
                Op::BitwiseOr => format!("({c})((u32)({a}) | (u32)({b}))"),
                Op::BitwiseXor => format!("({c})((u32)({a}) ^ (u32)({b}))"),
                _ => format!("({c})(~(u32)({a}))"),
            }
        })
    }

    fn conversion(&mut self, inst: &Instruction) -> Result<String, TranslateError> {
        let to = self.scalar_kind(inst.result_type.unwrap_or(0))?;
        let from = self.scalar_kind(self.ty_of(Self::id(inst, 0)))?;
        let op = inst.class.opcode;
        if op == Op::Bitcast
            && self.m.components(inst.result_type.unwrap_or(0)) != self.m.components(self.ty_of(Self::id(inst, 0)))
        {
            return Err(self.err("an OpBitcast between vectors of different lengths"));
        }
        let err = self.err(format!("an Op{op:?} from {from:?} to {to:?}"));
        let convert = move |e: &str| -> Option<String> {
            Some(match op {
                Op::ConvertFToS | Op::ConvertFToU => format!("({})({})", to.c_name(), as_f32(from, e)),
                Op::ConvertSToF | Op::ConvertUToF => convert_float(Scalar::F32, to, &format!("(float)({e})")),
                Op::FConvert => convert_float(from, to, e),
                Op::QuantizeToF16 => format!("h_to_f32(h_from_f32({e}))"),
                Op::UConvert | Op::SConvert if from.size() == to.size() => format!("({})({e})", to.c_name()),
                Op::Bitcast => match (from, to) {
                    (Scalar::F32, Scalar::U32 | Scalar::I32) => format!("({})f32_bits({e})", to.c_name()),
                    (Scalar::U32 | Scalar::I32, Scalar::F32) => format!("f32_from_bits((u32)({e}))"),
                    (Scalar::U32 | Scalar::I32, Scalar::U32 | Scalar::I32) => format!("({})({e})", to.c_name()),
                    (a, b) if a == b => e.to_string(),
                    _ => return None,
                },
                _ => return None,
            })
        };
        let ty = inst.result_type.unwrap_or(0);
        let n = self.m.components(ty);
        let v = self.v(Self::id(inst, 0))?;
        let parts =
            (0..n).map(|k| convert(&comp(&v, n, k)).ok_or_else(|| err.clone())).collect::<Result<Vec<_>, _>>()?;
        self.build(ty, parts)
    }

    fn float_compare(&mut self, inst: &Instruction) -> Result<String, TranslateError> {
        let s = self.scalar_kind(self.ty_of(Self::id(inst, 0)))?;
        let op = inst.class.opcode;
        self.each(inst, |o| {
            if s == Scalar::F16 {
                return half_compare(op, &o[0], &o[1]);
            }
            let (a, b) = (&o[0], &o[1]);
            match op {
                Op::FOrdEqual => format!("({a} == {b})"),
                Op::FUnordEqual => format!("(!({a} < {b} || {a} > {b}))"),
                Op::FOrdNotEqual => format!("({a} < {b} || {a} > {b})"),
                Op::FUnordNotEqual => format!("({a} != {b})"),
                Op::FOrdLessThan => format!("({a} < {b})"),
                Op::FUnordLessThan => format!("(!({a} >= {b}))"),
                Op::FOrdGreaterThan => format!("({a} > {b})"),
                Op::FUnordGreaterThan => format!("(!({a} <= {b}))"),
                Op::FOrdLessThanEqual => format!("({a} <= {b})"),
                Op::FUnordLessThanEqual => format!("(!({a} > {b}))"),
                Op::FOrdGreaterThanEqual => format!("({a} >= {b})"),
                _ => format!("(!({a} < {b}))"),
            }
        })
    }

    fn int_compare(&mut self, inst: &Instruction) -> Result<String, TranslateError> {
        let op = inst.class.opcode;
        let cast = match op {
            Op::SLessThan | Op::SLessThanEqual | Op::SGreaterThan | Op::SGreaterThanEqual => "(i32)",
            _ => "(u32)",
        };
        let sym = match op {
            Op::IEqual => "==",
            Op::INotEqual => "!=",
            Op::SLessThan | Op::ULessThan => "<",
            Op::SLessThanEqual | Op::ULessThanEqual => "<=",
            Op::SGreaterThan | Op::UGreaterThan => ">",
            _ => ">=",
        };
        self.each(inst, |o| format!("({cast}({}) {sym} {cast}({}))", o[0], o[1]))
    }

    fn select(&mut self, inst: &Instruction) -> Result<String, TranslateError> {
        let cond = Self::id(inst, 0);
        if self.m.components(self.ty_of(cond)) == 1 {
            let (c, a, b) = (self.v(cond)?, self.v(Self::id(inst, 1))?, self.v(Self::id(inst, 2))?);
            return Ok(format!("({c} ? {a} : {b})"));
        }
        self.each(inst, |o| format!("({} ? {} : {})", o[0], o[1], o[2]))
    }

    fn construct(&mut self, inst: &Instruction) -> Result<String, TranslateError> {
        let ty = inst.result_type.unwrap_or(0);
        let mut parts = Vec::new();
        let vector = matches!(self.m.ty(ty), Type::Vector { .. });
        for k in 0..inst.operands.len() {
            let id = Self::id(inst, k);
            let e = self.v(id)?;
            let n = self.m.components(self.ty_of(id));
            if vector && n > 1 {
                parts.extend((0..n).map(|c| comp(&e, n, c)));
            } else {
                parts.push(e);
            }
        }
        Ok(format!("mk_{}({})", self.m.c_type(ty)?, parts.join(", ")))
    }

    /// The C accessor of a literal index path into a composite of type `ty`.
    fn member_path(&self, mut ty: Word, path: &[u32]) -> Result<String, TranslateError> {
        let mut out = String::new();
        for &k in path {
            match self.m.ty(ty).clone() {
                Type::Struct { members } => {
                    write!(out, ".m{k}").unwrap();
                    ty = *members.get(k as usize).ok_or_else(|| self.err("a member index past the struct"))?;
                }
                Type::Vector { elem, .. } | Type::Array { elem, .. } => {
                    write!(out, ".c[{k}]").unwrap();
                    ty = elem;
                }
                Type::Matrix { column, .. } => {
                    write!(out, ".c[{k}]").unwrap();
                    ty = column;
                }
                other => return Err(self.err(format!("a composite index into {other:?}"))),
            }
        }
        Ok(out)
    }

    /// CompositeInsert (object, composite, indices) and VectorInsertDynamic (vector, component, index): a copy,
    /// then one member replaced.
    pub fn insert(&mut self, inst: &Instruction) -> Result<(), TranslateError> {
        let id = inst.result_id.unwrap_or(0);
        let (copy, member, value) = if inst.class.opcode == Op::CompositeInsert {
            let path: Vec<u32> = (2..inst.operands.len()).map(|k| Self::lit(inst, k)).collect();
            (
                self.v(Self::id(inst, 1))?,
                self.member_path(self.ty_of(Self::id(inst, 1)), &path)?,
                self.v(Self::id(inst, 0))?,
            )
        } else {
            let n = self.m.components(self.ty_of(Self::id(inst, 0)));
            (
                self.v(Self::id(inst, 0))?,
                format!(".c[{}]", self.index(Self::id(inst, 2), n)?),
                self.v(Self::id(inst, 1))?,
            )
        };
        self.assign(inst, copy)?;
        writeln!(self.body, "  _{id}{member} = {value};").unwrap();
        Ok(())
    }

    fn shuffle(&mut self, inst: &Instruction) -> Result<String, TranslateError> {
        let ty = inst.result_type.unwrap_or(0);
        let (a, b) = (Self::id(inst, 0), Self::id(inst, 1));
        let (ea, eb) = (self.v(a)?, self.v(b)?);
        let (na, nb) = (self.m.components(self.ty_of(a)), self.m.components(self.ty_of(b)));
        let zero = self.m.zero(self.m.scalar_of(ty))?;
        let parts = inst.operands[2..]
            .iter()
            .map(|o| match o {
                Operand::LiteralBit32(c) if *c < na => comp(&ea, na, *c),
                Operand::LiteralBit32(c) if *c < na + nb => comp(&eb, nb, *c - na),
                _ => zero.clone(),
            })
            .collect();
        self.build(ty, parts)
    }

    fn matrix(&mut self, inst: &Instruction) -> Result<String, TranslateError> {
        let ty = inst.result_type.unwrap_or(0);
        let s = self.scalar_kind(ty)?;
        let (a, b) = (Self::id(inst, 0), Self::id(inst, 1));
        let ea = self.v(a)?;
        let eb = if inst.operands.len() > 1 { self.v(b)? } else { String::new() };
        let shape = |t: Word| match self.m.ty(t) {
            Type::Matrix { column, columns } => (*columns, self.m.components(*column)),
            Type::Vector { n, .. } => (1, *n),
            _ => (1, 1),
        };
        let (ac, ar) = shape(self.ty_of(a));
        let (bc, _) = if inst.operands.len() > 1 { shape(self.ty_of(b)) } else { (0, 0) };
        let at = |e: &str, col: u32, row: u32| format!("{e}.c[{col}].c[{row}]");
        let sum = |terms: Vec<String>| terms.into_iter().reduce(|x, y| fbin(s, "+", &x, &y)).unwrap_or_default();
        let column = |f: &dyn Fn(u32) -> String, rows: u32| -> Result<String, TranslateError> {
            let col_ty = match self.m.ty(ty) {
                Type::Matrix { column, .. } => *column,
                _ => ty,
            };
            self.build(col_ty, (0..rows).map(f).collect())
        };
        let (cols, rows) = shape(ty);
        let columns: Vec<String> = match inst.class.opcode {
            Op::MatrixTimesScalar => {
                (0..cols).map(|c| column(&|r| fbin(s, "*", &at(&ea, c, r), &eb), rows)).collect::<Result<_, _>>()?
            }
            Op::MatrixTimesVector => {
                return self.build(
                    ty,
                    (0..ar)
                        .map(|r| sum((0..ac).map(|c| fbin(s, "*", &at(&ea, c, r), &comp(&eb, ac, c))).collect()))
                        .collect(),
                );
            }
            Op::VectorTimesMatrix => {
                return self.build(
                    ty,
                    (0..bc)
                        .map(|c| sum((0..ar).map(|r| fbin(s, "*", &comp(&ea, ar, r), &at(&eb, c, r))).collect()))
                        .collect(),
                );
            }
            Op::MatrixTimesMatrix => (0..cols)
                .map(|c| {
                    column(&|r| sum((0..ac).map(|k| fbin(s, "*", &at(&ea, k, r), &at(&eb, c, k))).collect()), rows)
                })
                .collect::<Result<_, _>>()?,
            Op::OuterProduct => (0..cols)
                .map(|c| column(&|r| fbin(s, "*", &comp(&ea, ar, r), &comp(&eb, cols, c)), rows))
                .collect::<Result<_, _>>()?,
            _ => (0..cols).map(|c| column(&|r| at(&ea, r, c), rows)).collect::<Result<_, _>>()?,
        };
        Ok(format!("mk_{}({})", self.m.c_type(ty)?, columns.join(", ")))
    }
}
