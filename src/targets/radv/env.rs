//! The user's environment cannot crash brdfprof. Mesa's RADV reads `RADV_FORCE_FAMILY` when the Vulkan
//! loader enumerates devices and aborts the process (`radv: Unknown family`, SIGABRT) for a value it does not
//! know, an empty one included. Before any Vulkan call, a value that is not one of brdfprof's compile-only
//! families (`families::FAMILIES`, which Mesa accepts) is tried in a child process (`PROBE_COMMAND`): a family
//! Mesa knows but brdfprof does not list (`hawaii`) is kept, a value that kills the child is removed from this
//! process' environment (and so from its children's) with a warning. The other Mesa variables brdfprof sets
//! for its children (`MESA_SHADER_CACHE_DISABLE`, `LP_NUM_THREADS`) are read by Mesa as numbers or booleans
//! with defaults, and any value of them runs (`tests/cli/devices.rs` tries garbage, empty, negative and huge
//! values).

use super::families::{FAMILIES, FORCE_FAMILY_VAR};
use anyhow::{Context, Result};

/// The hidden subcommand of the probe: enumerate the Vulkan devices and exit.
pub const PROBE_COMMAND: &str = "__probe-vulkan";

/// Removes a `RADV_FORCE_FAMILY` that would abort the process (see the module's comment). Call it before
/// anything loads Vulkan, on the main thread.
pub fn sanitise() -> Result<()> {
    let Some(value) = std::env::var_os(FORCE_FAMILY_VAR) else { return Ok(()) };
    let text = value.to_string_lossy().into_owned();
    // Mesa compares with strcasecmp, without trimming.
    if FAMILIES.iter().any(|t| t.family.eq_ignore_ascii_case(&text)) || (!text.is_empty() && !aborts(&text)?) {
        return Ok(());
    }
    crate::messages::warning(format!(
        "{FORCE_FAMILY_VAR}=`{text}` is not a GPU family Mesa's RADV knows (RADV aborts any process that loads it with this value): ignored for this run. Unset it, or use --device radv:FAMILY (see `brdfprof devices --targets`)"
    ));
    // SAFETY: called from `main` before any thread but the signal handler's (which reads no environment
    // variable) exists and before the Vulkan loader, which reads it, is loaded.
    unsafe { std::env::remove_var(FORCE_FAMILY_VAR) };
    Ok(())
}

/// Whether a child enumerating Vulkan devices with `RADV_FORCE_FAMILY=value` dies of a signal (an exit
/// status, a failure without RADV, does not count).
fn aborts(value: &str) -> Result<bool> {
    let mut cmd = crate::cleanup::self_command(PROBE_COMMAND)?;
    cmd.env(FORCE_FAMILY_VAR, value);
    let out = crate::launch::output_quick(&mut cmd, "brdfprof's Vulkan probe")
        .context("cannot run brdfprof's Vulkan probe")?;
    Ok(out.status.code().is_none())
}

/// The probe: enumerates the devices (where RADV would abort) and exits 0.
pub fn probe_main() -> Result<()> {
    crate::gpu::list_devices().map(|_| ())
}
