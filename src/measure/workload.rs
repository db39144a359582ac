//! The profile's work on the device: the synthetic G-buffer, the lights and the output, padded to whole
//! workgroups (the kernel has no bounds check), and each model's shading kernel bound to them (`Variant`).
//!
//! A profile of L lights runs its lights in blocks of at most `LIGHT_BLOCK`, one dispatch per block, each
//! adding to what the previous wrote: the kernel unrolls one block (so light loads are uniform scalar loads
//! on lavapipe and the unrolled code stays small at any light count), and the cost per light stays that of a
//! block whatever L is.

use super::gbuffer::{GBuffer, GBufferFormat, LIGHT_FLOATS};
use super::protocol::{Dispatch, Pipelines, Timed};
use crate::gpu::{Buffer, ChunkPlan, Commands, Gpu, MemoryKind};
use crate::model::Model;
use crate::shaders::Shaders;
use anyhow::Result;

pub use crate::kernels::shade::{
    LIGHT_BLOCK, PUSH_BYTES, bindings, kernel_hash, light_blocks, shade_kernel, steady_block,
};

/// The most lights a profile takes: 512 dispatches per run, 128 KiB of lights. Compilation does not grow
/// with the count (one block kernel), the run time does.
pub const MAX_LIGHTS: u32 = 4096;

/// Bytes of one block of lights in the light buffer (std140: two vec4 per light), the dynamic offset's step.
const BLOCK_BYTES: u64 = LIGHT_BLOCK as u64 * LIGHT_FLOATS as u64 * 4;

/// The G-buffer, lights and output on the device.
pub struct Workload<'g> {
    gbuffer: Buffer<'g>,
    radiance: Buffer<'g>,
    lights: Buffer<'g>,
    pub format: GBufferFormat,
    pub light_count: u32,
    pub width: u32,
    /// Pixels in the picture (the padding is not counted in evaluations).
    pub pixel_count: u64,
    camera: [f32; 4],
    plan: ChunkPlan,
}

/// Host bytes per pixel while a profile builds and uploads its G-buffer: the picture, the padded copy that is
/// uploaded, and (on a CPU driver such as lavapipe, whose device memory is host memory) the device's copy and
/// its output, per light count.
fn host_bytes_per_pixel(format: GBufferFormat, light_counts: u64) -> u64 {
    2 * format.bytes_in() + light_counts * (format.bytes_in() + format.bytes_out())
}

/// Refuses, before anything is allocated, a G-buffer that cannot be one device allocation or would not fit in
/// the memory this machine has available, naming the size and the limit.
pub fn check_size(
    info: &crate::gpu::DeviceInfo,
    width: u32,
    height: u32,
    format: GBufferFormat,
    light_counts: usize,
) -> Result<()> {
    let pixels = width as u64 * height as u64;
    let padded = pixels.div_ceil(crate::gpu::WORKGROUP as u64) * crate::gpu::WORKGROUP as u64;
    let side = |max_pixels: u64| {
        let h = ((max_pixels as f64 * 9.0 / 16.0).sqrt() as u64).max(1);
        format!("{}x{h}", max_pixels / h)
    };
    let bytes = padded * format.bytes_in();
    if bytes > info.max_memory_allocation_size {
        let most = info.max_memory_allocation_size / format.bytes_in();
        anyhow::bail!(
            "--size {width}x{height}: the {} G-buffer is {bytes} bytes, more than one allocation on `{}` may be ({} bytes, maxMemoryAllocationSize); at most {most} pixels (about {})",
            format.name(),
            info.name,
            info.max_memory_allocation_size,
            side(most)
        );
    }
    if let Some((available, source)) = crate::host_cpu::memory_budget() {
        let need = pixels * host_bytes_per_pixel(format, light_counts as u64);
        if need > available {
            let most = available / host_bytes_per_pixel(format, light_counts as u64);
            anyhow::bail!(
                "--size {width}x{height}: building and uploading the G-buffer needs about {need} bytes of memory and {available} are available ({source}); at most about {most} pixels here (about {})",
                side(most)
            );
        }
    }
    Ok(())
}

impl<'g> Workload<'g> {
    pub fn upload(gpu: &'g Gpu, gbuffer: &GBuffer, lights: &[f32], max_chunk: Option<u64>) -> Result<Self> {
        let count = lights.len() / LIGHT_FLOATS;
        if count == 0 || count > MAX_LIGHTS as usize || lights.len() % LIGHT_FLOATS != 0 {
            anyhow::bail!("{count} lights: a profile takes 1 to {MAX_LIGHTS} whole lights");
        }
        let n = gbuffer.pixel_count();
        let words = padded_words(gbuffer);
        let padded = words.len() as u64 / gbuffer.words_per_pixel() as u64;
        let (f, c) = (gbuffer.format, gbuffer.camera);
        let light_data = light_buffer(lights);
        Ok(Workload {
            gbuffer: Buffer::with_data(gpu, bytemuck::cast_slice(&words), MemoryKind::Device)?,
            radiance: Buffer::new(gpu, padded * f.bytes_out(), MemoryKind::Device)?,
            lights: Buffer::with_data(gpu, bytemuck::cast_slice(&light_data), MemoryKind::Device)?,
            format: f,
            light_count: (lights.len() / LIGHT_FLOATS) as u32,
            width: gbuffer.width,
            pixel_count: n,
            camera: [c.scale[0], c.offset[0], c.scale[1], c.offset[1]],
            plan: ChunkPlan::new(&gpu.info, padded, &[f.bytes_in(), f.bytes_out()], texel_cap(gpu, f, max_chunk)),
        })
    }

    /// BRDF evaluations per run of a variant (every light block).
    pub fn evaluations(&self) -> u64 {
        self.pixel_count * self.light_count as u64
    }

    pub fn chunks(&self) -> usize {
        self.plan.chunks.len()
    }

    /// The radiance the last run wrote (rgb per pixel), for checks.
    pub fn radiance(&self) -> Result<Vec<[f32; 3]>> {
        match self.format {
            GBufferFormat::Float => {
                let v: Vec<f32> = self.radiance.read_as(0, self.pixel_count as usize * 4)?;
                Ok(v.chunks_exact(4).map(|c| [c[0], c[1], c[2]]).collect())
            }
            GBufferFormat::Packed => {
                let v: Vec<u32> = self.radiance.read_as(0, self.pixel_count as usize)?;
                Ok(v.into_iter().map(super::gbuffer::unpack_r11g11b10).collect())
            }
        }
    }

    fn push(&self, first_pixel: u64) -> Vec<u8> {
        push_constants(first_pixel, self.width, self.camera)
    }
}

/// The G-buffer's words padded to whole workgroups with copies of its last pixel (the kernel has no bounds
/// check).
pub fn padded_words(gbuffer: &GBuffer) -> Vec<u32> {
    let n = gbuffer.pixel_count();
    let wg = crate::gpu::WORKGROUP as u64;
    let per = gbuffer.words_per_pixel();
    let mut words = gbuffer.words.clone();
    let last = words[words.len() - per..].to_vec();
    for _ in n..n.div_ceil(wg) * wg {
        words.extend_from_slice(&last);
    }
    words
}

/// The light buffer: the lights in whole blocks, so that every dispatch's window of BLOCK_BYTES lies inside it.
pub fn light_buffer(lights: &[f32]) -> Vec<f32> {
    let mut light_data = lights.to_vec();
    light_data.resize(light_blocks((lights.len() / LIGHT_FLOATS) as u32).len().max(1) * BLOCK_BYTES as usize / 4, 0.0);
    light_data
}

/// The push constants of a dispatch over the chunk starting at pixel `first_pixel` of a picture `width`
/// wide, with the camera's (scale x, offset x, scale y, offset y) (glsl/shade.glsl `Push`).
pub fn push_constants(first_pixel: u64, width: u32, camera: [f32; 4]) -> Vec<u8> {
    // keep_inputs = 0: the kernels add their inputs times it, so that no compiler drops them.
    let words: [u32; 8] = [
        first_pixel as u32,
        width,
        0,
        0,
        camera[0].to_bits(),
        camera[1].to_bits(),
        camera[2].to_bits(),
        camera[3].to_bits(),
    ];
    bytemuck::cast_slice(&words).to_vec()
}

/// The packed layout's views hold at most maxTexelBufferElements pixels each: chunks no larger.
fn texel_cap(gpu: &Gpu, format: GBufferFormat, cap: Option<u64>) -> Option<u64> {
    match format {
        GBufferFormat::Packed => Some(cap.unwrap_or(u64::MAX).min(gpu.info.max_texel_buffer_elements as u64)),
        GBufferFormat::Float => cap,
    }
}

/// A model's shading kernel (or the memory-only baseline) bound to the workload, every light block, ready to
/// dispatch.
pub struct Variant<'g> {
    pub label: String,
    /// None for the memory-only baseline.
    pub model: Option<Model>,
    pipelines: Pipelines<'g>,
}

pub use crate::model::BASELINE_LABEL;

/// One kernel per distinct (lights per dispatch, accumulate) among the light `blocks`: those kinds, and each
/// block's index among them.
fn kernel_kinds(blocks: &[(u32, u32)]) -> (Vec<(u32, bool)>, Vec<usize>) {
    let mut kinds: Vec<(u32, bool)> = Vec::new();
    let kind_of: Vec<usize> = blocks
        .iter()
        .enumerate()
        .map(|(b, &(_, count))| {
            let kind = (count, b > 0);
            kinds.iter().position(|k| *k == kind).unwrap_or_else(|| {
                kinds.push(kind);
                kinds.len() - 1
            })
        })
        .collect();
    (kinds, kind_of)
}

impl<'g> Variant<'g> {
    /// The shading kernels for `model` (None: the memory-only baseline) from `shaders`, as `instances`
    /// independent pipelines.
    pub fn new(
        gpu: &'g Gpu,
        work: &Workload<'g>,
        model: Option<&Model>,
        shaders: &Shaders,
        instances: usize,
    ) -> Result<Self> {
        if let Some(m) = model {
            m.check_support(&gpu.info)?;
        }
        let blocks = light_blocks(work.light_count);
        let (kinds, kind_of) = kernel_kinds(&blocks);
        let compiled = kinds
            .iter()
            .map(|&(count, acc)| shade_kernel(model, work.format, count, acc, shaders).map(|k| (k.spirv, k.constants)))
            .collect::<Result<Vec<_>>>()?;
        let (f, chunks) = (work.format, &work.plan.chunks);
        let pipelines = Pipelines::compile(gpu, &compiled, &bindings(f), PUSH_BYTES, instances, |kernels| {
            // One set per kernel and chunk, shared by every block that kernel runs.
            let sets = kernels
                .iter()
                .map(|k| {
                    chunks
                        .iter()
                        .map(|&(first, len)| {
                            k.bind(&[
                                (&work.gbuffer, first * f.bytes_in(), len * f.bytes_in()),
                                (&work.radiance, first * f.bytes_out(), len * f.bytes_out()),
                                (&work.lights, 0, BLOCK_BYTES),
                            ])
                        })
                        .collect::<Result<Vec<_>>>()
                })
                .collect::<Result<Vec<_>>>()?;
            Ok(blocks
                .iter()
                .zip(&kind_of)
                .map(|(&(first_light, _), &k)| {
                    let offsets = vec![(first_light as u64 / LIGHT_BLOCK as u64 * BLOCK_BYTES) as u32];
                    chunks
                        .iter()
                        .zip(&sets[k])
                        .map(|(&(first, len), &set)| Dispatch {
                            kernel: k,
                            set,
                            offsets: offsets.clone(),
                            push: work.push(first),
                            invocations: len,
                        })
                        .collect()
                })
                .collect())
        })?;
        Ok(Variant {
            label: model.map_or_else(|| BASELINE_LABEL.to_string(), Model::label),
            model: model.cloned(),
            pipelines,
        })
    }
}

impl Timed for Variant<'_> {
    fn instances(&self) -> usize {
        self.pipelines.len()
    }

    fn record(&self, cmd: &Commands, instance: usize) {
        self.pipelines.record(cmd, instance)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn blocks_cover_every_light_once() {
        for lights in [1, 4, 7, 8, 9, 16, 63, 64, 65, 1024] {
            let b = light_blocks(lights);
            assert_eq!(b.iter().map(|x| x.1).sum::<u32>(), lights);
            assert!(b.windows(2).all(|w| w[0].0 + w[0].1 == w[1].0) && b[0].0 == 0);
            assert!(b.iter().all(|x| x.1 >= 1 && x.1 <= LIGHT_BLOCK));
        }
        assert_eq!(steady_block(4), (4, false));
        assert_eq!(steady_block(64), (8, true));
    }
}
