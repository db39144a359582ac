//! The SPIR-V a translation starts from: a model's kernel specialised exactly as `inspect` counts it
//! (`spirv::specialise`: constants set and frozen, the code they do not select removed), then in SSA
//! form with the loops its `[[unroll]]` marks unrolled (`spirv-opt --ssa-rewrite --loop-unroll`), as a Vulkan
//! driver unrolls the light loop the hint marks. Nothing else is optimised: the target's compiler does that.

use super::{translate, TexelFormat, TranslateError, TranslateOptions, Translation};
use crate::gpu::SpecConstants;
use crate::spirv;
use crate::model::file_model::FileModel;
use crate::model::{KernelKind, Model};
use crate::kernels::shade::{self, GBufferFormat};
use crate::shaders::Shaders;
use anyhow::{anyhow, Result};

/// spirv-opt passes after specialisation.
pub const UNROLL_PASSES: [&str; 2] = ["--ssa-rewrite", "--loop-unroll"];

/// `words` specialised with `constants` and unrolled.
pub fn prepared(words: &[u32], constants: &SpecConstants) -> Result<Vec<u32>> {
    let frozen = spirv::specialise(words, constants)?;
    spirv::spirv_opt(&frozen, &UNROLL_PASSES.map(str::to_string))
}

/// The translation of a model's kernel; for a `.brdf` model a construct the translation cannot express is
/// located again in a line-annotated compile of the file, and named at the file's own line.
fn translated(model: Option<&Model>, kind: KernelKind, words: &[u32], constants: &SpecConstants, options: &TranslateOptions, shaders: &Shaders) -> Result<Translation> {
    let label = model.map_or_else(|| crate::model::BASELINE_LABEL.to_string(), Model::label);
    match translate(&prepared(words, constants)?, options) {
        Ok(t) => Ok(t),
        Err(e) => match model.and_then(Model::file) {
            Some(f) => {
                let lines = f.kernel_with_lines(kind, shaders)?;
                let located = translate(&prepared(&lines.words, constants)?, options).err().unwrap_or(e);
                Err(anyhow!("{}", locate(f, &located)))
            }
            None => Err(anyhow!("{label}: {e}")),
        },
    }
}

/// `model`'s eval kernel (f_s per sample, glsl/eval.comp), translated.
pub fn eval_kernel(model: &Model, shaders: &Shaders) -> Result<Translation> {
    let k = model.kernel(KernelKind::Eval, shaders)?;
    translated(Some(model), KernelKind::Eval, &k.spirv.words, &k.constants, &TranslateOptions::default(), shaders)
}

/// The profiling kernel over the packed G-buffer (glsl/shade.comp) for `model` (None: the memory-only
/// kernel) with `lights` lights per dispatch, as `inspect` compiles it, translated.
pub fn shade_kernel(model: Option<&Model>, lights: u32, shaders: &Shaders) -> Result<Translation> {
    let (per_dispatch, accumulate) = shade::steady_block(lights);
    let k = shade::shade_kernel(model, GBufferFormat::Packed, per_dispatch, accumulate, shaders)?;
    // The G-buffer's texel view (`shade::bindings`): four 32-bit words per pixel.
    let options = TranslateOptions { texel_formats: [((0, 0), TexelFormat::Rgba32ui)].into() };
    translated(model, KernelKind::Shade, &k.spirv.words, &k.constants, &options, shaders)
}

/// The file's line and own name of a translation error located in its composed kernel: `file.brdf:LINE`
/// for the file's lines, its identifiers without brdfprof's prefix.
fn locate(f: &FileModel, e: &TranslateError) -> String {
    let prefix = f.file.renamed_shader().prefix.clone();
    let function = e.function.as_deref().map(|f| f.strip_prefix(prefix.as_str()).unwrap_or(f).to_string());
    let construct = format!("the C translation cannot express {}{}", e.construct, function.map_or(String::new(), |f| format!(" (in function `{f}`)")));
    match &e.location {
        Some(l) if l.file == f.file.path.display().to_string() || l.file.ends_with(".brdf") => format!("{}:{}: {construct}", f.path, l.line),
        Some(l) => format!("{}: {construct} (at {}:{} of brdfprof's kernel)", f.path, l.file, l.line),
        None => format!("{}: {construct}", f.path),
    }
}
