//! The term library in f64, and the one table of terms: every GLSL term of `glsl/brdf.glsl` has its twin here
//! under the same id (the value of the specialisation constant that selects it), name and citation, and the
//! GLSL side's ids, parameters, metals and dispatch `switch`es are generated from these tables
//! (`brdf::glsl_gen`, checked by tests/kernels/sources.rs). Adding a term is one row in a table below and its twin
//! function here, and one GLSL function `D_<Variant>` / `Vis_<Variant>` / `F_<Variant>` in glsl/brdf.glsl.

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
    ($(#[$meta:meta])* pub enum $Name:ident: $row:ident ($prefix:literal) {
        $($Variant:ident = $id:literal, $name:literal, $cite:literal, $data:expr;)*
    }) => {
        $(#[$meta])*
        #[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
        pub enum $Name { $($Variant = $id),* }
        impl $Name {
            pub const ALL: &'static [$Name] = &[$($Name::$Variant),*];
            /// The id the GLSL kernels switch on.
            pub fn id(self) -> u32 { self as u32 }
            /// The name in model specs.
            pub fn name(self) -> &'static str { match self { $($Name::$Variant => $name),* } }
            /// Paper and formula.
            pub fn citation(self) -> &'static str { match self { $($Name::$Variant => $cite),* } }
            /// The GLSL function (or, for metals, the id macro suffix) implementing it.
            pub fn glsl_name(self) -> &'static str { match self { $($Name::$Variant => concat!($prefix, stringify!($Variant))),* } }
            pub fn from_name(s: &str) -> Option<Self> { Self::ALL.iter().copied().find(|t| t.name() == s) }
            pub fn names() -> Vec<&'static str> { Self::ALL.iter().map(|t| t.name()).collect() }
            /// This term's row: its twin and what the library knows about it.
            pub fn row(self) -> $row { match self { $($Name::$Variant => $data),* } }
        }
    };
}

// ---- Term parameters ----------------------------------------------------------------------------

/// A value a term reads besides the cosines, roughness and F0: a specialisation constant in the GLSL, and a
/// `key=value` in model specs.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Param {
    Gamma,
    Metal,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ParamKind {
    /// A number with its default and the range the kernels are stable in (`why` says what breaks beyond it).
    Number { default: f64, min: f64, max: f64, why: &'static str },
    /// One of the metals of `Metal`.
    Metal,
}

pub struct ParamDef {
    pub param: Param,
    /// The key in model specs.
    pub name: &'static str,
    /// The GLSL specialisation constant.
    pub glsl: &'static str,
    pub constant_id: u32,
    pub kind: ParamKind,
    pub about: &'static str,
    /// Values the stability suite tries (limit forms and range ends), also just outside the accepted range.
    pub hard_values: &'static [f64],
}

/// Every term parameter, in `Param` order. Specialisation constant ids 3..16 are reserved for them
/// (0..2 select the terms, kernel constants start at 16: `kernels::constants`).
pub const PARAMS: [ParamDef; 2] = [
    ParamDef {
        param: Param::Gamma,
        name: "gamma",
        glsl: "GTR_GAMMA",
        constant_id: 3,
        kind: ParamKind::Number {
            default: 1.5,
            min: 1.0,
            max: 3.0,
            why: "GTR's peak a2^-gamma at the fp32 roughness floor leaves fp32's range for large gamma (measured by `brdfprof stability`: docs/limits.md)",
        },
        about: "GTR exponent [Burley 2012]: 1 Berry, 2 GGX; the thesis used 1.5",
        // g = 1 is the normaliser's limit form (a2-1)/ln(a2); 1 +- 1e-6 straddle it; 2 is GGX; 3 the range end.
        hard_values: &[1.0, 1.0 - 1e-6, 1.0 + 1e-6, 2.0, 3.0],
    },
    ParamDef {
        param: Param::Metal,
        name: "metal",
        glsl: "METAL",
        constant_id: 4,
        kind: ParamKind::Metal,
        about: "metal of the conductor Fresnel terms",
        hard_values: &[],
    },
];

impl Param {
    pub const ALL: [Param; 2] = [Param::Gamma, Param::Metal];
    pub fn def(self) -> &'static ParamDef {
        &PARAMS[self as usize]
    }
    pub fn name(self) -> &'static str {
        self.def().name
    }
    pub fn from_name(s: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|p| p.name() == s)
    }
}

/// A parameter's value.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ParamValue {
    Number(f64),
    Metal(Metal),
}

impl ParamValue {
    pub fn text(self) -> String {
        match self {
            ParamValue::Number(x) => format!("{x}"),
            ParamValue::Metal(m) => m.name().to_string(),
        }
    }
    /// Bits that identify the value (for hashing specs).
    pub fn bits(self) -> u64 {
        match self {
            ParamValue::Number(x) => x.to_bits(),
            ParamValue::Metal(m) => m.id() as u64,
        }
    }
}

/// The value of every parameter (read or not by a spec's terms).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Params([ParamValue; 2]);

impl Default for Params {
    fn default() -> Self {
        Params(Param::ALL.map(|p| match p.def().kind {
            ParamKind::Number { default, .. } => ParamValue::Number(default),
            ParamKind::Metal => ParamValue::Metal(Metal::Gold),
        }))
    }
}

impl Params {
    pub fn get(&self, p: Param) -> ParamValue {
        self.0[p as usize]
    }
    pub fn set(&mut self, p: Param, v: ParamValue) {
        self.0[p as usize] = v;
    }
    /// A number parameter's value.
    pub fn number(&self, p: Param) -> f64 {
        match self.get(p) {
            ParamValue::Number(x) => x,
            ParamValue::Metal(m) => m.id() as f64,
        }
    }
    pub fn metal(&self) -> Metal {
        match self.get(Param::Metal) {
            ParamValue::Metal(m) => m,
            ParamValue::Number(_) => Metal::Gold,
        }
    }
    /// Parses `value` for `p`; the error names the parameter and the accepted values or range.
    pub fn parse_value(p: Param, value: &str) -> Result<ParamValue, String> {
        match p.def().kind {
            ParamKind::Number { min, max, why, .. } => {
                let x: f64 = value.parse().map_err(|_| format!("{} `{value}` is not a number", p.name()))?;
                if !(x.is_finite() && (min..=max).contains(&x)) {
                    return Err(format!(
                        "{} {value} is outside [{min}, {max}], the range brdfprof's kernels are stable in: {why}",
                        p.name()
                    ));
                }
                Ok(ParamValue::Number(x))
            }
            ParamKind::Metal => Metal::from_name(value)
                .map(ParamValue::Metal)
                .ok_or_else(|| format!("unknown metal `{value}`: valid are {}", Metal::names().join(", "))),
        }
    }
}

// ---- Rows: what the library knows about each term ---------------------------------------------------

/// Which microfacet family a term belongs to: Vis terms derived for one family suit the D's of that family
/// (Walter et al. 2007 pair Blinn-Phong with Beckmann's G; Burley pairs GTR with GGX's Smith G).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Family {
    Ggx,
    Beckmann,
    Sheen,
}

/// Where a D's lobe lies: around the normal (its Smith Lambda is nearly a function of a tan theta), or towards
/// grazing angles (Charlie's sheen).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Lobe {
    AroundNormal,
    Grazing,
}

pub struct DRow {
    /// D(NoH, sin2h = 1 - NoH^2, a = roughness^2, parameters).
    pub eval: fn(f64, f64, f64, &Params) -> f64,
    pub reads: &'static [Param],
    pub family: Family,
    pub lobe: Lobe,
    /// The exact Smith Lambda(cos, a) in closed form, where it has one for these parameters
    /// (otherwise `exact` integrates it from its definition).
    pub lambda: fn(f64, f64, &Params) -> Option<f64>,
    /// The scene kernel's anisotropic lobe extends this D.
    pub anisotropic: bool,
}

pub struct VisRow {
    pub eval: fn(&Cosines, f64) -> f64,
    /// The family it was derived for; None when it assumes no particular D.
    pub family: Option<Family>,
    /// The exact height-correlated Smith G2 of this D (so the spec is exact with an exact Fresnel).
    pub exact_for: Option<D>,
}

/// What a Fresnel term approximates.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Exact {
    /// The dielectric with the sample's F0 (`f_dielectric`).
    Dielectric,
    /// The metal's complex IOR (`f_conductor`).
    Conductor,
}

pub struct FRow {
    /// F per channel from F0, VoH and the parameters.
    pub eval: fn([f64; 3], f64, &Params) -> [f64; 3],
    pub reads: &'static [Param],
    /// The exact Fresnel it stands for; `is_exact`: it is that Fresnel.
    pub exact: Exact,
    pub is_exact: bool,
}

fn no_closed_lambda(_: f64, _: f64, _: &Params) -> Option<f64> {
    None
}

term_table! {
    /// Normal distribution functions D(NoH; a), a = roughness^2.
    pub enum D: DRow ("D_") {
        Ggx = 0, "ggx", "GGX/Trowbridge-Reitz [Walter et al. 2007, eq. 33]: a2 / (pi (NoH^2 (a2-1) + 1)^2)",
            DRow { eval: d_ggx, reads: &[], family: Family::Ggx, lobe: Lobe::AroundNormal, lambda: |c, a, _| Some(lambda_ggx(c, a)), anisotropic: true };
        Beckmann = 1, "beckmann", "Beckmann [Beckmann & Spizzichino 1963; Walter et al. 2007, eq. 25]: exp((NoH^2-1)/(a2 NoH^2)) / (pi a2 NoH^4)",
            DRow { eval: d_beckmann, reads: &[], family: Family::Beckmann, lobe: Lobe::AroundNormal, lambda: |c, a, _| Some(lambda_beckmann_exact(c, a)), anisotropic: false };
        Blinn = 2, "blinn", "Normalised Blinn-Phong [Blinn 1977; m = 2/a2 - 2 from Walter et al. 2007]: (m+2)/(2 pi) NoH^m",
            DRow { eval: d_blinn, reads: &[], family: Family::Beckmann, lobe: Lobe::AroundNormal, lambda: no_closed_lambda, anisotropic: false };
        Gtr = 3, "gtr", "Generalized Trowbridge-Reitz [Burley 2012, App. B]: (g-1)(a2-1) / (pi (1 - a2^(1-g)) (1 + (a2-1) NoH^2)^g); g=1 Berry, g=2 GGX",
            DRow { eval: d_gtr, reads: &[Param::Gamma], family: Family::Ggx, lobe: Lobe::AroundNormal, lambda: |c, a, p| (p.number(Param::Gamma) == 2.0).then(|| lambda_ggx(c, a)), anisotropic: false };
        Charlie = 4, "charlie", "Charlie sheen [Estevez & Kulla 2017, eq. 2]: (2 + 1/a) sin(theta_h)^(1/a) / (2 pi)",
            DRow { eval: d_charlie, reads: &[], family: Family::Sheen, lobe: Lobe::Grazing, lambda: no_closed_lambda, anisotropic: false };
    }
}

term_table! {
    /// Visibility terms Vis = G / (4 NoL NoV).
    pub enum Vis: VisRow ("Vis_") {
        Implicit = 0, "implicit", "Implicit [Hoffman 2010]: G = NoL NoV, Vis = 1/4",
            VisRow { eval: vis_implicit, family: None, exact_for: None };
        Neumann = 1, "neumann", "Neumann [Neumann et al. 1999]: G = NoL NoV / max(NoL, NoV)",
            VisRow { eval: vis_neumann, family: None, exact_for: None };
        Kelemen = 2, "kelemen", "Kelemen [Kelemen & Szirmay-Kalos 2001]: G = NoL NoV / VoH^2",
            VisRow { eval: vis_kelemen, family: None, exact_for: None };
        VCavity = 3, "vcavity", "Cook-Torrance V-cavity [Cook & Torrance 1982, eq. 6]: G = min(1, 2 NoH NoV / VoH, 2 NoH NoL / VoH)",
            VisRow { eval: vis_vcavity, family: None, exact_for: None };
        SchlickBeckmann = 4, "schlick-beckmann", "Schlick-Beckmann [Schlick 1994; Karis 2013]: G1 = x / (x (1-k) + k), k = a sqrt(2/pi)",
            VisRow { eval: vis_schlick_beckmann, family: Some(Family::Beckmann), exact_for: None };
        SchlickGgx = 5, "schlick-ggx", "Schlick-GGX [Karis 2013]: G1 = x / (x (1-k) + k), k = a/2",
            VisRow { eval: vis_schlick_ggx, family: Some(Family::Ggx), exact_for: None };
        SmithGgxSeparable = 6, "smith-ggx-separable", "Smith GGX separable, exact [Walter et al. 2007, eq. 34]: 1 / ((NoV + sqrt(NoV^2 (1-a2) + a2)) (NoL + sqrt(NoL^2 (1-a2) + a2)))",
            VisRow { eval: vis_smith_ggx_separable, family: Some(Family::Ggx), exact_for: None };
        SmithGgxCorrelated = 7, "smith-ggx-correlated", "Smith GGX height-correlated, exact [Heitz 2014, eq. 99]: 0.5 / (NoL sqrt(NoV^2 (1-a2) + a2) + NoV sqrt(NoL^2 (1-a2) + a2))",
            VisRow { eval: vis_smith_ggx_correlated, family: Some(Family::Ggx), exact_for: Some(D::Ggx) };
        SmithGgxJointApprox = 8, "smith-ggx-joint-approx", "UE Vis_SmithJointApprox [Heitz 2014; Karis, UE5 BRDF.ush]: 0.5 / (NoL (NoV (1-a) + a) + NoV (NoL (1-a) + a))",
            VisRow { eval: vis_smith_ggx_joint_approx, family: Some(Family::Ggx), exact_for: None };
        SmithGgxCorrelatedFast = 9, "smith-ggx-correlated-fast", "Filament V_SmithGGXCorrelatedFast [Filament documentation, sec. 4.4.2]: the correlated form without square roots, 0.5 / (NoL (NoV (1-a) + a) + NoV (NoL (1-a) + a)); the same function as UE's joint approx",
            VisRow { eval: vis_smith_ggx_joint_approx, family: Some(Family::Ggx), exact_for: None };
        Hammon = 10, "hammon", "Hammon [Hammon 2017, \"PBR Diffuse Lighting for GGX+Smith Microsurfaces\"]: 0.5 / mix(2 NoL NoV, NoL + NoV, a); Filament's current V_SmithGGXCorrelated_Fast",
            VisRow { eval: vis_hammon, family: Some(Family::Ggx), exact_for: None };
        SmithBeckmannSeparable = 11, "smith-beckmann-separable", "Smith Beckmann separable, exact erf Lambda [Walter et al. 2007, eq. 25]: G = G1(v) G1(l), G1 = 1/(1 + Lambda)",
            VisRow { eval: vis_smith_beckmann_separable, family: Some(Family::Beckmann), exact_for: None };
        SmithBeckmannCorrelated = 12, "smith-beckmann-correlated", "Smith Beckmann height-correlated, exact erf Lambda [Heitz 2014, eq. 99]: G = 1/(1 + Lambda(v) + Lambda(l))",
            VisRow { eval: vis_smith_beckmann_correlated, family: Some(Family::Beckmann), exact_for: Some(D::Beckmann) };
        SmithBeckmannWalter = 13, "smith-beckmann-walter", "Smith Beckmann, Walter's rational G1 [Walter et al. 2007, eq. 27]: (3.535c + 2.181c^2)/(1 + 2.276c + 2.577c^2) for c < 1.6, separable",
            VisRow { eval: vis_smith_beckmann_walter, family: Some(Family::Beckmann), exact_for: None };
        SchlickGgxKaris = 14, "schlick-ggx-karis", "Schlick-GGX with Karis' remap for analytic lights [Karis 2013, p. 3; de Vries, LearnOpenGL \"PBR: Theory\" 2014]: G1 = x / (x (1-k) + k), k = (r + 1)^2 / 8, r = sqrt(a)",
            VisRow { eval: vis_schlick_ggx_karis, family: Some(Family::Ggx), exact_for: None };
    }
}

term_table! {
    /// Fresnel terms. Conductor and F82 read the metal's complex IOR, not the sample's F0.
    pub enum F: FRow ("F_") {
        None = 0, "none", "No Fresnel [Karis 2013, \"Specular BRDF Reference\"]: F = F0",
            FRow { eval: |f0, _, _| f0, reads: &[], exact: Exact::Dielectric, is_exact: false };
        Schlick = 1, "schlick", "Schlick [Schlick 1994, eq. 15]: F0 + (1 - F0)(1 - VoH)^5",
            FRow { eval: |f0, voh, _| f0.map(|f| f_schlick(f, voh)), reads: &[], exact: Exact::Dielectric, is_exact: false };
        SchlickSg = 2, "schlick-sg", "Schlick with a spherical-Gaussian exponent [Karis 2013, p. 3]: F0 + (1 - F0) 2^((-5.55473 VoH - 6.98316) VoH)",
            FRow { eval: f_schlick_sg, reads: &[], exact: Exact::Dielectric, is_exact: false };
        SchlickUe = 3, "schlick-ue", "UE5 F_Schlick [BRDF.ush]: F0 + (f90 - F0) Fc with f90 = saturate(50 F0.g) (pre-baked specular occlusion), Fc = (1 - VoH)^5",
            FRow { eval: f_schlick_ue, reads: &[], exact: Exact::Dielectric, is_exact: false };
        SchlickFilament = 4, "schlick-filament", "Filament fresnel() [surface_brdf.fs]: F0 + (f90 - F0)(1 - VoH)^5, f90 = saturate(dot(F0, 50 * 0.33))",
            FRow { eval: f_schlick_filament, reads: &[], exact: Exact::Dielectric, is_exact: false };
        Dielectric = 5, "dielectric", "Exact unpolarised dielectric Fresnel [Walter et al. 2007, eq. 22], IOR n = (1 + sqrt F0)/(1 - sqrt F0)",
            FRow { eval: |f0, voh, _| f0.map(|f| f_dielectric(f, voh)), reads: &[], exact: Exact::Dielectric, is_exact: true };
        Conductor = 6, "conductor", "Exact unpolarised conductor Fresnel, complex IOR n + ik [Lagarde 2013, \"Memo on Fresnel equations\"]",
            FRow { eval: |_, voh, p| f_conductor(p.metal(), voh), reads: &[Param::Metal], exact: Exact::Conductor, is_exact: true };
        F82Tint = 7, "f82", "F82-tint [Kutz et al. 2021, \"Novel aspects of the Adobe Standard Material\"; Hoffman 2019]: Schlick(F0) - b VoH (1-VoH)^6, F0 and tint fitted to the metal at 0 and 82 deg",
            FRow { eval: |_, voh, p| f_f82(p.metal(), voh), reads: &[Param::Metal], exact: Exact::Conductor, is_exact: false };
    }
}

/// A metal's row: complex IOR (n, k) per RGB channel at 650/550/450 nm.
pub struct MetalRow {
    pub n: [f64; 3],
    pub k: [f64; 3],
}

term_table! {
    /// Metals for the conductor Fresnel terms (refractiveindex.info).
    pub enum Metal: MetalRow ("METAL_") {
        Gold = 0, "gold", "Au, Johnson & Christy 1972 (refractiveindex.info) at 650/550/450 nm",
            MetalRow { n: [0.18299, 0.42108, 1.3734], k: [3.4242, 2.3459, 1.7704] };
        Silver = 1, "silver", "Ag, Johnson & Christy 1972 (refractiveindex.info) at 650/550/450 nm",
            MetalRow { n: [0.15943, 0.14512, 0.13547], k: [3.9291, 3.19, 2.3808] };
        Copper = 2, "copper", "Cu, Johnson & Christy 1972 (refractiveindex.info) at 650/550/450 nm",
            MetalRow { n: [0.27105, 0.67693, 1.3164], k: [3.6092, 2.6248, 2.2921] };
        Aluminium = 3, "aluminium", "Al, Rakic 1995 (refractiveindex.info) at 650/550/450 nm",
            MetalRow { n: [1.3456, 0.96521, 0.61722], k: [7.4746, 6.3995, 5.3031] };
        Iron = 4, "iron", "Fe, Johnson & Christy 1974 (refractiveindex.info) at 650/550/450 nm",
            MetalRow { n: [2.9114, 2.9497, 2.5845], k: [3.0893, 2.9318, 2.767] };
    }
}

impl Metal {
    /// Complex index of refraction (n, k) per RGB channel.
    pub fn nk(self) -> ([f64; 3], [f64; 3]) {
        let r = self.row();
        (r.n, r.k)
    }
}

impl D {
    /// D(NoH) for a = roughness^2, given sin2h = 1 - NoH^2 too.
    pub fn eval(self, noh: f64, sin2h: f64, a: f64, params: &Params) -> f64 {
        (self.row().eval)(noh, sin2h, a, params)
    }

    /// D at cos theta_h alone (sin2h = 1 - cos^2, exact enough in f64).
    pub fn at(self, noh: f64, a: f64, params: &Params) -> f64 {
        self.eval(noh, (1.0 - noh * noh).max(0.0), a, params)
    }

    pub fn family(self) -> Family {
        self.row().family
    }

    /// The visibility terms that make sense with this D: those of its family and those of none.
    pub fn sensible_visibilities(self) -> Vec<Vis> {
        Vis::ALL.iter().copied().filter(|v| v.family().is_none_or(|f| f == self.family())).collect()
    }
}

impl Vis {
    pub fn eval(self, c: &Cosines, a: f64) -> f64 {
        (self.row().eval)(c, a)
    }

    pub fn family(self) -> Option<Family> {
        self.row().family
    }
}

impl F {
    /// F per channel.
    pub fn eval(self, f0: [f64; 3], voh: f64, params: &Params) -> [f64; 3] {
        (self.row().eval)(f0, voh, params)
    }
}

fn pow5(x: f64) -> f64 {
    let x2 = x * x;
    x2 * x2 * x
}

// ---- D ----------------------------------------------------------------------------------------------

/// a2 / (pi (NoH^2 (a2-1) + 1)^2), the denominator as NoH^2 a2 + sin2h.
pub fn d_ggx(noh: f64, sin2h: f64, a: f64, _: &Params) -> f64 {
    let a2 = a * a;
    let d = noh * noh * a2 + sin2h;
    a2 / (PI * d * d)
}

pub fn d_beckmann(noh: f64, sin2h: f64, a: f64, _: &Params) -> f64 {
    let a2 = a * a;
    let noh2 = noh * noh;
    (-sin2h / (a2 * noh2)).exp() / (PI * a2 * noh2 * noh2)
}

/// Blinn-Phong exponent from a [Walter et al. 2007]: m = 2/a2 - 2.
pub fn blinn_exponent(a: f64) -> f64 {
    2.0 / (a * a) - 2.0
}

/// (m+2)/(2 pi) NoH^m with NoH^m = exp(m/2 ln(1 - sin2h)), the log floored at ln(MIN_COSINE^2) as in the GLSL.
pub fn d_blinn(_noh: f64, sin2h: f64, a: f64, _: &Params) -> f64 {
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

pub fn d_gtr(noh: f64, sin2h: f64, a: f64, p: &Params) -> f64 {
    let g = p.number(Param::Gamma);
    let a2 = a * a;
    let t = noh * noh * a2 + sin2h;
    gtr_normaliser(a2, g) / (PI * t.powf(g))
}

pub fn d_charlie(_noh: f64, sin2h: f64, a: f64, _: &Params) -> f64 {
    let inv_a = 1.0 / a;
    (2.0 + inv_a) * sin2h.powf(0.5 * inv_a) / (2.0 * PI)
}

/// GGX Smith Lambda [Walter et al. 2007; Heitz 2014, eq. 86]: (-1 + sqrt(1 + a^2 tan^2 theta)) / 2.
pub fn lambda_ggx(cos: f64, a: f64) -> f64 {
    if cos >= 1.0 {
        return 0.0;
    }
    let tan2 = (1.0 - cos * cos) / (cos * cos);
    0.5 * (-1.0 + (1.0 + a * a * tan2).sqrt())
}

/// Beckmann Smith Lambda [Walter et al. 2007, eq. 25]: (erf(c) - 1)/2 + exp(-c^2) / (2 c sqrt(pi)),
/// c = 1 / (a tan theta), without the kernels' sine floor.
pub fn lambda_beckmann_exact(cos: f64, a: f64) -> f64 {
    if cos >= 1.0 {
        return 0.0;
    }
    let c = cos / (a * (1.0 - cos * cos).sqrt());
    (libm::erf(c) - 1.0) * 0.5 + (-c * c).exp() / (2.0 * PI.sqrt() * c)
}

// ---- Vis --------------------------------------------------------------------------------------------

fn vis_implicit(_: &Cosines, _: f64) -> f64 {
    0.25
}

fn vis_neumann(c: &Cosines, _: f64) -> f64 {
    0.25 / c.nol.max(c.nov)
}

fn vis_kelemen(c: &Cosines, _: f64) -> f64 {
    0.25 / (c.voh * c.voh)
}

/// min(1/(4 NoL NoV), NoH / (2 VoH max(NoL, NoV))): G/(4 NoL NoV) divided through term by term.
fn vis_vcavity(c: &Cosines, _: f64) -> f64 {
    (1.0 / (4.0 * c.nol * c.nov)).min(c.noh / (2.0 * c.voh * c.nol.max(c.nov)))
}

fn vis_schlick(nov: f64, nol: f64, k: f64) -> f64 {
    0.25 / ((nol * (1.0 - k) + k) * (nov * (1.0 - k) + k))
}

fn vis_schlick_beckmann(c: &Cosines, a: f64) -> f64 {
    vis_schlick(c.nov, c.nol, a * (2.0 / PI).sqrt())
}

fn vis_schlick_ggx(c: &Cosines, a: f64) -> f64 {
    vis_schlick(c.nov, c.nol, a * 0.5)
}

/// Karis' k = a'/2 with a' = ((r + 1) / 2)^2: the roughness remapped for punctual lights (perceptual r = sqrt(a)).
fn vis_schlick_ggx_karis(c: &Cosines, a: f64) -> f64 {
    let r1 = a.sqrt() + 1.0;
    vis_schlick(c.nov, c.nol, r1 * r1 * 0.125)
}

/// sqrt(x^2 (1 - a2) + a2), written x (x - x a2) + a2 as in the GLSL.
fn smith_ggx_root(x: f64, a2: f64) -> f64 {
    (x * (x - x * a2) + a2).sqrt()
}

fn vis_smith_ggx_separable(c: &Cosines, a: f64) -> f64 {
    let a2 = a * a;
    1.0 / ((c.nov + smith_ggx_root(c.nov, a2)) * (c.nol + smith_ggx_root(c.nol, a2)))
}

fn vis_smith_ggx_correlated(c: &Cosines, a: f64) -> f64 {
    let a2 = a * a;
    0.5 / (c.nol * smith_ggx_root(c.nov, a2) + c.nov * smith_ggx_root(c.nol, a2))
}

fn vis_smith_ggx_joint_approx(c: &Cosines, a: f64) -> f64 {
    0.5 / (c.nol * (c.nov * (1.0 - a) + a) + c.nov * (c.nol * (1.0 - a) + a))
}

fn vis_hammon(c: &Cosines, a: f64) -> f64 {
    let (x, y) = (2.0 * c.nol * c.nov, c.nol + c.nov);
    0.5 / (x * (1.0 - a) + y * a)
}

fn vis_smith_beckmann_separable(c: &Cosines, a: f64) -> f64 {
    1.0 / ((1.0 + lambda_beckmann(c.nov, a)) * (1.0 + lambda_beckmann(c.nol, a))) / (4.0 * c.nol * c.nov)
}

fn vis_smith_beckmann_correlated(c: &Cosines, a: f64) -> f64 {
    1.0 / (1.0 + lambda_beckmann(c.nov, a) + lambda_beckmann(c.nol, a)) / (4.0 * c.nol * c.nov)
}

fn vis_smith_beckmann_walter(c: &Cosines, a: f64) -> f64 {
    g1_walter(c.nov, a) * g1_walter(c.nol, a) / (4.0 * c.nol * c.nov)
}

/// c = cos / (a sin) with the sine floored at MIN_COSINE, as in the GLSL.
fn beckmann_c(cos: f64, a: f64) -> f64 {
    cos / (a * (1.0 - cos * cos).max(MIN_COSINE * MIN_COSINE).sqrt())
}

/// The kernels' Smith Lambda of Beckmann: (erf(c) - 1)/2 + exp(-c^2) / (2 c sqrt(pi)), c with its sine floor.
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

/// Schlick's weight (1 - VoH)^5, shared by every Schlick-style term.
pub fn schlick_weight(voh: f64) -> f64 {
    pow5(1.0 - voh)
}

/// F0 + (f90 - F0) Fc, Fc = (1 - VoH)^5: Schlick with a reflectance at grazing.
pub fn f_schlick_f90(f0: f64, f90: f64, voh: f64) -> f64 {
    f0 + (f90 - f0) * schlick_weight(voh)
}

pub fn f_schlick(f0: f64, voh: f64) -> f64 {
    f_schlick_f90(f0, 1.0, voh)
}

fn f_schlick_sg(f0: [f64; 3], voh: f64, _: &Params) -> [f64; 3] {
    f0.map(|f| f + (1.0 - f) * ((-5.55473 * voh - 6.98316) * voh).exp2())
}

fn f_schlick_ue(f0: [f64; 3], voh: f64, _: &Params) -> [f64; 3] {
    let f90 = (50.0 * f0[1]).clamp(0.0, 1.0);
    f0.map(|f| f_schlick_f90(f, f90, voh))
}

fn f_schlick_filament(f0: [f64; 3], voh: f64, _: &Params) -> [f64; 3] {
    let f90 = ((f0[0] + f0[1] + f0[2]) * 50.0 * 0.33).clamp(0.0, 1.0);
    f0.map(|f| f_schlick_f90(f, f90, voh))
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
