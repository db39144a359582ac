//! SPIR-V types as C types: scalars as the prelude's names (`i32`, `u32`, `float`, `half_t`, `double`), every
//! composite as a struct so that it is a value C can copy and index: a vector or a matrix holds its components
//! or columns in `c[]` (so a component index may be dynamic, as SPIR-V allows), an array `c[N]`, a struct its
//! members `m0, m1, ...`. Each composite gets `mk_T(...)` (its constructor) and `z_T()` (its zero value).

use super::TranslateError;
use super::module::{ModuleInfo, Type};
use rspirv::spirv::Word;
use std::fmt::Write;

/// The scalar kinds the translation computes with.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Scalar {
    Bool,
    I32,
    U32,
    F16,
    F32,
    F64,
}

impl Scalar {
    pub fn c_name(self) -> &'static str {
        match self {
            Scalar::Bool => "bool",
            Scalar::I32 => "i32",
            Scalar::U32 => "u32",
            Scalar::F16 => "half_t",
            Scalar::F32 => "float",
            Scalar::F64 => "double",
        }
    }

    fn tag(self) -> &'static str {
        match self {
            Scalar::Bool => "b",
            Scalar::I32 => "i32",
            Scalar::U32 => "u32",
            Scalar::F16 => "f16",
            Scalar::F32 => "f32",
            Scalar::F64 => "f64",
        }
    }

    #[allow(dead_code)]
    pub fn is_float(self) -> bool {
        matches!(self, Scalar::F16 | Scalar::F32 | Scalar::F64)
    }

    /// Bytes in a buffer.
    pub fn size(self) -> u32 {
        match self {
            Scalar::Bool | Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::F16 => 2,
            Scalar::F64 => 8,
        }
    }
}

/// Largest composite that gets a `mk_` constructor (one parameter per member).
pub const MAX_CONSTRUCTOR_MEMBERS: u32 = 64;

impl ModuleInfo {
    /// The scalar kind of a scalar type, or an error naming what the translation lacks.
    pub fn scalar(&self, ty: Word) -> Result<Scalar, TranslateError> {
        match self.ty(ty) {
            Type::Bool => Ok(Scalar::Bool),
            Type::Int { width: 32, signed: true } => Ok(Scalar::I32),
            Type::Int { width: 32, signed: false } => Ok(Scalar::U32),
            Type::Float { width: 16 } => Ok(Scalar::F16),
            Type::Float { width: 32 } => Ok(Scalar::F32),
            Type::Float { width: 64 } => Ok(Scalar::F64),
            Type::Int { width, signed } => Err(TranslateError::new(format!(
                "{width}-bit {} integers (OpTypeInt {width} {})",
                if *signed { "signed" } else { "unsigned" },
                *signed as u8
            ))),
            Type::Float { width } => Err(TranslateError::new(format!("{width}-bit floats (OpTypeFloat {width})"))),
            other => Err(TranslateError::new(format!("a {other:?} where a scalar was expected"))),
        }
    }

    /// The C name of a value type.
    pub fn c_type(&self, ty: Word) -> Result<String, TranslateError> {
        Ok(match self.ty(ty) {
            Type::Void => "void".into(),
            Type::Bool | Type::Int { .. } | Type::Float { .. } => self.scalar(ty)?.c_name().into(),
            Type::Vector { elem, n } => format!("v{n}{}", self.scalar(*elem)?.tag()),
            Type::Matrix { column, columns } => match self.ty(*column) {
                Type::Vector { elem, n } => format!("m{columns}x{n}{}", self.scalar(*elem)?.tag()),
                _ => return Err(TranslateError::new("a matrix whose columns are not vectors".into())),
            },
            Type::Array { .. } => format!("arr{ty}"),
            Type::Struct { .. } => match self.name(ty) {
                Some(n) => format!("st{ty}_{}", sanitize(n)),
                None => format!("st{ty}"),
            },
            Type::Pointer { pointee, .. } => format!("{}*", self.c_type(*pointee)?),
            Type::RuntimeArray { .. } => return Err(TranslateError::new("a runtime array outside a buffer".into())),
            Type::Image { .. } | Type::SampledImage { .. } | Type::Sampler => {
                return Err(TranslateError::new("an image or sampler value outside its binding".into()));
            }
            Type::Function { .. } => return Err(TranslateError::new("a function type as a value".into())),
        })
    }

    /// The members of a composite type: (member type, C accessor), in order.
    pub fn members(&self, ty: Word) -> Vec<(Word, String)> {
        match self.ty(ty) {
            Type::Vector { elem, n } => (0..*n).map(|k| (*elem, format!("c[{k}]"))).collect(),
            Type::Matrix { column, columns } => (0..*columns).map(|k| (*column, format!("c[{k}]"))).collect(),
            Type::Array { elem, len } => (0..*len).map(|k| (*elem, format!("c[{k}]"))).collect(),
            Type::Struct { members } => members.iter().enumerate().map(|(k, m)| (*m, format!("m{k}"))).collect(),
            _ => Vec::new(),
        }
    }

    /// Whether `ty` is a value type that needs a C declaration (a composite).
    fn is_composite(&self, ty: Word) -> bool {
        matches!(self.ty(ty), Type::Vector { .. } | Type::Matrix { .. } | Type::Array { .. } | Type::Struct { .. })
    }

    /// The zero value of a type, as a C expression.
    pub fn zero(&self, ty: Word) -> Result<String, TranslateError> {
        Ok(match self.ty(ty) {
            Type::Bool => "false".into(),
            Type::Int { .. } | Type::Float { .. } => match self.scalar(ty)? {
                Scalar::I32 => "0".into(),
                Scalar::U32 => "0u".into(),
                Scalar::F16 => "h_from_bits(0u)".into(),
                Scalar::F32 => "0.0f".into(),
                Scalar::F64 => "0.0".into(),
                Scalar::Bool => "false".into(),
            },
            _ if self.is_composite(ty) => format!("z_{}()", self.c_type(ty)?),
            _ => return Err(TranslateError::new(format!("the zero of {:?}", self.ty(ty)))),
        })
    }

    /// Every composite value type's typedef, constructor and zero function, in declaration order.
    pub fn type_declarations(&self) -> Result<String, TranslateError> {
        let mut out = String::new();
        let mut done: Vec<String> = Vec::new();
        for &ty in &self.type_order {
            if !self.is_composite(ty) || self.has_runtime_array(ty) {
                continue;
            }
            let name = self.c_type(ty)?;
            if done.contains(&name) {
                continue;
            }
            self.declare(ty, &name, &mut out)?;
            done.push(name);
        }
        Ok(out)
    }

    /// Whether a struct holds a runtime array (a buffer block, read through byte offsets, never as a value).
    pub fn has_runtime_array(&self, ty: Word) -> bool {
        match self.ty(ty) {
            Type::RuntimeArray { .. } => true,
            Type::Struct { members } => members.iter().any(|m| self.has_runtime_array(*m)),
            Type::Array { elem, .. } => self.has_runtime_array(*elem),
            _ => false,
        }
    }

    fn declare(&self, ty: Word, name: &str, out: &mut String) -> Result<(), TranslateError> {
        let members = self.members(ty);
        let array = matches!(self.ty(ty), Type::Vector { .. } | Type::Matrix { .. } | Type::Array { .. });
        if array {
            let elem = self.c_type(members.first().map_or(0, |m| m.0))?;
            writeln!(out, "typedef struct {{ {elem} c[{}]; }} {name};", members.len()).unwrap();
        } else {
            let fields = members
                .iter()
                .map(|(t, a)| Ok(format!("{} {a};", self.c_type(*t)?)))
                .collect::<Result<Vec<_>, TranslateError>>()?;
            writeln!(out, "typedef struct {{ {} }} {name};", fields.join(" ")).unwrap();
        }
        if members.len() as u32 <= MAX_CONSTRUCTOR_MEMBERS {
            let params = members
                .iter()
                .enumerate()
                .map(|(k, (t, _))| Ok(format!("{} a{k}", self.c_type(*t)?)))
                .collect::<Result<Vec<_>, TranslateError>>()?;
            let sets: String = members.iter().enumerate().map(|(k, (_, a))| format!(" r.{a} = a{k};")).collect();
            writeln!(out, "BRDFPROF_FN {name} mk_{name}({}) {{ {name} r;{sets} return r; }}", params.join(", "))
                .unwrap();
        }
        if array && members.len() as u32 > MAX_CONSTRUCTOR_MEMBERS {
            let z = self.zero(members[0].0)?;
            writeln!(out, "BRDFPROF_FN {name} z_{name}(void) {{ {name} r; for (u32 k = 0u; k < {}u; ++k) r.c[k] = {z}; return r; }}", members.len()).unwrap();
        } else {
            let zeros = members.iter().map(|(t, _)| self.zero(*t)).collect::<Result<Vec<_>, TranslateError>>()?;
            writeln!(out, "BRDFPROF_FN {name} z_{name}(void) {{ return mk_{name}({}); }}", zeros.join(", ")).unwrap();
        }
        Ok(())
    }
}

/// An identifier made of C-safe characters.
pub fn sanitize(name: &str) -> String {
    let s: String = name.chars().map(|c| if c.is_ascii_alphanumeric() || c == '_' { c } else { '_' }).collect();
    s.trim_matches('_').chars().take(40).collect()
}
