//! How a kernel's cost is measured on a device, for every command that times kernels (`profile`, `check`'s
//! timing, `inspect`'s callgrind counts, a scene's profile, the translation's verifier): the synthetic
//! G-buffer and lights (`gbuffer`), the workload of one model's kernel over them (`workload`), and the
//! protocol (`protocol`): warm-up, interleaved rounds, timestamps and when to stop.

pub mod gbuffer;
pub mod protocol;
pub mod workload;
