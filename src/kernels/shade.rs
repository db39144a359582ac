//! The shading kernel (glsl/shade.glsl) as every command builds it: its G-buffer layouts and bindings, the
//! light blocks it unrolls, the kernel of a model with its constants set, and the hash that names it.
//! `profile` times it, `inspect`, `check`, `sweep` and the compile-only targets compile it; all build it here.

use super::{WithConstant, constants};
use crate::gpu::Binding;
use crate::model::{KernelKind, Model, ModelKernel};
use crate::shaders::Shaders;
use anyhow::Result;
use serde::Serialize;

pub use super::constants::LIGHT_BLOCK;

/// Floats per float-layout pixel: (n.xyz, roughness), (v.xyz, metallic), (base colour, 1).
pub const PIXEL_FLOATS: usize = 12;
/// How the G-buffer is stored.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum GBufferFormat {
    Packed,
    Float,
}

impl GBufferFormat {
    /// Bytes per pixel read and written by the shading kernel.
    pub fn bytes_in(self) -> u64 {
        match self {
            GBufferFormat::Packed => 16,
            GBufferFormat::Float => (PIXEL_FLOATS * 4) as u64,
        }
    }
    pub fn bytes_out(self) -> u64 {
        match self {
            GBufferFormat::Packed => 4,
            GBufferFormat::Float => 16,
        }
    }
    pub fn name(self) -> &'static str {
        match self {
            GBufferFormat::Packed => "packed",
            GBufferFormat::Float => "float",
        }
    }
}

/// The dispatches of a profile with `lights` lights: (first light, lights) per block.
pub fn light_blocks(lights: u32) -> Vec<(u32, u32)> {
    (0..lights.div_ceil(LIGHT_BLOCK)).map(|b| (b * LIGHT_BLOCK, LIGHT_BLOCK.min(lights - b * LIGHT_BLOCK))).collect()
}

/// The block kernel that most of a profile's dispatches run: (lights per dispatch, whether it accumulates).
pub fn steady_block(lights: u32) -> (u32, bool) {
    (lights.min(LIGHT_BLOCK), lights > LIGHT_BLOCK)
}

/// Bytes of shade.glsl's push constants.
pub const PUSH_BYTES: u32 = 32;
/// shade.glsl's bindings: the G-buffer, the radiance, one block of lights.
pub fn bindings(format: GBufferFormat) -> [Binding; 3] {
    use crate::gpu::TexelFormat;
    match format {
        GBufferFormat::Packed => [
            Binding::TexelRead(TexelFormat::Rgba32Uint),
            Binding::TexelStorage(TexelFormat::B10g11r11Ufloat),
            Binding::UniformDynamic,
        ],
        GBufferFormat::Float => [Binding::Storage, Binding::Storage, Binding::UniformDynamic],
    }
}

/// The kernel of the G-buffer format.
fn shade_kind(format: GBufferFormat) -> KernelKind {
    match format {
        GBufferFormat::Packed => KernelKind::Shade,
        GBufferFormat::Float => KernelKind::ShadeFloat,
    }
}

/// glsl/shade.glsl for `model` (None: the memory-only baseline, compiled with the reference model's selectors,
/// which it never runs) over `format`, lighting `lights` lights per dispatch and adding to the radiance of an
/// earlier block when `accumulate`, with every specialisation constant set.
pub fn shade_kernel(
    model: Option<&Model>,
    format: GBufferFormat,
    lights: u32,
    accumulate: bool,
    shaders: &Shaders,
) -> Result<ModelKernel> {
    let reference = Model::reference();
    let mut k = model.unwrap_or(&reference).kernel(shade_kind(format), shaders)?;
    k.constants = k
        .constants
        .with(constants::NUM_LIGHTS, lights as f64)
        .with(constants::BASELINE, model.is_none() as i32 as f64)
        .with(constants::ACCUMULATE, accumulate as i32 as f64);
    Ok(k)
}

/// SHA-256 of a model's shading kernel (None: the memory-only kernel) over `format`: the SPIR-V words and the
/// constants that select the model, with the light count fixed at one block of one light, so that the hash
/// names the code and the model, not the workload.
pub fn kernel_hash(model: Option<&Model>, format: GBufferFormat, shaders: &Shaders) -> Result<String> {
    let k = shade_kernel(model, format, 1, false, shaders)?;
    use sha2::Digest;
    let mut h = sha2::Sha256::new();
    for w in k.spirv.words.iter() {
        h.update(w.to_le_bytes());
    }
    h.update(format!("{:?}", k.constants).as_bytes());
    Ok(h.finalize().iter().map(|b| format!("{b:02x}")).collect())
}
