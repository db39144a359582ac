//! Seeded sample sets of BRDF queries: random well-conditioned ones, and stratified grids over
//! (roughness, NoV, NoL, azimuth). Vectors are built around a random normal so that no axis is special.

use super::Sample;
use glam::DVec3;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

/// The ranges samples are drawn from: perceptual roughness, NoV and NoL (`diff`'s default samples, `sweep`'s
/// stratified set).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SampleDomain {
    pub roughness: (f64, f64),
    pub nov: (f64, f64),
    pub nol: (f64, f64),
}

/// NoV and NoL of `diff`'s default samples start here: well conditioned, so that grazing rounding is not a model's
/// error.
pub const DEFAULT_MIN_COS: f64 = 0.05;

impl Default for SampleDomain {
    /// `diff`'s: roughness in [0, 1] so that the roughness floor is crossed; NoV, NoL in [DEFAULT_MIN_COS, 1].
    fn default() -> Self {
        SampleDomain { roughness: (0.0, 1.0), nov: (DEFAULT_MIN_COS, 1.0), nol: (DEFAULT_MIN_COS, 1.0) }
    }
}

/// Unit vector with the given cosine to `n` and azimuth `phi` about it.
pub fn around(n: DVec3, cos_theta: f64, phi: f64) -> DVec3 {
    let (t, b) = tangent_frame(n);
    let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
    let (s, c) = phi.sin_cos();
    sin_theta * (c * t + s * b) + cos_theta * n
}

/// An orthonormal tangent and bitangent for unit `n`, with (t, b, n) right-handed [Duff et al. 2017,
/// "Building an Orthonormal Basis, Revisited", as glam's `any_orthonormal_pair`].
pub fn tangent_frame(n: DVec3) -> (DVec3, DVec3) {
    n.any_orthonormal_pair()
}

fn random_unit(rng: &mut Pcg64) -> DVec3 {
    let z: f64 = rng.random_range(-1.0..1.0);
    let phi: f64 = rng.random_range(0.0..std::f64::consts::TAU);
    let r = (1.0 - z * z).sqrt();
    DVec3::new(r * phi.cos(), r * phi.sin(), z)
}

fn to_f32(v: DVec3) -> [f32; 3] {
    v.as_vec3().to_array()
}

/// `count` samples with NoV and NoL uniform in [min_cos, 1], roughness uniform in `roughness`, F0 uniform in
/// [0, 1]^3, the normal uniform on the sphere.
pub fn well_conditioned(count: usize, seed: u64, min_cos: f64, roughness: std::ops::Range<f64>) -> Vec<Sample> {
    well_conditioned_in(count, seed, (min_cos, 1.0), (min_cos, 1.0), roughness)
}

/// `well_conditioned` with NoV uniform in [nov.0, nov.1] and NoL in [nol.0, nol.1] (an engine's domain); the
/// same draws, so that [min_cos, 1] gives `well_conditioned`'s samples exactly.
pub fn well_conditioned_in(
    count: usize,
    seed: u64,
    nov: (f64, f64),
    nol: (f64, f64),
    roughness: std::ops::Range<f64>,
) -> Vec<Sample> {
    let mut rng = Pcg64::seed_from_u64(seed);
    (0..count)
        .map(|_| {
            let n = random_unit(&mut rng);
            let v = around(n, rng.random_range(nov.0..=nov.1), rng.random_range(0.0..std::f64::consts::TAU));
            let l = around(n, rng.random_range(nol.0..=nol.1), rng.random_range(0.0..std::f64::consts::TAU));
            Sample {
                n: to_f32(n),
                v: to_f32(v),
                l: to_f32(l),
                roughness: rng.random_range(roughness.clone()) as f32,
                f0: [rng.random::<f32>(), rng.random::<f32>(), rng.random::<f32>()],
            }
        })
        .collect()
}

/// A stratified set: `per_axis` strata in each of roughness (over `roughness`), NoV and NoL (over
/// [min_cos, 1]) and the azimuth between V and L (over [0, pi]), one jittered sample per cell. F0 is a
/// dielectric's, so that the exact dielectric Fresnel is a physical reference for it: the channels hold water
/// (0.02), plastic (0.04) and a gemstone (0.08), or 0.03, 0.05, 0.045 in alternate cells (metals are measured
/// by the conductor and F82 terms, which take their metal's complex IOR instead).
pub fn stratified(per_axis: usize, seed: u64, min_cos: f64, roughness: std::ops::Range<f64>) -> Vec<Sample> {
    stratified_in(per_axis, seed, (min_cos, 1.0), (min_cos, 1.0), (roughness.start, roughness.end))
}

/// `stratified` with NoV, NoL and roughness each in its own range (a degenerate range gives its one value).
pub fn stratified_in(
    per_axis: usize,
    seed: u64,
    nov_range: (f64, f64),
    nol_range: (f64, f64),
    roughness: (f64, f64),
) -> Vec<Sample> {
    let mut rng = Pcg64::seed_from_u64(seed);
    let k = per_axis as f64;
    let mut out = Vec::with_capacity(per_axis.pow(4));
    for ir in 0..per_axis {
        for iv in 0..per_axis {
            for il in 0..per_axis {
                for ia in 0..per_axis {
                    let u = |i: usize, rng: &mut Pcg64| (i as f64 + rng.random::<f64>()) / k;
                    let within = |(lo, hi): (f64, f64), t: f64| lo + (hi - lo) * t;
                    let r = within(roughness, u(ir, &mut rng));
                    let nov = within(nov_range, u(iv, &mut rng));
                    let nol = within(nol_range, u(il, &mut rng));
                    let phi = std::f64::consts::PI * u(ia, &mut rng);
                    let n = random_unit(&mut rng);
                    let phi0: f64 = rng.random_range(0.0..std::f64::consts::TAU);
                    let f0 = if (ir + iv + il + ia) % 2 == 0 { [0.02, 0.04, 0.08] } else { [0.03, 0.05, 0.045] };
                    out.push(Sample {
                        n: to_f32(n),
                        v: to_f32(around(n, nov, phi0)),
                        l: to_f32(around(n, nol, phi0 + phi)),
                        roughness: r as f32,
                        f0,
                    });
                }
            }
        }
    }
    out
}

/// Integer hash to [0, 1) (PCG-style), so synthetic G-buffers and pictures are identical on every run and
/// machine.
pub fn hash01(mut x: u32) -> f32 {
    x = x.wrapping_mul(747796405).wrapping_add(2891336453);
    x = ((x >> ((x >> 28) + 4)) ^ x).wrapping_mul(277803737);
    x = (x >> 22) ^ x;
    (x >> 8) as f32 / (1u32 << 24) as f32
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn samples_have_the_cosines_asked_for() {
        for s in well_conditioned(1000, 7, 0.05, 0.2..1.0) {
            let f = |v: [f32; 3]| DVec3::from(v.map(f64::from));
            let (n, v, l) = (f(s.n), f(s.v), f(s.l));
            assert!(n.dot(v) >= 0.05 - 1e-6 && n.dot(l) >= 0.05 - 1e-6);
            assert!((v.length_squared() - 1.0).abs() < 1e-6);
            assert!((0.2..1.0).contains(&s.roughness));
        }
        assert_eq!(well_conditioned(10, 3, 0.05, 0.2..1.0), well_conditioned(10, 3, 0.05, 0.2..1.0));
        assert_eq!(stratified(4, 1, 0.05, 0.1..1.0).len(), 256);
    }
}
