//! Directional albedo E(v) = integral over l of f(v, l) NoL, in f64 on the CPU: the reference the GPU's
//! importance-sampled albedo is checked against. Integrated in half-vector space, dl = 4 VoH dh, with
//! piecewise Gauss-Legendre in theta_h (pieces at the lobe's scales, tan theta_h = a, 4a, 16a, ..., and at
//! the angles where reflected directions start and finish falling below the horizon) and, for each theta_h, in the
//! azimuth over exactly the range that stays above the horizon, so the integrand is smooth on every piece.

use crate::brdf::Cosines;
use crate::brdf::guards::guard_cosine;
use gauss_quad::legendre::GaussLegendre;
use std::f64::consts::{FRAC_PI_2, PI};
use std::sync::OnceLock;

fn rule(n: usize) -> &'static GaussLegendre {
    static THETA: OnceLock<GaussLegendre> = OnceLock::new();
    static PHI: OnceLock<GaussLegendre> = OnceLock::new();
    let cell = if n == THETA_NODES { &THETA } else { &PHI };
    cell.get_or_init(|| GaussLegendre::new(n.try_into().unwrap()))
}

const THETA_NODES: usize = 96;
const PHI_NODES: usize = 128;

/// Gauss-Legendre integral of a vector-valued `f` over [lo, hi].
fn integrate(n: usize, lo: f64, hi: f64, mut f: impl FnMut(f64) -> [f64; 3]) -> [f64; 3] {
    let (half, mid) = (0.5 * (hi - lo), 0.5 * (hi + lo));
    let mut sum = [0.0; 3];
    for &(x, w) in rule(n).as_node_weight_pairs() {
        let y = f(mid + half * x);
        for c in 0..3 {
            sum[c] += w * half * y[c];
        }
    }
    sum
}

/// E(v) at NoV = `nov` of a BRDF given as a function of guarded cosines; `a` (= roughness^2) sets where the
/// theta_h pieces break.
pub fn albedo_f64(f: &impl Fn(&Cosines) -> [f64; 3], nov: f64, a: f64) -> [f64; 3] {
    let cos_v = nov.clamp(1e-6, 1.0);
    let sin_v = (1.0 - cos_v * cos_v).sqrt();
    let theta_v = cos_v.acos();
    // Reflections start to clip at theta_h = (pi/2 - theta_v)/2 and are all clipped past (pi/2 + theta_v)/2.
    let mut breaks = vec![0.0, FRAC_PI_2, 0.5 * (FRAC_PI_2 - theta_v), 0.5 * (FRAC_PI_2 + theta_v)];
    let mut t = a.max(1e-6);
    while t < 1e4 {
        breaks.push(t.atan());
        t *= 4.0;
    }
    breaks.retain(|x| (0.0..=FRAC_PI_2).contains(x));
    breaks.sort_by(f64::total_cmp);
    breaks.dedup_by(|x, y| (*x - *y).abs() < 1e-12);
    let mut total = [0.0; 3];
    for w in breaks.windows(2) {
        let piece = integrate(THETA_NODES, w[0], w[1], |th| {
            let (sin_h, cos_h) = th.sin_cos();
            // NoL(phi) = 2 cos_h VoH(phi) - cos_v falls with phi in [0, pi]; it is 0 at phi_max.
            let denom = sin_v * (2.0 * th).sin();
            let phi_max = if denom <= 1e-300 {
                if (2.0 * th).cos() >= 0.0 { PI } else { 0.0 }
            } else {
                let x = -cos_v * (2.0 * th).cos() / denom;
                if x <= -1.0 {
                    PI
                } else if x >= 1.0 {
                    0.0
                } else {
                    x.acos()
                }
            };
            if phi_max <= 0.0 {
                return [0.0; 3];
            }
            let inner = integrate(PHI_NODES, 0.0, phi_max, |phi| {
                let voh = sin_v * sin_h * phi.cos() + cos_v * cos_h;
                let nol = 2.0 * cos_h * voh - cos_v;
                if nol <= 0.0 || voh <= 0.0 {
                    return [0.0; 3];
                }
                let c = Cosines {
                    nov: guard_cosine(cos_v),
                    nol: guard_cosine(nol),
                    noh: guard_cosine(cos_h),
                    voh: guard_cosine(voh),
                    sin2h: sin_h * sin_h,
                };
                f(&c).map(|x| x * nol * 4.0 * voh)
            });
            // Both halves of the azimuth, and the solid-angle factor sin(theta_h).
            inner.map(|x| 2.0 * x * sin_h)
        });
        for c in 0..3 {
            total[c] += piece[c];
        }
    }
    total
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::brdf::{D, F, ModelSpec, Vis};

    #[test]
    fn a_lambertian_brdf_reflects_everything() {
        for nov in [0.02, 0.3, 0.7, 1.0] {
            for a in [0.002, 0.1, 1.0] {
                let e = albedo_f64(&|_| [1.0 / PI; 3], nov, a);
                assert!((e[0] - 1.0).abs() < 1e-6, "nov {nov} a {a}: {}", e[0]);
            }
        }
    }

    #[test]
    fn implicit_ggx_at_normal_incidence_has_its_closed_form() {
        // Vis = 1/4, F = 1, v = n: E = int D NoL/4 dl = int D NoL VoH dh with NoL = 2 NoH^2 - 1, VoH = NoH, over
        // NoH > 1/sqrt(2); GGX at a = 1 is D = 1/pi, so E = 2 int_{1/sqrt 2}^1 (2c^2 - 1) c dc = 1/4.
        let spec = ModelSpec::new(D::Ggx, Vis::Implicit, F::None);
        let e = albedo_f64(&|c| spec.from_cosines(c, 1.0, [1.0; 3]), 1.0, 1.0);
        assert!((e[0] - 0.25).abs() < 1e-6, "{}", e[0]);
    }
}
