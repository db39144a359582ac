//! The kernels' C translation as brdfprof uses it: the SPIR-V to C writer (`brdfprof_spirv_c`, re-exported
//! here) fed with specialised kernels (`prepare`), run on the CPU (`host`, `opencl`, `runner`) and judged against
//! its own f64 evaluation (`judge`, `verify`) before any cost is believed.

pub use brdfprof_spirv_c::*;

pub mod host;
pub mod judge;
pub mod opencl;
pub mod prepare;
pub mod runner;
pub mod verify;
