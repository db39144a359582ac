//! brdfprof's kernels as functions on a Gpu, for any model, over inputs of any size (chunked to the device's
//! limits): `eval` (f_s per sample), `terms` (each term per sample) and `albedo` (directional albedo).

pub mod constants;
pub mod shade;

use crate::brdf::Sample;
use crate::gpu::{Binding, Bindings, Buffer, ChunkPlan, Gpu, Kernel, MemoryKind, SpecConstants};
use crate::model::{KernelKind, Model};
use crate::shaders::{Shaders, Spirv};
use anyhow::Result;
use constants::{Constant, ConstantKind};
use std::sync::OnceLock;

/// Every file under glsl/generated/ and its contents: the term table's (`brdf::glsl_gen`) and the kernel
/// constants'. `brdfprof __generate-glsl` writes them (`make spv`); tests/kernels/sources.rs compares.
pub fn generated_glsl() -> Vec<(&'static str, String)> {
    let mut files = crate::brdf::glsl_gen::files();
    files.push(("kernel_constants.glsl", constants::glsl()));
    files
}

/// The embedded kernels (`spv/`), shared by every command that does not compile its own.
pub fn embedded() -> &'static Shaders {
    static EMBEDDED: OnceLock<Shaders> = OnceLock::new();
    EMBEDDED.get_or_init(Shaders::embedded)
}

/// Sets a kernel-level constant (`constants`) by its table entry.
pub trait WithConstant {
    fn with(self, c: Constant, value: f64) -> Self;
}

impl WithConstant for SpecConstants {
    fn with(self, c: Constant, value: f64) -> Self {
        match c.kind {
            ConstantKind::Int => self.int(c.id, value as i32),
            ConstantKind::Float => self.float(c.id, value as f32),
        }
    }
}

/// A pipeline of `model`'s kernel of `kind`, with `extra` constants on top of the model's.
pub fn model_kernel<'g>(
    gpu: &'g Gpu,
    model: &Model,
    kind: KernelKind,
    extra: impl FnOnce(SpecConstants) -> SpecConstants,
    bindings: u32,
    push_bytes: u32,
) -> Result<Kernel<'g>> {
    model.check_support(&gpu.info)?;
    let k = model.kernel(kind, embedded())?;
    kernel(gpu, &k.spirv, &extra(k.constants), bindings, push_bytes)
}

/// A pipeline of `spirv` with `bindings` storage buffers.
pub fn kernel<'g>(
    gpu: &'g Gpu,
    spirv: &Spirv,
    constants: &SpecConstants,
    bindings: u32,
    push_bytes: u32,
) -> Result<Kernel<'g>> {
    Kernel::new(gpu, &spirv.name, &spirv.words, constants, &Binding::storage(bindings), push_bytes)
}

/// Limits on one kernel run over many elements.
#[derive(Clone, Copy, Debug, Default)]
pub struct RunLimits {
    /// Elements per dispatch chunk, below what the device allows (tests use it to force chunking).
    pub max_chunk: Option<u64>,
}

/// Host batches: at most this many bytes of input per submission, so host and device memory stay bounded
/// whatever the input size.
const MAX_BATCH_BYTES: u64 = 1 << 30;

/// Runs an elementwise kernel (binding 0: `in_stride` bytes per element, binding 1: `out_stride`, push constant:
/// element count) over `input`, returning the raw output bytes.
fn run_elementwise(
    gpu: &Gpu,
    kernel: &Kernel,
    input: &[u8],
    in_stride: u64,
    out_stride: u64,
    n: u64,
    limits: RunLimits,
) -> Result<Vec<u8>> {
    let mut output = Vec::with_capacity((n * out_stride) as usize);
    let batch = (MAX_BATCH_BYTES.min(gpu.info.max_memory_allocation_size.max(1 << 27)) / in_stride).max(1);
    let mut first = 0;
    while first < n {
        let count = batch.min(n - first);
        let bytes = &input[(first * in_stride) as usize..((first + count) * in_stride) as usize];
        let inputs = Buffer::with_data(gpu, bytes, MemoryKind::Device)?;
        let outputs = Buffer::new(gpu, count * out_stride, MemoryKind::Device)?;
        let plan = ChunkPlan::new(&gpu.info, count, &[in_stride, out_stride], limits.max_chunk);
        let sets = plan
            .chunks
            .iter()
            .map(|&(start, len)| {
                kernel.bind(&[
                    (&inputs, start * in_stride, len * in_stride),
                    (&outputs, start * out_stride, len * out_stride),
                ])
            })
            .collect::<Result<Vec<_>>>()?;
        gpu.submit(|cmd| {
            for (set, &(_, len)) in sets.iter().zip(&plan.chunks) {
                kernel.dispatch(cmd, *set, &(len as u32).to_ne_bytes(), len);
            }
        })?;
        output.extend_from_slice(&outputs.read(0, count * out_stride)?);
        kernel.reset_bindings()?;
        first += count;
    }
    Ok(output)
}

/// What eval.comp reads per sample besides the sample, for a `.brdf` model: its tangent (X before
/// orthogonalisation; none: the documented basis) and `row_floats` values of the parameters set per row.
#[derive(Clone, Copy, Debug, Default)]
pub struct EvalExtras<'a> {
    pub tangents: Option<&'a [[f32; 3]]>,
    /// `row_floats` values per sample, samples one after another (`FileModel::with_rows`).
    pub rows: &'a [f32],
    pub row_floats: usize,
}

impl EvalExtras<'_> {
    /// vec4s per sample: 4, then the per-row values rounded up to whole vec4s (EVAL_STRIDE in eval.comp).
    fn stride(&self) -> usize {
        4 + self.row_floats.div_ceil(4)
    }
}

pub fn pack_samples(samples: &[Sample], extras: &EvalExtras) -> Vec<u8> {
    let stride = extras.stride();
    let mut floats: Vec<f32> = Vec::with_capacity(samples.len() * stride * 4);
    for (i, s) in samples.iter().enumerate() {
        let [nx, ny, nz] = s.n;
        let [vx, vy, vz] = s.v;
        let [lx, ly, lz] = s.l;
        let [r, g, b] = s.f0;
        let [tx, ty, tz] = extras.tangents.map_or([0.0; 3], |t| t[i]);
        floats.extend_from_slice(&[nx, ny, nz, s.roughness, vx, vy, vz, tx, lx, ly, lz, ty, r, g, b, tz]);
        let row = &extras.rows[i * extras.row_floats..(i + 1) * extras.row_floats];
        floats.extend_from_slice(row);
        floats.resize(floats.len() + (stride - 4) * 4 - row.len(), 0.0);
    }
    bytemuck::cast_slice(&floats).to_vec()
}

/// f_s of `model` for every sample, evaluated on the GPU.
pub fn eval(gpu: &Gpu, model: &Model, samples: &[Sample], limits: RunLimits) -> Result<Vec<[f32; 3]>> {
    eval_with(gpu, model, samples, &EvalExtras::default(), limits)
}

/// `eval` with a `.brdf` model's tangents and per-row parameters.
pub fn eval_with(
    gpu: &Gpu,
    model: &Model,
    samples: &[Sample],
    extras: &EvalExtras,
    limits: RunLimits,
) -> Result<Vec<[f32; 3]>> {
    eval_from(gpu, model, embedded(), samples, extras, limits)
}

/// `eval_with` on the kernels of `shaders` (the embedded ones, or a `--glsl DIR`).
pub fn eval_from(
    gpu: &Gpu,
    model: &Model,
    shaders: &Shaders,
    samples: &[Sample],
    extras: &EvalExtras,
    limits: RunLimits,
) -> Result<Vec<[f32; 3]>> {
    assert_eq!(extras.rows.len(), samples.len() * extras.row_floats, "one row of parameters per sample");
    model.check_support(&gpu.info)?;
    let k = model.kernel(KernelKind::Eval, shaders)?;
    let kernel = self::kernel(gpu, &k.spirv, &k.constants, 2, 4)?;
    let in_stride = 16 * extras.stride() as u64;
    let out =
        run_elementwise(gpu, &kernel, &pack_samples(samples, extras), in_stride, 16, samples.len() as u64, limits)?;
    let floats: Vec<f32> = bytemuck::pod_collect_to_vec(&out);
    Ok(as_f(model, floats.chunks_exact(4).map(|c| [c[0], c[1], c[2]]).collect(), samples))
}

/// The eval kernel's values (of any device) as f_s: a `.brdf` entry that returns f_s N.L (`returns f_nol`)
/// divided by N.L (`f_from_f_nol`), any other model's as they are.
pub fn as_f(model: &Model, values: Vec<[f32; 3]>, samples: &[Sample]) -> Vec<[f32; 3]> {
    if !model.file().is_some_and(|f| f.returns_f_nol()) {
        return values;
    }
    values.into_iter().zip(samples).map(|(g, s)| f_from_f_nol(g, s)).collect()
}

/// f_s from an entry's f_s N.L (`returns f_nol`), divided on the host so that no kernel holds the division:
/// N.L of the unit n and l in f64. Where N.L <= 0 there is no f_s to recover (the light is below the horizon):
/// the value is kept as the entry returned it, f_s N.L, which must be finite, non-negative and about 0 there
/// (an engine's `max(NoL, 1e-8)` returns a tiny positive value; dividing it by a negative N.L would call it a
/// negative f_s).
pub fn f_from_f_nol(g: [f32; 3], s: &Sample) -> [f32; 3] {
    let unit = |v: [f32; 3]| glam::DVec3::new(v[0].into(), v[1].into(), v[2].into()).normalize_or_zero();
    let nol = unit(s.n).dot(unit(s.l));
    if nol <= 0.0 {
        return g;
    }
    g.map(|x| if x == 0.0 { 0.0 } else { (f64::from(x) / nol) as f32 })
}

/// Inputs of the per-term kernel: cosines as given (the kernel guards them), sin2h = 1 - NoH^2, roughness, F0.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TermInput {
    pub nov: f32,
    pub nol: f32,
    pub noh: f32,
    pub voh: f32,
    pub sin2h: f32,
    pub roughness: f32,
    pub f0: [f32; 3],
}

/// Each selected term on its own.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TermOutput {
    pub d: f32,
    pub vis: f32,
    pub f: [f32; 3],
}

/// D, Vis and F of `model` for every input, evaluated on the GPU.
pub fn terms(gpu: &Gpu, model: &Model, inputs: &[TermInput]) -> Result<Vec<TermOutput>> {
    let kernel = model_kernel(gpu, model, KernelKind::Terms, |c| c, 2, 4)?;
    let floats: Vec<f32> = inputs
        .iter()
        .flat_map(|t| [t.nov, t.nol, t.noh, t.voh, t.roughness, t.f0[0], t.f0[1], t.f0[2], t.sin2h, 0.0, 0.0, 0.0])
        .collect();
    let out = run_elementwise(
        gpu,
        &kernel,
        bytemuck::cast_slice(&floats),
        48,
        32,
        inputs.len() as u64,
        RunLimits::default(),
    )?;
    let floats: Vec<f32> = bytemuck::pod_collect_to_vec(&out);
    Ok(floats.chunks_exact(8).map(|c| TermOutput { d: c[0], vis: c[1], f: [c[4], c[5], c[6]] }).collect())
}

/// One directional-albedo cell: the view cosine, perceptual roughness and F0.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AlbedoCell {
    pub nov: f32,
    pub roughness: f32,
    pub f0: [f32; 3],
}

/// E(NoV, r) per channel and an estimate of its integration error: the largest channel difference between E
/// on the full grid and E on its half-resolution subgrid (even rows and columns), which errs more.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Albedo {
    pub e: [f64; 3],
    pub error: f64,
}

/// The albedo kernel's grid: ALBEDO_N azimuth rows x 3 components x ALBEDO_N columns per cell.
pub const ALBEDO_GRID: u32 = 256;

/// Directional albedo of `model` for every cell, integrated on the GPU.
pub fn albedo(gpu: &Gpu, model: &Model, cells: &[AlbedoCell]) -> Result<Vec<Albedo>> {
    let kernel =
        model_kernel(gpu, model, KernelKind::Albedo, |c| c.with(constants::ALBEDO_N, ALBEDO_GRID as f64), 2, 4)?;
    let floats: Vec<f32> =
        cells.iter().flat_map(|c| [c.nov, c.roughness, 0.0, 0.0, c.f0[0], c.f0[1], c.f0[2], 0.0]).collect();
    let inputs = Buffer::with_data(gpu, bytemuck::cast_slice(&floats), MemoryKind::Device)?;
    reduce_albedo(gpu, &kernel, cells.len(), |first, count, rows| {
        kernel.bind(&[(&inputs, first * 32, count * 32), (rows, 0, rows.size)])
    })
}

/// Dispatches an albedo kernel (ALBEDO_GRID rows per cell, two vec4 out per row: the row's mean and its even
/// columns' mean) over `cells` cells in chunks within maxComputeWorkGroupCount.x, and reduces each cell to E and
/// its half-resolution error estimate. `bind(first cell, cells, rows buffer)` binds one chunk.
pub fn reduce_albedo(
    gpu: &Gpu,
    kernel: &Kernel,
    cells: usize,
    bind: impl Fn(u64, u64, &Buffer) -> Result<Bindings>,
) -> Result<Vec<Albedo>> {
    let n = ALBEDO_GRID as u64;
    let mut results = Vec::with_capacity(cells);
    let per_dispatch = (gpu.info.max_compute_work_group_count[0] as u64 * crate::gpu::WORKGROUP as u64 / n).max(1);
    for first in (0..cells as u64).step_by(per_dispatch as usize) {
        let count = per_dispatch.min(cells as u64 - first);
        let rows = Buffer::new(gpu, count * n * 32, MemoryKind::Device)?;
        let set = bind(first, count, &rows)?;
        gpu.submit(|cmd| kernel.dispatch(cmd, set, &((count * n) as u32).to_ne_bytes(), count * n))?;
        let v: Vec<f32> = rows.read_as(0, (count * n * 8) as usize)?;
        for cell in v.chunks_exact(8 * n as usize) {
            let (mut full, mut half) = ([0.0f64; 3], [0.0f64; 3]);
            for (r, row) in cell.chunks_exact(8).enumerate() {
                for c in 0..3 {
                    full[c] += row[c] as f64 / n as f64;
                    if r % 2 == 0 {
                        half[c] += row[4 + c] as f64 / (n / 2) as f64;
                    }
                }
            }
            let error = (0..3).map(|c| (full[c] - half[c]).abs()).fold(0.0, f64::max);
            results.push(Albedo { e: full, error });
        }
        kernel.reset_bindings()?;
    }
    Ok(results)
}

/// View angle of the lobe plots, from the normal.
pub const LOBE_VIEW_DEG: f64 = 45.0;

/// One panel of the lobe plot: its roughness and, per model, (theta_l, f_s NoL) in the plane of incidence.
pub type LobePanel = (f32, Vec<Vec<(f64, f64)>>);

/// The lobe plot's curves, evaluated on the device: per roughness, per model, f_s NoL (red channel) at every
/// half degree of the plane of incidence, view at 45 degrees, F0 = 1.
pub fn lobe_curves(gpu: &Gpu, models: &[Model], roughness: &[f32]) -> Result<Vec<LobePanel>> {
    let theta_v = LOBE_VIEW_DEG.to_radians();
    let v = [-(theta_v.sin()) as f32, 0.0, theta_v.cos() as f32];
    let angles: Vec<f64> = (0..=358).map(|i| (-89.5 + i as f64 * 0.5).to_radians()).collect();
    let mut panels = Vec::new();
    for &r in roughness {
        let samples: Vec<Sample> = angles
            .iter()
            .map(|t| Sample {
                n: [0.0, 0.0, 1.0],
                v,
                l: [t.sin() as f32, 0.0, t.cos() as f32],
                roughness: r,
                f0: [1.0; 3],
            })
            .collect();
        let mut curves = Vec::new();
        for m in models {
            let fs = eval(gpu, m, &samples, RunLimits::default())?;
            curves.push(angles.iter().zip(&fs).map(|(t, f)| (*t, f[0] as f64 * t.cos())).collect::<Vec<_>>());
        }
        panels.push((r, curves));
    }
    Ok(panels)
}
