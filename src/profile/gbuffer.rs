//! The synthetic G-buffer and lights of the default profile: what a deferred lighting pass reads.
//!
//! The picture is a grid of spheres in front of a floor, seen by a pinhole camera, like the thesis' material
//! rows (Fig. 5.2): roughness rises along a row, rows alternate metal and dielectric base colours, so every
//! model meets the whole range of roughness, normal and view angles, and some back-facing lights.

use crate::util::hash01;
use glam::Vec3;
use rayon::prelude::*;

/// Floats per pixel: (n.xyz, roughness), (v.xyz, metallic), (base colour, 1).
pub const PIXEL_FLOATS: usize = 12;
/// Floats per light: (l.xyz, 0), (rgb, 0).
pub const LIGHT_FLOATS: usize = 8;

pub struct GBuffer {
    pub width: u32,
    pub height: u32,
    /// PIXEL_FLOATS per pixel, row-major.
    pub pixels: Vec<f32>,
}

impl GBuffer {
    pub fn pixel_count(&self) -> u64 {
        self.width as u64 * self.height as u64
    }
}

fn normalize(v: [f32; 3]) -> [f32; 3] {
    Vec3::from(v).normalize().to_array()
}

const SPHERE_COLUMNS: u32 = 8;
const SPHERE_ROWS: u32 = 4;

/// Base colours of the sphere rows: gold and aluminium metals, red plastic, black rubber (thesis Fig. 5.3-5.5).
const ROW_MATERIALS: [([f32; 3], f32); SPHERE_ROWS as usize] =
    [([1.0, 0.78, 0.34], 1.0), ([0.91, 0.92, 0.92], 1.0), ([0.6, 0.05, 0.04], 0.0), ([0.02, 0.02, 0.02], 0.0)];

pub fn synthetic(width: u32, height: u32) -> GBuffer {
    let mut pixels = vec![0f32; width as usize * height as usize * PIXEL_FLOATS];
    let aspect = width as f32 / height as f32;
    let tan_half_fov = (30f32).to_radians().tan();
    pixels.par_chunks_mut(width as usize * PIXEL_FLOATS).enumerate().for_each(|(y, row)| {
        for x in 0..width as usize {
            // Camera at the origin looking down -z; V points from the surface to the eye.
            let sx = ((x as f32 + 0.5) / width as f32 * 2.0 - 1.0) * aspect * tan_half_fov;
            let sy = (1.0 - (y as f32 + 0.5) / height as f32 * 2.0) * tan_half_fov;
            let view = normalize([-sx, -sy, 1.0]);
            // Which sphere cell, and where inside it.
            let cu = (x as f32 + 0.5) / width as f32 * SPHERE_COLUMNS as f32;
            let cv = (y as f32 + 0.5) / height as f32 * SPHERE_ROWS as f32;
            let (col, rowi) = (cu.floor() as u32, cv.floor() as u32);
            let (px, py) = ((cu.fract() - 0.5) * 2.2, (0.5 - cv.fract()) * 2.2);
            let d2 = px * px + py * py;
            let id = (y * width as usize + x) as u32;
            let noise = hash01(id);
            let (normal, roughness, base, metallic) = if d2 < 1.0 {
                let n = normalize([px, py, (1.0 - d2).sqrt()]);
                let r = (col as f32 + 0.5) / SPHERE_COLUMNS as f32;
                let (base, metallic) = ROW_MATERIALS[rowi as usize];
                (n, (r + 0.04 * (noise - 0.5)).clamp(0.0, 1.0), base, metallic)
            } else {
                // Floor: a bumpy plane facing the camera at a grazing tilt.
                let jitter = [hash01(id ^ 0x9e37_79b9) - 0.5, hash01(id ^ 0x7f4a_7c15) - 0.5];
                let n = normalize([0.15 * jitter[0], 0.8 + 0.15 * jitter[1], 0.6]);
                (n, 0.3 + 0.6 * noise, [0.5, 0.45, 0.4], 0.0)
            };
            let p = &mut row[x * PIXEL_FLOATS..(x + 1) * PIXEL_FLOATS];
            p.copy_from_slice(&[
                normal[0], normal[1], normal[2], roughness, view[0], view[1], view[2], metallic, base[0], base[1], base[2], 1.0,
            ]);
        }
    });
    GBuffer { width, height, pixels }
}

/// `count` directional lights spread over the sphere by a golden-angle spiral biased towards the camera,
/// so most light most pixels but some come from behind; colours and intensities vary.
pub fn lights(count: u32) -> Vec<f32> {
    let golden = std::f32::consts::PI * (3.0 - 5f32.sqrt());
    (0..count)
        .flat_map(|i| {
            let t = (i as f32 + 0.5) / count as f32;
            let z = 1.0 - 1.6 * t; // from the camera side (z = 1) to partly behind (z = -0.6)
            let r = (1.0 - z * z).max(0.0).sqrt();
            let phi = golden * i as f32;
            let dir = [r * phi.cos(), r * phi.sin(), z];
            let warm = hash01(i * 7919 + 1);
            let intensity = 0.5 + 2.0 * hash01(i * 104729 + 3);
            let colour = [intensity * (0.8 + 0.2 * warm), intensity * 0.9, intensity * (1.0 - 0.2 * warm)];
            [dir[0], dir[1], dir[2], 0.0, colour[0], colour[1], colour[2], 0.0]
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gbuffer_is_deterministic_and_plausible() {
        let a = synthetic(64, 36);
        assert_eq!(a.pixels, synthetic(64, 36).pixels);
        let mut visible = 0;
        for p in a.pixels.chunks_exact(PIXEL_FLOATS) {
            let nov = p[0] * p[4] + p[1] * p[5] + p[2] * p[6];
            assert!((0.0..=1.0).contains(&p[3]), "roughness {}", p[3]);
            visible += (nov > 0.0) as u32;
        }
        assert!(visible as usize > a.pixels.len() / PIXEL_FLOATS * 9 / 10, "most pixels face the camera");
    }
}
