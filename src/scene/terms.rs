//! f64 twins of every function of `glsl/scene.glsl` (same names, formulas and citations), and of the scene
//! kernel's per-pixel shading built from them. tests/scenes/terms.rs ties each GLSL term to its twin, and the
//! whole kernel (every light type, every effect) to `shade_pixel`.

use crate::brdf::ModelSpec;
use crate::brdf::guards::{self, MIN_COSINE};
use crate::brdf::terms::{Params, d_ggx, schlick_weight};
use glam::DVec3;
use std::f64::consts::PI;

/// scene.glsl's MIN_LIGHT_DISTANCE: a light closer than this (world units) is taken at this distance.
pub const MIN_LIGHT_DISTANCE: f64 = 1e-2;
/// Filament's clear coat F0 (IOR 1.5).
pub const CLEAR_COAT_F0: f64 = 0.04;

type V3 = DVec3;

fn guard_cos(x: f64) -> f64 {
    x.clamp(MIN_COSINE, 1.0)
}

fn rgb(v: V3) -> [f64; 3] {
    v.to_array()
}

/// at = a (1 + s), ab = a (1 - s), floored at min_roughness^2 [Kulla & Conty 2017, as Filament].
pub fn anisotropic_alphas(a: f64, s: f64, min_roughness: f64) -> (f64, f64) {
    let floor = min_roughness * min_roughness;
    ((a * (1.0 + s)).max(floor), (a * (1.0 - s)).max(floor))
}

/// Anisotropic GGX [Burley 2012, App. B, eq. 13]: 1 / (pi at ab ((ToH/at)^2 + (BoH/ab)^2 + NoH^2)^2).
pub fn d_ggx_anisotropic(noh: f64, toh: f64, boh: f64, at: f64, ab: f64) -> f64 {
    let x = (toh / at).powi(2) + (boh / ab).powi(2) + noh * noh;
    1.0 / (PI * at * ab * x * x)
}

/// Anisotropic height-correlated Smith GGX [Heitz 2014, eq. 99]:
/// 0.5 / (NoL |(at ToV, ab BoV, NoV)| + NoV |(at ToL, ab BoL, NoL)|).
#[allow(clippy::too_many_arguments)]
pub fn vis_smith_ggx_correlated_anisotropic(
    tov: f64,
    bov: f64,
    nov: f64,
    tol: f64,
    bol: f64,
    nol: f64,
    at: f64,
    ab: f64,
) -> f64 {
    let lv = nol * DVec3::new(at * tov, ab * bov, nov).length();
    let ll = nov * DVec3::new(at * tol, ab * bol, nol).length();
    0.5 / (lv + ll)
}

/// f_s with anisotropic GGX D and Vis and the spec's Fresnel (twin of `specular_anisotropic`).
#[allow(clippy::too_many_arguments)]
pub fn specular_anisotropic(spec: &ModelSpec, n: V3, v: V3, l: V3, t: V3, b: V3, roughness: f64, s: f64, f0: V3) -> V3 {
    let h = guards::safe_normalize(v + l);
    let (nov, nol) = (n.dot(v), n.dot(l));
    if !(nov > 0.0 && nol > 0.0) {
        return DVec3::ZERO;
    }
    let (at, ab) = anisotropic_alphas(spec.alpha(roughness), s, spec.min_roughness());
    let (nv, nl) = (guard_cos(nov), guard_cos(nol));
    let d = d_ggx_anisotropic(guard_cos(n.dot(h)), t.dot(h), b.dot(h), at, ab);
    let vis = vis_smith_ggx_correlated_anisotropic(t.dot(v), b.dot(v), nv, t.dot(l), b.dot(l), nl, at, ab);
    DVec3::from(spec.f.eval(rgb(f0.clamp(DVec3::ZERO, DVec3::ONE)), guard_cos(v.dot(h)), &spec.params)) * (d * vis)
}

/// Lambert: 1/pi.
pub fn fd_lambert() -> f64 {
    1.0 / PI
}

/// Burley diffuse [Burley 2012, sec. 5.3]: (1 + (F_D90 - 1)(1 - NoL)^5)(1 + (F_D90 - 1)(1 - NoV)^5) / pi,
/// F_D90 = 0.5 + 2 r LoH^2 (r perceptual).
pub fn fd_burley(nov: f64, nol: f64, loh: f64, roughness: f64) -> f64 {
    let f90 = 0.5 + 2.0 * roughness * loh * loh;
    (1.0 + (f90 - 1.0) * schlick_weight(nol)) * (1.0 + (f90 - 1.0) * schlick_weight(nov)) / PI
}

/// Clear coat Fresnel [Filament sec. 4.9]: Schlick with F0 = 0.04, f90 = 1, times the coat strength.
pub fn clear_coat_fresnel(loh: f64, strength: f64) -> f64 {
    crate::brdf::terms::f_schlick(CLEAR_COAT_F0, loh) * strength
}

/// Clear coat lobe D_GGX(a_c) Vis_Kelemen(LoH) Fc [Filament sec. 4.9]; 0 unless NoL > 0 and NoV > 0.
/// `min_roughness` is the precision's roughness floor.
pub fn clear_coat_lobe(n: V3, v: V3, l: V3, coat_roughness: f64, strength: f64, min_roughness: f64) -> f64 {
    if !(n.dot(v) > 0.0 && n.dot(l) > 0.0) {
        return 0.0;
    }
    let h = guards::safe_normalize(v + l);
    let noh = guard_cos(n.dot(h));
    let loh = guard_cos(l.dot(h));
    let r = coat_roughness.clamp(min_roughness, 1.0);
    let d = d_ggx(noh, n.cross(h).length_squared().min(1.0), r * r, &Params::default());
    d * (0.25 / (loh * loh)) * clear_coat_fresnel(loh, strength)
}

/// Filament's energy compensation factor [Filament sec. 4.7.2]: 1 + F0 (1/E - 1), per channel.
pub fn energy_compensation(f0: V3, e: f64) -> V3 {
    DVec3::ONE + f0 * (1.0 / e - 1.0)
}

/// 1 / max(d^2, MIN_LIGHT_DISTANCE^2).
pub fn inverse_square(d2: f64) -> f64 {
    1.0 / d2.max(MIN_LIGHT_DISTANCE * MIN_LIGHT_DISTANCE)
}

/// saturate(cd scale + offset)^2 [Karis 2013; Filament getAngleAttenuation].
pub fn spot_cone(cd: f64, scale: f64, offset: f64) -> f64 {
    let t = (cd * scale + offset).clamp(0.0, 1.0);
    t * t
}

/// The cone parameters the host passes: scale = 1 / max(cos_inner - cos_outer, 1e-4), offset = -cos_outer scale.
pub fn spot_scale_offset(inner_deg: f64, outer_deg: f64) -> (f64, f64) {
    let (ci, co) = (inner_deg.to_radians().cos(), outer_deg.to_radians().cos());
    let scale = 1.0 / (ci - co).max(1e-4);
    (scale, -co * scale)
}

/// Karis 2013, eq. 11: Lc + c saturate(R / |c|), c = (Lc . r) r - Lc.
pub fn sphere_representative_point(lc: V3, r: V3, radius: f64) -> V3 {
    let c = r * lc.dot(r) - lc;
    let t = (radius / c.length().max(1e-20)).clamp(0.0, 1.0);
    lc + c * t
}

/// Karis 2013, eqs. 10 and 14: (a / a')^2, a' = saturate(a + R / (2 d)).
pub fn sphere_normalisation(a: f64, radius: f64, d: f64) -> f64 {
    let ap = (a + radius / (2.0 * d)).clamp(0.0, 1.0);
    (a / ap).powi(2)
}

/// A table of E(mu, r): mu_i = (i + 0.5) / mu_nodes, r_j = j / (r_nodes - 1), values[j * mu_nodes + i].
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct ETable {
    pub mu_nodes: usize,
    pub r_nodes: usize,
    pub values: Vec<f32>,
}

impl ETable {
    pub fn mu(&self, i: usize) -> f64 {
        (i as f64 + 0.5) / self.mu_nodes as f64
    }
    pub fn r(&self, j: usize) -> f64 {
        j as f64 / (self.r_nodes - 1) as f64
    }

    /// Bilinear lookup, clamped to the first and last nodes (twin of `e_lookup`).
    pub fn lookup(&self, mu: f64, r: f64) -> f64 {
        let (n, m) = (self.mu_nodes, self.r_nodes);
        let x = (mu * n as f64 - 0.5).clamp(0.0, (n - 1) as f64);
        let y = (r * (m - 1) as f64).clamp(0.0, (m - 1) as f64);
        let (i, j) = ((x as usize).min(n - 2), (y as usize).min(m - 2));
        let (tx, ty) = (x - i as f64, y - j as f64);
        let k = j * n + i;
        let e = |k: usize| self.values[k] as f64;
        let lerp = |a: f64, b: f64, t: f64| a * (1.0 - t) + b * t;
        lerp(lerp(e(k), e(k + 1), tx), lerp(e(k + n), e(k + n + 1), tx), ty)
    }
}

/// The kernel's effect switches (`kernels::constants` `ANISOTROPY`, `ENERGY_COMPENSATION`, `DIFFUSE`, `CLEAR_COAT`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, serde::Serialize)]
pub struct Switches {
    pub anisotropy: bool,
    /// 0 off, 1 every pixel, 2 per-pixel flag.
    pub energy: i32,
    /// 0 none, 1 Lambert, 2 Burley, 3 per-pixel choice.
    pub diffuse: i32,
    pub clear_coat: bool,
}

/// A pixel as the scene kernel sees it (twin of scene.glsl's Surface).
#[derive(Clone, Copy, Debug)]
pub struct Surface {
    pub n: V3,
    pub v: V3,
    pub t: V3,
    pub b: V3,
    pub roughness: f64,
    pub f0: V3,
    pub diffuse_colour: V3,
    pub anisotropy: f64,
    pub coat: f64,
    pub coat_roughness: f64,
    pub diffuse: i32,
    pub energy: V3,
}

/// Twin of `specular_lobe`.
pub fn specular_lobe(spec: &ModelSpec, sw: Switches, s: &Surface, l: V3) -> V3 {
    if sw.anisotropy && s.anisotropy != 0.0 {
        specular_anisotropic(spec, s.n, s.v, l, s.t, s.b, s.roughness, s.anisotropy, s.f0)
    } else {
        DVec3::from(spec.eval_unit(s.n, s.v, l, s.roughness, rgb(s.f0)))
    }
}

/// Twin of `diffuse_lobe`.
pub fn diffuse_lobe(sw: Switches, s: &Surface, l: V3) -> f64 {
    let mode = if sw.diffuse == 3 { s.diffuse } else { sw.diffuse };
    let (nov, nol) = (s.n.dot(s.v), s.n.dot(l));
    if !(nov > 0.0 && nol > 0.0) {
        return 0.0;
    }
    match mode {
        1 => fd_lambert(),
        2 => {
            let h = guards::safe_normalize(s.v + l);
            fd_burley(guard_cos(nov), guard_cos(nol), guard_cos(l.dot(h)), s.roughness)
        }
        _ => 0.0,
    }
}

/// Twin of `shade`: reflected radiance per unit incident radiance.
pub fn shade(spec: &ModelSpec, sw: Switches, s: &Surface, ld: V3, ls: V3, spec_scale: f64) -> V3 {
    let nold = s.n.dot(ld).max(0.0);
    let nols = s.n.dot(ls).max(0.0);
    let mut c = specular_lobe(spec, sw, s, ls) * (spec_scale * nols);
    if sw.energy != 0 {
        c *= s.energy;
    }
    if sw.diffuse != 0 {
        c += s.diffuse_colour * (diffuse_lobe(sw, s, ld) * nold);
    }
    if sw.clear_coat {
        let h = guards::safe_normalize(s.v + ls);
        let fc = clear_coat_fresnel(guard_cos(ls.dot(h)), s.coat);
        let coat = clear_coat_lobe(s.n, s.v, ls, s.coat_roughness, s.coat, spec.min_roughness()) * spec_scale * nols;
        c = c * (1.0 - fc) + DVec3::splat(coat);
    }
    c
}

/// One light as the kernel receives it (world space).
#[derive(Clone, Copy, Debug)]
pub enum KernelLight {
    Directional { direction: V3, radiance: V3 },
    Point { position: V3, intensity: V3 },
    Spot { position: V3, intensity: V3, axis: V3, scale: f64, offset: f64 },
    Sphere { position: V3, radius: f64, intensity: V3 },
}

/// Twin of scene.comp's light loops: the radiance reflected by `s` at world position `p`.
pub fn shade_pixel(spec: &ModelSpec, sw: Switches, s: &Surface, p: V3, lights: &[KernelLight]) -> V3 {
    let unit = guards::safe_normalize;
    let mut acc = DVec3::ZERO;
    for light in lights {
        acc += match *light {
            KernelLight::Directional { direction, radiance } => {
                let l = unit(-direction);
                shade(spec, sw, s, l, l, 1.0) * radiance
            }
            KernelLight::Point { position, intensity } => {
                let lv = position - p;
                let l = unit(lv);
                shade(spec, sw, s, l, l, 1.0) * (intensity * inverse_square(lv.length_squared()))
            }
            KernelLight::Spot { position, intensity, axis, scale, offset } => {
                let lv = position - p;
                let l = unit(lv);
                let cone = spot_cone(-axis.dot(l), scale, offset);
                shade(spec, sw, s, l, l, 1.0) * (intensity * (inverse_square(lv.length_squared()) * cone))
            }
            KernelLight::Sphere { position, radius, intensity } => {
                let lc = position - p;
                let d = lc.length().max(radius.max(MIN_LIGHT_DISTANCE));
                let r = s.n * (2.0 * s.n.dot(s.v)) - s.v;
                let ls = unit(sphere_representative_point(lc, r, radius));
                let norm = sphere_normalisation(spec.alpha(s.roughness), radius, d);
                shade(spec, sw, s, unit(lc), ls, norm) * (intensity * inverse_square(d * d))
            }
        };
    }
    acc
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn anisotropic_ggx_reduces_to_isotropic_ggx() {
        let a = 0.3;
        for noh in [0.3, 0.7, 0.99] {
            let sin = (1.0f64 - noh * noh).sqrt();
            let (toh, boh) = (sin * 0.6, sin * 0.8);
            let iso = d_ggx(noh, sin * sin, a, &Params::default());
            assert!((d_ggx_anisotropic(noh, toh, boh, a, a) / iso - 1.0).abs() < 1e-12);
        }
        let (nov, nol) = (0.4, 0.8);
        let c = crate::brdf::Cosines { nov, nol, noh: 0.9, voh: 0.8, sin2h: 0.19 };
        // The isotropic height-correlated Smith GGX of the term table (the exact G2 of GGX).
        let vis = crate::brdf::Vis::ALL.iter().find(|v| v.row().exact_for == Some(crate::brdf::D::Ggx)).unwrap();
        let iso = vis.eval(&c, a);
        let (tv, tl) = ((1.0f64 - nov * nov).sqrt(), (1.0f64 - nol * nol).sqrt());
        assert!((vis_smith_ggx_correlated_anisotropic(tv, 0.0, nov, 0.0, tl, nol, a, a) / iso - 1.0).abs() < 1e-12);
    }

    #[test]
    fn anisotropic_ggx_is_normalised() {
        // int D(h) NoH dh = 1 over the hemisphere, for an anisotropic lobe (midpoint rule in theta, phi).
        let (at, ab) = (0.2, 0.5);
        let (nt, np) = (2000, 400);
        let mut sum = 0.0;
        for i in 0..nt {
            let th = (i as f64 + 0.5) / nt as f64 * PI / 2.0;
            for j in 0..np {
                let ph = (j as f64 + 0.5) / np as f64 * 2.0 * PI;
                let (st, ct) = th.sin_cos();
                sum += d_ggx_anisotropic(ct, st * ph.cos(), st * ph.sin(), at, ab) * ct * st;
            }
        }
        sum *= (PI / 2.0 / nt as f64) * (2.0 * PI / np as f64);
        assert!((sum - 1.0).abs() < 2e-3, "{sum}");
    }

    #[test]
    fn representative_point_lies_on_the_sphere_or_on_the_ray() {
        let lc = DVec3::new(0.0, 2.0, 0.0);
        // The ray passes through the sphere: the point is on the ray.
        let p = sphere_representative_point(lc, DVec3::Y, 0.5);
        assert!((p.y - 2.0).abs() < 1e-12 && p.x.abs() < 1e-12);
        // The ray misses: the point is on the sphere, closest to the ray.
        let r = guards::safe_normalize(DVec3::new(1.0, 1.0, 0.0));
        let p = sphere_representative_point(lc, r, 0.5);
        assert!(((p - lc).length() - 0.5).abs() < 1e-12);
        assert!(sphere_normalisation(0.2, 0.0, 3.0) == 1.0 && sphere_normalisation(0.2, 1.0, 1.0) < 1.0);
    }

    #[test]
    fn e_table_lookup_hits_nodes_and_interpolates() {
        let t = ETable { mu_nodes: 4, r_nodes: 3, values: (0..12).map(|k| k as f32).collect() };
        assert_eq!(t.lookup(t.mu(1), t.r(2)), 9.0);
        assert!((t.lookup(0.5, 0.25) - (1.5 + 2.0)).abs() < 1e-12);
        assert_eq!(t.lookup(0.0, 0.0), 0.0);
        assert_eq!(t.lookup(1.0, 1.0), 11.0);
    }

    #[test]
    fn energy_compensation_makes_white_lossless() {
        let k = energy_compensation(DVec3::ONE, 0.8);
        assert!((0.8 * k.x - 1.0).abs() < 1e-12);
        assert_eq!(energy_compensation(DVec3::ZERO, 0.8), DVec3::ONE);
    }
}
