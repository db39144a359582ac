//! Scenes (`brdfprof profile --scene`, `brdfprof render`, `brdfprof scene`): a G-buffer (procedural or from
//! image files), a camera, lights and materials with effects, compiled into one kernel per model present with
//! only the light types and effects the scene uses (`plan`), run on the device (`run`), timed effect by effect
//! (`profile`) and drawn (`render`).

pub mod effects;
pub mod format;
pub mod gbuffer;
pub mod plan;
pub mod run;
pub mod spirv;
pub mod terms;

pub use format::{Scene, EXPLAIN};
