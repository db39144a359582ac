//! The exact physical references against independent facts: Smith G1 -> 1 at normal incidence, separable G2 <=
//! height-correlated G2, Beckmann's closed-form Lambda against numerical integration of its definition, Fresnel
//! at normal incidence = F0 and -> 1 at grazing, and conductor Fresnel against the textbook complex-amplitude
//! equations and published reflectances.

use crate::common;
use brdfprof::brdf::exact::{self, lambda_beckmann, lambda_numeric};
use brdfprof::brdf::terms::{self, Lobe, Params, f_conductor, f_dielectric};
use brdfprof::brdf::{D, Metal};

#[test]
fn smith_g1_tends_to_one_at_normal_incidence() {
    for spec in common::every_d() {
        let (d, p) = (spec.d, &spec.params);
        for r in [0.1, 0.3, 0.6, 1.0] {
            let a = r * r;
            for cos in [1.0, 0.99999] {
                let g1 = 1.0 / (1.0 + exact::lambda(d, cos, a, p));
                assert!((g1 - 1.0).abs() < 1e-3, "{} r {r} cos {cos}: G1 = {g1}", spec.name());
            }
            // and falls to 0 at grazing (a grazing lobe, like sheen's, masks less there)
            let g1 = 1.0 / (1.0 + exact::lambda(d, 1e-4, a, p));
            assert!(
                g1 < 0.05 || d.row().lobe == Lobe::Grazing && g1 < 0.5,
                "{} r {r}: G1 at grazing = {g1}",
                spec.name()
            );
        }
    }
}

#[test]
fn separable_g2_never_exceeds_height_correlated() {
    for spec in common::every_d() {
        let (d, p) = (spec.d, &spec.params);
        for r in [0.1, 0.5, 1.0] {
            let a = r * r;
            for nov in [0.05, 0.2, 0.5, 0.9] {
                for nol in [0.05, 0.3, 0.7, 1.0] {
                    let (lv, ll) = (exact::lambda(d, nov, a, p), exact::lambda(d, nol, a, p));
                    let separable = 1.0 / ((1.0 + lv) * (1.0 + ll));
                    let correlated = 1.0 / (1.0 + lv + ll);
                    assert!(
                        separable <= correlated + 1e-12,
                        "{} r {r} NoV {nov} NoL {nol}: {separable} > {correlated}",
                        spec.name()
                    );
                }
            }
        }
    }
}

/// Every closed-form Lambda of the table equals the integral of its definition [Heitz 2014, eq. 20-22], and
/// Beckmann's erf form is what the table uses for it.
#[test]
fn closed_form_lambdas_equal_their_integrated_definition() {
    for spec in common::every_d() {
        for r in [0.1, 0.3, 0.5, 0.8, 1.0] {
            let a = r * r;
            for cos in [0.01, 0.05, 0.2, 0.5, 0.8, 0.95] {
                let Some(closed) = (spec.d.row().lambda)(cos, a, &spec.params) else { continue };
                let numeric = lambda_numeric(|c| spec.d.at(c, a, &spec.params), cos, a);
                assert!(
                    (numeric - closed).abs() <= 1e-6 * (1.0 + closed),
                    "{} r {r} cos {cos}: integrated {numeric}, closed form {closed}",
                    spec.name()
                );
            }
        }
    }
    let beckmann = D::ALL.iter().find(|d| d.name() == "beckmann").unwrap();
    assert_eq!((beckmann.row().lambda)(0.3, 0.2, &Params::default()), Some(lambda_beckmann(0.3, 0.2)));
}

#[test]
fn fresnel_is_f0_at_normal_incidence_and_one_at_grazing() {
    for f0 in [0.0, 0.02, 0.04, 0.08, 0.2, 0.5, 0.9] {
        assert!((f_dielectric(f0, 1.0) - f0).abs() < 1e-12, "dielectric F(1) for F0 {f0}");
        assert!(
            f_dielectric(f0, 1e-9) > 0.999999 || f0 == 0.0,
            "dielectric F(0) for F0 {f0}: {}",
            f_dielectric(f0, 1e-9)
        );
        assert!((terms::f_schlick(f0, 1.0) - f0).abs() < 1e-15 && (terms::f_schlick(f0, 0.0) - 1.0).abs() < 1e-15);
    }
    for &metal in Metal::ALL {
        let (n, k) = metal.nk();
        let at_normal = f_conductor(metal, 1.0);
        for c in 0..3 {
            let expected = ((n[c] - 1.0).powi(2) + k[c] * k[c]) / ((n[c] + 1.0).powi(2) + k[c] * k[c]);
            assert!((at_normal[c] - expected).abs() < 1e-12, "{metal:?}: F(1) = {} vs {expected}", at_normal[c]);
            assert!(f_conductor(metal, 1e-9)[c] > 0.999999, "{metal:?}: F at grazing");
        }
    }
}

/// Minimal complex numbers for the textbook Fresnel amplitudes.
#[derive(Clone, Copy)]
struct C(f64, f64);
impl C {
    fn add(self, o: C) -> C {
        C(self.0 + o.0, self.1 + o.1)
    }
    fn sub(self, o: C) -> C {
        C(self.0 - o.0, self.1 - o.1)
    }
    fn mul(self, o: C) -> C {
        C(self.0 * o.0 - self.1 * o.1, self.0 * o.1 + self.1 * o.0)
    }
    fn div(self, o: C) -> C {
        let d = o.0 * o.0 + o.1 * o.1;
        C((self.0 * o.0 + self.1 * o.1) / d, (self.1 * o.0 - self.0 * o.1) / d)
    }
    fn sqrt(self) -> C {
        let r = (self.0 * self.0 + self.1 * self.1).sqrt();
        let re = ((r + self.0) / 2.0).sqrt();
        C(re, (self.1).signum() * ((r - self.0) / 2.0).sqrt())
    }
    fn norm2(self) -> f64 {
        self.0 * self.0 + self.1 * self.1
    }
}

/// Born & Wolf: r_s = (cos_i - eta cos_t)/(cos_i + eta cos_t), r_p = (eta cos_i - cos_t)/(eta cos_i + cos_t),
/// eta = n + ik, cos_t = sqrt(1 - sin_i^2 / eta^2); R = (|r_s|^2 + |r_p|^2)/2.
fn fresnel_complex(n: f64, k: f64, cos_i: f64) -> f64 {
    let eta = C(n, k);
    let ci = C(cos_i, 0.0);
    let sin2 = C(1.0 - cos_i * cos_i, 0.0);
    let ct = C(1.0, 0.0).sub(sin2.div(eta.mul(eta))).sqrt();
    let rs = ci.sub(eta.mul(ct)).div(ci.add(eta.mul(ct)));
    let rp = eta.mul(ci).sub(ct).div(eta.mul(ci).add(ct));
    0.5 * (rs.norm2() + rp.norm2())
}

#[test]
fn conductor_fresnel_matches_complex_amplitudes_and_published_reflectance() {
    for &metal in Metal::ALL {
        let (n, k) = metal.nk();
        for i in 0..=40 {
            let cos = (i as f64 / 40.0).max(1e-3);
            let ours = f_conductor(metal, cos);
            for c in 0..3 {
                let textbook = fresnel_complex(n[c], k[c], cos);
                assert!(
                    (ours[c] - textbook).abs() < 1e-9,
                    "{metal:?} channel {c} cos {cos}: {} vs {textbook}",
                    ours[c]
                );
            }
        }
    }
    // Normal-incidence reflectance, linear RGB, from Real-Time Rendering 4th ed., Table 9.2 (spectrally
    // integrated, so single-wavelength n,k agree within a few hundredths; closest for the flat metals).
    let published = [
        (Metal::Silver, [0.972, 0.960, 0.915], 0.02),
        (Metal::Aluminium, [0.913, 0.922, 0.924], 0.02),
        (Metal::Gold, [1.000, 0.782, 0.344], 0.06),
        (Metal::Copper, [0.955, 0.638, 0.538], 0.09),
        (Metal::Iron, [0.562, 0.565, 0.578], 0.09),
    ];
    for (metal, f0, tolerance) in published {
        let ours = f_conductor(metal, 1.0);
        for c in 0..3 {
            assert!(
                (ours[c] - f0[c]).abs() <= tolerance,
                "{metal:?} channel {c}: F0 {} vs published {}",
                ours[c],
                f0[c]
            );
        }
    }
}
