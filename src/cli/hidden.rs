//! The hidden commands: the child processes brdfprof starts of itself (callgrind, Mesa's noop drivers, a
//! translated kernel's runner, the Vulkan probe) and the GLSL generator `make spv` runs.

use anyhow::{Context, Result};
use std::path::Path;
use std::process::ExitCode;

/// `__callgrind-child REQUEST`: each kernel measured under valgrind's callgrind (`inspect::callgrind`).
pub fn callgrind_child(request: &str) -> Result<ExitCode> {
    brdfprof::inspect::callgrind::child_main(request).map(|_| ExitCode::SUCCESS)
}

/// `__noop-child REQUEST`: every kernel compiled by a Mesa driver on its noop drm-shim (`targets::mesa_noop`).
pub fn noop_child(request: &str) -> Result<ExitCode> {
    brdfprof::targets::mesa_noop::child_main(request).map(|_| ExitCode::SUCCESS)
}

/// `__run-translation DIR`: a translated kernel run (g++ build or PoCL) outside brdfprof's process
/// (`translate::runner`).
pub fn run_translation(dir: &str) -> Result<ExitCode> {
    brdfprof::translate::runner::child_main(dir).map(|_| ExitCode::SUCCESS)
}

/// `__probe-vulkan`: the devices enumerated, where RADV might abort the process (`targets::radv::env`).
pub fn probe_vulkan() -> Result<ExitCode> {
    brdfprof::targets::radv::env::probe_main().map(|_| ExitCode::SUCCESS)
}

/// Writes glsl/generated/ (`make spv`).
pub fn generate_glsl(dir: &Path) -> Result<ExitCode> {
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    for (name, text) in brdfprof::kernels::generated_glsl() {
        let path = dir.join(name);
        brdfprof::io::write_output(&path, text.as_bytes())?;
        outln!("{}", path.display());
    }
    Ok(ExitCode::SUCCESS)
}
