//! The guards every kernel applies, named once. The same constants stand at the top of `glsl/brdf.glsl`;
//! README "Guards" says why each exists and where it comes from.

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

/// Clamp of a visible cosine into [MIN_COSINE, 1].
pub fn guard_cosine(x: f64) -> f64 {
    x.clamp(MIN_COSINE, 1.0)
}

/// Unit vector scaled by its largest component first; zero when that component is below MIN_VECTOR.
pub fn safe_normalize(v: [f64; 3]) -> [f64; 3] {
    let m = v[0].abs().max(v[1].abs()).max(v[2].abs());
    if !(m >= MIN_VECTOR) {
        return [0.0; 3];
    }
    let u = v.map(|x| x / m);
    let len = (u[0] * u[0] + u[1] * u[1] + u[2] * u[2]).sqrt();
    u.map(|x| x / len)
}

pub fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

pub fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

pub fn add(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
