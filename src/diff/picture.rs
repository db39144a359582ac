//! The diff picture: for each of a few roughness values a lit sphere of A, one of B and a heat map of B's
//! relative difference against A (largest channel, one scale for every map, its colour bar at the right), and
//! below them the polar lobe plot of both models (`kernels::lobe_curves`). Everything is evaluated on
//! the device by the models' eval kernels.

use crate::accuracy::rel_err;
use crate::brdf::Sample;
use crate::export::png;
use crate::export::raster::{LOBE_PANEL, blit, draw_lobes, label, log_colour_bar, log_position, tone_map, viridis};
use crate::gpu::Gpu;
use crate::kernels::{self, RunLimits};
use crate::model::Model;
use anyhow::Result;
use glam::DVec3;
use plotters::prelude::*;
use std::path::Path;

/// Roughness of the spheres and of the lobe panels.
pub const ROUGHNESS: [f32; 3] = [0.2, 0.5, 0.8];
/// Sphere tiles are this many pixels square.
const TILE: u32 = 120;
/// The spheres' material (a copper-like F0) and the light, from the upper right front.
const F0: [f32; 3] = [0.95, 0.64, 0.54];
const LIGHT: [f64; 3] = [0.45, 0.5, 0.74];
/// Light intensity the spheres are shown at (f_s NoL times this, then ACES and sRGB).
const INTENSITY: f32 = 2.0;
/// Colour of pixels off the sphere.
const BACKGROUND: [u8; 3] = [40, 40, 44];
const TOP: u32 = 40 + 22 + TILE + 12;

/// The sphere's pixels seen from +z (row-major, TILE x TILE): the sample of each pixel on it, None off it.
fn sphere(roughness: f32) -> Vec<Option<Sample>> {
    let l = DVec3::from(LIGHT).normalize().as_vec3().to_array();
    (0..TILE * TILE)
        .map(|i| {
            let t = |k: u32| (k as f64 + 0.5) / TILE as f64 * 2.0 - 1.0;
            let (x, y) = (t(i % TILE), -t(i / TILE));
            let r2 = x * x + y * y;
            (r2 < 1.0).then(|| Sample {
                n: [x as f32, y as f32, (1.0 - r2).sqrt() as f32],
                v: [0.0, 0.0, 1.0],
                l,
                roughness,
                f0: F0,
            })
        })
        .collect()
}

/// f_s NoL of `model` at each sphere pixel (0 off the sphere).
fn radiance(gpu: &Gpu, model: &Model, pixels: &[Option<Sample>]) -> Result<Vec<[f32; 3]>> {
    let on: Vec<Sample> = pixels.iter().flatten().copied().collect();
    let mut values = kernels::eval(gpu, model, &on, RunLimits::default())?.into_iter();
    Ok(pixels
        .iter()
        .map(|p| match p {
            Some(s) => {
                let nol = DVec3::from(s.n.map(f64::from)).dot(DVec3::from(s.l.map(f64::from))).max(0.0) as f32;
                values.next().expect("one value per sphere pixel").map(|f| f * nol)
            }
            None => [0.0; 3],
        })
        .collect())
}

/// Writes the picture of B against A to `path`.
pub fn write(gpu: &Gpu, path: &Path, a: &Model, b: &Model) -> Result<()> {
    let (w, h, px) = pixels(gpu, a, b)?;
    png::write_png(path, w, h, px)
}

/// The picture of B against A: (width, height, 8-bit RGB pixels).
pub fn pixels(gpu: &Gpu, a: &Model, b: &Model) -> Result<(u32, u32, Vec<u8>)> {
    let mut shown: Vec<[Vec<[u8; 3]>; 2]> = Vec::new();
    let mut diffs: Vec<Vec<Option<f32>>> = Vec::new();
    for r in ROUGHNESS {
        let pixels = sphere(r);
        let (ra, rb) = (radiance(gpu, a, &pixels)?, radiance(gpu, b, &pixels)?);
        let display = |v: &[[f32; 3]]| {
            v.iter()
                .zip(&pixels)
                .map(|(c, p)| if p.is_some() { tone_map(c.map(|x| x * INTENSITY), 1.0) } else { BACKGROUND })
                .collect::<Vec<_>>()
        };
        shown.push([display(&ra), display(&rb)]);
        let rel = |x: &[f32; 3], y: &[f32; 3]| {
            (0..3).map(|c| rel_err(f64::from(y[c]), f64::from(x[c]))).fold(0.0, f64::max) as f32
        };
        diffs.push(ra.iter().zip(&rb).zip(&pixels).map(|((x, y), p)| p.map(|_| rel(x, y))).collect());
    }
    let scale = diffs.iter().flatten().flatten().copied().fold(0.0f32, |m, x| if x.is_finite() { m.max(x) } else { m });
    let panels = kernels::lobe_curves(gpu, &[a.clone(), b.clone()], &ROUGHNESS)?;
    let names = [a.label(), b.label()];
    let width = LOBE_PANEL.0 * ROUGHNESS.len() as u32;
    // The map's log scale: three decades below the largest difference (none below 1e-5), so that small
    // differences spread over the colours instead of all reading as the darkest.
    let floor = (scale / 1000.0).max(1e-5);
    let size = (width + 90, TOP + LOBE_PANEL.1 + 40);
    let px = png::pixels(size.0, size.1, |root| {
        let title = format!(
            "B = {} against A = {}: lit spheres and |B - A| / max(|A|, 1e-3) (largest channel, log scale)",
            names[1], names[0]
        );
        label(root, &title, 10, 8, 18, BLACK)?;
        for (g, r) in ROUGHNESS.iter().enumerate() {
            let x0 = (g as u32 * LOBE_PANEL.0 + 10) as i32;
            let map: Vec<[u8; 3]> = diffs[g]
                .iter()
                .map(|d| {
                    d.map_or(BACKGROUND, |x| {
                        if x.is_finite() { viridis(log_position(x, floor, scale)) } else { [255, 0, 255] }
                    })
                })
                .collect();
            for (k, (px, what)) in [(&shown[g][0], "A"), (&shown[g][1], "B"), (&map, "B vs A")].into_iter().enumerate()
            {
                let x = x0 + (k as u32 * (TILE + 10)) as i32;
                label(root, &format!("{what}, r = {r}"), x, 42, 13, BLACK)?;
                blit(root, x, 62, TILE, px)?;
            }
        }
        log_colour_bar(root, (width as i32 + 8, 62, TILE as i32), floor, scale.max(floor))?;
        let (_, below) = root.split_vertically(TOP);
        let (lobes, _) = below.split_horizontally(width);
        draw_lobes(&lobes, &names, &panels)
    })?;
    Ok((size.0, size.1, px))
}
