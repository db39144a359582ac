//! The commands that time kernels or count their instructions under callgrind: profile, inspect and the check
//! gates (lavapipe's, the Mesa drivers' (ACO, ir3, Bifrost, brw), NVIDIA's and Intel's). They run one at a time (`serial`), so that no timing shares the two
//! cores with another measurement.
//!
//! What goes here: a test whose figure is a time, a callgrind count or a gate verdict on them, or that would
//! disturb such a figure by running beside it; each takes `serial()` first. Everything else goes to tests/cli,
//! tests/kernels or tests/scenes, which run their tests in parallel.

#[path = "../common/mod.rs"]
mod common;

mod check_gate;
mod inspect;
mod mesa_gate;
mod profile;
mod translated_gate;

/// Held by every test of this binary while it runs.
pub fn serial() -> std::sync::MutexGuard<'static, ()> {
    static SERIAL: std::sync::Mutex<()> = std::sync::Mutex::new(());
    SERIAL.lock().unwrap_or_else(|e| e.into_inner())
}
