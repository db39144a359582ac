//! brdfprof: evaluates and profiles specular BRDFs in Vulkan compute kernels.
//!
//! Data flows CLI (`main.rs`, `cli/`) -> models (`model`: a `brdf` spec) -> kernels (`kernels`, `shaders`, on
//! `gpu`) -> the measurement protocol (`measure`) and the commands (`profile`, ...) -> reports (`report`).

pub use brdfprof_brdf as brdf;
pub use brdfprof_files::cache;
pub use brdfprof_process::{cleanup, launch, messages, tools};
pub use brdfprof_vulkan as gpu;

pub mod accuracy;
pub mod check;
pub mod compare;
pub mod diff;
pub mod export;
pub mod host_cpu;
pub mod inspect;
pub mod io;
pub mod kernel_stats;
pub mod kernels;
pub mod measure;
pub mod model;
pub mod profile;
pub mod report;
pub mod scene;
pub mod schema;
pub mod shaders;
pub mod spirv;
pub mod stability;
pub mod stats;
pub mod sweep;
pub mod targets;
pub mod translate;
