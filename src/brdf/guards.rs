//! The guards every kernel applies, named once. `brdf::glsl_gen` writes the same constants into the GLSL
//! (glsl/generated/brdf_table.glsl); docs/limits.md ("Guards and evaluation forms") says why each exists and
//! where it comes from.

use glam::DVec3;

/// Perceptual roughness floor in fp32 kernels: Filament's MIN_PERCEPTUAL_ROUGHNESS (highp).
/// Below it a2 = r^4 makes D_GGX's `NoH^2 (a2-1) + 1` cancel to 0 at the peak in fp32.
pub const MIN_ROUGHNESS_F32: f64 = 0.045;
/// Perceptual roughness floor in fp16 kernels: Filament's mediump value, so that a2 stays a normal fp16.
pub const MIN_ROUGHNESS_F16: f64 = 0.089;
/// Floor of NoV, NoL, NoH and VoH once a light is visible: Filament's MIN_N_DOT_V. Keeps every Vis term
/// finite at grazing angles, where several are 0/0 at exactly 0.
pub const MIN_COSINE: f64 = 1e-4;
/// A vector whose largest component is below FLT_MIN counts as zero (GPUs may flush denormals).
pub const MIN_VECTOR: f64 = f32::MIN_POSITIVE as f64;
/// |a2 - 1| below which the GLSL GTR normaliser uses its series instead of the 0/0 closed form.
pub const GTR_SERIES_BAND: f64 = 0.05;
/// Dielectric F0 cap: the IOR (1 + sqrt F0)/(1 - sqrt F0) is infinite at F0 = 1.
pub const F0_MAX: f64 = 0.9999;

/// One guard as the GLSL declares it: name, value, and the comment that says why.
pub struct Guard {
    pub name: &'static str,
    pub value: f64,
    pub why: &'static str,
}

/// The guards the GLSL declares (MIN_ROUGHNESS, which depends on the precision, is written apart).
pub const GLSL_GUARDS: [Guard; 4] = [
    Guard { name: "MIN_COSINE", value: MIN_COSINE, why: "Filament MIN_N_DOT_V; NoV, NoL, NoH, VoH floor once a light is visible" },
    Guard { name: "MIN_VECTOR", value: MIN_VECTOR, why: "FLT_MIN: a vector whose largest component is below it counts as zero" },
    Guard { name: "GTR_SERIES_BAND", value: GTR_SERIES_BAND, why: "|a2-1| below which the GTR normaliser uses its series (0/0 at a2 = 1)" },
    Guard { name: "F0_MAX", value: F0_MAX, why: "dielectric F0 cap: the IOR (1+sqrt F0)/(1-sqrt F0) is infinite at 1" },
];

/// Clamp of a visible cosine into [MIN_COSINE, 1].
pub fn guard_cosine(x: f64) -> f64 {
    x.clamp(MIN_COSINE, 1.0)
}

/// Unit vector scaled by its largest component first; zero when that component is below MIN_VECTOR.
pub fn safe_normalize(v: DVec3) -> DVec3 {
    let m = v.abs().max_element();
    if !(m >= MIN_VECTOR) {
        return DVec3::ZERO;
    }
    let u = v / m;
    u / u.length()
}

/// `safe_normalize` of an f32 triple, in f64.
pub fn unit(v: [f32; 3]) -> DVec3 {
    safe_normalize(DVec3::from(v.map(f64::from)))
}
