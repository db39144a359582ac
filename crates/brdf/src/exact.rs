//! Exact physical references, in f64: a model's own D with its exact height-correlated Smith masking-shadowing
//! G2 = 1 / (1 + Lambda(v) + Lambda(l)) [Heitz 2014, eq. 99] and exact Fresnel (the dielectric whose
//! normal-incidence reflectance is F0, or the metal's complex IOR for conductor and F82 specs).
//!
//! Lambda has closed forms for GGX (= GTR with gamma 2) and Beckmann; for every other D it is computed from its
//! definition [Heitz 2014, eq. 20-22]: 1 + Lambda(o) = (1/cos theta_o) * integral of <o, m> D(m) over the
//! hemisphere of microfacet normals m, the azimuth done in closed form and theta_m by double-exponential
//! quadrature split at the lobe's scale and at the kink where <o, m> starts to clip.

use super::Sample;
use super::guards::MIN_ROUGHNESS_F32;
use super::spec::ModelSpec;
use super::terms::{Cosines, D, Lobe, Params};
use std::f64::consts::{FRAC_PI_2, PI};

pub use super::terms::{lambda_beckmann_exact as lambda_beckmann, lambda_ggx};

/// Integral over azimuth of max(0, <o, m>) for polar angles theta_o (sin_o, cos_o) and theta_m (sin_m, cos_m).
fn clipped_azimuth_integral(sin_o: f64, cos_o: f64, sin_m: f64, cos_m: f64) -> f64 {
    let (a, b) = (sin_o * sin_m, cos_o * cos_m);
    if a <= b {
        2.0 * PI * b
    } else {
        let phi0 = (-b / a).acos();
        2.0 * (a * phi0.sin() + b * phi0)
    }
}

/// Breakpoints of [0, pi/2] at the lobe's scale (tan theta = a, 4a, 16a, ...) and at `extra`.
fn breakpoints(a: f64, extra: &[f64]) -> Vec<f64> {
    let mut points = vec![0.0, FRAC_PI_2];
    let mut t = a.max(1e-6);
    while t < 1e4 {
        points.push(t.atan());
        t *= 4.0;
    }
    points.extend(extra.iter().copied().filter(|x| *x > 0.0 && *x < FRAC_PI_2));
    points.sort_by(f64::total_cmp);
    points.dedup_by(|x, y| (*x - *y).abs() < 1e-12);
    points
}

/// Integral of `f` over [0, pi/2] by double-exponential quadrature on each piece between `points`.
pub fn integrate_pieces(f: impl Fn(f64) -> f64, points: &[f64], tolerance: f64) -> f64 {
    points.windows(2).map(|w| quadrature::double_exponential::integrate(&f, w[0], w[1], tolerance).integral).sum()
}

/// Lambda of any isotropic `d` (D as a function of cos theta_m) from its definition.
pub fn lambda_numeric(d: impl Fn(f64) -> f64, cos: f64, a: f64) -> f64 {
    let cos = cos.clamp(1e-12, 1.0);
    let sin = (1.0 - cos * cos).max(0.0).sqrt();
    let kink = FRAC_PI_2 - cos.acos();
    let projected = integrate_pieces(
        |tm| {
            let (s, c) = tm.sin_cos();
            d(c) * clipped_azimuth_integral(sin, cos, s, c) * s
        },
        &breakpoints(a, &[kink]),
        1e-11,
    );
    projected / cos - 1.0
}

/// Lambda of a D by the best means available: its closed form where the term table has one, else the
/// integral of its definition.
pub fn lambda(d: D, cos: f64, a: f64, params: &Params) -> f64 {
    (d.row().lambda)(cos, a, params).unwrap_or_else(|| lambda_numeric(|c| d.at(c, a, params), cos, a))
}

/// Lambda of one (D, a, gamma), tabulated where it has no closed form: 1025 nodes over s = x/(1+x),
/// x = scale tan theta, interpolating Lambda (1 - s), which stays bounded at grazing angles. The scale is a
/// for lobes around the normal (Lambda is then nearly a function of a tan theta), 1 for Charlie's grazing lobe.
pub struct Lambda {
    d: D,
    a: f64,
    params: Params,
    scale: f64,
    table: Option<Vec<f64>>,
}

const TABLE_NODES: usize = 1025;

impl Lambda {
    pub fn new(d: D, a: f64, params: &Params) -> Self {
        let params = *params;
        let closed = (d.row().lambda)(0.5, a, &params).is_some();
        let scale = match d.row().lobe {
            Lobe::AroundNormal => a,
            Lobe::Grazing => 1.0,
        };
        let table = (!closed).then(|| {
            (0..TABLE_NODES)
                .map(|i| {
                    let s = i as f64 / (TABLE_NODES - 1) as f64;
                    if s >= 1.0 {
                        // x -> infinity: Lambda grows like x times a constant; extrapolate from the last nodes.
                        return f64::NAN;
                    }
                    let x = s / (1.0 - s);
                    let cos = 1.0 / (1.0 + (x / scale) * (x / scale)).sqrt();
                    lambda_numeric(|c| d.at(c, a, &params), cos, a) * (1.0 - s)
                })
                .collect::<Vec<f64>>()
        });
        let table = table.map(|mut t| {
            let n = t.len();
            t[n - 1] = 2.0 * t[n - 2] - t[n - 3];
            t
        });
        Lambda { d, a, params, scale, table }
    }

    pub fn at(&self, cos: f64) -> f64 {
        let Some(table) = &self.table else {
            return lambda(self.d, cos, self.a, &self.params);
        };
        if cos >= 1.0 {
            return 0.0;
        }
        let x = self.scale * (1.0 - cos * cos).max(0.0).sqrt() / cos;
        let s = x / (1.0 + x);
        let pos = s * (TABLE_NODES - 1) as f64;
        let i = (pos.floor() as usize).min(TABLE_NODES - 2);
        let t = pos - i as f64;
        (table[i] * (1.0 - t) + table[i + 1] * t) / (1.0 - s)
    }
}

/// Exact Fresnel for a spec: the one its F stands for (the metal's complex IOR for the conductor terms, the
/// dielectric with the sample's F0 otherwise).
pub fn fresnel(spec: &ModelSpec, f0: [f64; 3], voh: f64) -> [f64; 3] {
    spec.exact_fresnel().eval(f0, voh, &spec.params)
}

/// Which Fresnel an exact reference multiplies its exact D G2 / (4 NoL NoV) by: the physical one the spec's F
/// stands for (the default: the error then includes the Fresnel approximation), or the spec's own F term (the
/// error is then the D and visibility approximations alone; `sweep --exact-fresnel own`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum ExactFresnel {
    #[default]
    Physical,
    Own,
}

impl ExactFresnel {
    pub const NAMES: [&'static str; 2] = ["physical", "own"];

    pub fn parse(text: &str) -> Option<Self> {
        match text {
            "physical" => Some(ExactFresnel::Physical),
            "own" => Some(ExactFresnel::Own),
            _ => None,
        }
    }

    /// The Fresnel term the exact counterpart of `spec` uses.
    pub fn term(self, spec: &ModelSpec) -> crate::F {
        match self {
            ExactFresnel::Physical => spec.exact_fresnel(),
            ExactFresnel::Own => spec.f,
        }
    }

    /// The words a table says the reference is, after "the" or a possessive.
    pub fn describe(self) -> &'static str {
        match self {
            ExactFresnel::Physical => "exact physical model (same D, exact height-correlated Smith G2, exact Fresnel)",
            ExactFresnel::Own => "exact model with its own Fresnel (same D and F, exact height-correlated Smith G2)",
        }
    }
}

/// a = r^2 for the exact model: the requested roughness, floored at the fp32 guard whatever the spec's
/// precision (fp16's higher floor is part of what fp16 costs in accuracy).
pub fn alpha(roughness: f64) -> f64 {
    let r = roughness.clamp(MIN_ROUGHNESS_F32, 1.0);
    r * r
}

/// The exact physical counterpart of `spec` from guarded cosines; `lambda` must be for this spec's D at `a`.
pub fn from_cosines(spec: &ModelSpec, lambda: &Lambda, c: &Cosines, a: f64, f0: [f64; 3]) -> [f64; 3] {
    from_cosines_with(spec, ExactFresnel::Physical, lambda, c, a, f0)
}

/// `from_cosines` with the Fresnel `fresnel` chooses.
pub fn from_cosines_with(
    spec: &ModelSpec,
    fresnel: ExactFresnel,
    lambda: &Lambda,
    c: &Cosines,
    a: f64,
    f0: [f64; 3],
) -> [f64; 3] {
    let g2 = 1.0 / (1.0 + lambda.at(c.nov) + lambda.at(c.nol));
    let dv = spec.d.eval(c.noh, c.sin2h, a, &spec.params) * g2 / (4.0 * c.nol * c.nov);
    fresnel.term(spec).eval(f0, c.voh, &spec.params).map(|f| dv * f)
}

/// Exact f_s for one sample, Lambda integrated directly (`from_cosines` with a tabulated `Lambda` is the
/// fast path for many samples at one roughness).
pub fn eval(spec: &ModelSpec, s: &Sample) -> [f64; 3] {
    eval_with(spec, ExactFresnel::Physical, s)
}

/// `eval` with the Fresnel `fresnel` chooses.
pub fn eval_with(spec: &ModelSpec, fresnel: ExactFresnel, s: &Sample) -> [f64; 3] {
    let Some((c, f0)) = super::spec::guarded_cosines(s) else { return [0.0; 3] };
    let a = alpha(f64::from(s.roughness));
    let p = &spec.params;
    let g2 = 1.0 / (1.0 + lambda(spec.d, c.nov, a, p) + lambda(spec.d, c.nol, a, p));
    let dv = spec.d.eval(c.noh, c.sin2h, a, p) * g2 / (4.0 * c.nol * c.nov);
    fresnel.term(spec).eval(f0, c.voh, p).map(|f| dv * f)
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::spec::{ModelSpec, with_each_param_sample};
    use crate::{F, Vis};

    /// Every D with each sample of the parameters it reads.
    fn every_d() -> Vec<ModelSpec> {
        D::ALL.iter().flat_map(|&d| with_each_param_sample(ModelSpec::new(d, Vis::Implicit, F::None))).collect()
    }

    #[test]
    fn numeric_lambda_matches_closed_forms() {
        for spec in every_d() {
            for a in [0.01, 0.1, 0.3, 0.7, 1.0] {
                let Some(_) = (spec.d.row().lambda)(0.5, a, &spec.params) else { continue };
                for cos in [0.02, 0.1, 0.3, 0.6, 0.9, 0.999] {
                    let closed = lambda(spec.d, cos, a, &spec.params);
                    let numeric = lambda_numeric(|c| spec.d.at(c, a, &spec.params), cos, a);
                    assert!(
                        (numeric - closed).abs() <= 1e-6 * (1.0 + closed),
                        "{} a={a} cos={cos}: {numeric} vs {closed}",
                        spec.name()
                    );
                }
            }
        }
    }

    #[test]
    fn tables_match_direct_integration() {
        for spec in every_d().into_iter().filter(|s| (s.d.row().lambda)(0.5, 0.5, &s.params).is_none()) {
            for a in [0.01, 0.2, 0.8] {
                let table = Lambda::new(spec.d, a, &spec.params);
                for cos in [0.03, 0.2, 0.5, 0.8, 0.97] {
                    let direct = lambda_numeric(|c| spec.d.at(c, a, &spec.params), cos, a);
                    assert!(
                        (table.at(cos) - direct).abs() <= 2e-4 * (1.0 + direct),
                        "{} a={a} cos={cos}: {} vs {direct}",
                        spec.name(),
                        table.at(cos)
                    );
                }
            }
        }
    }
}
