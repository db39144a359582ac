//! `brdfprof render --scene FILE`: tone-mapped sRGB pictures of the scene, rendered on the device by the scene
//! kernels. One picture per compared model (every material switched to it, as the thesis switched its master
//! material's shading model), a labelled comparison grid of material spheres x models (thesis Figs. 5.3-5.5),
//! heat maps of each model's difference from the reference (GGX) as displayed, and polar plots of f_s NoL in
//! the plane of incidence per roughness (evaluated on the device by `kernels::eval`).

use super::format::{Light, Model, Scene};
use super::gbuffer::{self, GBuffer};
use super::plan;
use super::run;
use crate::export::png;
use crate::export::raster::{LOBE_PANEL, blit, draw_lobes, label, log_colour_bar, log_position, tone_map, viridis};
use crate::gpu::Gpu;
use crate::kernels::{self, RunLimits};
use crate::model::Model as BrdfModel;
use anyhow::Result;
use indicatif::ProgressBar;
use plotters::prelude::*;
use std::path::{Path, PathBuf};

/// Tiles of the comparison grid are this many pixels square.
pub const GRID_TILE: u32 = 200;

fn slug(spec: &BrdfModel) -> String {
    spec.label().chars().map(|c| if c.is_ascii_alphanumeric() || c == '-' { c } else { '-' }).collect()
}

/// Renders `scene` over `g` with every material's model replaced by `model` (the scene's own models when None).
pub fn radiance(
    gpu: &Gpu,
    scene: &Scene,
    g: &GBuffer,
    model: Option<&BrdfModel>,
) -> Result<(Vec<[f32; 3]>, Vec<String>)> {
    let p = plan::plan(scene, g, model);
    let tables = run::e_tables(gpu, &p)?;
    Ok((run::shade(gpu, scene, g, &p, &tables, RunLimits::default())?, p.notes))
}

/// The comparison grid's lights: a key from the upper left front, a cool fill from the right, a rim from behind.
fn studio_lights() -> Vec<Light> {
    vec![
        Light::Directional { direction: [0.55, -0.5, -0.67], colour: [1.0, 0.97, 0.92], intensity: 3.0 },
        Light::Directional { direction: [-0.8, -0.1, -0.6], colour: [0.7, 0.8, 1.0], intensity: 0.5 },
        Light::Directional { direction: [0.2, -0.4, 0.9], colour: [1.0, 1.0, 1.0], intensity: 1.5 },
    ]
}

/// What `render` wrote.
pub struct Rendered {
    pub files: Vec<PathBuf>,
    pub notes: Vec<String>,
    /// Pictures with NaN or Inf pixels, each with their count.
    pub warnings: Vec<String>,
}

/// Shown for a pixel whose radiance is NaN or Inf (never black, which a BRDF can be).
pub const NON_FINITE_COLOUR: [u8; 3] = [255, 0, 255];

/// Tone-mapped pixels, non-finite ones in `NON_FINITE_COLOUR`, and how many those are.
fn display(hdr: &[[f32; 3]], exposure: f32) -> (Vec<[u8; 3]>, usize) {
    let bad = |c: &[f32; 3]| c.iter().any(|x| !x.is_finite());
    (
        hdr.iter().map(|c| if bad(c) { NON_FINITE_COLOUR } else { tone_map(*c, exposure) }).collect(),
        hdr.iter().filter(|c| bad(c)).count(),
    )
}

/// Difference heat maps against the reference model, in displayed luminance (what a viewer sees), one shared
/// log scale per scene from one display level (1/255: what a viewer can see at all) to the largest
/// difference, so that small differences spread over the colours instead of all reading as the darkest.
/// One step of an 8-bit display: the smallest difference a viewer can see.
const LEVEL: f32 = 1.0 / 255.0;

fn difference_maps(g: &GBuffer, models: &[BrdfModel], displayed: &[Vec<[u8; 3]>], out: &Path) -> Result<Vec<PathBuf>> {
    let reference = models.iter().position(|m| *m == BrdfModel::reference()).unwrap_or(0);
    let luma = |c: &[u8; 3]| (0.2126 * c[0] as f32 + 0.7152 * c[1] as f32 + 0.0722 * c[2] as f32) / 255.0;
    let diffs: Vec<(usize, Vec<f32>)> = (0..models.len())
        .filter(|&i| i != reference)
        .map(|i| (i, displayed[i].iter().zip(&displayed[reference]).map(|(a, b)| (luma(a) - luma(b)).abs()).collect()))
        .collect();
    let scale = diffs.iter().flat_map(|(_, d)| d.iter().copied()).fold(0.0f32, f32::max).max(1.0 / 255.0);
    let mut files = Vec::new();
    for (i, d) in &diffs {
        let path = out.join(format!("diff-{}-vs-{}.png", slug(&models[*i]), slug(&models[reference])));
        let px: Vec<[u8; 3]> = d.iter().map(|&x| viridis(log_position(x, LEVEL, scale))).collect();
        let bar = 80;
        let title = format!("|{} - {}| in displayed luminance (log)", models[*i].label(), models[reference].label());
        let mean = d.iter().sum::<f32>() / d.len() as f32;
        png::render(&path, g.width + bar, g.height, |root| {
            blit(root, 0, 0, g.width, &px)?;
            label(root, &title, 8, 6, 16.max(g.height as i32 / 28), WHITE)?;
            label(root, &format!("mean {mean:.4}"), 8, g.height as i32 - 26, 16, WHITE)?;
            log_colour_bar(root, (g.width as i32 + 8, 10, g.height as i32 - 20), LEVEL, scale)
        })?;
        files.push(path);
    }
    Ok(files)
}

/// The comparison grid: one sphere per material (rows) and model (columns), under a studio rig.
fn comparison_grid(
    gpu: &Gpu,
    scene: &Scene,
    models: &[BrdfModel],
    out: &Path,
    warnings: &mut Vec<String>,
) -> Result<PathBuf> {
    let settings = &scene.file.render;
    let rows: Vec<String> = if settings.grid.is_empty() {
        scene.file.materials.iter().map(|m| m.name.clone()).collect()
    } else {
        settings.grid.clone()
    };
    let mut studio = scene.clone();
    studio.file.lights = studio_lights();
    studio.file.render.background = [0.1, 0.1, 0.11];
    let (label_w, header) = (140u32, 34u32);
    let (gw, gh) = (label_w + GRID_TILE * models.len() as u32, header + GRID_TILE * rows.len() as u32);
    let mut tiles = Vec::new();
    for name in &rows {
        let index = scene.material_index(name).expect("checked: grid names a material");
        let closeup = gbuffer::closeup(&studio, index as u32, GRID_TILE);
        for m in models {
            let (hdr, _) = radiance(gpu, &studio, &closeup, Some(m))?;
            let (px, bad) = display(&hdr, settings.exposure);
            if bad > 0 {
                warnings.push(format!(
                    "grid.png: {} on {name}: {bad} of {} pixels are NaN or Inf (drawn magenta)",
                    m.name(),
                    hdr.len()
                ));
            }
            tiles.push(px);
        }
    }
    let grid = out.join("grid.png");
    png::render(&grid, gw, gh, |root| {
        for (j, m) in models.iter().enumerate() {
            label(root, &m.label(), (label_w + j as u32 * GRID_TILE + 8) as i32, 8, 18, BLACK)?;
        }
        for (i, name) in rows.iter().enumerate() {
            let y0 = (header + i as u32 * GRID_TILE) as i32;
            label(root, name, 8, y0 + GRID_TILE as i32 / 2 - 10, 18, BLACK)?;
            for j in 0..models.len() {
                blit(root, (label_w + j as u32 * GRID_TILE) as i32, y0, GRID_TILE, &tiles[i * models.len() + j])?;
            }
        }
        Ok(())
    })?;
    Ok(grid)
}

/// Writes every picture of `scene` into `out`.
pub fn render(gpu: &Gpu, scene: &Scene, out: &Path, progress: &ProgressBar) -> Result<Rendered> {
    let settings = &scene.file.render;
    let exposure = settings.exposure;
    progress.set_message("building the G-buffer");
    let g = gbuffer::build_for(scene, &gpu.info)?;
    let models: Vec<BrdfModel> = settings.models.iter().map(|m: &Model| m.0.clone()).collect();
    let mut files = Vec::new();
    let mut notes = Vec::new();
    let mut warnings = Vec::new();
    let mut displayed: Vec<Vec<[u8; 3]>> = Vec::new();
    for m in &models {
        progress.set_message(format!("rendering {}", m.name()));
        let (hdr, n) = radiance(gpu, scene, &g, Some(m))?;
        notes.extend(n);
        let (px, bad) = display(&hdr, exposure);
        let path = out.join(format!("{}.png", slug(m)));
        if bad > 0 {
            warnings.push(format!(
                "{}: {} of {} pixels are NaN or Inf (drawn magenta in {})",
                m.name(),
                bad,
                hdr.len(),
                path.display()
            ));
        }
        let title = format!("{}: {} ({})", scene.name(), m.label(), m.canonical());
        png::render(&path, g.width, g.height, |root| {
            blit(root, 0, 0, g.width, &px)?;
            label(root, &title, 8, 6, 16.max(g.height as i32 / 28), WHITE)
        })?;
        files.push(path);
        displayed.push(px);
    }
    files.extend(difference_maps(&g, &models, &displayed, out)?);
    progress.set_message("comparison grid");
    files.push(comparison_grid(gpu, scene, &models, out, &mut warnings)?);
    progress.set_message("lobes");
    let lobes = out.join("lobes.png");
    lobe_plot(gpu, &lobes, &models, &settings.lobe_roughness.iter().map(|u| u.0).collect::<Vec<_>>())?;
    files.push(lobes);
    notes.sort();
    notes.dedup();
    Ok(Rendered { files, notes, warnings })
}

/// f_s NoL in the plane of incidence, view at 45 degrees, F0 = 1 (Schlick F = 1), one panel per roughness and a
/// curve per model, each panel normalised to its largest value; evaluated on the device.
pub fn lobe_plot(gpu: &Gpu, path: &Path, models: &[BrdfModel], roughness: &[f32]) -> Result<()> {
    let panels = kernels::lobe_curves(gpu, models, roughness)?;
    let labels: Vec<String> = models.iter().map(BrdfModel::label).collect();
    png::render(path, LOBE_PANEL.0 * panels.len() as u32, LOBE_PANEL.1 + 40, |root| draw_lobes(root, &labels, &panels))
}
