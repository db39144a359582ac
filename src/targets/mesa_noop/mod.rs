//! "A Mesa Vulkan driver on a device that only compiles, in a child process", written once for every driver
//! that runs so: RADV on its null winsys (`RADV_FORCE_FAMILY`), and Turnip (Adreno), PanVK (Mali) and ANV
//! (Intel) on Mesa's noop drm-shims (`LD_PRELOAD` of the shim, `VK_ICD_FILENAMES` naming the driver that
//! `make mesa` built, the GPU id in the driver's variable). Each driver is one file (`radv.rs`, `adreno.rs`,
//! `mali.rs`, `anv.rs`) implementing `NoopDriver`: its families, the environment that selects one, and how its
//! cost is read; `parent.rs` runs the child, reads its report and contains its crashes; `child.rs` is the child;
//! `builds.rs` finds the Mesa builds `make mesa` made; this file holds what both sides share: the request and
//! reply, the test hooks and what a report of a child says.
//!
//! brdfprof runs itself as a child (`brdfprof __noop-child REQUEST`) with the driver's environment, so that the
//! Vulkan loader of that process, and only of it, sees the compile-only device; neither the user's environment
//! nor the parent's devices change. The child marks every device it opens compile-only (nothing is submitted,
//! timed or read back: a noop shim executes nothing), runs `inspect`'s analyses on it (no callgrind), optionally
//! writes the driver's internal representations of every kernel, and prints its report as one JSON line. The
//! child dies with brdfprof (cleanup::command).
//!
//! A compile-only device has no queue that executes work: `Gpu` never waits on it when nothing was submitted
//! (Mesa 22.3 RADV's vkDeviceWaitIdle calls through a null pointer there), and a child that still crashes after
//! printing its complete report is accepted with a note, so the user gets the report and exit 0.

pub mod builds;
pub mod cache;
pub mod child;
pub mod parent;
pub mod shim;

use super::Vendor;
use crate::gpu::{CompilerLog, RepresentationStats};
use crate::schema::InspectReport;
use anyhow::{Result, anyhow};
use serde::{Deserialize, Serialize};
use std::path::PathBuf;

/// A Mesa driver that compiles for a family of GPUs this machine does not have, in a child process.
pub trait NoopDriver: Vendor {
    /// The compiler's name in messages ("ACO", "ir3").
    fn compiler(&self) -> &'static str;
    /// The environment that makes the child's Vulkan loader offer `family`'s compile-only device (every value
    /// set, none removed); an error, naming what to run, where the driver is not built.
    fn environment(&self, family: usize) -> Result<Vec<(String, String)>>;
    /// The device the child opens (a name substring), None for the only one its environment offers.
    fn device(&self, _family: usize) -> Option<String> {
        None
    }
    /// The folder of a family's listings under `--isa DIR` (`Target::slug`, `adreno-a660`).
    fn isa_folder(&self, family: usize) -> String {
        format!("{}-{}", self.prefix(), self.families()[family].name)
    }
    /// What to do when the child finds no such device.
    fn install_hint(&self) -> String;
    /// A stderr line of the child that is the driver's or its shim's chatter, not a message for the user
    /// (beside the non-conformance banner every Mesa driver may print).
    fn is_noise(&self, _line: &str) -> bool {
        false
    }
    /// Why the Khronos validation layer cannot judge this driver's compilations, where it cannot (the child
    /// then runs without it and the report says so).
    fn without_validation(&self, _family: usize) -> Option<&'static str> {
        None
    }
    /// Statistics the compiler prints on stderr (drivers without VK_KHR_pipeline_executable_properties).
    fn compiler_log(&self) -> Option<CompilerLog> {
        None
    }
    /// Statistics read from one of the driver's internal representations (every pipeline captures them).
    fn representation_stats(&self) -> Option<RepresentationStats> {
        None
    }
}

/// The hidden subcommand the child runs.
pub const CHILD_COMMAND: &str = "__noop-child";

/// Set in the child's environment to the target it compiles for (`adreno:a660`): the child refuses to run
/// without it, so that a stray `__noop-child` never reads a user's devices as a target's.
pub const TARGET_VAR: &str = "BRDFPROF_NOOP_TARGET";

/// What the parent asks the child (one JSON argument).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct NoopRequest {
    /// The driver's `--device` prefix and the family's name.
    pub driver: String,
    pub family: String,
    /// Models by their spec text (`Model::name`, label included, which `Model::parse` reads back); the memory-only
    /// kernel is analysed after them.
    pub models: Vec<String>,
    pub lights: u32,
    pub validate: bool,
    pub glsl: Option<PathBuf>,
    /// Write each kernel's internal representations under DIR/<family>/.
    pub isa_dir: Option<PathBuf>,
    /// Kernels from outside the model set (`RawKernel`), compiled instead of the models when given.
    #[serde(default)]
    pub raw: Vec<RawSpirv>,
}

/// A raw kernel for the child: its frozen SPIR-V in a file (a scene kernel's words are more than one
/// command-line argument may carry) and its interface.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct RawSpirv {
    pub label: String,
    /// The model's spec text (`Model::name`), to check the family can compile it.
    pub model: String,
    pub path: PathBuf,
    pub storage_buffers: u32,
    pub push_bytes: u32,
}

/// What the child prints on its last stdout line.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct NoopReply {
    /// `adreno:a660`.
    pub target: String,
    pub report: InspectReport,
    /// Files written under the ISA directory.
    pub isa_files: Vec<PathBuf>,
}

/// The driver of a `--device` prefix.
pub(super) fn driver_of(prefix: &str) -> Result<&'static dyn NoopDriver> {
    super::VENDORS
        .iter()
        .find_map(|v| v.noop().filter(|d| d.prefix() == prefix))
        .ok_or_else(|| anyhow!("`{prefix}` is not a driver brdfprof runs on a compile-only device"))
}

/// Adds a sentence to the driver section's notes.
pub(super) fn add_driver_note(report: &mut InspectReport, note: String) {
    let joined = report.section_notes.get("driver/").map_or(note.clone(), |n| format!("{n}; {note}"));
    report.section_notes.insert("driver/".into(), joined);
}

/// Set in a child's environment, it dies of SIGSEGV after printing its report, as Mesa 22.3's teardown of
/// RADV's null device did (vkDeviceWaitIdle through a null pointer): the test that the parent contains such a crash.
pub const CRASH_AFTER_REPLY: &str = "BRDFPROF_TEST_NOOP_CHILD_CRASH";

/// A test hook's variable: read only in a build with the `test-hooks` feature (the tests'), inert otherwise.
pub(super) fn test_hook(name: &str) -> Option<std::ffi::OsString> {
    if cfg!(feature = "test-hooks") { std::env::var_os(name) } else { None }
}

/// Set in a child's environment to a model's label, a child whose request holds that model dies of SIGSEGV
/// before it compiles anything, as a driver that crashes on one model's kernel would: the test that the other
/// models are still costed.
pub const CRASH_ON_MODEL: &str = "BRDFPROF_TEST_NOOP_CHILD_CRASH_ON";

/// Where a test makes the parent wait before it starts its children: set to a path P, the parent writes
/// P.waiting and waits (at most 120 s) until P exists, so that a test can edit a model file between the
/// parent's key and the child's compile.
pub const HOLD_BEFORE_CHILDREN: &str = "BRDFPROF_TEST_NOOP_HOLD";

/// The family a report of `driver`'s children was made for (its provenance names the target).
pub fn family_of(driver: &dyn NoopDriver, report: &InspectReport) -> Option<usize> {
    let (prefix, family) = report.provenance["target"].as_str()?.split_once(':')?;
    (prefix == driver.prefix()).then(|| driver.families().iter().position(|f| f.name == family)).flatten()
}

/// What a compile-only device's statistics depend on: the device (the family) and the Mesa that compiled,
/// not the host.
pub fn fingerprint(report: &InspectReport) -> std::collections::BTreeMap<String, String> {
    let device = report.provenance["device"]["name"].as_str().unwrap_or("?");
    [("device".to_string(), device.to_string()), ("mesa".to_string(), driver_version(report))].into()
}

/// The Mesa version of a compile-only device's report: the provenance's, else the driver's info or version
/// (PanVK, a Vulkan 1.0 driver, states only its driverVersion).
pub fn driver_version(report: &InspectReport) -> String {
    let p = &report.provenance;
    let nonempty = |v: &serde_json::Value| v.as_str().filter(|s| !s.is_empty()).map(str::to_string);
    nonempty(&p["mesa_version"])
        .or_else(|| nonempty(&p["device"]["driver_info"]))
        .or_else(|| nonempty(&p["device"]["driver_version"]))
        .unwrap_or_else(|| "?".into())
}
