//! The dense grid over (roughness, azimuth, NoV, NoL), denser where things break (0, 1e-7, the guard floors),
//! and the discontinuity detector that scans it.

use crate::brdf::Sample;
use std::f64::consts::PI;

pub const COSINES: [f64; 30] = [
    0.0, 1e-7, 1e-5, 1e-4, 1e-3, 0.01, 0.03, 0.05, 0.1, 0.15, 0.2, 0.25, 0.3, 0.35, 0.4, 0.45, 0.5, 0.55, 0.6, 0.65,
    0.7, 0.75, 0.8, 0.85, 0.9, 0.95, 0.98, 0.995, 0.9999, 1.0,
];
pub const ROUGHNESS: [f32; 21] = [
    0.0, 1e-4, 1e-3, 0.01, 0.02, 0.045, 0.06, 0.089, 0.1, 0.15, 0.2, 0.3, 0.4, 0.5, 0.6, 0.7, 0.8, 0.9, 0.95, 0.99, 1.0,
];
pub const AZIMUTHS: usize = 7;

/// Index of a grid point; NoL varies fastest, then NoV, azimuth, roughness.
pub fn index(r: usize, az: usize, v: usize, l: usize) -> usize {
    ((r * AZIMUTHS + az) * COSINES.len() + v) * COSINES.len() + l
}

pub fn len() -> usize {
    ROUGHNESS.len() * AZIMUTHS * COSINES.len() * COSINES.len()
}

fn dir(cos: f64, phi: f64) -> [f32; 3] {
    let sin = (1.0 - cos * cos).max(0.0).sqrt();
    [(sin * phi.cos()) as f32, (sin * phi.sin()) as f32, cos as f32]
}

/// The grid's samples (N = +z; F0 covers a dielectric, a coloured and a white one per channel).
pub fn samples() -> Vec<Sample> {
    let mut out = Vec::with_capacity(len());
    for &roughness in &ROUGHNESS {
        for az in 0..AZIMUTHS {
            let phi = PI * az as f64 / (AZIMUTHS - 1) as f64;
            for &nov in &COSINES {
                for &nol in &COSINES {
                    out.push(Sample {
                        n: [0.0, 0.0, 1.0],
                        v: dir(nov, 0.0),
                        l: dir(nol, phi),
                        roughness,
                        f0: [0.04, 0.5, 1.0],
                    });
                }
            }
        }
    }
    out
}

/// A jump at step i of a series: the step is far above its neighbours' (|d_i| > 8 max(|d_i-1|, |d_i+1|)) and
/// large in itself (> 5% of the values it joins). Detects steps, not steep but smooth slopes.
pub fn jumps(values: &[f64]) -> Vec<usize> {
    let d: Vec<f64> = values.windows(2).map(|w| w[1] - w[0]).collect();
    (0..d.len())
        .filter(|&i| {
            let neighbour = [i.checked_sub(1), Some(i + 1)]
                .iter()
                .flatten()
                .filter_map(|&j| d.get(j))
                .map(|x| x.abs())
                .fold(0.0, f64::max);
            let scale = values[i].abs().max(values[i + 1].abs());
            d[i].is_finite() && d[i].abs() > 8.0 * neighbour && d[i].abs() > 0.05 * scale && scale > 1e-6
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn jump_detector_finds_steps_not_slopes() {
        assert_eq!(jumps(&[1.0, 1.1, 1.2, 2.5, 2.6, 2.7]), vec![2]);
        assert!(jumps(&[1.0, 2.0, 4.0, 8.0, 16.0]).is_empty());
        assert!(jumps(&[0.0, 0.0, 0.0]).is_empty());
        assert_eq!(samples().len(), len());
    }
}
