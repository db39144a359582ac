//! `brdfprof render --scene FILE`: tone-mapped sRGB pictures of the scene, rendered on the device by the scene
//! kernels. One picture per compared model (every material switched to it, as the thesis switched its master
//! material's shading model), a labelled comparison grid of material spheres x models (thesis Figs. 5.3-5.5),
//! heat maps of each model's difference from the reference (GGX) as displayed, and polar plots of f_s NoL in
//! the plane of incidence per roughness (evaluated on the device by `kernels::eval`).

use super::format::{Light, Model, Scene};
use super::gbuffer::{self, GBuffer};
use super::plan;
use super::run;
use crate::brdf::Sample;
use crate::model::Model as BrdfModel;
use crate::chart::{self, FONT};
use crate::gpu::Gpu;
use crate::kernels::{self, RunLimits};
use anyhow::{anyhow, Result};
use indicatif::ProgressBar;
use plotters::prelude::*;
use std::path::{Path, PathBuf};

/// Tiles of the comparison grid are this many pixels square.
pub const GRID_TILE: u32 = 200;

/// ACES filmic tone curve, Narkowicz 2015 fit: x (2.51 x + 0.03) / (x (2.43 x + 0.59) + 0.14), clamped to [0, 1].
pub fn aces(x: f32) -> f32 {
    let x = x.max(0.0);
    (x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14)).clamp(0.0, 1.0)
}

/// The sRGB OETF (IEC 61966-2-1): linear [0, 1] to display-encoded.
pub fn linear_to_srgb(c: f32) -> f32 {
    if c <= 0.0031308 { 12.92 * c } else { 1.055 * c.powf(1.0 / 2.4) - 0.055 }
}

/// Radiance to 8-bit sRGB: exposure, ACES per channel, sRGB encoding.
pub fn tone_map(rgb: [f32; 3], exposure: f32) -> [u8; 3] {
    rgb.map(|c| (linear_to_srgb(aces(c * exposure)) * 255.0).round() as u8)
}

fn slug(spec: &BrdfModel) -> String {
    spec.label().chars().map(|c| if c.is_ascii_alphanumeric() || c == '-' { c } else { '-' }).collect()
}

/// Draws an RGB picture (w x h, row-major) at (x0, y0) of a plotters area.
pub fn blit(root: &DrawingArea<BitMapBackend, plotters::coord::Shift>, x0: i32, y0: i32, w: u32, px: &[[u8; 3]]) -> Result<()> {
    for (i, c) in px.iter().enumerate() {
        let (x, y) = ((i as u32 % w) as i32, (i as u32 / w) as i32);
        root.draw_pixel((x0 + x, y0 + y), &RGBColor(c[0], c[1], c[2])).map_err(|e| anyhow!("{e}"))?;
    }
    Ok(())
}

pub fn label(root: &DrawingArea<BitMapBackend, plotters::coord::Shift>, text: &str, x: i32, y: i32, size: i32, colour: RGBColor) -> Result<()> {
    root.draw(&Text::new(text.to_string(), (x, y), (FONT, size).into_font().color(&colour))).map_err(|e| anyhow!("{e}"))
}

/// Renders `scene` over `g` with every material's model replaced by `model` (the scene's own models when None).
pub fn radiance(gpu: &Gpu, scene: &Scene, g: &GBuffer, model: Option<&BrdfModel>) -> Result<(Vec<[f32; 3]>, Vec<String>)> {
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
    (hdr.iter().map(|c| if bad(c) { NON_FINITE_COLOUR } else { tone_map(*c, exposure) }).collect(), hdr.iter().filter(|c| bad(c)).count())
}

/// Difference heat maps against the reference model, in displayed luminance (what a viewer sees), one shared
/// scale per scene.
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
        let px: Vec<[u8; 3]> = d.iter().map(|x| viridis(x / scale)).collect();
        let bar = 60;
        let title = format!("|{} - {}| in displayed luminance", models[*i].label(), models[reference].label());
        let mean = d.iter().sum::<f32>() / d.len() as f32;
        chart::render(&path, g.width + bar, g.height, |root| {
            blit(root, 0, 0, g.width, &px)?;
            label(root, &title, 8, 6, 16.max(g.height as i32 / 28), WHITE)?;
            label(root, &format!("mean {mean:.4}"), 8, g.height as i32 - 26, 16, WHITE)?;
            colour_bar(root, g.width as i32 + 8, 10, g.height as i32 - 20, scale)
        })?;
        files.push(path);
    }
    Ok(files)
}

/// The comparison grid: one sphere per material (rows) and model (columns), under a studio rig.
fn comparison_grid(gpu: &Gpu, scene: &Scene, models: &[BrdfModel], out: &Path, warnings: &mut Vec<String>) -> Result<PathBuf> {
    let settings = &scene.file.render;
    let rows: Vec<String> = if settings.grid.is_empty() { scene.file.materials.iter().map(|m| m.name.clone()).collect() } else { settings.grid.clone() };
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
                warnings.push(format!("grid.png: {} on {name}: {bad} of {} pixels are NaN or Inf (drawn magenta)", m.name(), hdr.len()));
            }
            tiles.push(px);
        }
    }
    let grid = out.join("grid.png");
    chart::render(&grid, gw, gh, |root| {
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
            warnings.push(format!("{}: {} of {} pixels are NaN or Inf (drawn magenta in {})", m.name(), bad, hdr.len(), path.display()));
        }
        let title = format!("{}: {} ({})", scene.name(), m.label(), m.canonical());
        chart::render(&path, g.width, g.height, |root| {
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

/// Viridis colour map (matplotlib's, 9 control points, linear in between) for t in [0, 1].
pub fn viridis(t: f32) -> [u8; 3] {
    const P: [[f32; 3]; 9] = [
        [68.0, 1.0, 84.0], [71.0, 44.0, 122.0], [59.0, 81.0, 139.0], [44.0, 113.0, 142.0], [33.0, 144.0, 141.0],
        [39.0, 173.0, 129.0], [92.0, 200.0, 99.0], [170.0, 220.0, 50.0], [253.0, 231.0, 37.0],
    ];
    let x = t.clamp(0.0, 1.0) * 8.0;
    let i = (x as usize).min(7);
    let f = x - i as f32;
    [0, 1, 2].map(|c| (P[i][c] * (1.0 - f) + P[i + 1][c] * f).round() as u8)
}

/// A vertical viridis bar from 0 (bottom) to `scale` (top), the top labelled with `report::sig` (three
/// significant figures: a scale of 0.003 reads 0.003, not 0.00).
pub fn colour_bar(root: &DrawingArea<BitMapBackend, plotters::coord::Shift>, x0: i32, y0: i32, h: i32, scale: f32) -> Result<()> {
    for y in 0..h {
        let c = viridis(1.0 - y as f32 / (h - 1) as f32);
        root.draw(&Rectangle::new([(x0, y0 + y), (x0 + 14, y0 + y + 1)], RGBColor(c[0], c[1], c[2]).filled())).map_err(|e| anyhow!("{e}"))?;
    }
    label(root, &crate::results::sig(f64::from(scale), 3), x0 + 16, y0, 12, BLACK)?;
    label(root, "0", x0 + 16, y0 + h - 12, 12, BLACK)
}

/// f_s NoL in the plane of incidence, view at 45 degrees, F0 = 1 (Schlick F = 1), one panel per roughness and a
/// curve per model, each panel normalised to its largest value; evaluated on the device.
pub fn lobe_plot(gpu: &Gpu, path: &Path, models: &[BrdfModel], roughness: &[f32]) -> Result<()> {
    let panels = lobe_curves(gpu, models, roughness)?;
    let labels: Vec<String> = models.iter().map(BrdfModel::label).collect();
    chart::render(path, LOBE_PANEL.0 * panels.len() as u32, LOBE_PANEL.1 + 40, |root| draw_lobes(root, &labels, &panels))
}

/// One lobe panel's size in pixels (`draw_lobes` adds a 40-pixel title).
pub const LOBE_PANEL: (u32, u32) = (420, 300);

/// View angle of the lobe plots, from the normal.
const LOBE_VIEW_DEG: f64 = 45.0;

/// One panel of the lobe plot: its roughness and, per model, (theta_l, f_s NoL) in the plane of incidence.
pub type LobePanel = (f32, Vec<Vec<(f64, f64)>>);

/// The lobe plot's curves, evaluated on the device: per roughness, per model, f_s NoL (red channel) at every
/// half degree of the plane of incidence, view at 45 degrees, F0 = 1.
pub fn lobe_curves(gpu: &Gpu, models: &[BrdfModel], roughness: &[f32]) -> Result<Vec<LobePanel>> {
    let theta_v = LOBE_VIEW_DEG.to_radians();
    let v = [-(theta_v.sin()) as f32, 0.0, theta_v.cos() as f32];
    let angles: Vec<f64> = (0..=358).map(|i| (-89.5 + i as f64 * 0.5).to_radians()).collect();
    let mut panels = Vec::new();
    for &r in roughness {
        let samples: Vec<Sample> = angles
            .iter()
            .map(|t| Sample { n: [0.0, 0.0, 1.0], v, l: [t.sin() as f32, 0.0, t.cos() as f32], roughness: r, f0: [1.0; 3] })
            .collect();
        let mut curves = Vec::new();
        for m in models {
            let fs = kernels::eval(gpu, m, &samples, RunLimits::default())?;
            curves.push(angles.iter().zip(&fs).map(|(t, f)| (*t, f[0] as f64 * t.cos())).collect::<Vec<_>>());
        }
        panels.push((r, curves));
    }
    Ok(panels)
}

/// Draws `lobe_curves` (one curve per label) into `root`: a title, then the panels side by side.
pub fn draw_lobes(root: &DrawingArea<BitMapBackend, plotters::coord::Shift>, labels: &[String], panels: &[LobePanel]) -> Result<()> {
    let theta_v = LOBE_VIEW_DEG.to_radians();
    let err = |e: &dyn std::fmt::Display| anyhow!("lobes: {e}");
    let root = root.titled("f_s NoL in the plane of incidence (view at 45 deg, F0 = 1); each panel scaled to its peak", (FONT, 18)).map_err(|e| err(&e))?;
    for (area, (r, curves)) in root.split_evenly((1, panels.len())).iter().zip(panels) {
        let peak = curves.iter().flatten().map(|p| p.1).fold(0.0f64, f64::max).max(1e-30);
        let mut chart = ChartBuilder::on(area)
            .caption(format!("r = {r} (peak {})", crate::results::sig(peak, 3)), (FONT, 16))
            .margin(10)
            .build_cartesian_2d(-1.15f64..1.15, -0.05f64..1.15)
            .map_err(|e| err(&e))?;
        for rr in [0.25, 0.5, 0.75, 1.0] {
            let arc = (0..=180).map(|i| {
                let t = (i as f64 - 90.0).to_radians();
                (rr * t.sin(), rr * t.cos())
            });
            chart.draw_series(LineSeries::new(arc, RGBColor(215, 215, 215).stroke_width(1))).map_err(|e| err(&e))?;
        }
        let view = [(0.0, 0.0), (-theta_v.sin() * 1.1, theta_v.cos() * 1.1)];
        chart.draw_series(LineSeries::new(view, BLACK.stroke_width(2))).map_err(|e| err(&e))?;
        chart.draw_series(std::iter::once(Text::new("V", (-theta_v.sin() * 1.12, theta_v.cos() * 1.12 + 0.05), (FONT, 14)))).map_err(|e| err(&e))?;
        for (i, (label, c)) in labels.iter().zip(curves).enumerate() {
            let colour = chart::palette(i);
            let pts = c.iter().map(|(t, y)| {
                let rr = y / peak;
                (rr * t.sin(), rr * t.cos())
            });
            chart
                .draw_series(LineSeries::new(pts, colour.stroke_width(2)))
                .map_err(|e| err(&e))?
                .label(label.clone())
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], colour.stroke_width(2)));
        }
        chart.configure_series_labels().position(SeriesLabelPosition::UpperLeft).label_font((FONT, 12)).background_style(WHITE.mix(0.8)).border_style(BLACK).draw().map_err(|e| err(&e))?;
    }
    Ok(())
}
