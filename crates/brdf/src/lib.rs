//! BRDF definitions: the term library with its f64 twins, the guards, model specs and presets.

pub mod exact;
pub mod f0;
pub mod glsl_gen;
pub mod guards;
pub mod samples;
pub mod spec;
pub mod terms;

pub use spec::{ModelSpec, PRESETS, Precision, THESIS_MODELS};
pub use terms::{Cosines, D, F, Metal, Vis};

/// One BRDF query as the kernels receive it: world-space vectors (normalised by the kernel), perceptual
/// roughness and an RGB F0, all in f32.
#[derive(Clone, Copy, Debug, PartialEq, Default, serde::Serialize, serde::Deserialize)]
pub struct Sample {
    pub n: [f32; 3],
    pub v: [f32; 3],
    pub l: [f32; 3],
    pub roughness: f32,
    pub f0: [f32; 3],
}
