//! The term library and the kernels built on it, on the GPU against their f64 twins and exact references;
//! the stability suite and the sweep; and the sources (spv/ and the generated GLSL) against what builds them.
//!
//! What goes here: a test that calls the library (`brdfprof::kernels`, `model`, `accuracy`, ...) on the
//! default device and compares with an f64 twin, an exact reference or an independent fact; `.brdf` models as
//! library `Model`s too (`brdf_files`). Not here: running the binary (tests/cli), scenes (tests/scenes),
//! timing (tests/timed).

#[path = "../common/mod.rs"]
mod common;

mod albedo;
mod brdf_files;
mod chunking;
mod d_normalisation;
mod exact_reference;
mod fn_length;
mod layering;
mod loop_passes;
mod models;
mod shading;
mod sources;
mod spirv_counts;
mod stability;
mod sweep;
mod terms;
mod translation;
