//! The SPIR-V module the translator reads, indexed: every type, constant, decoration, name, global variable and
//! function by id, as rspirv parsed them. Nothing here knows C.

use super::{Location, TranslateError};
use rspirv::dr::{Function, Instruction, Operand};
use rspirv::spirv::{BuiltIn, Decoration, Dim, ExecutionMode, ImageFormat, Op, StorageClass, Word};
use std::collections::{BTreeMap, HashMap};

/// A SPIR-V type, as far as the translation represents it.
#[derive(Clone, Debug, PartialEq)]
pub enum Type {
    Void,
    Bool,
    Int { width: u32, signed: bool },
    Float { width: u32 },
    Vector { elem: Word, n: u32 },
    Matrix { column: Word, columns: u32 },
    Array { elem: Word, len: u32 },
    RuntimeArray { elem: Word },
    Struct { members: Vec<Word> },
    Pointer { class: StorageClass, pointee: Word },
    Function { ret: Word, params: Vec<Word> },
    Image { sampled: Word, dim: Dim, format: ImageFormat, storage: bool },
    SampledImage { image: Word },
    Sampler,
}

/// A module-level constant.
#[derive(Clone, Debug)]
pub enum Constant {
    /// An integer or float, as its bits (32- or 64-bit literal).
    Scalar {
        ty: Word,
        bits: u64,
    },
    Bool {
        ty: Word,
        value: bool,
    },
    Composite {
        ty: Word,
        parts: Vec<Word>,
    },
    /// OpConstantNull and OpUndef (read as zero).
    Zero {
        ty: Word,
    },
    /// An OpSpecConstantOp spirv-opt left unfolded: the operation and its operand ids.
    Op {
        ty: Word,
        op: Op,
        operands: Vec<Word>,
        literals: Vec<u32>,
    },
}

/// A global OpVariable.
#[derive(Clone, Debug)]
pub struct Global {
    pub ty: Word,
    pub class: StorageClass,
    pub pointee: Word,
    pub initializer: Option<Word>,
}

pub struct ModuleInfo {
    pub types: HashMap<Word, Type>,
    /// Types in declaration order (what C must declare first).
    pub type_order: Vec<Word>,
    pub constants: HashMap<Word, Constant>,
    pub globals: BTreeMap<Word, Global>,
    pub names: HashMap<Word, String>,
    pub decorations: HashMap<Word, Vec<(Decoration, Vec<u32>)>>,
    pub member_decorations: HashMap<(Word, u32), Vec<(Decoration, Vec<u32>)>>,
    /// Ids of OpExtInstImport "GLSL.std.450".
    pub glsl_std_450: Vec<Word>,
    /// OpString ids: file names of OpLine.
    pub strings: HashMap<Word, String>,
    pub functions: Vec<Function>,
    pub entry: Word,
    pub local_size: [u32; 3],
    /// Results defined by instructions (id -> result type), for every function.
    pub result_types: HashMap<Word, Word>,
}

fn ids(operands: &[Operand]) -> Vec<Word> {
    operands.iter().filter_map(|o| if let Operand::IdRef(i) = o { Some(*i) } else { None }).collect()
}

fn literal(o: Option<&Operand>) -> u32 {
    match o {
        Some(Operand::LiteralBit32(v)) => *v,
        Some(Operand::LiteralExtInstInteger(v)) => *v,
        _ => 0,
    }
}

fn id_at(inst: &Instruction, k: usize) -> Word {
    match inst.operands.get(k) {
        Some(Operand::IdRef(i)) => *i,
        _ => 0,
    }
}

fn unsupported(construct: String) -> TranslateError {
    TranslateError { construct, function: None, location: None::<Location> }
}

impl ModuleInfo {
    pub fn read(words: &[u32]) -> Result<Self, TranslateError> {
        let module = rspirv::dr::load_words(words)
            .map_err(|e| unsupported(format!("a SPIR-V module rspirv cannot parse ({e})")))?;
        let mut info = ModuleInfo {
            types: HashMap::new(),
            type_order: Vec::new(),
            constants: HashMap::new(),
            globals: BTreeMap::new(),
            names: HashMap::new(),
            decorations: HashMap::new(),
            member_decorations: HashMap::new(),
            glsl_std_450: Vec::new(),
            strings: HashMap::new(),
            functions: Vec::new(),
            entry: 0,
            local_size: [1, 1, 1],
            result_types: HashMap::new(),
        };
        info.read_header(&module)?;
        for inst in &module.types_global_values {
            info.read_global(inst)?;
        }
        for f in &module.functions {
            for inst in f.parameters.iter().chain(f.blocks.iter().flat_map(|b| &b.instructions)) {
                if let (Some(id), Some(ty)) = (inst.result_id, inst.result_type) {
                    info.result_types.insert(id, ty);
                }
            }
        }
        info.functions = module.functions;
        Ok(info)
    }

    fn read_header(&mut self, module: &rspirv::dr::Module) -> Result<(), TranslateError> {
        for i in &module.ext_inst_imports {
            match i.operands.first() {
                Some(Operand::LiteralString(s)) if s == "GLSL.std.450" => self.glsl_std_450.extend(i.result_id),
                Some(Operand::LiteralString(s)) => {
                    return Err(unsupported(format!("the extended instruction set `{s}`")));
                }
                _ => {}
            }
        }
        let entries: Vec<&Instruction> = module.entry_points.iter().collect();
        let [entry] = entries.as_slice() else {
            return Err(unsupported(format!(
                "a module with {} entry points (one compute entry point is translated)",
                entries.len()
            )));
        };
        if !matches!(entry.operands.first(), Some(Operand::ExecutionModel(rspirv::spirv::ExecutionModel::GLCompute))) {
            return Err(unsupported("an entry point that is not a compute shader".into()));
        }
        self.entry = id_at(entry, 1);
        for m in &module.execution_modes {
            if let [Operand::IdRef(_), Operand::ExecutionMode(ExecutionMode::LocalSize), x, y, z] =
                m.operands.as_slice()
            {
                self.local_size = [literal(Some(x)), literal(Some(y)), literal(Some(z))];
            }
        }
        for n in &module.debug_names {
            match (n.class.opcode, n.operands.as_slice()) {
                (Op::Name, [Operand::IdRef(id), Operand::LiteralString(s)]) => {
                    self.names.insert(*id, s.clone());
                }
                _ => {}
            }
        }
        for s in &module.debug_string_source {
            if let (Op::String, Some(id), Some(Operand::LiteralString(text))) =
                (s.class.opcode, s.result_id, s.operands.first())
            {
                self.strings.insert(id, text.clone());
            }
        }
        for a in &module.annotations {
            self.read_annotation(a);
        }
        Ok(())
    }

    fn read_annotation(&mut self, a: &Instruction) {
        let literals = |ops: &[Operand]| ops.iter().map(|o| literal(Some(o))).collect::<Vec<u32>>();
        let builtin = |ops: &[Operand]| {
            ops.iter()
                .filter_map(|o| if let Operand::BuiltIn(b) = o { Some(*b as u32) } else { None })
                .collect::<Vec<u32>>()
        };
        match (a.class.opcode, a.operands.as_slice()) {
            (Op::Decorate, [Operand::IdRef(id), Operand::Decoration(d), rest @ ..]) => {
                let args = if *d == Decoration::BuiltIn { builtin(rest) } else { literals(rest) };
                self.decorations.entry(*id).or_default().push((*d, args));
            }
            (Op::MemberDecorate, [Operand::IdRef(id), Operand::LiteralBit32(m), Operand::Decoration(d), rest @ ..]) => {
                let args = if *d == Decoration::BuiltIn { builtin(rest) } else { literals(rest) };
                self.member_decorations.entry((*id, *m)).or_default().push((*d, args));
            }
            _ => {}
        }
    }

    fn read_global(&mut self, inst: &Instruction) -> Result<(), TranslateError> {
        let op = inst.class.opcode;
        let Some(id) = inst.result_id else { return Ok(()) };
        if let Some(t) = self.read_type(inst)? {
            self.types.insert(id, t);
            self.type_order.push(id);
            return Ok(());
        }
        let ty = inst.result_type.unwrap_or(0);
        let constant = match op {
            Op::Constant | Op::SpecConstant => Constant::Scalar {
                ty,
                bits: match inst.operands.first() {
                    Some(Operand::LiteralBit32(v)) => u64::from(*v),
                    Some(Operand::LiteralBit64(v)) => *v,
                    _ => 0,
                },
            },
            Op::ConstantTrue | Op::SpecConstantTrue => Constant::Bool { ty, value: true },
            Op::ConstantFalse | Op::SpecConstantFalse => Constant::Bool { ty, value: false },
            Op::ConstantComposite | Op::SpecConstantComposite => Constant::Composite { ty, parts: ids(&inst.operands) },
            Op::ConstantNull | Op::Undef => Constant::Zero { ty },
            Op::SpecConstantOp => match inst.operands.first() {
                Some(Operand::LiteralSpecConstantOpInteger(inner)) => Constant::Op {
                    ty,
                    op: *inner,
                    operands: ids(&inst.operands[1..]),
                    literals: inst.operands[1..]
                        .iter()
                        .filter_map(|o| if let Operand::LiteralBit32(v) = o { Some(*v) } else { None })
                        .collect(),
                },
                _ => return Err(unsupported("an OpSpecConstantOp without its operation".into())),
            },
            Op::Variable => {
                let class = match inst.operands.first() {
                    Some(Operand::StorageClass(c)) => *c,
                    _ => StorageClass::Private,
                };
                let pointee = match self.types.get(&ty) {
                    Some(Type::Pointer { pointee, .. }) => *pointee,
                    _ => 0,
                };
                self.globals.insert(
                    id,
                    Global {
                        ty,
                        class,
                        pointee,
                        initializer: inst
                            .operands
                            .get(1)
                            .and_then(|o| if let Operand::IdRef(i) = o { Some(*i) } else { None }),
                    },
                );
                return Ok(());
            }
            Op::Line | Op::NoLine => return Ok(()),
            other => return Err(unsupported(format!("the module-level instruction Op{other:?}"))),
        };
        self.constants.insert(id, constant);
        Ok(())
    }

    fn read_type(&self, inst: &Instruction) -> Result<Option<Type>, TranslateError> {
        let lit = |k: usize| literal(inst.operands.get(k));
        Ok(Some(match inst.class.opcode {
            Op::TypeVoid => Type::Void,
            Op::TypeBool => Type::Bool,
            Op::TypeInt => Type::Int { width: lit(0), signed: lit(1) == 1 },
            Op::TypeFloat => Type::Float { width: lit(0) },
            Op::TypeVector => Type::Vector { elem: id_at(inst, 0), n: lit(1) },
            Op::TypeMatrix => Type::Matrix { column: id_at(inst, 0), columns: lit(1) },
            Op::TypeArray => {
                let len = id_at(inst, 1);
                let n = match self.constants.get(&len) {
                    Some(Constant::Scalar { bits, .. }) => *bits as u32,
                    _ => return Err(unsupported("an array whose length is not a constant".into())),
                };
                Type::Array { elem: id_at(inst, 0), len: n }
            }
            Op::TypeRuntimeArray => Type::RuntimeArray { elem: id_at(inst, 0) },
            Op::TypeStruct => Type::Struct { members: ids(&inst.operands) },
            Op::TypePointer => match inst.operands.as_slice() {
                [Operand::StorageClass(c), Operand::IdRef(p)] => Type::Pointer { class: *c, pointee: *p },
                _ => return Err(unsupported("a malformed OpTypePointer".into())),
            },
            Op::TypeFunction => {
                let all = ids(&inst.operands);
                Type::Function { ret: all[0], params: all[1..].to_vec() }
            }
            Op::TypeImage => {
                let dim = match inst.operands.get(1) {
                    Some(Operand::Dim(d)) => *d,
                    _ => Dim::Dim2D,
                };
                let format = match inst.operands.get(6) {
                    Some(Operand::ImageFormat(f)) => *f,
                    _ => ImageFormat::Unknown,
                };
                Type::Image { sampled: id_at(inst, 0), dim, format, storage: lit(5) == 2 }
            }
            Op::TypeSampledImage => Type::SampledImage { image: id_at(inst, 0) },
            Op::TypeSampler => Type::Sampler,
            Op::TypeForwardPointer => return Err(unsupported("a forward pointer (physical pointers)".into())),
            op if op.is_type() => return Err(unsupported(format!("the type Op{op:?}"))),
            _ => return Ok(None),
        }))
    }

    pub fn ty(&self, id: Word) -> &Type {
        self.types.get(&id).unwrap_or(&Type::Void)
    }

    /// The decoration `d` of `id`, with its literal arguments.
    pub fn decoration(&self, id: Word, d: Decoration) -> Option<&[u32]> {
        self.decorations.get(&id)?.iter().find(|(x, _)| *x == d).map(|(_, a)| a.as_slice())
    }

    pub fn member_decoration(&self, id: Word, member: u32, d: Decoration) -> Option<&[u32]> {
        self.member_decorations.get(&(id, member))?.iter().find(|(x, _)| *x == d).map(|(_, a)| a.as_slice())
    }

    pub fn builtin(&self, id: Word) -> Option<BuiltIn> {
        self.decoration(id, Decoration::BuiltIn).and_then(|a| a.first()).and_then(|b| BuiltIn::from_u32(*b))
    }

    /// The GLSL name glslang gave `id` (a function's before its parameter signature).
    pub fn name(&self, id: Word) -> Option<&str> {
        self.names.get(&id).map(|n| n.split('(').next().unwrap_or(n)).filter(|n| !n.is_empty())
    }

    /// The type of any value: a constant, a global, a function result or parameter.
    pub fn type_of(&self, id: Word) -> Option<Word> {
        match self.constants.get(&id) {
            Some(
                Constant::Scalar { ty, .. }
                | Constant::Bool { ty, .. }
                | Constant::Composite { ty, .. }
                | Constant::Zero { ty }
                | Constant::Op { ty, .. },
            ) => return Some(*ty),
            None => {}
        }
        self.globals.get(&id).map(|g| g.ty).or_else(|| self.result_types.get(&id).copied())
    }

    /// Components of a vector type (1 for a scalar).
    pub fn components(&self, ty: Word) -> u32 {
        match self.ty(ty) {
            Type::Vector { n, .. } => *n,
            _ => 1,
        }
    }

    /// The scalar type of a scalar or vector type.
    pub fn scalar_of(&self, ty: Word) -> Word {
        match self.ty(ty) {
            Type::Vector { elem, .. } => *elem,
            _ => ty,
        }
    }
}
