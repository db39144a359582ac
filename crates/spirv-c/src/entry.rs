//! The kernel's interface: its bindings, built-in inputs and private globals gathered into one per-invocation
//! `Env` struct, which every translated function receives, and the entry wrapper of each dialect, written once
//! here, that fills `Env` from the dialect's kernel arguments and invocation ids and calls the entry point.

use super::module::{ModuleInfo, Type};
use super::{Dialect, TexelFormat, TranslateError, TranslateOptions};
use rspirv::spirv::{BuiltIn, Decoration, StorageClass, Word};
use std::collections::BTreeMap;
use std::fmt::Write;

/// How a global variable is reached from a translated function.
#[derive(Clone, Debug)]
pub enum GlobalRep {
    /// A storage, uniform or push-constant buffer: `env->field` is its first byte; a uniform or push-constant
    /// block (`constant`) is in the dialect's constant memory (`BRDFPROF_CONSTANT_REF`).
    Buffer { field: String, readonly: bool, pointee: Word, constant: bool },
    /// A texel buffer of `format`.
    Image { field: String, format: TexelFormat, readonly: bool },
    /// Per-invocation memory in `Env` (private globals, built-in inputs).
    Local { field: String, pointee: Word },
}

/// What a kernel argument is, in the order the wrappers take them.
#[derive(Clone, Debug, PartialEq)]
pub enum BindingKind {
    StorageBuffer { readonly: bool },
    UniformBuffer,
    PushConstant,
    TexelBuffer { format: TexelFormat, storage: bool },
}

#[derive(Clone, Debug)]
pub struct EnvBinding {
    /// (descriptor set, binding); push constants come last, as (u32::MAX, 0).
    pub slot: (u32, u32),
    pub kind: BindingKind,
    pub field: String,
}

#[derive(Clone, Debug, Default)]
pub struct EnvLayout {
    pub globals: BTreeMap<Word, GlobalRep>,
    pub bindings: Vec<EnvBinding>,
    inputs: Vec<(String, BuiltIn, Word)>,
    privates: Vec<(String, Word, Option<Word>)>,
}

/// Storage classes whose pointers are C pointers to per-invocation memory.
pub fn is_local_class(class: StorageClass) -> bool {
    matches!(class, StorageClass::Function | StorageClass::Private | StorageClass::Input)
}

fn unsupported(construct: String) -> TranslateError {
    TranslateError::new(construct)
}

impl EnvLayout {
    pub fn of(m: &ModuleInfo, options: &TranslateOptions) -> Result<Self, TranslateError> {
        let mut layout = EnvLayout::default();
        for (&id, g) in &m.globals {
            let slot = (
                m.decoration(id, Decoration::DescriptorSet).and_then(|a| a.first().copied()).unwrap_or(0),
                m.decoration(id, Decoration::Binding).and_then(|a| a.first().copied()).unwrap_or(0),
            );
            let field = format!("b{}_{}", slot.0, slot.1);
            let (rep, kind) = match g.class {
                StorageClass::StorageBuffer | StorageClass::Uniform => {
                    let ssbo = g.class == StorageClass::StorageBuffer
                        || m.decoration(g.pointee, Decoration::BufferBlock).is_some();
                    let readonly = !ssbo || buffer_is_readonly(m, id, g.pointee);
                    let kind = if ssbo { BindingKind::StorageBuffer { readonly } } else { BindingKind::UniformBuffer };
                    (
                        GlobalRep::Buffer { field: field.clone(), readonly, pointee: g.pointee, constant: !ssbo },
                        Some((slot, kind, field)),
                    )
                }
                StorageClass::PushConstant => (
                    GlobalRep::Buffer { field: "push".into(), readonly: true, pointee: g.pointee, constant: true },
                    Some(((u32::MAX, 0), BindingKind::PushConstant, "push".to_string())),
                ),
                StorageClass::UniformConstant => {
                    let (format, storage) = texel_binding(m, g.pointee, slot, options)?;
                    let rep = GlobalRep::Image { field: field.clone(), format, readonly: !storage };
                    (rep, Some((slot, BindingKind::TexelBuffer { format, storage }, field)))
                }
                StorageClass::Input => {
                    let b =
                        m.builtin(id).ok_or_else(|| unsupported("an input variable that is not a built-in".into()))?;
                    if !matches!(
                        b,
                        BuiltIn::GlobalInvocationId
                            | BuiltIn::LocalInvocationId
                            | BuiltIn::WorkgroupId
                            | BuiltIn::NumWorkgroups
                            | BuiltIn::LocalInvocationIndex
                    ) {
                        return Err(unsupported(format!("the built-in {b:?}")));
                    }
                    let field = format!("in{id}");
                    layout.inputs.push((field.clone(), b, g.pointee));
                    (GlobalRep::Local { field, pointee: g.pointee }, None)
                }
                StorageClass::Private => {
                    let field = format!("pv{id}");
                    layout.privates.push((field.clone(), g.pointee, g.initializer));
                    (GlobalRep::Local { field, pointee: g.pointee }, None)
                }
                other => {
                    return Err(unsupported(format!(
                        "a global variable in {other:?} memory (shared memory, atomics or outputs)"
                    )));
                }
            };
            layout.globals.insert(id, rep);
            if let Some((slot, kind, field)) = kind {
                layout.bindings.push(EnvBinding { slot, kind, field });
            }
        }
        layout.bindings.sort_by_key(|b| b.slot);
        Ok(layout)
    }

    /// The `Env` struct, after the constant blocks it reads (`BRDFPROF_CONSTANT_BLOCK`: CUDA's `__constant__`
    /// arrays; nothing in the dialects whose constant memory is a kernel argument).
    pub fn declaration(&self, m: &ModuleInfo) -> Result<String, TranslateError> {
        let mut s = String::new();
        for b in self.bindings.iter().filter(|b| b.kind.is_constant()) {
            let ty = self.globals.values().find_map(|g| match g {
                GlobalRep::Buffer { field, pointee, .. } if *field == b.field => Some(*pointee),
                _ => None,
            });
            let bytes = ty.and_then(|t| block_size(m, t)).ok_or_else(|| {
                unsupported(format!(
                    "a uniform or push-constant block ({}) whose size its layout does not give",
                    b.field
                ))
            })?;
            writeln!(s, "BRDFPROF_CONSTANT_BLOCK({}, {bytes})", b.field).unwrap();
        }
        s += "typedef struct {\n";
        for b in &self.bindings {
            match &b.kind {
                k if k.is_constant() => writeln!(s, "  BRDFPROF_CONSTANT_FIELD({})", b.field).unwrap(),
                BindingKind::TexelBuffer { format: TexelFormat::R11g11b10f, storage: true } => {
                    writeln!(s, "  BRDFPROF_SURFACE_FIELD({})", b.field).unwrap()
                }
                k => {
                    writeln!(s, "  GLOBAL {}u8* {};", if binding_readonly(k) { "const " } else { "" }, b.field).unwrap()
                }
            }
        }
        for (field, _, ty) in &self.inputs {
            writeln!(s, "  {} {field};", m.c_type(*ty)?).unwrap();
        }
        for (field, ty, _) in &self.privates {
            writeln!(s, "  {} {field};", m.c_type(*ty)?).unwrap();
        }
        s += "  u32 loop_iterations;\n  u32 flags;\n} Env;\n";
        Ok(s)
    }

    /// Statements that fill `env` (a local `Env`) given the dialect's invocation ids `gid[k]`, `lid[k]`,
    /// `wg[k]`, `nwg[k]`, then call the entry point.
    fn fill(
        &self,
        m: &ModuleInfo,
        dialect: Dialect,
        ids: &dyn Fn(&str, u32) -> String,
        local_size: [u32; 3],
    ) -> Result<String, TranslateError> {
        let mut s = String::from("  BRDFPROF_INVOCATION_BEGIN();\n");
        // CUDA's constant blocks are module `__constant__` arrays, not `Env` fields.
        for b in self.bindings.iter().filter(|b| !(dialect == Dialect::Cuda && b.kind.is_constant())) {
            writeln!(s, "  env.{0} = {0};", b.field).unwrap();
        }
        for (field, builtin, ty) in &self.inputs {
            let parts: Vec<String> = match builtin {
                BuiltIn::GlobalInvocationId => (0..3).map(|k| ids("gid", k)).collect(),
                BuiltIn::LocalInvocationId => (0..3).map(|k| ids("lid", k)).collect(),
                BuiltIn::WorkgroupId => (0..3).map(|k| ids("wg", k)).collect(),
                BuiltIn::NumWorkgroups => (0..3).map(|k| ids("nwg", k)).collect(),
                _ => vec![format!(
                    "({} + {}u * ({} + {}u * {}))",
                    ids("lid", 0),
                    local_size[0],
                    ids("lid", 1),
                    local_size[1],
                    ids("lid", 2)
                )],
            };
            let value =
                if parts.len() > 1 { format!("mk_{}({})", m.c_type(*ty)?, parts.join(", ")) } else { parts[0].clone() };
            writeln!(s, "  env.{field} = {value};").unwrap();
        }
        for (field, ty, init) in &self.privates {
            let value = match init {
                Some(i) => super::constants::expr(m, *i)?,
                None => m.zero(*ty)?,
            };
            writeln!(s, "  env.{field} = {value};").unwrap();
        }
        s += "  env.loop_iterations = 0u;\n  env.flags = 0u;\n  fn_main(&env);\n";
        Ok(s)
    }

    /// The dialect's kernel entry (for the host: the function that runs every invocation of a dispatch).
    pub fn wrapper(&self, m: &ModuleInfo, dialect: Dialect, local_size: [u32; 3]) -> Result<String, TranslateError> {
        let threads = local_size.iter().product::<u32>();
        Ok(match dialect {
            Dialect::Cuda => {
                let ids = |name: &str, k: u32| {
                    let c = ["x", "y", "z"][k as usize];
                    match name {
                        "gid" => format!("(u32)(blockIdx.{c} * blockDim.{c} + threadIdx.{c})"),
                        "lid" => format!("(u32)threadIdx.{c}"),
                        "wg" => format!("(u32)blockIdx.{c}"),
                        _ => format!("(u32)gridDim.{c}"),
                    }
                };
                format!(
                    "extern \"C\" __global__ void __launch_bounds__({threads}) brdfprof_kernel({}) {{\n  Env env;\n{}}}\n",
                    self.params(dialect),
                    self.fill(m, dialect, &ids, local_size)?
                )
            }
            Dialect::OpenCl => {
                let ids = |name: &str, k: u32| match name {
                    "gid" => format!("(u32)get_global_id({k})"),
                    "lid" => format!("(u32)get_local_id({k})"),
                    "wg" => format!("(u32)get_group_id({k})"),
                    _ => format!("(u32)get_num_groups({k})"),
                };
                let [x, y, z] = local_size;
                format!(
                    "__kernel __attribute__((reqd_work_group_size({x}, {y}, {z}))) void brdfprof_kernel({}) {{\n  Env env;\n{}}}\n",
                    self.params(dialect),
                    self.fill(m, dialect, &ids, local_size)?
                )
            }
            Dialect::Host => self.host_wrapper(m, local_size)?,
        })
    }

    /// The kernel parameters of `dialect`'s entry, one per binding: storage buffers as global pointers
    /// (read-only ones `__restrict__` in CUDA), constant blocks as `__constant` pointers in OpenCL C (CUDA's
    /// are `__constant__` arrays, no parameter), a writable R11G11B10F texel buffer as a CUDA surface object.
    fn params(&self, dialect: Dialect) -> String {
        let param = |b: &EnvBinding| -> Option<String> {
            let (ro, f) = (binding_readonly(&b.kind), &b.field);
            Some(match (dialect, &b.kind) {
                (Dialect::Cuda, k) if k.is_constant() => return None,
                (Dialect::Cuda, BindingKind::TexelBuffer { format: TexelFormat::R11g11b10f, storage: true }) => {
                    format!("unsigned long long {f}")
                }
                (Dialect::Cuda, _) => {
                    format!("{}u8*{} {f}", if ro { "const " } else { "" }, if ro { " __restrict__" } else { "" })
                }
                (_, k) if k.is_constant() => format!("__constant u8* {f}"),
                _ => format!("__global {}u8* {f}", if ro { "const " } else { "" }),
            })
        };
        self.bindings.iter().filter_map(param).collect::<Vec<_>>().join(", ")
    }

    /// `brdfprof_host_run(bindings, groups_x, groups_y, groups_z)`: every invocation in order; returns the
    /// union of their flags (1: an invocation stopped at the loop limit).
    fn host_wrapper(&self, m: &ModuleInfo, local_size: [u32; 3]) -> Result<String, TranslateError> {
        let ids = |name: &str, k: u32| {
            let c = ["x", "y", "z"][k as usize];
            match name {
                "gid" => format!("(w{c} * {}u + l{c})", local_size[k as usize]),
                "lid" => format!("l{c}"),
                "wg" => format!("w{c}"),
                _ => format!("n{c}"),
            }
        };
        let mut s = String::from(
            "extern \"C\" u32 brdfprof_host_run(u8* const* bindings, u32 nx, u32 ny, u32 nz, u64* loop_passes) {\n  u32 flags = 0u;\n",
        );
        for (k, b) in self.bindings.iter().enumerate() {
            writeln!(s, "  u8* {} = bindings[{k}];", b.field).unwrap();
        }
        let [x, y, z] = local_size;
        writeln!(
            s,
            "  for (u32 wz = 0u; wz < nz; ++wz) for (u32 wy = 0u; wy < ny; ++wy) for (u32 wx = 0u; wx < nx; ++wx)"
        )
        .unwrap();
        writeln!(s, "  for (u32 lz = 0u; lz < {z}u; ++lz) for (u32 ly = 0u; ly < {y}u; ++ly) for (u32 lx = 0u; lx < {x}u; ++lx) {{\n  Env env;").unwrap();
        s += &self.fill(m, Dialect::Host, &ids, local_size)?;
        s += "  flags |= env.flags;\n  *loop_passes += env.loop_iterations;\n  }\n  return flags;\n}\n";
        Ok(s)
    }
}

impl BindingKind {
    /// A uniform or push-constant block: in the dialect's constant memory.
    pub fn is_constant(&self) -> bool {
        matches!(self, BindingKind::UniformBuffer | BindingKind::PushConstant)
    }
}

/// Bytes a block of type `ty` spans in its buffer, from its layout decorations (None: a runtime array, or a
/// member without an Offset).
fn block_size(m: &ModuleInfo, ty: Word) -> Option<u32> {
    match m.ty(ty).clone() {
        Type::Bool => Some(4),
        Type::Int { width, .. } | Type::Float { width } => Some(width / 8),
        Type::Vector { elem, n } => Some(n * block_size(m, elem)?),
        Type::Array { len, .. } => Some(len * m.decoration(ty, Decoration::ArrayStride)?.first().copied()?),
        Type::Struct { members } => members.iter().enumerate().try_fold(0, |end, (k, &t)| {
            let offset = m.member_decoration(ty, k as u32, Decoration::Offset)?.first().copied()?;
            let size = match (m.ty(t).clone(), m.member_decoration(ty, k as u32, Decoration::MatrixStride)) {
                (Type::Matrix { columns, .. }, Some(stride)) => columns * stride.first().copied()?,
                _ => block_size(m, t)?,
            };
            Some(end.max(offset + size))
        }),
        _ => None,
    }
}

fn binding_readonly(kind: &BindingKind) -> bool {
    match kind {
        BindingKind::StorageBuffer { readonly } => *readonly,
        BindingKind::UniformBuffer | BindingKind::PushConstant => true,
        BindingKind::TexelBuffer { storage, .. } => !storage,
    }
}

/// A storage buffer is read-only when the variable or every member of its block is NonWritable.
fn buffer_is_readonly(m: &ModuleInfo, var: Word, block: Word) -> bool {
    if m.decoration(var, Decoration::NonWritable).is_some() {
        return true;
    }
    match m.ty(block) {
        Type::Struct { members } => {
            (0..members.len() as u32).all(|k| m.member_decoration(block, k, Decoration::NonWritable).is_some())
        }
        _ => false,
    }
}

/// The texel format and access of an image binding: a storage texel buffer's format from its type, a sampled
/// one's from the options (Vulkan gives it in the buffer view, not in the shader).
fn texel_binding(
    m: &ModuleInfo,
    ty: Word,
    slot: (u32, u32),
    options: &TranslateOptions,
) -> Result<(TexelFormat, bool), TranslateError> {
    let image = match m.ty(ty) {
        Type::SampledImage { image } => *image,
        Type::Image { .. } => ty,
        _ => {
            return Err(unsupported(
                "a uniform-constant variable that is not an image (a sampler or an opaque type)".into(),
            ));
        }
    };
    let Type::Image { dim, format, storage, .. } = m.ty(image).clone() else {
        return Err(unsupported("a sampled image of something that is not an image".into()));
    };
    if dim != rspirv::spirv::Dim::DimBuffer {
        return Err(unsupported(format!("an image of dimension {dim:?} (only texel buffers are translated)")));
    }
    let format = match (format, options.texel_formats.get(&slot)) {
        (_, Some(f)) => *f,
        (rspirv::spirv::ImageFormat::Unknown, None) => {
            return Err(unsupported(format!(
                "a texel buffer at set {} binding {} whose view format the caller did not give",
                slot.0, slot.1
            )));
        }
        (f, None) => TexelFormat::from_spirv(f).ok_or_else(|| unsupported(format!("the texel format {f:?}")))?,
    };
    Ok((format, storage))
}
