//! The term library in f64: every GLSL term of `glsl/brdf.glsl` has its twin here, under the same id (the
//! value of the specialisation constant that selects it) and the same citation. Adding a term means one entry
//! in a table below and one function plus one `case` in the GLSL.

use super::guards::{F0_MAX, MIN_COSINE};
use std::f64::consts::PI;

/// The four cosines a term may read, already guarded (`guards::guard_cosine`), and sin2h = 1 - NoH^2 computed
/// without cancellation (|N x H|^2), which the D terms read near their peak.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Cosines {
    pub nov: f64,
    pub nol: f64,
    pub noh: f64,
    pub voh: f64,
    pub sin2h: f64,
}

macro_rules! term_table {
    ($(#[$meta:meta])* pub enum $Name:ident { $($Variant:ident = $id:literal, $name:literal, $cite:literal;)* }) => {
        $(#[$meta])*
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
        pub enum $Name { $($Variant = $id),* }
        impl $Name {
            pub const ALL: &'static [$Name] = &[$($Name::$Variant),*];
            /// The id the GLSL kernels switch on.
            pub fn id(self) -> u32 { self as u32 }
            /// The name in model specs (`d=`, `vis=`, `f=`, `metal=`).
            pub fn name(self) -> &'static str { match self { $($Name::$Variant => $name),* } }
            /// Paper and formula.
            pub fn citation(self) -> &'static str { match self { $($Name::$Variant => $cite),* } }
            pub fn from_name(s: &str) -> Option<Self> { Self::ALL.iter().copied().find(|t| t.name() == s) }
            pub fn names() -> Vec<&'static str> { Self::ALL.iter().map(|t| t.name()).collect() }
        }
    };
}

term_table! {
    /// Normal distribution functions D(NoH; a), a = roughness^2.
    pub enum D {
        Ggx = 0, "ggx", "GGX/Trowbridge-Reitz [Walter et al. 2007, eq. 33]: a2 / (pi (NoH^2 (a2-1) + 1)^2)";
        Beckmann = 1, "beckmann", "Beckmann [Beckmann & Spizzichino 1963; Walter et al. 2007, eq. 25]: exp((NoH^2-1)/(a2 NoH^2)) / (pi a2 NoH^4)";
        Blinn = 2, "blinn", "Normalised Blinn-Phong [Blinn 1977; m = 2/a2 - 2, Walter et al. 2007]: (m+2)/(2 pi) NoH^m";
        Gtr = 3, "gtr", "Generalized Trowbridge-Reitz [Burley 2012, App. B]: (g-1)(a2-1) / (pi (1 - a2^(1-g)) (1 + (a2-1) NoH^2)^g); g=1 Berry, g=2 GGX";
        Charlie = 4, "charlie", "Charlie sheen [Estevez & Kulla 2017, eq. 2]: (2 + 1/a) sin(theta_h)^(1/a) / (2 pi)";
    }
}

term_table! {
    /// Visibility terms Vis = G / (4 NoL NoV).
    pub enum Vis {
        Implicit = 0, "implicit", "Implicit [Hoffman 2010]: G = NoL NoV, Vis = 1/4";
        Neumann = 1, "neumann", "Neumann [Neumann et al. 1999]: G = NoL NoV / max(NoL, NoV)";
        Kelemen = 2, "kelemen", "Kelemen [Kelemen & Szirmay-Kalos 2001]: G = NoL NoV / VoH^2";
        VCavity = 3, "vcavity", "Cook-Torrance V-cavity [Cook & Torrance 1982]: G = min(1, 2 NoH NoV / VoH, 2 NoH NoL / VoH)";
        SchlickBeckmann = 4, "schlick-beckmann", "Schlick-Beckmann [Schlick 1994]: G1 = x / (x (1-k) + k), k = a sqrt(2/pi)";
        SchlickGgx = 5, "schlick-ggx", "Schlick-GGX [Karis 2013]: G1 = x / (x (1-k) + k), k = a/2";
        SmithGgxSeparable = 6, "smith-ggx-separable", "Smith GGX separable, exact [Walter et al. 2007, eq. 34]: 1 / ((NoV + sqrt(NoV^2 (1-a2) + a2)) (NoL + sqrt(NoL^2 (1-a2) + a2)))";
        SmithGgxCorrelated = 7, "smith-ggx-correlated", "Smith GGX height-correlated, exact [Heitz 2014, eq. 99]: 0.5 / (NoL sqrt(NoV^2 (1-a2) + a2) + NoV sqrt(NoL^2 (1-a2) + a2))";
        SmithGgxJointApprox = 8, "smith-ggx-joint-approx", "UE Vis_SmithJointApprox [Heitz 2014; UE5 BRDF.ush]: 0.5 / (NoL (NoV (1-a) + a) + NoV (NoL (1-a) + a))";
        SmithGgxCorrelatedFast = 9, "smith-ggx-correlated-fast", "Filament V_SmithGGXCorrelatedFast [Filament docs, sec. 4.4.2]: correlated form without square roots; the same function as UE's joint approx";
        Hammon = 10, "hammon", "Hammon [Hammon 2017, GDC]: 0.5 / mix(2 NoL NoV, NoL + NoV, a); Filament's current V_SmithGGXCorrelated_Fast";
        SmithBeckmannSeparable = 11, "smith-beckmann-separable", "Smith Beckmann separable, exact erf Lambda [Walter et al. 2007, eq. 25]: G = G1(v) G1(l), G1 = 1/(1 + Lambda)";
        SmithBeckmannCorrelated = 12, "smith-beckmann-correlated", "Smith Beckmann height-correlated, exact erf Lambda [Heitz 2014, eq. 99]: G = 1/(1 + Lambda(v) + Lambda(l))";
        SmithBeckmannWalter = 13, "smith-beckmann-walter", "Smith Beckmann, Walter's rational G1 [Walter et al. 2007, eq. 27]: (3.535c + 2.181c^2)/(1 + 2.276c + 2.577c^2) for c < 1.6, separable";
    }
}

term_table! {
    /// Fresnel terms. Conductor and F82 read the metal's complex IOR, not the sample's F0.
    pub enum F {
        None = 0, "none", "No Fresnel [Karis 2013, Specular BRDF Reference]: F = F0";
        Schlick = 1, "schlick", "Schlick [Schlick 1994, eq. 15]: F0 + (1 - F0)(1 - VoH)^5";
        SchlickSg = 2, "schlick-sg", "Schlick, spherical-Gaussian exponent [Karis 2013]: F0 + (1 - F0) 2^((-5.55473 VoH - 6.98316) VoH)";
        SchlickUe = 3, "schlick-ue", "UE5 F_Schlick [BRDF.ush]: F0 (1 - Fc) + saturate(50 F0.g) Fc, Fc = (1 - VoH)^5";
        SchlickFilament = 4, "schlick-filament", "Filament fresnel() [surface_brdf.fs]: F0 + (f90 - F0)(1 - VoH)^5, f90 = saturate(dot(F0, 50 * 0.33))";
        Dielectric = 5, "dielectric", "Exact dielectric Fresnel [Walter et al. 2007, eq. 22], IOR n = (1 + sqrt F0)/(1 - sqrt F0)";
        Conductor = 6, "conductor", "Exact conductor Fresnel, complex IOR n + ik [Lagarde 2013, Memo on Fresnel equations]";
        F82 = 7, "f82", "F82-tint [Kutz et al. 2021; Hoffman 2019]: Schlick(F0) - b VoH (1-VoH)^6, F0 and tint fitted to the metal at 0 and 82 deg";
    }
}

term_table! {
    /// Metals for the conductor and F82 Fresnel terms.
    pub enum Metal {
        Gold = 0, "gold", "Au, Johnson & Christy 1972 (refractiveindex.info) at 650/550/450 nm";
        Silver = 1, "silver", "Ag, Johnson & Christy 1972 (refractiveindex.info) at 650/550/450 nm";
        Copper = 2, "copper", "Cu, Johnson & Christy 1972 (refractiveindex.info) at 650/550/450 nm";
        Aluminium = 3, "aluminium", "Al, Rakic 1995 (refractiveindex.info) at 650/550/450 nm";
        Iron = 4, "iron", "Fe, Johnson & Christy 1974 (refractiveindex.info) at 650/550/450 nm";
    }
}

impl Metal {
    /// Complex index of refraction (n, k) per RGB channel; the same numbers as `metal_nk` in the GLSL.
    pub fn nk(self) -> ([f64; 3], [f64; 3]) {
        match self {
            Metal::Gold => ([0.18299, 0.42108, 1.3734], [3.4242, 2.3459, 1.7704]),
            Metal::Silver => ([0.15943, 0.14512, 0.13547], [3.9291, 3.19, 2.3808]),
            Metal::Copper => ([0.27105, 0.67693, 1.3164], [3.6092, 2.6248, 2.2921]),
            Metal::Aluminium => ([1.3456, 0.96521, 0.61722], [7.4746, 6.3995, 5.3031]),
            Metal::Iron => ([2.9114, 2.9497, 2.5845], [3.0893, 2.9318, 2.767]),
        }
    }
}

fn pow5(x: f64) -> f64 {
    let x2 = x * x;
    x2 * x2 * x
}

/// Which microfacet family a term belongs to: Vis terms derived for one family suit the D's of that family
/// (Walter et al. 2007 pair Blinn-Phong with Beckmann's G; Burley pairs GTR with GGX's Smith G).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Family {
    Ggx,
    Beckmann,
    Sheen,
}

impl D {
    pub fn family(self) -> Family {
        match self {
            D::Ggx | D::Gtr => Family::Ggx,
            D::Beckmann | D::Blinn => Family::Beckmann,
            D::Charlie => Family::Sheen,
        }
    }

    /// The visibility terms that make sense with this D: those of its family and those of none.
    pub fn sensible_visibilities(self) -> Vec<Vis> {
        Vis::ALL.iter().copied().filter(|v| v.family().is_none_or(|f| f == self.family())).collect()
    }
}

impl Vis {
    /// The family a Vis term was derived for; None for terms that assume no particular D.
    pub fn family(self) -> Option<Family> {
        match self {
            Vis::Implicit | Vis::Neumann | Vis::Kelemen | Vis::VCavity => None,
            Vis::SchlickGgx | Vis::SmithGgxSeparable | Vis::SmithGgxCorrelated | Vis::SmithGgxJointApprox | Vis::SmithGgxCorrelatedFast | Vis::Hammon => {
                Some(Family::Ggx)
            }
            Vis::SchlickBeckmann | Vis::SmithBeckmannSeparable | Vis::SmithBeckmannCorrelated | Vis::SmithBeckmannWalter => Some(Family::Beckmann),
        }
    }
}

// ---- D ----------------------------------------------------------------------------------------------

impl D {
    /// D(NoH) for a = roughness^2, given sin2h = 1 - NoH^2 too; `gamma` is read by GTR only.
    pub fn eval(self, noh: f64, sin2h: f64, a: f64, gamma: f64) -> f64 {
        match self {
            D::Ggx => d_ggx(noh, sin2h, a),
            D::Beckmann => d_beckmann(noh, sin2h, a),
            D::Blinn => d_blinn(noh, sin2h, a),
            D::Gtr => d_gtr(noh, sin2h, a, gamma),
            D::Charlie => d_charlie(sin2h, a),
        }
    }

    /// D at cos theta_h alone (sin2h = 1 - cos^2, exact enough in f64).
    pub fn at(self, noh: f64, a: f64, gamma: f64) -> f64 {
        self.eval(noh, (1.0 - noh * noh).max(0.0), a, gamma)
    }
}

/// a2 / (pi (NoH^2 (a2-1) + 1)^2), the denominator as NoH^2 a2 + sin2h.
pub fn d_ggx(noh: f64, sin2h: f64, a: f64) -> f64 {
    let a2 = a * a;
    let d = noh * noh * a2 + sin2h;
    a2 / (PI * d * d)
}

pub fn d_beckmann(noh: f64, sin2h: f64, a: f64) -> f64 {
    let a2 = a * a;
    let noh2 = noh * noh;
    (-sin2h / (a2 * noh2)).exp() / (PI * a2 * noh2 * noh2)
}

/// Blinn-Phong exponent from a [Walter et al. 2007]: m = 2/a2 - 2.
pub fn blinn_exponent(a: f64) -> f64 {
    2.0 / (a * a) - 2.0
}

/// (m+2)/(2 pi) NoH^m with NoH^m = exp(m/2 ln(1 - sin2h)), the log floored at ln(MIN_COSINE^2) as in the GLSL.
pub fn d_blinn(_noh: f64, sin2h: f64, a: f64) -> f64 {
    let m = blinn_exponent(a);
    let log_noh2 = (-sin2h).ln_1p().max(2.0 * (MIN_COSINE as f32).ln() as f64);
    (m + 2.0) / (2.0 * PI) * (0.5 * m * log_noh2).exp()
}

/// GTR normaliser c = (g-1)(a2-1) / (1 - a2^(1-g)); g = 1: (a2-1)/ln(a2); limit 1 at a2 = 1.
/// The twin evaluates the closed form (exact in f64 down to |a2-1| ~ 1e-6) where the GLSL switches to the
/// series inside `GTR_SERIES_BAND`; both meet the limit at a2 = 1.
pub fn gtr_normaliser(a2: f64, g: f64) -> f64 {
    let u = a2 - 1.0;
    if u.abs() < 1e-6 {
        return 1.0 / gtr_series(u, g);
    }
    if g == 1.0 { u / a2.ln() } else { (g - 1.0) * u / (1.0 - a2.powf(1.0 - g)) }
}

/// S(u) = 1 - g u/2 + g(g+1) u^2/6 - g(g+1)(g+2) u^3/24, the series of 1/c around a2 = 1 (used by the GLSL
/// within `GTR_SERIES_BAND`, by the twin within 1e-6).
pub fn gtr_series(u: f64, g: f64) -> f64 {
    1.0 - g * u / 2.0 + g * (g + 1.0) * u * u / 6.0 - g * (g + 1.0) * (g + 2.0) * u * u * u / 24.0
}

pub fn d_gtr(noh: f64, sin2h: f64, a: f64, g: f64) -> f64 {
    let a2 = a * a;
    let t = noh * noh * a2 + sin2h;
    gtr_normaliser(a2, g) / (PI * t.powf(g))
}

pub fn d_charlie(sin2h: f64, a: f64) -> f64 {
    let inv_a = 1.0 / a;
    (2.0 + inv_a) * sin2h.powf(0.5 * inv_a) / (2.0 * PI)
}

// ---- Vis --------------------------------------------------------------------------------------------

impl Vis {
    pub fn eval(self, c: &Cosines, a: f64) -> f64 {
        let Cosines { nov, nol, noh, voh, .. } = *c;
        match self {
            Vis::Implicit => 0.25,
            Vis::Neumann => 0.25 / nol.max(nov),
            Vis::Kelemen => 0.25 / (voh * voh),
            Vis::VCavity => (1.0 / (4.0 * nol * nov)).min(noh / (2.0 * voh * nol.max(nov))),
            Vis::SchlickBeckmann => vis_schlick(nov, nol, a * (2.0 / PI).sqrt()),
            Vis::SchlickGgx => vis_schlick(nov, nol, a * 0.5),
            Vis::SmithGgxSeparable => {
                let a2 = a * a;
                1.0 / ((nov + (nov * (nov - nov * a2) + a2).sqrt()) * (nol + (nol * (nol - nol * a2) + a2).sqrt()))
            }
            Vis::SmithGgxCorrelated => {
                let a2 = a * a;
                0.5 / (nol * (nov * (nov - nov * a2) + a2).sqrt() + nov * (nol * (nol - nol * a2) + a2).sqrt())
            }
            Vis::SmithGgxJointApprox | Vis::SmithGgxCorrelatedFast => {
                0.5 / (nol * (nov * (1.0 - a) + a) + nov * (nol * (1.0 - a) + a))
            }
            Vis::Hammon => 0.5 / lerp(2.0 * nol * nov, nol + nov, a),
            Vis::SmithBeckmannSeparable => {
                1.0 / ((1.0 + lambda_beckmann(nov, a)) * (1.0 + lambda_beckmann(nol, a))) / (4.0 * nol * nov)
            }
            Vis::SmithBeckmannCorrelated => {
                1.0 / (1.0 + lambda_beckmann(nov, a) + lambda_beckmann(nol, a)) / (4.0 * nol * nov)
            }
            Vis::SmithBeckmannWalter => g1_walter(nov, a) * g1_walter(nol, a) / (4.0 * nol * nov),
        }
    }
}

fn lerp(x: f64, y: f64, t: f64) -> f64 {
    x * (1.0 - t) + y * t
}

fn vis_schlick(nov: f64, nol: f64, k: f64) -> f64 {
    0.25 / ((nol * (1.0 - k) + k) * (nov * (1.0 - k) + k))
}

/// c = cos / (a sin) with the sine floored at MIN_COSINE, as in the GLSL.
fn beckmann_c(cos: f64, a: f64) -> f64 {
    cos / (a * (1.0 - cos * cos).max(MIN_COSINE * MIN_COSINE).sqrt())
}

/// Exact Smith Lambda of Beckmann: (erf(c) - 1)/2 + exp(-c^2) / (2 c sqrt(pi)).
pub fn lambda_beckmann(cos: f64, a: f64) -> f64 {
    let c = beckmann_c(cos, a);
    (libm::erf(c) - 1.0) * 0.5 + (-c * c).exp() / (2.0 * PI.sqrt() * c)
}

/// Walter's rational approximation of the Beckmann G1.
pub fn g1_walter(cos: f64, a: f64) -> f64 {
    let c = beckmann_c(cos, a);
    if c < 1.6 { (3.535 * c + 2.181 * c * c) / (1.0 + 2.276 * c + 2.577 * c * c) } else { 1.0 }
}

// ---- F ----------------------------------------------------------------------------------------------

impl F {
    /// F per channel; `metal` is read by the conductor and F82 terms only.
    pub fn eval(self, f0: [f64; 3], voh: f64, metal: Metal) -> [f64; 3] {
        match self {
            F::None => f0,
            F::Schlick => f0.map(|f| f_schlick(f, voh)),
            F::SchlickSg => f0.map(|f| f + (1.0 - f) * ((-5.55473 * voh - 6.98316) * voh).exp2()),
            F::SchlickUe => {
                let fc = pow5(1.0 - voh);
                let f90 = (50.0 * f0[1]).clamp(0.0, 1.0);
                f0.map(|f| f90 * fc + (1.0 - fc) * f)
            }
            F::SchlickFilament => {
                let f90 = ((f0[0] + f0[1] + f0[2]) * 50.0 * 0.33).clamp(0.0, 1.0);
                f0.map(|f| f + (f90 - f) * pow5(1.0 - voh))
            }
            F::Dielectric => f0.map(|f| f_dielectric(f, voh)),
            F::Conductor => f_conductor(metal, voh),
            F::F82 => f_f82(metal, voh),
        }
    }
}

pub fn f_schlick(f0: f64, voh: f64) -> f64 {
    f0 + (1.0 - f0) * pow5(1.0 - voh)
}

/// IOR of the dielectric whose normal-incidence reflectance is f0 (capped at F0_MAX).
pub fn dielectric_ior(f0: f64) -> f64 {
    let s = f0.min(F0_MAX).sqrt();
    (1.0 + s) / (1.0 - s)
}

/// Exact unpolarised dielectric Fresnel [Walter et al. 2007, eq. 22].
pub fn f_dielectric(f0: f64, c: f64) -> f64 {
    let n = dielectric_ior(f0);
    let g = (n * n - 1.0 + c * c).sqrt();
    let a = (g - c) / (g + c);
    let b = (c * (g + c) - 1.0) / (c * (g - c) + 1.0);
    0.5 * a * a * (1.0 + b * b)
}

/// Exact unpolarised conductor Fresnel for one channel [Lagarde 2013].
pub fn f_conductor_nk(n: f64, k: f64, c: f64) -> f64 {
    let c2 = c * c;
    let s2 = 1.0 - c2;
    let (n2, k2) = (n * n, k * k);
    let t0 = n2 - k2 - s2;
    let a2b2 = (t0 * t0 + 4.0 * n2 * k2).sqrt();
    let t1 = a2b2 + c2;
    let a = (0.5 * (a2b2 + t0)).sqrt();
    let t2 = 2.0 * c * a;
    let rs = (t1 - t2) / (t1 + t2);
    let t3 = c2 * a2b2 + s2 * s2;
    let t4 = t2 * s2;
    let rp = rs * (t3 - t4) / (t3 + t4);
    0.5 * (rp + rs)
}

pub fn f_conductor(metal: Metal, c: f64) -> [f64; 3] {
    let (n, k) = metal.nk();
    [0, 1, 2].map(|i| f_conductor_nk(n[i], k[i], c))
}

/// cos(82 deg) as the F82 model takes it: 1/7.
pub const F82_MU_BAR: f64 = 1.0 / 7.0;

/// F0 and tint of the F82 fit to a metal: exact at normal incidence and at mu = 1/7.
pub fn f82_fit(metal: Metal) -> ([f64; 3], [f64; 3]) {
    let f0 = f_conductor(metal, 1.0);
    let at_bar = f_conductor(metal, F82_MU_BAR);
    let tint = [0, 1, 2].map(|i| at_bar[i] / f_schlick(f0[i], F82_MU_BAR));
    (f0, tint)
}

pub fn f_f82(metal: Metal, c: f64) -> [f64; 3] {
    let (f0, tint) = f82_fit(metal);
    let x = 1.0 - c;
    [0, 1, 2].map(|i| {
        let schlick_bar = f_schlick(f0[i], F82_MU_BAR);
        let b = schlick_bar * (1.0 - tint[i]) / (F82_MU_BAR * (1.0 - F82_MU_BAR).powi(6));
        f_schlick(f0[i], c) - b * c * pow5(x) * x
    })
}
