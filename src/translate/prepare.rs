//! The SPIR-V a translation starts from: a model's kernel specialised exactly as `inspect` counts it
//! (`spirv::specialise`: constants set and frozen, the code they do not select removed), then brought to the
//! form a Vulkan driver's own front end gives its backend before that backend optimises, with no pass that
//! changes a value (`PASSES`):
//!
//! 1. functions inlined and in SSA form, the loops `[[unroll]]` marks unrolled (`INLINE_PASSES`), as a driver
//!    inlines everything and honours the hint;
//! 2. side-effect-free selections of at most 8 instructions a side flattened into OpSelect (`flatten`), as
//!    Mesa's `nir_opt_peephole_select` does for RADV;
//! 3. identical computations merged and dead code removed (`CSE_PASSES`: spirv-opt's value numbering), so a
//!    per-light invariant (Burley's GTR normaliser) is computed once per invocation, as ACO computes it.
//!
//! None of these rounds differently: inlining, SSA, unrolling and dead-code removal move no arithmetic;
//! flattening computes a side whose result is then unused where the branch was not taken; value numbering
//! replaces an instruction by an identical earlier one. Constant folding, algebraic simplification and
//! contraction are left to the target's compiler (spirv-opt's would change values). The result is tested
//! bit for bit against the unflattened translation on the host (tests/kernels/translation.rs). A construct the
//! translation cannot express is located in the plainly prepared module (`PLAIN_PASSES`), whose functions
//! are the source's.

use super::{TexelFormat, TranslateError, TranslateOptions, Translation, translate};
use crate::gpu::SpecConstants;
use crate::kernels::shade::{self, GBufferFormat};
use crate::model::file_model::FileModel;
use crate::model::{KernelKind, Model};
use crate::shaders::Shaders;
use crate::spirv;
use anyhow::{Result, anyhow};

/// spirv-opt passes after specialisation: inlining, SSA form, unrolling, dead code (bindings kept).
pub const INLINE_PASSES: [&str; 10] = [
    // Every binding stays, used or not: the caller passes them all (a constant BRDF reads no input).
    "--preserve-bindings",
    // One return per function first: spirv-opt inlines no function that returns before its end.
    "--merge-return",
    "--inline-entry-points-exhaustive",
    "--eliminate-dead-functions",
    // A private global (a .brdf file's parameters and inputs) used by the one function left is its local.
    "--private-to-local",
    "--eliminate-local-single-block",
    "--eliminate-local-single-store",
    "--ssa-rewrite",
    "--eliminate-dead-code-aggressive",
    "--loop-unroll",
];

/// spirv-opt passes after flattening: value numbering (an instruction identical to a dominating one replaced
/// by it), dead code.
pub const CSE_PASSES: [&str; 3] =
    ["--preserve-bindings", "--redundancy-elimination", "--eliminate-dead-code-aggressive"];

/// The plain preparation (SSA form and unrolling only, every function kept): where a translation error is
/// located, and what the flattened translation is tested against.
pub const PLAIN_PASSES: [&str; 2] = ["--ssa-rewrite", "--loop-unroll"];

/// How a kernel is prepared for translation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Preparation {
    /// `INLINE_PASSES`, `flatten`, `CSE_PASSES`: what every target compiles and the checks run.
    Flattened,
    /// `PLAIN_PASSES`.
    Plain,
}

/// `words` specialised with `constants` and prepared (`Preparation::Flattened`).
pub fn prepared(words: &[u32], constants: &SpecConstants) -> Result<Vec<u32>> {
    prepared_as(words, constants, Preparation::Flattened)
}

/// `words` specialised with `constants` and prepared as `how`.
pub fn prepared_as(words: &[u32], constants: &SpecConstants, how: Preparation) -> Result<Vec<u32>> {
    let frozen = spirv::specialise(words, constants)?;
    match how {
        Preparation::Plain => spirv::spirv_opt(&frozen, &PLAIN_PASSES.map(str::to_string)),
        Preparation::Flattened => {
            let inlined = spirv::spirv_opt(&frozen, &INLINE_PASSES.map(str::to_string))?;
            spirv::spirv_opt(&super::flatten::flatten(&inlined)?, &CSE_PASSES.map(str::to_string))
        }
    }
}

/// The translation of a model's kernel. A construct the translation cannot express is located in the plainly
/// prepared module (its functions the source's); for a `.brdf` model in a line-annotated compile of the file,
/// and named at the file's own line.
fn translated(
    model: Option<&Model>,
    kind: KernelKind,
    (words, constants): (&[u32], &SpecConstants),
    options: &TranslateOptions,
    how: Preparation,
    shaders: &Shaders,
) -> Result<Translation> {
    let label = model.map_or_else(|| crate::model::BASELINE_LABEL.to_string(), Model::label);
    let e = match translate(&prepared_as(words, constants, how)?, options) {
        Ok(t) => return Ok(t),
        Err(e) => e,
    };
    let plain = |words: &[u32]| -> Result<TranslateError> {
        Ok(translate(&prepared_as(words, constants, Preparation::Plain)?, options).err().unwrap_or_else(|| e.clone()))
    };
    match model.and_then(Model::file) {
        Some(f) => Err(anyhow!("{}", locate(f, &plain(&f.kernel_with_lines(kind, shaders)?.words)?))),
        None => Err(anyhow!("{label}: {}", plain(words)?)),
    }
}

/// `model`'s eval kernel (f_s per sample, glsl/eval.comp), translated.
pub fn eval_kernel(model: &Model, shaders: &Shaders) -> Result<Translation> {
    eval_kernel_as(model, shaders, Preparation::Flattened)
}

/// `eval_kernel` prepared as `how`.
pub fn eval_kernel_as(model: &Model, shaders: &Shaders, how: Preparation) -> Result<Translation> {
    let k = model.kernel(KernelKind::Eval, shaders)?;
    translated(
        Some(model),
        KernelKind::Eval,
        (&k.spirv.words, &k.constants),
        &TranslateOptions::default(),
        how,
        shaders,
    )
}

/// The profiling kernel over the packed G-buffer (glsl/shade.comp) for `model` (None: the memory-only
/// kernel) with `lights` lights per dispatch, as `inspect` compiles it, translated.
pub fn shade_kernel(model: Option<&Model>, lights: u32, shaders: &Shaders) -> Result<Translation> {
    shade_kernel_as(model, lights, shaders, Preparation::Flattened)
}

/// `shade_kernel` prepared as `how`.
pub fn shade_kernel_as(model: Option<&Model>, lights: u32, shaders: &Shaders, how: Preparation) -> Result<Translation> {
    let (per_dispatch, accumulate) = shade::steady_block(lights);
    let k = shade::shade_kernel(model, GBufferFormat::Packed, per_dispatch, accumulate, shaders)?;
    // The G-buffer's texel view (`shade::bindings`): four 32-bit words per pixel.
    let options = TranslateOptions { texel_formats: [((0, 0), TexelFormat::Rgba32ui)].into(), line_directives: false };
    translated(model, KernelKind::Shade, (&k.spirv.words, &k.constants), &options, how, shaders)
}

/// `shade_kernel` with each statement's source line (`#line`, from the kernel compiled again with glslang's
/// `-g`), for `inspect --lines`: the same code as `shade_kernel`'s, whose compilers' line information then maps
/// machine instructions to the `.brdf` file's lines and glsl/'s.
pub fn shade_kernel_with_lines(model: Option<&Model>, lights: u32, shaders: &Shaders) -> Result<Translation> {
    let (per_dispatch, accumulate) = shade::steady_block(lights);
    let mut k = shade::shade_kernel(model, GBufferFormat::Packed, per_dispatch, accumulate, shaders)?;
    let reference = Model::reference();
    k.spirv = model.unwrap_or(&reference).kernel_with_lines(KernelKind::Shade, shaders)?.spirv;
    let options = TranslateOptions { texel_formats: [((0, 0), TexelFormat::Rgba32ui)].into(), line_directives: true };
    translated(model, KernelKind::Shade, (&k.spirv.words, &k.constants), &options, Preparation::Flattened, shaders)
}

/// The file's line and own name of a translation error located in its composed kernel: `file.brdf:LINE`
/// for the file's lines, its identifiers without brdfprof's prefix.
fn locate(f: &FileModel, e: &TranslateError) -> String {
    let prefix = f.file.renamed_shader().prefix.clone();
    let function = e.function.as_deref().map(|f| f.strip_prefix(prefix.as_str()).unwrap_or(f).to_string());
    let construct = format!(
        "the C translation cannot express {}{}",
        e.construct,
        function.map_or(String::new(), |f| format!(" (in function `{f}`)"))
    );
    match &e.location {
        Some(l) if l.file == f.file.path.display().to_string() || l.file.ends_with(".brdf") => {
            format!("{}:{}: {construct}", f.path, l.line)
        }
        Some(l) => format!("{}: {construct} (at {}:{} of brdfprof's kernel)", f.path, l.file, l.line),
        None => format!("{}: {construct}", f.path),
    }
}
