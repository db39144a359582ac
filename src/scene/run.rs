//! The scene on the device: per kernel of the plan its pixels (padded to whole workgroups; the kernel has no
//! bounds check), per-pixel extras, output and E table; the lights shared. A `SceneVariant` is one kernel
//! compiled with some switches and bound chunk by chunk (bindings within maxStorageBufferRange, dispatches within
//! maxComputeWorkGroupCount), so a 4K or larger G-buffer runs as several dispatches of one pipeline.

use super::effects;
use super::format::Scene;
use super::gbuffer::{GBuffer, PIXEL_BYTES};
use super::plan::ScenePlan;
use super::terms::{ETable, Switches};
use crate::gpu::{Binding, Buffer, ChunkPlan, Commands, Gpu, MemoryKind};
use crate::kernels::{self, RunLimits};
use crate::measure::protocol::{Dispatch, Pipelines, Timed};
use crate::model::KernelKind;
use anyhow::Result;

/// glsl/scene.comp's interface: storage buffers 0..5 of set 0 (pixels, radiance, lights, extras, E table) and
/// the push constants (the camera); the radiance output's slot.
pub const STORAGE_BUFFERS: u32 = 5;
pub const PUSH_BYTES: u32 = 16;
pub const RADIANCE: (u32, u32) = (0, 1);

/// A kernel's buffers by (set, binding), its push constants and the invocations of one run.
pub type HostInputs = (std::collections::BTreeMap<(u32, u32), Vec<u8>>, Vec<u8>, u64);

/// Bytes per pixel of the other per-pixel bindings: output (1 vec4), extras (2 vec4); pixels: `PIXEL_BYTES`.
const OUT_BYTES: u64 = 16;
const EXTRA_BYTES: u64 = 32;

/// One kernel's buffers.
pub struct KernelBuffers<'g> {
    pixels: Buffer<'g>,
    radiance: Buffer<'g>,
    extras: Buffer<'g>,
    table: Buffer<'g>,
    /// Pixels shaded (before padding).
    pub count: u64,
    chunks: ChunkPlan,
}

/// The scene uploaded.
pub struct SceneWork<'g> {
    lights: Buffer<'g>,
    pub kernels: Vec<KernelBuffers<'g>>,
    camera: [f32; 4],
}

/// E tables for the kernels that compile energy compensation in (None for the others).
pub fn e_tables(gpu: &Gpu, plan: &ScenePlan) -> Result<Vec<Option<ETable>>> {
    plan.kernels.iter().map(|k| (k.switches.energy != 0).then(|| effects::e_table(gpu, &k.model)).transpose()).collect()
}

impl<'g> SceneWork<'g> {
    pub fn upload(
        gpu: &'g Gpu,
        scene: &Scene,
        gbuffer: &GBuffer,
        plan: &ScenePlan,
        tables: &[Option<ETable>],
        limits: RunLimits,
    ) -> Result<Self> {
        let wg = crate::gpu::WORKGROUP as u64;
        let mut kernels = Vec::new();
        for (k, kp) in plan.kernels.iter().enumerate() {
            let n = kp.pixels.len() as u64;
            let padded = n.div_ceil(wg).max(1) * wg;
            let mut data: Vec<f32> = Vec::with_capacity(padded as usize * 12);
            for &i in &kp.pixels {
                let p = &gbuffer.pixels[i as usize];
                let (nn, pos, b) = (p.normal, p.position, p.base_colour);
                data.extend_from_slice(&[
                    nn[0],
                    nn[1],
                    nn[2],
                    p.roughness,
                    pos[0],
                    pos[1],
                    pos[2],
                    p.metallic,
                    b[0],
                    b[1],
                    b[2],
                    0.0,
                ]);
            }
            let mut extras = plan.extras(scene, gbuffer, k);
            for _ in n..padded {
                let last = data[data.len() - 12..].to_vec();
                data.extend_from_slice(&last);
                let last = extras[extras.len() - 8..].to_vec();
                extras.extend_from_slice(&last);
            }
            let table: &[f32] = tables[k].as_ref().map_or(&[1.0; 4], |t| &t.values);
            kernels.push(KernelBuffers {
                pixels: Buffer::with_data(gpu, bytemuck::cast_slice(&data), MemoryKind::Device)?,
                radiance: Buffer::new(gpu, padded * OUT_BYTES, MemoryKind::Device)?,
                extras: Buffer::with_data(gpu, bytemuck::cast_slice(&extras), MemoryKind::Device)?,
                table: Buffer::with_data(gpu, bytemuck::cast_slice(table), MemoryKind::Device)?,
                count: n,
                chunks: ChunkPlan::new(&gpu.info, padded, &[PIXEL_BYTES, OUT_BYTES, EXTRA_BYTES], limits.max_chunk),
            });
        }
        let light_data: &[f32] = if plan.light_data.is_empty() { &[0.0; 12] } else { &plan.light_data };
        let c = gbuffer.camera.position;
        Ok(SceneWork {
            lights: Buffer::with_data(gpu, bytemuck::cast_slice(light_data), MemoryKind::Device)?,
            kernels,
            camera: [c[0], c[1], c[2], 0.0],
        })
    }

    /// Pixels shaded in all kernels together.
    pub fn pixels(&self) -> u64 {
        self.kernels.iter().map(|k| k.count).sum()
    }

    /// Dispatches per run of kernel `k`.
    pub fn chunks(&self, k: usize) -> usize {
        self.kernels[k].chunks.chunks.len()
    }

    /// Kernel `k`'s bindings as bytes by (set, binding), as its last run read them (the radiance zeroed), its
    /// push constants (the camera), and the invocations of one run (its pixels padded to whole workgroups):
    /// what the kernel's translation runs on, on the host.
    pub fn host_inputs(&self, k: usize) -> Result<HostInputs> {
        let kb = &self.kernels[k];
        let bytes = |b: &Buffer| b.read_as::<u8>(0, b.size as usize);
        let buffers = [
            ((0, 0), bytes(&kb.pixels)?),
            (RADIANCE, vec![0u8; kb.radiance.size as usize]),
            ((0, 2), bytes(&self.lights)?),
            ((0, 3), bytes(&kb.extras)?),
            ((0, 4), bytes(&kb.table)?),
        ];
        Ok((buffers.into(), bytemuck::cast::<[f32; 4], [u8; 16]>(self.camera).to_vec(), kb.radiance.size / OUT_BYTES))
    }

    /// Radiance written by kernel `k`'s last run, one rgb per pixel of the kernel.
    pub fn radiance(&self, k: usize) -> Result<Vec<[f32; 3]>> {
        let kb = &self.kernels[k];
        let v: Vec<f32> = kb.radiance.read_as(0, kb.count as usize * 4)?;
        Ok(v.chunks_exact(4).map(|c| [c[0], c[1], c[2]]).collect())
    }
}

/// Kernel `k` of a plan compiled with `switches`, bound to the uploaded scene, as one or more independently
/// compiled pipelines (`measure::protocol::Pipelines`: an effect's cost is a difference of two kernels, so a
/// badly placed compilation of either would take the whole error).
pub struct SceneVariant<'g> {
    pub label: String,
    pub kernel_index: usize,
    pub switches: Switches,
    pipelines: Pipelines<'g>,
}

impl<'g> SceneVariant<'g> {
    pub fn new(
        gpu: &'g Gpu,
        work: &SceneWork<'g>,
        plan: &ScenePlan,
        k: usize,
        switches: Switches,
        label: String,
        instances: usize,
    ) -> Result<Self> {
        let model = &plan.kernels[k].model;
        model.check_support(&gpu.info)?;
        let kb = &work.kernels[k];
        let push: [u8; 16] = bytemuck::cast(work.camera);
        let mk = model.kernel(KernelKind::Scene, kernels::embedded())?;
        let kernel = [(mk.spirv, plan.constants(mk.constants, switches))];
        let pipelines =
            Pipelines::compile(gpu, &kernel, &Binding::storage(STORAGE_BUFFERS), PUSH_BYTES, instances, |k| {
                let chunk = |&(first, len): &(u64, u64)| -> Result<Dispatch> {
                    let set = k[0].bind(&[
                        (&kb.pixels, first * PIXEL_BYTES, len * PIXEL_BYTES),
                        (&kb.radiance, first * OUT_BYTES, len * OUT_BYTES),
                        (&work.lights, 0, work.lights.size),
                        (&kb.extras, first * EXTRA_BYTES, len * EXTRA_BYTES),
                        (&kb.table, 0, kb.table.size),
                    ])?;
                    Ok(Dispatch { kernel: 0, set, offsets: Vec::new(), push: push.to_vec(), invocations: len })
                };
                Ok(vec![kb.chunks.chunks.iter().map(chunk).collect::<Result<Vec<_>>>()?])
            })?;
        Ok(SceneVariant { label, kernel_index: k, switches, pipelines })
    }
}

impl Timed for SceneVariant<'_> {
    fn instances(&self) -> usize {
        self.pipelines.len()
    }

    fn record(&self, cmd: &Commands, instance: usize) {
        self.pipelines.record(cmd, instance)
    }
}

/// Shades the whole G-buffer (every kernel of the plan, as compiled) and returns the radiance per G-buffer
/// pixel, row-major; pixels no surface covers get `background`.
pub fn shade(
    gpu: &Gpu,
    scene: &Scene,
    gbuffer: &GBuffer,
    plan: &ScenePlan,
    tables: &[Option<ETable>],
    limits: RunLimits,
) -> Result<Vec<[f32; 3]>> {
    plan.check_device(&gpu.info)?;
    let work = SceneWork::upload(gpu, scene, gbuffer, plan, tables, limits)?;
    let bg = scene.file.render.background;
    let mut out = vec![bg; gbuffer.pixel_count()];
    for (k, kp) in plan.kernels.iter().enumerate() {
        let variant = SceneVariant::new(gpu, &work, plan, k, kp.switches, kp.model.name(), 1)?;
        variant.run_once(gpu, 0)?;
        for (&i, rgb) in kp.pixels.iter().zip(work.radiance(k)?) {
            out[i as usize] = rgb;
        }
    }
    Ok(out)
}
