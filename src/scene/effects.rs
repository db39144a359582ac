//! Effects that need the GPU beyond the scene kernel: the E(mu, r) table of multiple-scattering energy
//! compensation (the model's directional albedo with F = 1, integrated by `kernels::albedo`), and the white
//! furnace of the scene's whole shading (`glsl/scene_albedo.comp`: effects, diffuse and clear coat included).

use super::plan::{self, E_TABLE_MU, E_TABLE_R};
use super::terms::{ETable, Switches};
use crate::brdf::F;
use crate::gpu::{Buffer, Gpu, MemoryKind};
use crate::kernels::{self, Albedo, AlbedoCell, WithConstant, constants};
use crate::model::{KernelKind, Model};
use anyhow::Result;

/// E(mu, r) of `model` with F = 1 (F = none, F0 = 1) at mu_i = (i + 0.5) / E_TABLE_MU, r_j = j / (E_TABLE_R - 1),
/// integrated on the GPU.
pub fn e_table(gpu: &Gpu, model: &Model) -> Result<ETable> {
    let white = match model.twin() {
        Some(spec) => Model::spec(crate::brdf::ModelSpec { f: F::None, ..*spec }),
        None => model.clone(),
    };
    let mut table = ETable { mu_nodes: E_TABLE_MU, r_nodes: E_TABLE_R, values: Vec::new() };
    let cells: Vec<AlbedoCell> = (0..E_TABLE_R)
        .flat_map(|j| (0..E_TABLE_MU).map(move |i| (i, j)))
        .map(|(i, j)| AlbedoCell { nov: table.mu(i) as f32, roughness: table.r(j) as f32, f0: [1.0; 3] })
        .collect();
    table.values = kernels::albedo(gpu, &white, &cells)?.iter().map(|a| a.e[0] as f32).collect();
    Ok(table)
}

/// One furnace cell of the scene shading: a surface with N = +z, T = +x.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FurnaceCell {
    pub nov: f32,
    pub roughness: f32,
    pub f0: [f32; 3],
    pub diffuse_colour: [f32; 3],
    pub anisotropy: f32,
    pub coat: f32,
    pub coat_roughness: f32,
    /// 0 none, 1 Lambert, 2 Burley (read when switches.diffuse == 3).
    pub diffuse: i32,
}

/// The directional albedo of the scene's shading (scene.glsl `shade`) for `model` with `switches`, per cell,
/// integrated on the GPU with albedo.comp's estimator; `table` is E for energy compensation (when switched on).
pub fn scene_albedo(
    gpu: &Gpu,
    model: &Model,
    switches: Switches,
    table: Option<&ETable>,
    cells: &[FurnaceCell],
) -> Result<Vec<Albedo>> {
    let kernel = kernels::model_kernel(
        gpu,
        model,
        KernelKind::SceneAlbedo,
        |c| {
            plan::effect_constants(c, switches)
                .with(constants::E_TABLE_MU, table.map_or(E_TABLE_MU, |t| t.mu_nodes) as f64)
                .with(constants::E_TABLE_R, table.map_or(E_TABLE_R, |t| t.r_nodes) as f64)
                .with(constants::ALBEDO_N, kernels::ALBEDO_GRID as f64)
        },
        3,
        4,
    )?;
    let floats: Vec<f32> = cells
        .iter()
        .flat_map(|c| {
            let (f, d) = (c.f0, c.diffuse_colour);
            [
                c.nov,
                c.roughness,
                c.anisotropy,
                c.coat,
                f[0],
                f[1],
                f[2],
                c.coat_roughness,
                d[0],
                d[1],
                d[2],
                c.diffuse as f32,
            ]
        })
        .collect();
    let inputs = Buffer::with_data(gpu, bytemuck::cast_slice(&floats), MemoryKind::Device)?;
    let table_buf = Buffer::with_data(
        gpu,
        bytemuck::cast_slice(table.map_or(&[1.0f32; 4][..], |t| &t.values)),
        MemoryKind::Device,
    )?;
    kernels::reduce_albedo(gpu, &kernel, cells.len(), |first, count, rows| {
        kernel.bind(&[(&inputs, first * 48, count * 48), (rows, 0, rows.size), (&table_buf, 0, table_buf.size)])
    })
}

/// Floats per sample of `glsl/scene_terms.comp`'s input (13 vec4) and output (6 vec4).
pub const TERM_IN: usize = 52;
pub const TERM_OUT: usize = 24;

/// Every scene.glsl term on its own for each sample (layouts in glsl/scene_terms.comp), with `model` selecting
/// the Fresnel of `specular_anisotropic` and `table` the E table of `e_lookup`; for the tests against the twins.
pub fn scene_terms(
    gpu: &Gpu,
    model: &Model,
    table: &ETable,
    samples: &[[f32; TERM_IN]],
) -> Result<Vec<[f32; TERM_OUT]>> {
    let extra = |c: crate::gpu::SpecConstants| {
        c.with(constants::E_TABLE_MU, table.mu_nodes as f64).with(constants::E_TABLE_R, table.r_nodes as f64)
    };
    let kernel = kernels::model_kernel(gpu, model, KernelKind::SceneTerms, extra, 3, 4)?;
    let n = samples.len() as u64;
    let per_dispatch = gpu.info.max_compute_work_group_count[0] as u64 * crate::gpu::WORKGROUP as u64;
    assert!(n <= per_dispatch, "scene_terms: at most {per_dispatch} samples");
    let flat: Vec<f32> = samples.iter().flatten().copied().collect();
    let inputs = Buffer::with_data(gpu, bytemuck::cast_slice(&flat), MemoryKind::Device)?;
    let outputs = Buffer::new(gpu, n * TERM_OUT as u64 * 4, MemoryKind::Device)?;
    let table_buf = Buffer::with_data(gpu, bytemuck::cast_slice(&table.values), MemoryKind::Device)?;
    let set =
        kernel.bind(&[(&inputs, 0, inputs.size), (&outputs, 0, outputs.size), (&table_buf, 0, table_buf.size)])?;
    gpu.submit(|cmd| kernel.dispatch(cmd, set, &(n as u32).to_ne_bytes(), n))?;
    let v: Vec<f32> = outputs.read_as(0, samples.len() * TERM_OUT)?;
    Ok(v.chunks_exact(TERM_OUT).map(|c| c.try_into().unwrap()).collect())
}
