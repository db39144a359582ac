//! Energy: the directional albedo E(NoV, r) of every spec with F = 1, integrated on the GPU (`kernels::albedo`,
//! with its error bound), which specs gain energy (E > 1 beyond that bound) and how much each loses at r = 1;
//! shown as a white furnace (spheres on white: a lossless BRDF vanishes, loss shows grey, gain shows red) and
//! as E(NoV) curves per roughness.

use super::SpecStability;
use crate::brdf::{F, ModelSpec};
use crate::export::png;
use crate::gpu::Gpu;
use crate::kernels::{self, AlbedoCell};
use crate::model::Model;
use anyhow::{Result, anyhow};
use indicatif::ProgressBar;
use plotters::prelude::*;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::path::Path;

pub const NOV: [f32; 16] = [0.02, 0.05, 0.1, 0.15, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.85, 0.9, 0.95, 0.98, 1.0];
pub const ROUGHNESS: [f32; 5] = [0.1, 0.25, 0.5, 0.75, 1.0];

/// Read back from stability reports too: what no reader shows is skipped, and null figures read as NaN.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Energy {
    /// E[r][nov] over ROUGHNESS x NOV, with F = 1 (f32 is precise enough for integrals good to 1e-3).
    #[serde(deserialize_with = "nan_if_null_cells")]
    pub e: Vec<Vec<f32>>,
    /// The largest integration-error estimate of the cells.
    #[serde(skip_deserializing)]
    pub error_bound: f64,
    /// The largest E of the finite cells (None when no cell is finite).
    pub max_e: Option<f64>,
    /// (NoV, roughness) of max_e.
    #[serde(skip_deserializing)]
    pub max_at: (f32, f32),
    /// Cells whose E is NaN or Inf (left out of max_e; never a gain or a loss).
    #[serde(skip_deserializing)]
    pub nonfinite: usize,
    /// max_e > 1 + error_bound.
    pub gains_energy: bool,
    /// Hemispherical albedo 2 * integral of E(mu) mu dmu at r = 1 (1 - this is the energy lost to single scattering).
    #[serde(default = "crate::io::nan", deserialize_with = "crate::io::nan_if_null")]
    pub hemispherical_at_r1: f64,
    /// Check against the CPU's f64 integration of the same formula at r in {0.1, 0.5, 1}: the largest
    /// |E_gpu - E_cpu| / max(1, E_cpu) over the finite cells, and how many cells were not finite; None for a
    /// model without an f64 twin (a `.brdf` file).
    #[serde(skip_deserializing)]
    pub cpu_check: Option<f64>,
    #[serde(skip_deserializing)]
    pub cpu_check_nonfinite: usize,
}

/// `e` as read back: a NaN or Inf cell, written as null, reads as NaN.
fn nan_if_null_cells<'de, D: serde::Deserializer<'de>>(d: D) -> std::result::Result<Vec<Vec<f32>>, D::Error> {
    let cells = Vec::<Vec<Option<f32>>>::deserialize(d)?;
    Ok(cells.into_iter().map(|row| row.into_iter().map(|x| x.unwrap_or(f32::NAN)).collect()).collect())
}

impl Energy {
    /// The number of (roughness, NoV) cells.
    pub fn cells(&self) -> usize {
        self.e.iter().map(Vec::len).sum()
    }
}

/// The spec with F = 1 (F = none with F0 = 1): only D and Vis (and the precision) decide energy.
pub fn white(spec: &ModelSpec) -> ModelSpec {
    ModelSpec { f: F::None, ..*spec }
}

pub fn cells() -> Vec<AlbedoCell> {
    ROUGHNESS
        .iter()
        .flat_map(|&roughness| NOV.iter().map(move |&nov| AlbedoCell { nov, roughness, f0: [1.0; 3] }))
        .collect()
}

/// The model whose albedo is E: a spec with F = 1; a `.brdf` file as it is, given F0 = 1 (so F = 1 where its
/// Fresnel is Schlick's of a parameter bound to `@f0`).
pub fn white_model(model: &Model) -> Model {
    match model.twin() {
        Some(spec) => Model::spec(white(spec)),
        None => model.clone(),
    }
}

pub fn energy_of(gpu: &Gpu, model: &Model) -> Result<Energy> {
    let white = white_model(model);
    let albedo = kernels::albedo(gpu, &white, &cells())?;
    let e: Vec<Vec<f32>> = albedo.chunks(NOV.len()).map(|row| row.iter().map(|a| a.e[0] as f32).collect()).collect();
    let error_bound = albedo.iter().map(|a| a.error).fold(0.0, f64::max);
    let (mut max_e, mut max_at, mut nonfinite) = (None, (0.0, 0.0), 0);
    for (ri, row) in e.iter().enumerate() {
        for (vi, &x) in row.iter().enumerate() {
            let x = x as f64;
            if !x.is_finite() {
                nonfinite += 1;
            } else if max_e.is_none_or(|m| x > m) {
                max_e = Some(x);
                max_at = (NOV[vi], ROUGHNESS[ri]);
            }
        }
    }
    let last: Vec<f64> = e.last().unwrap().iter().map(|&x| x as f64).collect();
    // Trapezoid over NoV, with E held at its first node down to NoV = 0.
    let mut hemi = (NOV[0] as f64).powi(2) * last[0];
    for i in 1..NOV.len() {
        let (m0, m1) = (NOV[i - 1] as f64, NOV[i] as f64);
        hemi += (m1 - m0) * (last[i - 1] * m0 + last[i] * m1);
    }
    let (mut cpu_check, mut cpu_check_nonfinite) = (None, 0);
    if let Some(white) = white.twin() {
        let checked: Vec<(usize, usize)> = (0..ROUGHNESS.len())
            .filter(|&r| [0.1, 0.5, 1.0].contains(&ROUGHNESS[r]))
            .flat_map(|r| (0..NOV.len()).map(move |v| (r, v)))
            .collect();
        let cells = cells();
        let cpu: Vec<f64> = checked
            .par_iter()
            .map(|&(r, v)| crate::accuracy::albedo_twin(white, &cells[r * NOV.len() + v])[0])
            .collect();
        let mut worst = 0.0f64;
        for (&(r, v), c) in checked.iter().zip(&cpu) {
            let g = e[r][v] as f64;
            if g.is_finite() { worst = worst.max((g - c).abs() / c.max(1.0)) } else { cpu_check_nonfinite += 1 }
        }
        cpu_check = Some(worst);
    }
    let gains_energy = max_e.is_some_and(|m| m > 1.0 + error_bound);
    Ok(Energy {
        e,
        error_bound,
        max_e,
        max_at,
        nonfinite,
        gains_energy,
        hemispherical_at_r1: hemi,
        cpu_check,
        cpu_check_nonfinite,
    })
}

/// Computes energy once per distinct white model and attaches it to every result.
pub fn attach(gpu: &Gpu, models: &[Model], results: &mut [SpecStability], progress: &ProgressBar) -> Result<()> {
    let mut done: Vec<(Model, Energy)> = Vec::new();
    for (i, (spec, result)) in models.iter().zip(results.iter_mut()).enumerate() {
        progress.set_position(i as u64);
        progress.set_message(format!("energy: {}", spec.name()));
        let w = white_model(spec);
        let energy = match done.iter().find(|(s, _)| *s == w) {
            Some((_, e)) => e.clone(),
            None => {
                let e = energy_of(gpu, spec)?;
                done.push((w, e.clone()));
                e
            }
        };
        result.energy = Some(energy);
    }
    Ok(())
}

fn interpolate(e: &[f32], nov: f64) -> f64 {
    if nov <= NOV[0] as f64 {
        return e[0] as f64;
    }
    for i in 1..NOV.len() {
        let (a, b) = (NOV[i - 1] as f64, NOV[i] as f64);
        if nov <= b {
            let t = (nov - a) / (b - a);
            return e[i - 1] as f64 * (1.0 - t) + e[i] as f64 * t;
        }
    }
    e[NOV.len() - 1] as f64
}

/// Colour of a furnace pixel: grey (display-encoded) for E <= 1, towards red as E exceeds 1 (full red at 1.5).
fn furnace_colour(e: f64) -> RGBColor {
    if !e.is_finite() {
        return RGBColor(255, 0, 255);
    }
    if e <= 1.0 {
        let g = (e.max(0.0).powf(1.0 / 2.2) * 255.0).round() as u8;
        RGBColor(g, g, g)
    } else {
        let t = ((e - 1.0) / 0.5).min(1.0);
        let g = (255.0 * (1.0 - t)).round() as u8;
        RGBColor(255, g, g)
    }
}

/// White furnace: one row of spheres per spec (columns: roughness), on white.
pub fn furnace_png(path: &Path, entries: &[(String, &Energy)]) -> Result<()> {
    let (cell, label_w, header) = (64i32, 420i32, 60i32);
    let width = (label_w + cell * ROUGHNESS.len() as i32 + 20) as u32;
    let height = (header + cell * entries.len() as i32 + 60) as u32;
    png::render(path, width, height, |root| {
        let err = |e: &dyn std::fmt::Display| anyhow!("furnace: {e}");
        let text = |s: &str, x: i32, y: i32, size: i32| Text::new(s.to_string(), (x, y), (png::FONT, size).into_font());
        root.draw(&text(
            "White furnace: E(NoV) with F = 1 (white = lossless, grey = loss, red = gain, magenta = non-finite)",
            10,
            10,
            16,
        ))
        .map_err(|e| err(&e))?;
        for (j, r) in ROUGHNESS.iter().enumerate() {
            root.draw(&text(&format!("r = {r}"), label_w + j as i32 * cell + 8, header - 24, 16))
                .map_err(|e| err(&e))?;
        }
        for (i, (label, energy)) in entries.iter().enumerate() {
            let y0 = header + i as i32 * cell;
            root.draw(&text(label, 10, y0 + cell / 2 - 8, 14)).map_err(|e| err(&e))?;
            for (j, row) in energy.e.iter().enumerate() {
                let x0 = label_w + j as i32 * cell;
                let radius = (cell / 2 - 4) as f64;
                for py in 0..cell {
                    for px in 0..cell {
                        let (dx, dy) = (
                            (px as f64 + 0.5 - cell as f64 / 2.0) / radius,
                            (py as f64 + 0.5 - cell as f64 / 2.0) / radius,
                        );
                        let d2 = dx * dx + dy * dy;
                        if d2 < 1.0 {
                            root.draw_pixel((x0 + px, y0 + py), &furnace_colour(interpolate(row, (1.0 - d2).sqrt())))
                                .map_err(|e| err(&e))?;
                        }
                    }
                }
            }
        }
        Ok(())
    })
}

/// E(NoV) per roughness, one panel per roughness, one line per spec.
pub fn albedo_chart(path: &Path, entries: &[(String, &Energy)]) -> Result<()> {
    let panels: Vec<(String, Vec<(String, Vec<(f64, f64)>)>)> = ROUGHNESS
        .iter()
        .enumerate()
        .map(|(ri, r)| {
            let series = entries
                .iter()
                .map(|(label, e)| {
                    (label.clone(), NOV.iter().zip(&e.e[ri]).map(|(&v, &x)| (v as f64, (x as f64).min(4.0))).collect())
                })
                .collect();
            (format!("r = {r}"), series)
        })
        .collect();
    png::line_panels(path, "Directional albedo E(NoV) with F = 1", "NoV", "E", &panels, (0.0, 1.3))
}
