//! Scenes: every scene.glsl term and the scene kernel against their f64 twins, effects compiled out of the
//! SPIR-V, energy compensation, image G-buffers, and the scene CLI.

#[path = "../common/mod.rs"]
mod common;

mod cli;
mod energy;
mod gpu;
mod images;
mod spirv;
mod terms;
