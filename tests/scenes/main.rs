//! Scenes: every scene.glsl term and the scene kernel against their f64 twins, effects compiled out of the
//! SPIR-V, energy compensation, image G-buffers, and the scene commands (`scene`, `render`, `profile --scene`)
//! end to end, scene names included.
//!
//! What goes here: everything about scenes, through the library or the binary, short of a timing figure (a
//! `profile --scene` run here checks plumbing with small G-buffers and short budgets). Not here: scene-size
//! refusals that belong to the limits table (tests/cli/limits.rs), timed gates (tests/timed).

#[path = "../common/mod.rs"]
mod common;

mod cli;
mod energy;
mod gpu;
mod images;
mod names;
mod spirv;
mod terms;
