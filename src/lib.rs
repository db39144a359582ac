//! brdfprof: evaluates and profiles specular BRDFs in Vulkan compute kernels.
//!
//! Data flows CLI (`main.rs`, `cli/`) -> models (`model`: a `brdf` spec) -> kernels (`kernels`, `shaders`, on
//! `gpu`) -> the measurement protocol (`profile`) -> reports (`report`).

pub mod accuracy;
pub mod brdf;
pub mod cache;
pub mod chart;
pub mod check;
pub mod cleanup;
pub mod compare;
pub mod compile_limit;
pub mod devices;
pub mod diff;
pub mod gpu;
pub mod host;
pub mod page;
pub mod report_page;
pub mod inspect;
pub mod io;
pub mod kernels;
pub mod messages;
pub mod model;
pub mod profile;
pub mod results;
pub mod shaders;
pub mod spirv;
pub mod stability;
pub mod stats;
pub mod sweep;
pub mod sweep_cost;
pub mod targets;
pub mod translate;
pub mod scene;
pub mod util;
