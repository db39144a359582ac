//! Compile-only targets: GPU families whose production compiler brdfprof runs without the GPU.

pub mod nvidia;
pub mod nvrtc;
