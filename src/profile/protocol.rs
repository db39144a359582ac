//! The measurement protocol. Every variant (a model's kernel, or the memory-only baseline) gets an untimed
//! warm-up dispatch (lavapipe JIT-compiles a pipeline at its first dispatch). Then rounds: each round is one
//! submission in which every variant runs `reps` times, interleaved (A B C, C A B, ...; a fresh seeded
//! permutation per repetition), each dispatch between a barrier-fenced pair of BOTTOM_OF_PIPE timestamps.
//! Costs are compared as ratios within a round, so the machine's drift between rounds cancels. All raw times
//! are kept, outliers included.

use super::gbuffer::{GBuffer, LIGHT_FLOATS, PIXEL_FLOATS};
use crate::gpu::{Bindings, Buffer, ChunkPlan, Commands, Gpu, Kernel, MemoryKind, SpecConstants, Timestamps};
use crate::kernels::{self, constants, WithConstant};
use crate::model::{KernelKind, Model, ModelKernel};
use crate::shaders::{Shaders, Spirv};
use anyhow::Result;
use rand::seq::SliceRandom;
use rand::SeedableRng;
use serde::Serialize;
use std::time::{Duration, Instant};

/// The G-buffer, lights and output on the device, padded to whole workgroups (the kernel has no bounds check).
pub struct Workload<'g> {
    pixels: Buffer<'g>,
    radiance: Buffer<'g>,
    lights: Buffer<'g>,
    pub light_count: u32,
    /// Pixels in the picture (the padding is not counted in evaluations).
    pub pixel_count: u64,
    plan: ChunkPlan,
}

impl<'g> Workload<'g> {
    pub fn upload(gpu: &'g Gpu, gbuffer: &GBuffer, lights: &[f32], max_chunk: Option<u64>) -> Result<Self> {
        let n = gbuffer.pixel_count();
        let wg = crate::gpu::WORKGROUP as u64;
        let padded = n.div_ceil(wg) * wg;
        let mut data = gbuffer.pixels.clone();
        let last = data[data.len() - PIXEL_FLOATS..].to_vec();
        for _ in n..padded {
            data.extend_from_slice(&last);
        }
        let stride_in = (PIXEL_FLOATS * 4) as u64;
        Ok(Workload {
            pixels: Buffer::with_data(gpu, bytemuck::cast_slice(&data), MemoryKind::Device)?,
            radiance: Buffer::new(gpu, padded * 16, MemoryKind::Device)?,
            lights: Buffer::with_data(gpu, bytemuck::cast_slice(lights), MemoryKind::Device)?,
            light_count: (lights.len() / LIGHT_FLOATS) as u32,
            pixel_count: n,
            plan: ChunkPlan::new(&gpu.info, padded, &[stride_in, 16], max_chunk),
        })
    }

    /// BRDF evaluations per dispatch.
    pub fn evaluations(&self) -> u64 {
        self.pixel_count * self.light_count as u64
    }

    pub fn chunks(&self) -> usize {
        self.plan.chunks.len()
    }

    /// The radiance written by the last dispatch (rgb per pixel), for checks.
    pub fn radiance(&self) -> Result<Vec<[f32; 3]>> {
        let v: Vec<f32> = self.radiance.read_as(0, self.pixel_count as usize * 4)?;
        Ok(v.chunks_exact(4).map(|c| [c[0], c[1], c[2]]).collect())
    }
}

/// One kernel compiled as one or more independent pipelines (instances), each bound to the same chunk
/// windows: on lavapipe the same kernel JIT-compiled twice has been seen to run 2x slower in every round of one
/// process (code placement), and only a second pipeline exposes that. `measure` times every instance.
pub struct Pipelines<'g> {
    instances: Vec<(Kernel<'g>, Vec<(Bindings, u64)>)>,
    push: Vec<u8>,
}

impl<'g> Pipelines<'g> {
    /// `count` pipelines of `source` specialised with `constants`, over `chunks` (first element, length);
    /// `bind(kernel, first, len)` binds one chunk's windows; `push` is the push-constant block of every dispatch.
    #[allow(clippy::too_many_arguments)]
    pub fn compile(
        gpu: &'g Gpu,
        spirv: &Spirv,
        constants: &SpecConstants,
        bindings: u32,
        push: Vec<u8>,
        chunks: &[(u64, u64)],
        count: usize,
        bind: impl Fn(&Kernel<'g>, u64, u64) -> Result<Bindings>,
    ) -> Result<Self> {
        let instances = (0..count.max(1))
            .map(|_| {
                let kernel = kernels::kernel(gpu, spirv, constants, bindings, push.len() as u32)?;
                let sets = chunks.iter().map(|&(first, len)| Ok((bind(&kernel, first, len)?, len))).collect::<Result<Vec<_>>>()?;
                Ok((kernel, sets))
            })
            .collect::<Result<Vec<_>>>()?;
        Ok(Pipelines { instances, push })
    }

    pub fn len(&self) -> usize {
        self.instances.len()
    }

    pub fn is_empty(&self) -> bool {
        self.instances.is_empty()
    }

    /// Records every chunk's dispatch of pipeline `instance`.
    pub fn record(&self, cmd: &Commands, instance: usize) {
        let (kernel, sets) = &self.instances[instance];
        for &(set, len) in sets {
            kernel.dispatch(cmd, set, &self.push, len);
        }
    }
}

/// The profile's shading kernel bound to the workload, ready to dispatch.
pub struct Variant<'g> {
    pub label: String,
    /// None for the memory-only baseline.
    pub model: Option<Model>,
    pipelines: Pipelines<'g>,
}

/// The label of the memory-only baseline kernel in every report.
pub const BASELINE_LABEL: &str = "baseline";

/// glsl/shade.comp for `model` (None: the memory-only baseline, compiled with the reference model's
/// selectors, which it never runs) and `lights`, with every specialisation constant set.
pub fn shade_kernel(model: Option<&Model>, lights: u32, shaders: &Shaders) -> Result<ModelKernel> {
    let reference = Model::reference();
    let mut k = model.unwrap_or(&reference).kernel(KernelKind::Shade, shaders)?;
    k.constants = k.constants.with(constants::NUM_LIGHTS, lights as f64).with(constants::BASELINE, model.is_none() as i32 as f64);
    Ok(k)
}

impl<'g> Variant<'g> {
    /// The shading kernel for `model`, or the memory-only baseline when `model` is None, as `instances`
    /// independent pipelines, from `shaders`.
    pub fn new(gpu: &'g Gpu, work: &Workload<'g>, model: Option<&Model>, shaders: &Shaders, instances: usize) -> Result<Self> {
        if let Some(m) = model {
            m.check_support(&gpu.info)?;
        }
        let k = shade_kernel(model, work.light_count, shaders)?;
        let stride_in = (PIXEL_FLOATS * 4) as u64;
        let pipelines = Pipelines::compile(gpu, &k.spirv, &k.constants, 3, Vec::new(), &work.plan.chunks, instances, |kernel, first, len| {
            kernel.bind(&[(&work.pixels, first * stride_in, len * stride_in), (&work.radiance, first * 16, len * 16), (&work.lights, 0, work.lights.size)])
        })?;
        Ok(Variant { label: model.map_or_else(|| BASELINE_LABEL.to_string(), Model::name), model: model.cloned(), pipelines })
    }
}

#[derive(Clone, Debug)]
pub struct ProtocolOptions {
    pub min_rounds: usize,
    pub max_rounds: usize,
    /// Timed dispatches of every variant per round.
    pub reps: usize,
    /// Wall-clock budget for the timed rounds; the run stops after the round that exceeds it.
    pub budget: Duration,
    pub seed: u64,
}

/// Every timed dispatch, as measured.
#[derive(Clone, Debug, Default, Serialize)]
pub struct RawTimes {
    /// ns[variant][round][rep]: dispatch time in nanoseconds, of the variant's faster instance that round.
    pub ns: Vec<Vec<Vec<f64>>>,
    /// instance_ns[variant][round][instance]: each instance's median over its repetitions (the spread between
    /// instances is what code placement alone costs).
    pub instance_ns: Vec<Vec<Vec<f64>>>,
    /// The order of every repetition of every round, as (variant, instance) pairs.
    pub orders: Vec<Vec<Vec<(usize, usize)>>>,
    /// Wall time of each variant's first instance's untimed warm-up dispatch (includes JIT compilation).
    pub warmup_ms: Vec<f64>,
    pub elapsed_s: f64,
}

impl RawTimes {
    pub fn rounds(&self) -> usize {
        self.orders.len()
    }

    /// The median of `variant`'s repetitions in each round: the figure every analysis starts from.
    pub fn round_medians(&self, variant: usize) -> Vec<f64> {
        self.ns[variant].iter().map(|reps| crate::stats::median(reps)).collect()
    }

    /// Median over rounds of (slowest instance / fastest instance) of `variant`: 1 when its pipelines agree.
    pub fn instance_spread(&self, variant: usize) -> f64 {
        let spreads: Vec<f64> = self.instance_ns[variant]
            .iter()
            .map(|r| r.iter().copied().fold(f64::NEG_INFINITY, f64::max) / r.iter().copied().fold(f64::INFINITY, f64::min))
            .collect();
        if spreads.is_empty() { 1.0 } else { crate::stats::median(&spreads) }
    }
}

/// Runs the protocol. After each round (from `min_rounds` on) `converged` sees the times so far; the run
/// stops when it returns true, at `max_rounds`, or when the budget is spent.
pub fn measure<V: Timed>(
    gpu: &Gpu,
    variants: &[V],
    options: &ProtocolOptions,
    mut converged: impl FnMut(&RawTimes) -> bool,
    mut on_round: impl FnMut(&RawTimes),
) -> Result<RawTimes> {
    let v = variants.len();
    let mut raw = RawTimes { ns: vec![Vec::new(); v], instance_ns: vec![Vec::new(); v], ..Default::default() };
    let slots: Vec<(usize, usize)> = variants.iter().enumerate().flat_map(|(i, var)| (0..var.instances()).map(move |k| (i, k))).collect();
    for &(i, k) in &slots {
        let warm = variants[i].run_once(gpu, k)?;
        if k == 0 {
            raw.warmup_ms.push(warm.as_secs_f64() * 1e3);
        }
    }
    let timestamps = Timestamps::new(gpu, (2 * slots.len() * options.reps) as u32)?;
    let mut rng = rand_pcg::Pcg64::seed_from_u64(options.seed);
    let start = Instant::now();
    for round in 0..options.max_rounds {
        let orders: Vec<Vec<(usize, usize)>> = (0..options.reps)
            .map(|_| {
                let mut o = slots.clone();
                o.shuffle(&mut rng);
                o
            })
            .collect();
        let mut pairs = Vec::new();
        gpu.submit(|cmd| {
            timestamps.reset(cmd);
            for order in &orders {
                for &(i, k) in order {
                    let q = pairs.len() as u32 * 2;
                    gpu.barrier(cmd);
                    timestamps.write(cmd, q);
                    variants[i].record(cmd, k);
                    timestamps.write(cmd, q + 1);
                    pairs.push((q, q + 1));
                }
            }
        })?;
        let times = timestamps.intervals_ns(&pairs)?;
        // Per variant: each instance's repetitions; keep the faster instance's (by median) for the round.
        let mut by_slot: Vec<Vec<Vec<f64>>> = variants.iter().map(|var| vec![Vec::new(); var.instances()]).collect();
        for (t, &(i, k)) in times.iter().zip(orders.iter().flatten()) {
            by_slot[i][k].push(*t);
        }
        for (i, instances) in by_slot.into_iter().enumerate() {
            let medians: Vec<f64> = instances.iter().map(|reps| crate::stats::median(reps)).collect();
            let fastest = (0..medians.len()).min_by(|&a, &b| medians[a].total_cmp(&medians[b])).unwrap();
            raw.ns[i].push(instances[fastest].clone());
            raw.instance_ns[i].push(medians);
        }
        raw.orders.push(orders);
        raw.elapsed_s = start.elapsed().as_secs_f64();
        on_round(&raw);
        if round + 1 >= options.min_rounds && (converged(&raw) || start.elapsed() >= options.budget) {
            break;
        }
    }
    Ok(raw)
}

/// What the protocol can time: a variant that records its dispatches into a command buffer (the profile's
/// `Variant`; the scene kernels of `scene::run`), as one or more independently compiled instances. `measure`
/// warms every instance up untimed first (lavapipe compiles a pipeline at its first dispatch).
pub trait Timed {
    /// Independently compiled pipelines of the same kernel.
    fn instances(&self) -> usize {
        1
    }
    /// Records instance `instance`'s dispatches (no barriers or timestamps: `measure` adds those).
    fn record(&self, cmd: &Commands, instance: usize);

    /// One untimed run of `instance`, waited for; its wall time (on lavapipe the first includes compilation).
    fn run_once(&self, gpu: &Gpu, instance: usize) -> Result<Duration> {
        let start = Instant::now();
        gpu.submit(|cmd| self.record(cmd, instance))?;
        Ok(start.elapsed())
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
