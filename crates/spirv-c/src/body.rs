//! One SPIR-V function as one C function. Every SSA result is a C variable `_ID` declared at the top of the
//! function (so that a `goto` never crosses an initialisation), every block a label, every branch a `goto`
//! after the target block's OpPhi assignments: the control flow is the SPIR-V's own graph, unstructured, which
//! C, CUDA C++ and OpenCL C all express exactly. Pointers into function or private memory are C pointers;
//! pointers into buffers are a binding plus a byte offset computed from the module's layout decorations, so
//! every load and store reads exactly the bytes the Vulkan kernel reads.

use super::ctypes::Scalar;
use super::entry::{EnvLayout, GlobalRep};
use super::module::{Constant, ModuleInfo, Type};
use super::{Location, TranslateError};
use rspirv::dr::{Function, Instruction, Operand};
use rspirv::spirv::{Decoration, Op, Word};
use std::collections::{HashMap, HashSet};
use std::fmt::Write;

/// What a pointer-valued id points at.
#[derive(Clone, Debug)]
pub(super) enum Val {
    /// A C pointer expression to function, private or input memory.
    Local { ptr: String, pointee: Word },
    /// Bytes of a buffer binding: the global variable, a C expression of the byte offset, the pointee type, and
    /// the matrix stride of the matrix member the chain went through.
    Buffer { var: Word, off: String, pointee: Word, matrix_stride: Option<u32> },
    /// An image (a texel buffer binding).
    Image { var: Word },
}

pub(super) struct FunctionWriter<'m> {
    pub m: &'m ModuleInfo,
    pub env: &'m EnvLayout,
    pub vals: HashMap<Word, Val>,
    pub decls: Vec<String>,
    declared: HashSet<Word>,
    /// Phi results whose `_ID_n` temporary is declared.
    phi_temps: HashSet<Word>,
    pub body: String,
    pub location: Option<Location>,
    /// Write `#line` directives (`TranslateOptions::line_directives`).
    line_directives: bool,
    phis: HashMap<Word, Vec<(Word, Vec<(Word, Word)>)>>,
    params: HashSet<Word>,
    ret: Word,
    id: Word,
    pub name: String,
    /// Function variables that only ever hold one lookup table (`tables`), by the table constant.
    tables: HashMap<Word, Word>,
    /// The table variables and the chains into them: pointers into the dialect's table space
    /// (BRDFPROF_TABLE_SPACE: OpenCL's __constant) where it keeps the table as one object.
    table_pointers: HashSet<Word>,
}

impl<'m> FunctionWriter<'m> {
    pub fn new(m: &'m ModuleInfo, env: &'m EnvLayout, f: &'m Function, line_directives: bool) -> Self {
        let def = f.def.as_ref().expect("a function has its OpFunction");
        let id = def.result_id.unwrap_or(0);
        let mut phis: HashMap<Word, Vec<(Word, Vec<(Word, Word)>)>> = HashMap::new();
        for b in &f.blocks {
            let label = b.label.as_ref().and_then(|l| l.result_id).unwrap_or(0);
            for inst in b.instructions.iter().filter(|i| i.class.opcode == Op::Phi) {
                let pairs = inst.operands.chunks(2).filter_map(|p| match p {
                    [Operand::IdRef(v), Operand::IdRef(b)] => Some((*v, *b)),
                    _ => None,
                });
                phis.entry(label).or_default().push((inst.result_id.unwrap_or(0), pairs.collect()));
            }
        }
        FunctionWriter {
            m,
            env,
            vals: HashMap::new(),
            decls: Vec::new(),
            declared: HashSet::new(),
            phi_temps: HashSet::new(),
            // Statements before the function's first OpLine are the translation's own.
            body: if line_directives { format!("#line 1 \"{}\"\n", super::TRANSLATION_FILE) } else { String::new() },
            location: None,
            line_directives,
            phis,
            params: f.parameters.iter().filter_map(|p| p.result_id).collect(),
            ret: def.result_type.unwrap_or(0),
            id,
            name: function_name(m, id),
            tables: tables(m, f),
            table_pointers: HashSet::new(),
        }
    }

    pub fn err(&self, construct: impl Into<String>) -> TranslateError {
        TranslateError {
            construct: construct.into(),
            function: Some(self.m.name(self.id).unwrap_or("?").to_string()),
            location: self.location.clone(),
        }
    }

    /// The C function: signature, declarations, body.
    pub fn write(mut self, f: &Function) -> Result<String, TranslateError> {
        let mut params = vec!["Env* env".to_string()];
        for p in &f.parameters {
            let (id, ty) = (p.result_id.unwrap_or(0), p.result_type.unwrap_or(0));
            match self.m.ty(ty) {
                Type::Pointer { class, pointee } => {
                    if !super::entry::is_local_class(*class) {
                        return Err(self.err(format!("a function parameter pointing into {class:?} memory")));
                    }
                    params.push(format!("{}* p{id}", self.m.c_type(*pointee)?));
                    self.vals.insert(id, Val::Local { ptr: format!("p{id}"), pointee: *pointee });
                }
                _ => params.push(format!("{} p{id}", self.m.c_type(ty)?)),
            }
        }
        let qualifiers = if self.line_directives { LINED_FN } else { "BRDFPROF_FN" };
        let signature = format!("{qualifiers} {} {}({})", self.m.c_type(self.ret)?, self.name, params.join(", "));
        for (i, b) in f.blocks.iter().enumerate() {
            let label = b.label.as_ref().and_then(|l| l.result_id).unwrap_or(0);
            if i > 0 {
                writeln!(self.body, "L{label}:;").unwrap();
            }
            if b.instructions.iter().any(|x| x.class.opcode == Op::LoopMerge) {
                writeln!(self.body, "  if (BRDFPROF_LOOP_LIMIT(env)) return{};", self.return_zero()?).unwrap();
            }
            for inst in &b.instructions {
                self.instruction(inst, label)?;
            }
        }
        let mut out = format!("{signature} {{\n");
        for d in &self.decls {
            writeln!(out, "  {d}").unwrap();
        }
        out += &self.body;
        out += "}\n";
        Ok(out)
    }

    fn return_zero(&self) -> Result<String, TranslateError> {
        Ok(match self.m.ty(self.ret) {
            Type::Void => String::new(),
            _ => format!(" {}", self.m.zero(self.ret)?),
        })
    }

    /// Declares the C variable of result `id` (once).
    fn declare(&mut self, id: Word, ty: &str) {
        if self.declared.insert(id) {
            self.decls.push(format!("{ty} _{id};"));
        }
    }

    /// `_ID = expr;`, declaring `_ID` with the instruction's result type.
    pub fn assign(&mut self, inst: &Instruction, expr: String) -> Result<(), TranslateError> {
        let id = inst.result_id.unwrap_or(0);
        let ty = self.m.c_type(inst.result_type.unwrap_or(0))?;
        self.declare(id, &ty);
        writeln!(self.body, "  _{id} = {expr};").unwrap();
        Ok(())
    }

    /// The C expression of a value id: a parameter, a constant (a local `k_ID` for composites), or `_ID`.
    pub fn v(&mut self, id: Word) -> Result<String, TranslateError> {
        if self.params.contains(&id) {
            return Ok(format!("p{id}"));
        }
        if self.m.constants.contains_key(&id) {
            let ty = self.m.type_of(id).unwrap_or(0);
            let e = super::constants::expr(self.m, id).map_err(|e| self.err(e.construct))?;
            if !matches!(
                self.m.ty(ty),
                Type::Vector { .. } | Type::Matrix { .. } | Type::Array { .. } | Type::Struct { .. }
            ) {
                return Ok(e);
            }
            let name = format!("k{id}");
            if self.declared.insert(id) {
                self.decls.push(format!("const {} {name} = {e};", self.m.c_type(ty)?));
            }
            return Ok(name);
        }
        Ok(format!("_{id}"))
    }

    pub fn id(inst: &Instruction, k: usize) -> Word {
        match inst.operands.get(k) {
            Some(Operand::IdRef(i)) => *i,
            _ => 0,
        }
    }

    pub fn lit(inst: &Instruction, k: usize) -> u32 {
        match inst.operands.get(k) {
            Some(Operand::LiteralBit32(v)) | Some(Operand::LiteralExtInstInteger(v)) => *v,
            _ => 0,
        }
    }

    fn instruction(&mut self, inst: &Instruction, block: Word) -> Result<(), TranslateError> {
        use Op::*;
        match inst.class.opcode {
            Line => {
                let file = self.m.strings.get(&Self::id(inst, 0)).cloned().unwrap_or_default();
                let here = Location { file, line: Self::lit(inst, 1) };
                if self.line_directives && self.location.as_ref() != Some(&here) {
                    writeln!(self.body, "#line {} \"{}\"", here.line, absolute_source(&here.file)).unwrap();
                }
                self.location = Some(here);
            }
            NoLine if self.line_directives && self.location.take().is_some() => {
                writeln!(self.body, "#line 1 \"{}\"", super::TRANSLATION_FILE).unwrap()
            }
            NoLine | Nop | SelectionMerge | LoopMerge | Phi => {}
            Variable => self.variable(inst)?,
            Load => self.load(inst)?,
            Store => self.store(inst)?,
            AccessChain | InBoundsAccessChain => self.access_chain(inst)?,
            CopyMemory => {
                let (to, from) = (Self::id(inst, 0), Self::id(inst, 1));
                let value = self.load_ptr(from)?;
                self.store_ptr(to, &value)?;
            }
            Branch => {
                let to = Self::id(inst, 0);
                let jump = self.jump(block, to)?;
                writeln!(self.body, "  {jump}").unwrap();
            }
            BranchConditional => {
                let c = self.v(Self::id(inst, 0))?;
                let (t, f) = (self.jump(block, Self::id(inst, 1))?, self.jump(block, Self::id(inst, 2))?);
                writeln!(self.body, "  if ({c}) {{ {t} }} else {{ {f} }}").unwrap();
            }
            Switch => self.switch(inst, block)?,
            Return => writeln!(self.body, "  return;").unwrap(),
            ReturnValue => {
                let v = self.v(Self::id(inst, 0))?;
                writeln!(self.body, "  return {v};").unwrap();
            }
            Unreachable => writeln!(self.body, "  return{};", self.return_zero()?).unwrap(),
            FunctionCall => self.call(inst)?,
            SampledImage | Image => {
                let source = Self::id(inst, 0);
                let val = self
                    .vals
                    .get(&source)
                    .cloned()
                    .ok_or_else(|| self.err("an image that does not come from a binding"))?;
                self.vals.insert(inst.result_id.unwrap_or(0), val);
            }
            ImageFetch | ImageRead => self.image_read(inst)?,
            ImageWrite => self.image_write(inst)?,
            CompositeInsert | VectorInsertDynamic => self.insert(inst)?,
            ExtInst => {
                let e = self.ext_inst(inst)?;
                self.assign(inst, e)?;
            }
            _ => {
                let e = self.operation(inst)?;
                self.assign(inst, e)?;
            }
        }
        Ok(())
    }

    /// The phi assignments of edge `from -> to`, then the jump.
    fn jump(&mut self, from: Word, to: Word) -> Result<String, TranslateError> {
        let phis = self.phis.get(&to).cloned().unwrap_or_default();
        let mut s = String::new();
        let many = phis.len() > 1;
        for (result, pairs) in &phis {
            let ty = self.m.c_type(self.m.result_types.get(result).copied().unwrap_or(0))?;
            self.declare(*result, &ty);
            let value = pairs
                .iter()
                .find(|(_, b)| *b == from)
                .map(|(v, _)| *v)
                .ok_or_else(|| self.err(format!("an OpPhi without a value for block {from}")))?;
            let value = self.v(value)?;
            if many {
                if self.phi_temps.insert(*result) {
                    self.decls.push(format!("{ty} _{result}_n;"));
                }
                write!(s, "_{result}_n = {value}; ").unwrap();
            } else {
                write!(s, "_{result} = {value}; ").unwrap();
            }
        }
        if many {
            for (result, _) in &phis {
                write!(s, "_{result} = _{result}_n; ").unwrap();
            }
        }
        write!(s, "goto L{to};").unwrap();
        Ok(s)
    }

    fn switch(&mut self, inst: &Instruction, block: Word) -> Result<(), TranslateError> {
        let selector = self.v(Self::id(inst, 0))?;
        let default = self.jump(block, Self::id(inst, 1))?;
        let mut cases = String::new();
        for pair in inst.operands[2..].chunks(2) {
            if let [Operand::LiteralBit32(value), Operand::IdRef(target)] = pair {
                let jump = self.jump(block, *target)?;
                write!(cases, " case {}: {{ {jump} }}", *value as i32).unwrap();
            } else {
                return Err(self.err("an OpSwitch on a selector wider than 32 bits"));
            }
        }
        writeln!(self.body, "  switch ((i32)({selector})) {{{cases} default: {{ {default} }} }}").unwrap();
        Ok(())
    }

    fn call(&mut self, inst: &Instruction) -> Result<(), TranslateError> {
        let callee = Self::id(inst, 0);
        let mut args = vec!["env".to_string()];
        for k in 1..inst.operands.len() {
            let a = Self::id(inst, k);
            match self.vals.get(&a).cloned() {
                Some(Val::Local { ptr, .. }) => args.push(ptr),
                Some(_) => return Err(self.err("a buffer or image passed to a function")),
                None => args.push(self.v(a)?),
            }
        }
        let call = format!("{}({})", function_name(self.m, callee), args.join(", "));
        if matches!(self.m.ty(inst.result_type.unwrap_or(0)), Type::Void) {
            writeln!(self.body, "  {call};").unwrap();
            Ok(())
        } else {
            self.assign(inst, call)
        }
    }

    fn variable(&mut self, inst: &Instruction) -> Result<(), TranslateError> {
        let id = inst.result_id.unwrap_or(0);
        let Type::Pointer { class, pointee } = self.m.ty(inst.result_type.unwrap_or(0)).clone() else {
            return Err(self.err("an OpVariable that is not a pointer"));
        };
        if !super::entry::is_local_class(class) {
            return Err(self.err(format!("a function-level variable in {class:?} memory")));
        }
        let ty = self.m.c_type(pointee)?;
        if let Some(table) = self.tables.get(&id) {
            // The table itself where the dialect keeps it as one object (read only: `tables`), else a copy.
            self.decls.push(format!(
                "#ifdef BRDFPROF_CONST_TABLE\n#define BRDFPROF_V{id} ((BRDFPROF_TABLE_SPACE {ty}*)&k_{table}_v)\n#else\n  {ty} v{id};\n#define BRDFPROF_V{id} (&v{id})\n#endif"
            ));
            if inst.operands.get(1).is_some() {
                let e = self.v(*table)?;
                writeln!(self.body, "#ifndef BRDFPROF_CONST_TABLE\n  v{id} = {e};\n#endif").unwrap();
            }
            self.vals.insert(id, Val::Local { ptr: format!("BRDFPROF_V{id}"), pointee });
            self.table_pointers.insert(id);
            return Ok(());
        }
        self.decls.push(format!("{ty} v{id};"));
        if let Some(Operand::IdRef(init)) = inst.operands.get(1) {
            let e = self.v(*init)?;
            writeln!(self.body, "  v{id} = {e};").unwrap();
        }
        self.vals.insert(id, Val::Local { ptr: format!("(&v{id})"), pointee });
        Ok(())
    }

    /// The pointer value of `id`: a local or global variable, a parameter or an access chain.
    fn pointer(&self, id: Word) -> Result<Val, TranslateError> {
        if let Some(v) = self.vals.get(&id) {
            return Ok(v.clone());
        }
        match self.env.globals.get(&id) {
            Some(GlobalRep::Local { field, pointee }) => {
                Ok(Val::Local { ptr: format!("(&env->{field})"), pointee: *pointee })
            }
            Some(GlobalRep::Buffer { pointee, .. }) => {
                Ok(Val::Buffer { var: id, off: "0u".into(), pointee: *pointee, matrix_stride: None })
            }
            Some(GlobalRep::Image { .. }) => Ok(Val::Image { var: id }),
            None => Err(self.err(format!("a pointer (%{id}) the translation does not know"))),
        }
    }

    fn load(&mut self, inst: &Instruction) -> Result<(), TranslateError> {
        let from = Self::id(inst, 0);
        if let Val::Image { var } = self.pointer(from)? {
            self.vals.insert(inst.result_id.unwrap_or(0), Val::Image { var });
            return Ok(());
        }
        let e = self.load_ptr(from)?;
        self.assign(inst, e)
    }

    fn load_ptr(&mut self, from: Word) -> Result<String, TranslateError> {
        match self.pointer(from)? {
            Val::Local { ptr, .. } => Ok(format!("(*{ptr})")),
            Val::Buffer { var, off, pointee, matrix_stride } => self.buffer_load(var, &off, pointee, matrix_stride),
            Val::Image { .. } => Err(self.err("an image loaded as a value")),
        }
    }

    fn store(&mut self, inst: &Instruction) -> Result<(), TranslateError> {
        let value = self.v(Self::id(inst, 1))?;
        if self.tables.contains_key(&Self::id(inst, 0)) {
            self.body += "#ifndef BRDFPROF_CONST_TABLE\n";
            self.store_ptr(Self::id(inst, 0), &value)?;
            self.body += "#endif\n";
            return Ok(());
        }
        self.store_ptr(Self::id(inst, 0), &value)
    }

    fn store_ptr(&mut self, to: Word, value: &str) -> Result<(), TranslateError> {
        match self.pointer(to)? {
            Val::Local { ptr, .. } => writeln!(self.body, "  *{ptr} = {value};").unwrap(),
            Val::Buffer { var, off, pointee, matrix_stride } => {
                let stores = self.buffer_store(var, &off, pointee, matrix_stride, value)?;
                self.body += &stores;
            }
            Val::Image { .. } => return Err(self.err("a store to an image variable")),
        }
        Ok(())
    }

    fn access_chain(&mut self, inst: &Instruction) -> Result<(), TranslateError> {
        let id = inst.result_id.unwrap_or(0);
        let base = self.pointer(Self::id(inst, 0))?;
        let indices: Vec<Word> = (1..inst.operands.len()).map(|k| Self::id(inst, k)).collect();
        let val = match base {
            Val::Local { ptr, pointee } => {
                let (lvalue, ty) = self.local_chain(format!("(*{ptr})"), pointee, &indices)?;
                let c = self.m.c_type(ty)?;
                if self.table_pointers.contains(&Self::id(inst, 0)) {
                    self.table_pointers.insert(id);
                    self.decls.push(format!(
                        "#ifdef BRDFPROF_CONST_TABLE\n  BRDFPROF_TABLE_SPACE {c}* _{id};\n#else\n  {c}* _{id};\n#endif"
                    ));
                } else {
                    self.decls.push(format!("{c}* _{id};"));
                }
                self.declared.insert(id);
                writeln!(self.body, "  _{id} = &{lvalue};").unwrap();
                Val::Local { ptr: format!("_{id}"), pointee: ty }
            }
            Val::Buffer { var, off, pointee, matrix_stride } => {
                let (off, ty, stride) = self.buffer_chain(off, pointee, matrix_stride, &indices)?;
                self.decls.push(format!("u32 _{id};"));
                self.declared.insert(id);
                writeln!(self.body, "  _{id} = {off};").unwrap();
                Val::Buffer { var, off: format!("_{id}"), pointee: ty, matrix_stride: stride }
            }
            Val::Image { .. } => return Err(self.err("an access chain into an image")),
        };
        self.vals.insert(id, val);
        Ok(())
    }

    fn local_chain(
        &mut self,
        mut lvalue: String,
        mut ty: Word,
        indices: &[Word],
    ) -> Result<(String, Word), TranslateError> {
        for &i in indices {
            match self.m.ty(ty).clone() {
                Type::Struct { members } => {
                    let k = self.constant_index(i)?;
                    lvalue = format!("{lvalue}.m{k}");
                    ty = members[k as usize];
                }
                Type::Vector { elem, n: len } | Type::Array { elem, len } => {
                    lvalue = format!("{lvalue}.c[{}]", self.index(i, len)?);
                    ty = elem;
                }
                Type::Matrix { column, columns } => {
                    lvalue = format!("{lvalue}.c[{}]", self.index(i, columns)?);
                    ty = column;
                }
                other => return Err(self.err(format!("an access chain through {other:?}"))),
            }
        }
        Ok((lvalue, ty))
    }

    /// The C index of element `id` of a composite of `len` elements: a constant as it is (glslang refuses one
    /// out of range), any other value clamped into the composite, as robust Vulkan drivers treat an
    /// out-of-bounds index (SPIR-V leaves it undefined; unclamped, the C would read or write outside the value).
    pub fn index(&mut self, id: Word, len: u32) -> Result<String, TranslateError> {
        match self.m.constants.get(&id) {
            Some(Constant::Scalar { bits, .. }) if (*bits as u32) < len => Ok((*bits as u32).to_string()),
            _ => Ok(format!("m_index((u32)({}), {len}u)", self.v(id)?)),
        }
    }

    fn constant_index(&self, id: Word) -> Result<u32, TranslateError> {
        match self.m.constants.get(&id) {
            Some(Constant::Scalar { bits, .. }) => Ok(*bits as u32),
            _ => Err(self.err("a struct member chosen by a value that is not a constant")),
        }
    }

    /// Byte offset of a chain into a buffer, from Offset, ArrayStride and MatrixStride.
    fn buffer_chain(
        &mut self,
        mut off: String,
        mut ty: Word,
        mut stride: Option<u32>,
        indices: &[Word],
    ) -> Result<(String, Word, Option<u32>), TranslateError> {
        for &i in indices {
            match self.m.ty(ty).clone() {
                Type::Struct { members } => {
                    let k = self.constant_index(i)?;
                    let o = self
                        .m
                        .member_decoration(ty, k, Decoration::Offset)
                        .and_then(|a| a.first().copied())
                        .ok_or_else(|| self.err("a buffer struct member without an Offset"))?;
                    if self.m.member_decoration(ty, k, Decoration::RowMajor).is_some() {
                        return Err(self.err("a row_major matrix in a buffer"));
                    }
                    stride = self.m.member_decoration(ty, k, Decoration::MatrixStride).and_then(|a| a.first().copied());
                    off = format!("({off} + {o}u)");
                    ty = members[k as usize];
                }
                Type::Array { elem, .. } | Type::RuntimeArray { elem } => {
                    let s = self
                        .m
                        .decoration(ty, Decoration::ArrayStride)
                        .and_then(|a| a.first().copied())
                        .ok_or_else(|| self.err("a buffer array without an ArrayStride"))?;
                    off = format!("({off} + (u32)({}) * {s}u)", self.v(i)?);
                    ty = elem;
                }
                Type::Matrix { column, .. } => {
                    let s = stride.ok_or_else(|| self.err("a buffer matrix without a MatrixStride"))?;
                    off = format!("({off} + (u32)({}) * {s}u)", self.v(i)?);
                    ty = column;
                }
                Type::Vector { elem, .. } => {
                    let size = self.m.scalar(elem).map_err(|e| self.err(e.construct))?.size();
                    off = format!("({off} + (u32)({}) * {size}u)", self.v(i)?);
                    ty = elem;
                }
                other => return Err(self.err(format!("a buffer access chain through {other:?}"))),
            }
        }
        Ok((off, ty, stride))
    }

    /// The binding's C expression, whether the translation may treat it as read-only, and the prelude's
    /// load prefix for it: `ldc` for constant memory (uniform and push-constant blocks), `ldro` for a
    /// read-only storage buffer, `ld` otherwise.
    fn binding(&self, var: Word) -> Result<(String, bool, &'static str), TranslateError> {
        match self.env.globals.get(&var) {
            Some(GlobalRep::Buffer { field, constant: true, .. }) => {
                Ok((format!("BRDFPROF_CONSTANT_REF(env, {field})"), true, "ldc"))
            }
            Some(GlobalRep::Buffer { field, readonly, .. }) | Some(GlobalRep::Image { field, readonly, .. }) => {
                Ok((format!("env->{field}"), *readonly, if *readonly { "ldro" } else { "ld" }))
            }
            _ => Err(self.err("a buffer access to something that is not a binding")),
        }
    }

    /// A value of type `ty` read from `var` at byte offset `off`, member by member.
    fn buffer_load(
        &mut self,
        var: Word,
        off: &str,
        ty: Word,
        matrix_stride: Option<u32>,
    ) -> Result<String, TranslateError> {
        let (field, _, ld) = self.binding(var)?;
        match self.m.ty(ty).clone() {
            Type::Bool => Ok(format!("({ld}_u32({field}, {off}) != 0u)")),
            Type::Int { .. } | Type::Float { .. } => {
                let s = self.m.scalar(ty).map_err(|e| self.err(e.construct))?;
                Ok(format!("{ld}_{}({field}, {off})", scalar_suffix(s)))
            }
            Type::Vector { elem, n } => {
                let s = self.m.scalar(elem).map_err(|e| self.err(e.construct))?;
                // A vec4 of 32-bit words is 16-byte aligned in every buffer layout: one 128-bit load, as a
                // driver issues it.
                if n == 4 && matches!(s, Scalar::F32 | Scalar::U32 | Scalar::I32) {
                    return self.buffer_load_vec4(&field, ld, off, ty, s);
                }
                let parts: Vec<String> = (0..n)
                    .map(|k| self.buffer_load(var, &format!("({off} + {}u)", k * s.size()), elem, None))
                    .collect::<Result<_, _>>()?;
                Ok(format!("mk_{}({})", self.m.c_type(ty)?, parts.join(", ")))
            }
            Type::Matrix { column, columns } => {
                let s = matrix_stride.ok_or_else(|| self.err("a buffer matrix without a MatrixStride"))?;
                let parts: Vec<String> = (0..columns)
                    .map(|k| self.buffer_load(var, &format!("({off} + {}u)", k * s), column, None))
                    .collect::<Result<_, _>>()?;
                Ok(format!("mk_{}({})", self.m.c_type(ty)?, parts.join(", ")))
            }
            Type::Array { elem, len } if len <= 64 => {
                let s = self
                    .m
                    .decoration(ty, Decoration::ArrayStride)
                    .and_then(|a| a.first().copied())
                    .ok_or_else(|| self.err("a buffer array without an ArrayStride"))?;
                let parts: Vec<String> = (0..len)
                    .map(|k| self.buffer_load(var, &format!("({off} + {}u)", k * s), elem, None))
                    .collect::<Result<_, _>>()?;
                Ok(format!("mk_{}({})", self.m.c_type(ty)?, parts.join(", ")))
            }
            Type::Struct { members } => {
                let mut parts = Vec::new();
                for (k, m) in members.iter().enumerate() {
                    let o = self
                        .m
                        .member_decoration(ty, k as u32, Decoration::Offset)
                        .and_then(|a| a.first().copied())
                        .ok_or_else(|| self.err("a buffer struct member without an Offset"))?;
                    let stride = self
                        .m
                        .member_decoration(ty, k as u32, Decoration::MatrixStride)
                        .and_then(|a| a.first().copied());
                    parts.push(self.buffer_load(var, &format!("({off} + {o}u)"), *m, stride)?);
                }
                Ok(format!("mk_{}({})", self.m.c_type(ty)?, parts.join(", ")))
            }
            other => Err(self.err(format!("a buffer load of {other:?}"))),
        }
    }

    /// A vec4 of 32-bit words (`s` its scalar) read from `field` at byte offset `off` in one 128-bit load.
    fn buffer_load_vec4(
        &mut self,
        field: &str,
        ld: &str,
        off: &str,
        ty: Word,
        s: Scalar,
    ) -> Result<String, TranslateError> {
        let (suffix, c) = if s == Scalar::F32 { ("f32", "float") } else { ("u32", "u32") };
        let tmp = format!("q{}_{}", self.decls.len(), self.body.len());
        self.decls.push(format!("{c} {tmp}[4];"));
        writeln!(self.body, "  {ld}4_{suffix}({field}, {off}, {tmp});").unwrap();
        let cast = if s == Scalar::I32 { "(i32)" } else { "" };
        Ok(format!(
            "mk_{}({})",
            self.m.c_type(ty)?,
            (0..4).map(|k| format!("{cast}{tmp}[{k}]")).collect::<Vec<_>>().join(", ")
        ))
    }

    /// Statements writing `value` (a C expression of type `ty`) to `var` at byte offset `off`.
    fn buffer_store(
        &mut self,
        var: Word,
        off: &str,
        ty: Word,
        matrix_stride: Option<u32>,
        value: &str,
    ) -> Result<String, TranslateError> {
        let (field, readonly, _) = self.binding(var)?;
        if readonly {
            return Err(self.err("a store to a read-only binding"));
        }
        let members: Vec<(Word, String, u32, Option<u32>)> = match self.m.ty(ty).clone() {
            Type::Bool => return Ok(format!("  st_u32({field}, {off}, ({value}) ? 1u : 0u);\n")),
            Type::Int { .. } | Type::Float { .. } => {
                let s = self.m.scalar(ty).map_err(|e| self.err(e.construct))?;
                return Ok(format!("  st_{}({field}, {off}, {value});\n", scalar_suffix(s)));
            }
            Type::Vector { elem, n } => {
                let s = self.m.scalar(elem).map_err(|e| self.err(e.construct))?;
                if n == 4 && matches!(s, Scalar::F32 | Scalar::U32 | Scalar::I32) {
                    let (suffix, cast) = if s == Scalar::F32 { ("f32", "") } else { ("u32", "(u32)") };
                    let parts: Vec<String> = (0..4).map(|k| format!("{cast}({value}).c[{k}]")).collect();
                    return Ok(format!("  st4_{suffix}({field}, {off}, {});\n", parts.join(", ")));
                }
                (0..n).map(|k| (elem, format!("c[{k}]"), k * s.size(), None)).collect()
            }
            Type::Matrix { column, columns } => {
                let s = matrix_stride.ok_or_else(|| self.err("a buffer matrix without a MatrixStride"))?;
                (0..columns).map(|k| (column, format!("c[{k}]"), k * s, None)).collect()
            }
            Type::Array { elem, len } => {
                let s = self
                    .m
                    .decoration(ty, Decoration::ArrayStride)
                    .and_then(|a| a.first().copied())
                    .ok_or_else(|| self.err("a buffer array without an ArrayStride"))?;
                (0..len).map(|k| (elem, format!("c[{k}]"), k * s, None)).collect()
            }
            Type::Struct { members } => {
                let mut out = Vec::new();
                for (k, m) in members.iter().enumerate() {
                    let o = self
                        .m
                        .member_decoration(ty, k as u32, Decoration::Offset)
                        .and_then(|a| a.first().copied())
                        .ok_or_else(|| self.err("a buffer struct member without an Offset"))?;
                    out.push((
                        *m,
                        format!("m{k}"),
                        o,
                        self.m
                            .member_decoration(ty, k as u32, Decoration::MatrixStride)
                            .and_then(|a| a.first().copied()),
                    ));
                }
                out
            }
            other => return Err(self.err(format!("a buffer store of {other:?}"))),
        };
        let mut s = String::new();
        for (mty, accessor, o, stride) in members {
            s += &self.buffer_store(var, &format!("({off} + {o}u)"), mty, stride, &format!("({value}).{accessor}"))?;
        }
        Ok(s)
    }

    fn image_read(&mut self, inst: &Instruction) -> Result<(), TranslateError> {
        let Val::Image { var } = self.pointer(Self::id(inst, 0))? else {
            return Err(self.err("an image read of something that is not an image"));
        };
        let Some(GlobalRep::Image { field, format, .. }) = self.env.globals.get(&var).cloned() else {
            return Err(self.err("an image read of an unknown binding"));
        };
        let coord = self.v(Self::id(inst, 1))?;
        let ty = inst.result_type.unwrap_or(0);
        let (scalar, n) = format.texel();
        let tmp = format!("t{}", inst.result_id.unwrap_or(0));
        self.decls.push(format!("{} {tmp}[4];", scalar.c_name()));
        writeln!(self.body, "  tex_ld_{}(env->{field}, (u32)({coord}), {tmp});", format.suffix()).unwrap();
        let fill = |k: u32| {
            if k < n {
                format!("{tmp}[{k}]")
            } else if k == 3 {
                one(scalar)
            } else {
                zero(scalar)
            }
        };
        let parts: Vec<String> = (0..self.m.components(ty)).map(fill).collect();
        self.assign(inst, format!("mk_{}({})", self.m.c_type(ty)?, parts.join(", ")))
    }

    fn image_write(&mut self, inst: &Instruction) -> Result<(), TranslateError> {
        let Val::Image { var } = self.pointer(Self::id(inst, 0))? else {
            return Err(self.err("an image write to something that is not an image"));
        };
        let Some(GlobalRep::Image { field, format, readonly }) = self.env.globals.get(&var).cloned() else {
            return Err(self.err("an image write to an unknown binding"));
        };
        if readonly {
            return Err(self.err("an image write to a sampled (read-only) binding"));
        }
        let coord = self.v(Self::id(inst, 1))?;
        let texel = self.v(Self::id(inst, 2))?;
        let n = self.m.components(self.m.type_of(Self::id(inst, 2)).unwrap_or(0));
        let parts: Vec<String> = (0..format.texel().1)
            .map(|k| if k < n { format!("{texel}.c[{k}]") } else { zero(format.texel().0) })
            .collect();
        writeln!(self.body, "  tex_st_{}(env->{field}, (u32)({coord}), {});", format.suffix(), parts.join(", "))
            .unwrap();
        Ok(())
    }
}

/// The C name of function `id`: `fn_main` for the entry point, else `fnID_name`.
pub fn function_name(m: &ModuleInfo, id: Word) -> String {
    if id == m.entry {
        return "fn_main".into();
    }
    match m.name(id) {
        Some(n) => format!("fn{id}_{}", super::ctypes::sanitize(n)),
        None => format!("fn{id}"),
    }
}

/// The suffix of the prelude's buffer load and store functions for a scalar.
fn scalar_suffix(s: Scalar) -> &'static str {
    match s {
        Scalar::Bool | Scalar::U32 => "u32",
        Scalar::I32 => "i32",
        Scalar::F16 => "f16",
        Scalar::F32 => "f32",
        Scalar::F64 => "f64",
    }
}

fn zero(s: Scalar) -> String {
    match s {
        Scalar::F32 => "0.0f".into(),
        Scalar::I32 => "0".into(),
        _ => "0u".into(),
    }
}

fn one(s: Scalar) -> String {
    match s {
        Scalar::F32 => "1.0f".into(),
        Scalar::I32 => "1".into(),
        _ => "1u".into(),
    }
}

/// The qualifiers of the module's own functions where they carry `#line` directives
/// (`Translation::source_with_lines` defines it): the prelude's helpers may then differ from them.
pub(super) const LINED_FN: &str = "BRDFPROF_LINED_FN";

/// A source name as a `#line` directive gives it to a C compiler: absolute (the compilers run in their own
/// directories and would otherwise resolve it there), with forward slashes and no quotes.
fn absolute_source(file: &str) -> String {
    let path = std::path::Path::new(file);
    let path = if path.is_relative() {
        std::env::current_dir().map(|d| d.join(path)).unwrap_or_else(|_| path.to_path_buf())
    } else {
        path.to_path_buf()
    };
    path.to_string_lossy().replace('\\', "/").replace('"', "")
}

/// The function variables of `f` that only ever hold one lookup table (`constants::is_table`): each store to
/// the variable stores that table, whole (or it is the variable's initializer), and the variable and every
/// access chain into it are only loaded or chained further (never stored through, passed or copied). GLSL's
/// `const float T[64] = ...; T[i]` is such a variable in glslang's SPIR-V; read in place, it is the table.
fn tables(m: &ModuleInfo, f: &Function) -> HashMap<Word, Word> {
    let insts: Vec<&Instruction> = f.blocks.iter().flat_map(|b| &b.instructions).collect();
    let ids = |i: &Instruction| -> Vec<Word> {
        i.operands.iter().filter_map(|o| if let Operand::IdRef(x) = o { Some(*x) } else { None }).collect()
    };
    let mut out = HashMap::new();
    for var in insts.iter().filter(|i| i.class.opcode == Op::Variable) {
        let id = var.result_id.unwrap_or(0);
        let mut table = ids(var).first().copied();
        let mut derived: HashSet<Word> = [id].into();
        let mut ok = table.is_none_or(|t| super::constants::is_table(m, t));
        // Chains into the variable first (a chain of a chain included), then every use of them.
        loop {
            let before = derived.len();
            for i in &insts {
                if matches!(i.class.opcode, Op::AccessChain | Op::InBoundsAccessChain)
                    && ids(i).first().is_some_and(|b| derived.contains(b))
                {
                    derived.insert(i.result_id.unwrap_or(0));
                }
            }
            if derived.len() == before {
                break;
            }
        }
        for i in insts.iter().filter(|i| i.result_id != Some(id)) {
            let used: Vec<Word> = ids(i);
            if !used.iter().any(|u| derived.contains(u)) {
                continue;
            }
            ok &= match i.class.opcode {
                Op::Load | Op::AccessChain | Op::InBoundsAccessChain => !used[1..].iter().any(|u| derived.contains(u)),
                Op::Store if used.first() == Some(&id) && !derived.contains(&used[1]) => {
                    let t = used[1];
                    let same = table.is_none_or(|x| x == t) && super::constants::is_table(m, t);
                    table = Some(t);
                    same
                }
                _ => false,
            };
        }
        if let (true, Some(t)) = (ok, table) {
            out.insert(id, t);
        }
    }
    out
}
