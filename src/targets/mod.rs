//! Compile-only targets: GPU families whose production compiler brdfprof runs without the GPU, one `Vendor`
//! per `--device` prefix, each in its own file or folder (`radv`: Mesa RADV's ACO in a child process; `nvidia`:
//! NVRTC and ptxas on the kernels' CUDA C++ translation; `intel`: IGC through ocloc on their OpenCL C
//! translation; `adreno`, `mali`, `anv`, `nak`: Mesa's Turnip, PanVK, ANV and NVK on Mesa's noop drm-shims), listed once in
//! `VENDORS`. Two runtimes carry them: `mesa_noop`, the child process every Mesa driver runs in, and
//! `translated`, the one `Vendor` of the translating vendors, each of them a `Translator`. A target is `--device PREFIX:FAMILY` (or `PREFIX:all`, or
//! `PREFIX:a,b`); `devices --targets`, `inspect`, `check`, `sweep --cost-device`, `profile --scene --cost-device` and `compare` reach the vendors
//! only through this module: a vendor is its families, how it compiles every kernel for them (an `inspect`
//! report per family, with its compiler's statistics under `driver/`), its cost model (`cost`), and what its
//! statistics depend on (the gate's fingerprint). Kernels from outside the model set (a scene's kernels) reach
//! the same compilers as `RawKernel`s (`compile_raw_all`).

pub mod adreno;
pub mod anv;
pub mod cost;
pub mod intel;
pub mod mali;
pub mod mesa_noop;
pub mod nak;
pub mod nvidia;
pub mod radv;
pub mod translated;
pub mod trips;

use crate::gpu::Gpu;
use crate::model::Model;
use crate::schema::InspectReport;
use crate::schema::cost::TargetCost;
use crate::shaders::Shaders;
use anyhow::{Result, anyhow, bail};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// One family of a vendor, as the tables and `devices --targets` show it.
#[derive(Clone, Debug, PartialEq)]
pub struct Family {
    /// The name after the prefix (`navi21`, `sm_89`).
    pub name: &'static str,
    pub architecture: &'static str,
    pub products: &'static str,
    /// What else identifies it (`GFX10.3, wave64`; `compute capability 8.9`).
    pub detail: String,
    /// In `PREFIX:all`.
    pub default: bool,
}

/// What a compile-only run compiles.
pub struct Request<'a> {
    pub models: &'a [Model],
    pub lights: u32,
    pub shaders: &'a Shaders,
    pub validate: bool,
    /// Writes each kernel's compiler output under DIR/<vendor>-<family>/ (RADV: DIR/<family>/).
    pub isa_dir: Option<&'a Path>,
    /// The target's IEEE-exact maths instead of the precision freedom a Vulkan driver has (where the vendor
    /// distinguishes them).
    pub precise: bool,
    /// The Vulkan device translations are checked against before their cost is reported (vendors that
    /// compile a translation need one).
    pub verify_on: Option<&'a Gpu>,
    /// Cost per source line (`inspect --lines`): each model's kernel compiled again with line information
    /// where the vendor's compiler gives it (`InspectReport::lines`).
    pub lines: bool,
}

/// A kernel from outside the model set (a scene's kernels, `scene::compile`), ready for every vendor: its
/// SPIR-V specialised and frozen (what RADV compiles), its translation checked against the Vulkan kernel
/// before (what NVIDIA's and Intel's compilers compile), and its interface: storage buffers 0..n of set 0
/// and the push-constant bytes.
pub struct RawKernel {
    /// The row name in the reports ("ggx", "ggx without clear-coat").
    pub label: String,
    /// The model whose kernel it is: a family that cannot compile it (fp16 arithmetic without shaderFloat16)
    /// leaves it out with a note, as it leaves out such a model.
    pub model: Model,
    pub spirv: Vec<u32>,
    pub storage_buffers: u32,
    pub push_bytes: u32,
    /// None when no target compiles a translation (the check would cost a host build for nothing).
    pub translation: Option<CheckedTranslation>,
}

/// A translation that agreed with its Vulkan kernel.
pub struct CheckedTranslation {
    pub translation: crate::translate::Translation,
    /// The row note: the device the translation was checked on and the worst difference.
    pub agreement: String,
}

/// One family's result.
pub struct Run {
    pub target: Target,
    pub report: InspectReport,
    pub isa_files: Vec<PathBuf>,
    /// Something the user should know about how the run went (a child that crashed after its report).
    pub note: Option<String>,
}

/// A vendor's compile-only targets.
pub trait Vendor: Sync {
    /// The `--device` prefix, without the colon.
    fn prefix(&self) -> &'static str;
    /// The GPU vendor ("AMD").
    fn name(&self) -> &'static str;
    /// One line: the vendor and its compiler, how brdfprof runs it.
    fn title(&self) -> &'static str;
    fn families(&self) -> Vec<Family>;
    /// The compiler's name and version, or an error saying how to install it.
    fn status(&self) -> Result<String>;
    /// Whether `compile` needs `Request::verify_on` (it compiles a translation that must run first).
    fn needs_verification(&self) -> bool;
    /// Every kernel (the models' and the memory-only one) compiled for each of `families` (indices into
    /// `families()`), in order.
    fn compile(&self, families: &[usize], request: &Request) -> Result<Vec<Run>>;
    /// `kernels` compiled for each of `families`: one report per family whose rows are the kernels, in order,
    /// with the vendor's cost table (`request` gives the lights per kernel the cost divides by, and the
    /// options; its models are not compiled).
    fn compile_raw(&self, families: &[usize], kernels: &[RawKernel], request: &Request) -> Result<Vec<Run>>;
    /// The cost table of a report whose statistics are this vendor's, None for any other report.
    fn cost(&self, report: &InspectReport) -> Option<TargetCost>;
    /// The family a report of this vendor's compile-only targets was made for.
    fn family_of(&self, report: &InspectReport) -> Option<usize>;
    /// What the report's compiler statistics depend on: the gate compares them only where this is the same.
    fn fingerprint(&self, report: &InspectReport) -> BTreeMap<String, String>;
    /// The vendor as a Mesa driver on a compile-only device in a child process (`mesa_noop`), if it is one.
    fn noop(&self) -> Option<&dyn mesa_noop::NoopDriver> {
        None
    }
}

/// Every vendor: the one list (a new compiler lands here and in its own file or folder).
pub static VENDORS: [&dyn Vendor; 7] =
    [&radv::RADV, &nvidia::NVIDIA, &intel::INTEL, &adreno::ADRENO, &mali::MALI, &anv::ANV, &nak::NAK];

/// Statistics a compiler's listing gave, as the driver statistics of `executable`.
pub fn driver_stats(executable: &str, stats: Vec<brdfprof_isa_cost::Stat>) -> Vec<crate::gpu::DriverStat> {
    let executable = executable.to_string();
    let stat = |s: brdfprof_isa_cost::Stat| crate::gpu::DriverStat {
        executable: executable.clone(),
        name: s.name,
        description: s.description,
        value: s.value,
    };
    stats.into_iter().map(stat).collect()
}

/// Statistics read from a compiler's log, as those of the executable logs stand for (`gpu::LOGGED_EXECUTABLE`).
pub fn logged(stats: Vec<brdfprof_isa_cost::Stat>) -> Vec<crate::gpu::DriverStat> {
    driver_stats(crate::gpu::LOGGED_EXECUTABLE, stats)
}

/// Whether more than one vendor has a family of this name (`sm_86`: `nvidia:` and `nak:`).
pub fn shared_family_name(name: &str) -> bool {
    VENDORS.iter().filter(|v| v.families().iter().any(|f| f.name == name)).count() > 1
}

/// A cost table's column name in cross-device tables (`TargetCost::column_name`), a family name two vendors
/// share named by its target: "nak:sm_86 cycles/eval".
pub fn column_name(cost: &TargetCost) -> String {
    match (&cost.family, &cost.target) {
        (Some(f), Some(t)) if shared_family_name(f) => format!("{t} cycles/eval"),
        _ => cost.column_name(),
    }
}

/// One family of one vendor.
#[derive(Clone, Copy)]
pub struct Target {
    pub vendor: &'static dyn Vendor,
    pub family: usize,
}

impl PartialEq for Target {
    fn eq(&self, other: &Self) -> bool {
        self.vendor.prefix() == other.vendor.prefix() && self.family == other.family
    }
}

impl std::fmt::Debug for Target {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.name())
    }
}

impl Target {
    pub fn info(&self) -> Family {
        self.vendor.families().swap_remove(self.family)
    }

    /// `radv:navi21`.
    pub fn name(&self) -> String {
        format!("{}:{}", self.vendor.prefix(), self.info().name)
    }

    /// `radv-navi21`: the name in file names (`inspect`'s default outputs).
    pub fn slug(&self) -> String {
        self.name().replace(':', "-")
    }
}

/// `all`, after a prefix: the vendor's default set.
pub const ALL: &str = "all";

fn vendor_of(device: &str) -> Option<(&'static dyn Vendor, &str)> {
    let (prefix, rest) = device.trim().split_once(':')?;
    VENDORS.iter().copied().find(|v| v.prefix().eq_ignore_ascii_case(prefix.trim())).map(|v| (v, rest))
}

/// The vendor of a `--device` target ("nvidia:sm_75" -> "NVIDIA"; "nak:sm_86" -> "NVIDIA").
pub fn vendor_name(target: &str) -> Option<&'static str> {
    vendor_of(target).map(|(v, _)| v.name())
}

/// Whether a `--device` value names compile-only targets.
pub fn is_compile_only(device: &str) -> bool {
    vendor_of(device).is_some()
}

/// Every prefix, for messages: "radv:, nvidia:".
pub fn prefixes() -> String {
    VENDORS.iter().map(|v| format!("{}:", v.prefix())).collect::<Vec<_>>().join(", ")
}

/// The targets a `--device PREFIX:FAMILY[,FAMILY...]` (or `PREFIX:all`) names; None for any other device.
pub fn parse(device: &str) -> Result<Option<Vec<Target>>> {
    let Some((vendor, rest)) = vendor_of(device) else { return Ok(None) };
    let families = vendor.families();
    let known = || {
        format!(
            "{} (or `{}:{ALL}` for {})",
            families.iter().map(|f| f.name).collect::<Vec<_>>().join(", "),
            vendor.prefix(),
            families.iter().filter(|f| f.default).map(|f| f.name).collect::<Vec<_>>().join(", ")
        )
    };
    if rest.trim().is_empty() {
        bail!("`{device}`: give a family after `{}:`; known: {}", vendor.prefix(), known());
    }
    let mut out: Vec<Target> = Vec::new();
    for name in rest.split(',').map(str::trim) {
        let found: Vec<usize> = if name.eq_ignore_ascii_case(ALL) {
            (0..families.len()).filter(|&k| families[k].default).collect()
        } else {
            vec![
                families
                    .iter()
                    .position(|f| f.name.eq_ignore_ascii_case(name))
                    .ok_or_else(|| anyhow!("unknown {} family `{name}`; known: {}", vendor.name(), known()))?,
            ]
        };
        for family in found {
            let t = Target { vendor, family };
            if !out.contains(&t) {
                out.push(t);
            }
        }
    }
    Ok(Some(out))
}

/// `compile(vendor, its families)` for every vendor among `targets`, each vendor's families at once; results in
/// `targets` order.
fn vendor_by_vendor(
    targets: &[Target],
    mut compile: impl FnMut(&dyn Vendor, &[usize]) -> Result<Vec<Run>>,
) -> Result<Vec<Run>> {
    let mut runs: Vec<Option<Run>> = targets.iter().map(|_| None).collect();
    for vendor in VENDORS {
        let mine: Vec<usize> = (0..targets.len()).filter(|&k| targets[k].vendor.prefix() == vendor.prefix()).collect();
        if mine.is_empty() {
            continue;
        }
        let families: Vec<usize> = mine.iter().map(|&k| targets[k].family).collect();
        for (k, run) in mine.into_iter().zip(compile(vendor, &families)?) {
            runs[k] = Some(run);
        }
    }
    Ok(runs.into_iter().map(|r| r.expect("every target compiled")).collect())
}

/// Compiles the models' kernels for every target; results in `targets` order, each report's driver note with
/// its harness share (`harness_note`). The vendors that check a translation on the Vulkan device (NVIDIA's,
/// Intel's: host builds, then their compilers) run beside the others (Mesa's compilers in their children), so
/// that a cold run keeps both of a 2-core machine's cores busy; each side goes vendor by vendor.
pub fn compile_all(targets: &[Target], request: &Request) -> Result<Vec<Run>> {
    let at = std::sync::Arc::new(std::sync::Mutex::new(Vec::<String>::new()));
    let said = std::sync::Arc::clone(&at);
    let _heartbeat = crate::messages::Heartbeat::start(move || {
        format!("compiling for the compile-only targets: {}", said.lock().unwrap_or_else(|e| e.into_inner()).join(", "))
    });
    let trips = trips::Trips::of(request.models, request.shaders);
    let models: Vec<Model> = request.models.iter().cloned().chain(trips::Trips::twins(&trips)).collect();
    let request = &Request { models: &models, ..*request };
    let total = targets.len();
    let done = std::sync::atomic::AtomicUsize::new(0);
    let compile = |vendor: &dyn Vendor, families: &[usize], request: &Request| -> Result<Vec<Run>> {
        let before = done.fetch_add(families.len(), std::sync::atomic::Ordering::Relaxed);
        let now = format!("{} ({} families; {before} of {total} targets done)", vendor.prefix(), families.len());
        at.lock().unwrap_or_else(|e| e.into_inner()).push(now.clone());
        if vendor.needs_verification() && request.verify_on.is_none() {
            bail!(
                "{}: its costs are of a translation that must first run against a Vulkan device, and none was opened",
                vendor.prefix()
            );
        }
        let out = vendor.compile(families, request);
        at.lock().unwrap_or_else(|e| e.into_inner()).retain(|a| *a != now);
        out
    };
    let checked: Vec<usize> = (0..targets.len()).filter(|&k| targets[k].vendor.needs_verification()).collect();
    let others: Vec<usize> = (0..targets.len()).filter(|k| !checked.contains(k)).collect();
    let pick = |ks: &[usize]| ks.iter().map(|&k| targets[k]).collect::<Vec<Target>>();
    let (checked_targets, other_targets) = (pick(&checked), pick(&others));
    // The Vulkan device stays on this thread; the other side's request has none.
    let Request { models, lights, shaders, validate, isa_dir, precise, lines, .. } = *request;
    let (mine, theirs) = std::thread::scope(|scope| {
        let other_side = scope.spawn(|| {
            let request = Request { models, lights, shaders, validate, isa_dir, precise, verify_on: None, lines };
            vendor_by_vendor(&other_targets, |vendor, families| compile(vendor, families, &request))
        });
        let mine = vendor_by_vendor(&checked_targets, |vendor, families| compile(vendor, families, request));
        (mine, other_side.join())
    });
    let theirs = theirs.unwrap_or_else(|panic| std::panic::resume_unwind(panic));
    let mut runs: Vec<Option<Run>> = targets.iter().map(|_| None).collect();
    for (k, run) in checked.into_iter().zip(mine?).chain(others.into_iter().zip(theirs?)) {
        runs[k] = Some(run);
    }
    let mut runs: Vec<Run> = runs.into_iter().map(|r| r.expect("every target compiled")).collect();
    for run in &mut runs {
        let attached = trips::Trips::attach(&trips, run);
        let loops = trips::Trips::note(&trips, &attached);
        let harness = run.report.cost.as_ref().and_then(harness_note);
        for note in harness.iter().chain(run.report.cost.as_ref().and(loops.as_ref())) {
            let driver = run.report.section_notes.entry("driver/".into()).or_default();
            *driver = if driver.is_empty() { note.clone() } else { format!("{driver}\n\n{note}") };
        }
        if let Some(note) = harness {
            run.report.section_notes.insert(HARNESS_NOTE.into(), note);
        }
    }
    Ok(runs)
}

/// The report's section note that holds `harness_note`.
pub const HARNESS_NOTE: &str = "harness";

/// The memory-only kernel's share of each kernel's cycles per evaluation on one target: the harness every
/// kernel carries (the G-buffer and light loads, the R11G11B10F store), whose cost differs between targets.
pub fn harness_note(cost: &TargetCost) -> Option<String> {
    let base = cost.row(crate::model::BASELINE_LABEL)?.cycles_per_eval;
    let shares: Vec<String> = cost
        .rows
        .iter()
        .filter(|r| r.model != crate::model::BASELINE_LABEL && r.cycles_per_eval > 0.0)
        .map(|r| format!("{} {:.0}%", r.model, 100.0 * base / r.cycles_per_eval))
        .collect();
    (!shares.is_empty()).then(|| format!("Harness share on {} (the memory-only kernel's cycles/eval as a share of each kernel's: the G-buffer and light loads and the R11G11B10F store every kernel carries): {}.", cost.label(), shares.join(", ")))
}

/// `compile_all` for kernels outside the model set.
pub fn compile_raw_all(targets: &[Target], kernels: &[RawKernel], request: &Request) -> Result<Vec<Run>> {
    vendor_by_vendor(targets, |vendor, families| vendor.compile_raw(families, kernels, request))
}

/// Whether the target's compiler names each instruction's source line (`Request::lines`): the translating
/// vendors (NVRTC `-lineinfo`, IGC `-gline-tables-only`); ACO in Mesa 22.3 carries no source lines, nor do ir3, Bifrost or brw
/// there.
pub fn names_lines(target: &Target) -> bool {
    target.vendor.needs_verification()
}

/// The compile-only target a report was made for, if any.
pub fn of_report(report: &InspectReport) -> Option<Target> {
    VENDORS.iter().find_map(|v| v.family_of(report).map(|family| Target { vendor: *v, family }))
}

/// The cost table of a report: its vendor's model applied to its statistics (a real RADV GPU's too).
pub fn cost_of(report: &InspectReport) -> Option<TargetCost> {
    VENDORS.iter().find_map(|v| v.cost(report))
}

/// A lower-case file-name-safe form of a device name ("llvmpipe (LLVM 15.0.6, 256 bits)" -> "llvmpipe").
pub fn device_slug(device: &crate::gpu::DeviceInfo) -> String {
    // RADV's compile-only devices are all "Null hardware (RADV <FAMILY>)": the family tells them apart.
    if let Some(t) = radv::families::family_of_device(&device.name) {
        return format!("radv-{}", t.family);
    }
    crate::export::name_slug(&device.name)
}

/// File-name form of a kernel label.
pub fn file_slug(label: &str) -> String {
    let s: String = label
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() || c == '.' { c.to_ascii_lowercase() } else { '-' })
        .collect();
    s.trim_matches('-').to_string()
}
