//! SPIR-V compute kernels translated mechanically into C dialects, so that compilers that take no Vulkan
//! SPIR-V (NVIDIA's NVRTC/ptxas: CUDA C++; Intel's IGC: OpenCL C) compile the very kernel a Vulkan driver
//! compiles, and so that the translation can be run on the CPU (the CUDA C++ text under g++; the OpenCL C text
//! under PoCL) and checked against the Vulkan kernel before its cost is believed.
//!
//! Why from SPIR-V (and not naga's IR or the GLSL): the SPIR-V glslang emits is what every Vulkan driver
//! compiles, specialised by spirv-opt exactly as `inspect` counts it; every result carries its type; texel
//! buffers and the specialisation-constant operations of the fp16 kernels are representable (naga 30's
//! SPIR-V reader refuses both); and a user's `.brdf` file reaches it through the same glslang composition as
//! the Vulkan kernel. The control flow is kept as the SPIR-V's own block graph (labels and gotos), which C and
//! both dialects express exactly without restructuring. What the translation cannot express is an error naming
//! the construct, the function and, where the module has line information, the source line.
//!
//! One translator, three preludes (`prelude/`): the body (types, `Env`, functions) is the same text in every
//! dialect; a dialect is its prelude (scalar types, math and buffer access) and its entry wrapper.

mod body;
mod constants;
mod ctypes;
mod entry;
mod ext;
pub mod flatten;
mod module;
mod ops;

pub use entry::{BindingKind, EnvBinding};

use module::ModuleInfo;
use rspirv::spirv::ImageFormat;
use std::collections::BTreeMap;
use std::fmt;

/// The C dialects the translation is printed in.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Dialect {
    /// CUDA C++ for NVRTC.
    Cuda,
    /// OpenCL C 1.2 for IGC (ocloc) and PoCL.
    OpenCl,
    /// The CUDA C++ text compiled for the CPU by g++, with a prelude that defines CUDA's names on the host.
    Host,
}

impl Dialect {
    pub fn name(self) -> &'static str {
        match self {
            Dialect::Cuda => "CUDA C++",
            Dialect::OpenCl => "OpenCL C",
            Dialect::Host => "C++ (host)",
        }
    }

    fn prelude(self) -> &'static str {
        match self {
            Dialect::Cuda => include_str!("prelude/cuda.h"),
            Dialect::OpenCl => include_str!("prelude/opencl.h"),
            Dialect::Host => concat!(
                include_str!("prelude/host_maths.h"),
                include_str!("prelude/host.h"),
                include_str!("prelude/host_doubles.h")
            ),
        }
    }
}

/// The C text shared by every dialect's prelude (after the dialect's own part).
const COMMON_PRELUDE: &str = include_str!("prelude/common.h");
/// The f64 reference's prelude (before the common part) and what it defines after it.
const REFERENCE_PRELUDE: &str = concat!(
    include_str!("prelude/host_maths.h"),
    include_str!("prelude/reference.h"),
    include_str!("prelude/host_doubles.h")
);
const REFERENCE_TAIL: &str = include_str!("prelude/reference_tail.h");

/// Texel formats of the texel buffers the translation reads and writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TexelFormat {
    Rgba32ui,
    Rgba32f,
    R32ui,
    R32f,
    R11g11b10f,
    Rgba8,
}

impl TexelFormat {
    pub fn from_spirv(f: ImageFormat) -> Option<Self> {
        Some(match f {
            ImageFormat::Rgba32ui => TexelFormat::Rgba32ui,
            ImageFormat::Rgba32f => TexelFormat::Rgba32f,
            ImageFormat::R32ui => TexelFormat::R32ui,
            ImageFormat::R32f => TexelFormat::R32f,
            ImageFormat::R11fG11fB10f => TexelFormat::R11g11b10f,
            ImageFormat::Rgba8 => TexelFormat::Rgba8,
            _ => return None,
        })
    }

    /// The prelude's `tex_ld_`/`tex_st_` suffix.
    fn suffix(self) -> &'static str {
        match self {
            TexelFormat::Rgba32ui => "rgba32ui",
            TexelFormat::Rgba32f => "rgba32f",
            TexelFormat::R32ui => "r32ui",
            TexelFormat::R32f => "r32f",
            TexelFormat::R11g11b10f => "r11g11b10f",
            TexelFormat::Rgba8 => "rgba8",
        }
    }

    /// The scalar a texel holds in the shader and how many of them.
    fn texel(self) -> (ctypes::Scalar, u32) {
        match self {
            TexelFormat::Rgba32ui => (ctypes::Scalar::U32, 4),
            TexelFormat::R32ui => (ctypes::Scalar::U32, 1),
            TexelFormat::Rgba32f | TexelFormat::Rgba8 => (ctypes::Scalar::F32, 4),
            TexelFormat::R32f => (ctypes::Scalar::F32, 1),
            TexelFormat::R11g11b10f => (ctypes::Scalar::F32, 3),
        }
    }

    /// Bytes per texel in the buffer.
    pub fn bytes(self) -> u32 {
        match self {
            TexelFormat::Rgba32ui | TexelFormat::Rgba32f => 16,
            _ => 4,
        }
    }
}

#[derive(Clone, Debug, Default)]
pub struct TranslateOptions {
    /// The view format of each sampled texel buffer, by (descriptor set, binding).
    pub texel_formats: BTreeMap<(u32, u32), TexelFormat>,
    /// `#line N "FILE"` before the statements of each source line the module's OpLine names, so that the C
    /// compiler's line information maps machine code to the kernel's sources (`inspect --lines`).
    pub line_directives: bool,
}

/// The file name `#line` gives the translation's own statements (the harness, the entry wrapper), which no
/// source line owns.
pub const TRANSLATION_FILE: &str = "brdfprof-translation";

/// Where in the source a construct is, from the module's OpLine.
#[derive(Clone, Debug, PartialEq)]
pub struct Location {
    pub file: String,
    pub line: u32,
}

/// A construct the translation cannot express.
#[derive(Clone, Debug, PartialEq)]
pub struct TranslateError {
    pub construct: String,
    /// The GLSL function it is in.
    pub function: Option<String>,
    pub location: Option<Location>,
}

impl TranslateError {
    pub fn new(construct: String) -> Self {
        TranslateError { construct, function: None, location: None }
    }
}

impl fmt::Display for TranslateError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "the C translation cannot express {}", self.construct)?;
        if let Some(func) = &self.function {
            write!(f, " (in function `{func}`)")?;
        }
        if let Some(l) = &self.location {
            write!(f, " at {}:{}", l.file, l.line)?;
        }
        Ok(())
    }
}

impl std::error::Error for TranslateError {}

/// What the kernel needs from a dialect: which optional scalar types it computes with.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Features {
    pub f16: bool,
    pub f64: bool,
}

/// A translated kernel: the dialect-independent body and what the wrappers need.
#[derive(Clone, Debug)]
pub struct Translation {
    body: String,
    wrappers: [String; 3],
    pub bindings: Vec<EnvBinding>,
    pub local_size: [u32; 3],
    pub features: Features,
}

/// `text` with its last `#line` directive repeated before every further line of code: a directive numbers
/// the lines after it, so one source line written as several C lines would otherwise name the lines below it.
fn pin_line_directives(text: &str) -> String {
    let mut out = String::with_capacity(text.len() * 2);
    let mut current: Option<&str> = None;
    let mut just_set = false;
    for line in text.lines() {
        let directive = line.starts_with("#line ");
        if directive {
            current = Some(line);
        } else if let (Some(d), false) = (current, just_set) {
            out += d;
            out.push('\n');
        }
        out += line;
        out.push('\n');
        just_set = directive;
    }
    out
}

/// Translates a compute kernel (specialised SPIR-V words, see `prepare`).
pub fn translate(words: &[u32], options: &TranslateOptions) -> Result<Translation, TranslateError> {
    let m = ModuleInfo::read(words)?;
    let layout = entry::EnvLayout::of(&m, options)?;
    let mut body = m.type_declarations()?;
    body += &constants::large_composites(&m)?;
    body += &layout.declaration(&m)?;
    let mut prototypes = String::new();
    let mut functions = String::new();
    for f in &m.functions {
        let w = body::FunctionWriter::new(&m, &layout, f, options.line_directives);
        let text = w.write(f)?;
        prototypes += text.lines().next().unwrap_or_default().trim_end_matches(" {");
        prototypes += ";\n";
        functions += &text;
        if options.line_directives {
            functions += &format!("#line 1 \"{TRANSLATION_FILE}\"\n");
        }
    }
    body += &prototypes;
    body += &if options.line_directives { pin_line_directives(&functions) } else { functions };
    let wrappers = [Dialect::Cuda, Dialect::OpenCl, Dialect::Host].map(|d| layout.wrapper(&m, d, m.local_size));
    let [cuda, opencl, host] = wrappers;
    let features = Features {
        f16: m.types.values().any(|t| *t == module::Type::Float { width: 16 }),
        f64: m.types.values().any(|t| *t == module::Type::Float { width: 64 }),
    };
    Ok(Translation {
        body,
        wrappers: [cuda?, opencl?, host?],
        bindings: layout.bindings,
        local_size: m.local_size,
        features,
    })
}

impl Translation {
    /// The whole source in `dialect`: prelude, body, entry wrapper.
    pub fn source(&self, dialect: Dialect) -> String {
        let wrapper = self.entry_wrapper(dialect);
        let mut s = String::new();
        if self.features.f64 && dialect == Dialect::OpenCl {
            s += "#pragma OPENCL EXTENSION cl_khr_fp64 : enable\n#define BRDFPROF_F64 1\n";
        }
        if self.features.f16 && dialect == Dialect::OpenCl {
            s += "#pragma OPENCL EXTENSION cl_khr_fp16 : enable\n";
        }
        format!(
            "// Generated by brdfprof from SPIR-V: {}.\n{s}{}{COMMON_PRELUDE}\n// ---- the kernel ----\n{}\n{wrapper}",
            dialect.name(),
            dialect.prelude(),
            self.body
        )
    }

    /// `source` of a translation made with `TranslateOptions::line_directives`, for a compiler's line
    /// information: what comes before the module's first line named as the translation's own
    /// (`TRANSLATION_FILE`), and in OpenCL C the prelude's helpers without debug information, so that LLVM's
    /// inliner gives their code the call site's line (IGC names no inlining chain; nvdisasm does).
    pub fn source_with_lines(&self, dialect: Dialect) -> String {
        let qualifiers = match dialect {
            Dialect::OpenCl => format!(
                "#define BRDFPROF_FN static inline __attribute__((always_inline, nodebug))\n#define {} static inline\n",
                body::LINED_FN
            ),
            _ => format!("#define {} BRDFPROF_FN\n", body::LINED_FN),
        };
        format!("{qualifiers}#line 1 \"{TRANSLATION_FILE}\"\n{}", self.source(dialect))
    }

    /// The host text of the f64 reference (`prelude/reference.h`): the body and host wrapper of `source(Host)`
    /// with every f32 and f16 value a (value, Vulkan precision bound) pair computed in double.
    pub fn reference_source(&self) -> String {
        format!(
            "// Generated by brdfprof from SPIR-V: the f64 reference.\n{REFERENCE_PRELUDE}{COMMON_PRELUDE}{REFERENCE_TAIL}\n// ---- the kernel ----\n{}\n{}",
            self.body, self.wrappers[2]
        )
    }

    /// The entry wrapper of `dialect` alone: its kernel arguments, `Env` filled, the entry point called.
    pub fn entry_wrapper(&self, dialect: Dialect) -> &str {
        match dialect {
            Dialect::Cuda => &self.wrappers[0],
            Dialect::OpenCl => &self.wrappers[1],
            Dialect::Host => &self.wrappers[2],
        }
    }

    /// The body alone (types, Env, functions): the same text in every dialect.
    pub fn body(&self) -> &str {
        &self.body
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn each_line_of_code_keeps_its_directives_line() {
        let text = "int f() {\n#line 7 \"a\"\nint x = 1;\nint y = x;\n#line 9 \"a\"\nreturn y;\n}\n";
        let pinned = super::pin_line_directives(text);
        assert_eq!(
            pinned,
            "int f() {\n#line 7 \"a\"\nint x = 1;\n#line 7 \"a\"\nint y = x;\n#line 9 \"a\"\nreturn y;\n#line 9 \"a\"\n}\n"
        );
    }
}
