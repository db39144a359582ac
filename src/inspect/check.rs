//! `brdfprof check`: a shader-db-style comparison of this build's counts and timings with a saved baseline,
//! and a regression gate that a noisy CI machine can trust.
//!
//! - Deterministic counts (SPIR-V, naga, driver, callgrind) regress when they grow by more than a threshold
//!   (default 1%, `--threshold KEY=FRACTION` per statistic or per group).
//! - Timings (per-round cost ratios to a reference measured in the same rounds, see `timing`) regress only
//!   when the change is significant (Mann-Whitney U, alpha 0.05, at least 9 rounds on each side) and larger
//!   than a noise threshold (default 5%).
//! - SPIR-V and naga counts depend only on the shaders and the tools, so they are always compared. Driver
//!   statistics, callgrind counts and timings depend on the machine: each group is compared only when the
//!   environment it depends on (its fingerprint) is the same as the baseline's, or with `--force`;
//!   otherwise it is reported as "not comparable" with the reason and cannot fail the check.

use super::callgrind::{self, CallgrindOptions};
use super::glsl::KernelSet;
use super::timing::{self, TimingOptions, TimingRun};
use super::{format_value, InspectOptions, InspectReport};
use crate::brdf::{spec, ModelSpec};
use crate::gpu::Gpu;
use crate::report::{self, Table};
use crate::stats;
use anyhow::{anyhow, bail, Context, Result};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The `format` field of a baseline file.
pub const FORMAT: &str = "brdfprof-check-baseline/1";
/// Significance level of the timing test.
pub const ALPHA: f64 = 0.05;
/// Fewest per-round ratios on each side for a timing verdict.
pub const MIN_TIMING_ROUNDS: usize = 9;
pub const DEFAULT_COUNT_THRESHOLD: f64 = 0.01;
pub const DEFAULT_TIMING_THRESHOLD: f64 = 0.05;
/// Statistic groups (the part of a key before '/').
pub const GROUPS: [&str; 6] = ["spirv", "spirv-O", "naga", "driver", "callgrind", "timing"];
/// The timing statistic of each model.
pub const TIMING_KEY: &str = "timing/cost-ratio";
/// Driver statistics that cost more when they grow (the aliases); other driver statistics are reported only.
const GATED_DRIVER_KEYS: [&str; 8] =
    ["driver/registers", "driver/scalar-registers", "driver/instructions", "driver/code-bytes", "driver/spills", "driver/fills", "driver/scratch-bytes", "driver/branches"];

/// The fingerprint key only a successful callgrind run can fill in (the CPU features valgrind shows the JIT).
const JIT_FEATURES: &str = "jit-cpu-features";

/// A saved run: every count, the timing ratios and the environment they were measured in.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Baseline {
    pub format: String,
    pub inspect: InspectReport,
    pub timing: Option<TimingRun>,
    /// Group -> what its figures depend on (key -> value); compared before the group's figures are.
    pub environment: BTreeMap<String, BTreeMap<String, String>>,
}

/// The group of a statistic key.
pub fn group_of(key: &str) -> &str {
    key.split('/').next().unwrap_or(key)
}

/// True for statistics whose growth is a cost (and so can regress).
pub fn is_gated(key: &str) -> bool {
    match group_of(key) {
        "driver" => GATED_DRIVER_KEYS.contains(&key),
        _ => !key.ends_with("/functions"),
    }
}

/// Reads and checks a baseline file; every error names the file and what is wrong with it.
pub fn load(path: &Path) -> Result<Baseline> {
    let name = path.display();
    let text = std::fs::read_to_string(path).with_context(|| format!("baseline {name}: cannot read it"))?;
    let value: serde_json::Value = serde_json::from_str(&text).map_err(|e| anyhow!("baseline {name}: corrupt, not valid JSON ({e})"))?;
    match value.get("format").and_then(|f| f.as_str()) {
        Some(FORMAT) => {}
        Some(other) => bail!("baseline {name}: format `{other}`, this brdfprof reads `{FORMAT}`; save a new one with --save-baseline"),
        None => bail!("baseline {name}: not a brdfprof check baseline (no `format` field; expected `{FORMAT}`)"),
    }
    let baseline: Baseline = serde_json::from_value(value).map_err(|e| anyhow!("baseline {name}: corrupt ({e})"))?;
    validate(&baseline).map_err(|e| anyhow!("baseline {name}: corrupt ({e})"))?;
    Ok(baseline)
}

/// What serde cannot check: models that parse, finite statistics, timing ratios for known models.
fn validate(b: &Baseline) -> Result<()> {
    if b.inspect.rows.is_empty() {
        bail!("no rows");
    }
    for row in &b.inspect.rows {
        if let Some(s) = &row.spec {
            ModelSpec::parse(s).map_err(|e| anyhow!("row `{}`: spec `{s}`: {e}", row.model))?;
        }
        if let Some((k, v)) = row.stats.iter().find(|(_, v)| !v.is_finite()) {
            bail!("row `{}`: statistic {k} is {v}", row.model);
        }
    }
    if let Some(t) = &b.timing {
        for (model, ratios) in &t.ratios {
            if ratios.is_empty() || ratios.iter().any(|r| !r.is_finite() || *r <= 0.0) {
                bail!("timing ratios of `{model}` are empty or not positive numbers");
            }
        }
    }
    Ok(())
}

/// Per-statistic regression thresholds from `--threshold KEY=FRACTION` (KEY: a statistic key such as
/// spirv/total, or a group such as callgrind).
#[derive(Clone, Debug, Default)]
pub struct Thresholds {
    entries: Vec<(String, f64)>,
}

impl Thresholds {
    pub fn parse(items: &[String]) -> Result<Self> {
        let mut entries = Vec::new();
        for item in items {
            let (key, value) = item.split_once('=').ok_or_else(|| anyhow!("--threshold `{item}`: expected STAT=FRACTION, e.g. spirv/total=0.02"))?;
            let (key, value) = (key.trim(), value.trim());
            if !GROUPS.contains(&group_of(key)) {
                bail!("--threshold `{item}`: unknown statistic `{key}`: give a group ({}) or a key such as spirv/total", GROUPS.join(", "));
            }
            let fraction: f64 = value.parse().map_err(|_| anyhow!("--threshold `{item}`: `{value}` is not a number (a fraction: 0.01 is 1%)"))?;
            if !(fraction.is_finite() && fraction >= 0.0) {
                bail!("--threshold `{item}`: the fraction must be finite and not negative");
            }
            entries.push((key.to_string(), fraction));
        }
        Ok(Thresholds { entries })
    }

    /// The threshold of `key`: its own, else its group's, else the default.
    pub fn get(&self, key: &str) -> f64 {
        let find = |k: &str| self.entries.iter().rev().find(|(e, _)| e == k).map(|(_, v)| *v);
        find(key).or_else(|| find(group_of(key))).unwrap_or(if group_of(key) == "timing" { DEFAULT_TIMING_THRESHOLD } else { DEFAULT_COUNT_THRESHOLD })
    }
}

/// "vendor family F model M stepping S (model name)" from /proc/cpuinfo: the host CPU as the JIT sees it.
pub fn host_cpu() -> String {
    let Ok(text) = std::fs::read_to_string("/proc/cpuinfo") else { return std::env::consts::ARCH.to_string() };
    let field = |name: &str| {
        text.lines()
            .find(|l| l.split(':').next().is_some_and(|k| k.trim() == name))
            .and_then(|l| l.split_once(':'))
            .map_or(String::from("?"), |(_, v)| v.trim().to_string())
    };
    format!("{} family {} model {} stepping {} ({})", field("vendor_id"), field("cpu family"), field("model"), field("stepping"), field("model name"))
}

/// What each group's figures depend on.
pub fn environment(inspect: &InspectReport, timing: Option<&TimingRun>) -> BTreeMap<String, BTreeMap<String, String>> {
    let p = &inspect.provenance;
    let text = |v: &serde_json::Value| v.as_str().map(str::to_string).unwrap_or_else(|| v.to_string());
    let device = text(&p["device"]["name"]);
    let driver = format!("{} {} ({})", text(&p["device"]["driver_name"]), text(&p["device"]["driver_info"]), text(&p["device"]["driver_version"]));
    let env: Vec<String> = p["env"].as_object().map(|m| m.iter().map(|(k, v)| format!("{k}={}", text(v))).collect()).unwrap_or_default();
    let machine = |extra: Vec<(&str, String)>| -> BTreeMap<String, String> {
        let mut m: BTreeMap<String, String> = [("device", device.clone()), ("driver", driver.clone())].into_iter().map(|(k, v)| (k.to_string(), v)).collect();
        m.extend(extra.into_iter().map(|(k, v)| (k.to_string(), v)));
        m
    };
    let mut out = BTreeMap::new();
    out.insert("spirv".into(), BTreeMap::new());
    out.insert("naga".into(), BTreeMap::new());
    out.insert("spirv-O".into(), [("spirv-opt".to_string(), inspect.tools.get("spirv-opt").cloned().unwrap_or_default())].into());
    out.insert("driver".into(), machine(vec![]));
    if !inspect.callgrind_setup.is_empty() {
        let mut extra = vec![("host-cpu", host_cpu()), ("driver-env", env.join(" "))];
        extra.extend(inspect.callgrind_setup.iter().map(|(k, v)| (k.as_str(), v.clone())));
        if let Some(cg) = &inspect.callgrind {
            extra.push((JIT_FEATURES, cg.jit_cpu_features.join(" ")));
        }
        out.insert("callgrind".into(), machine(extra));
    }
    if let Some(t) = timing {
        out.insert(
            "timing".into(),
            machine(vec![
                ("host-cpu", host_cpu()),
                ("cpu-features", callgrind::cpu_features().join(" ")),
                ("host-threads", text(&p["host_threads"])),
                ("driver-env", env.join(" ")),
                ("workload", format!("{}x{} pixels x {} lights", t.width, t.height, t.lights)),
                ("reference", t.reference.clone()),
            ]),
        );
    }
    out
}

/// Everything `check` measures.
pub struct CheckOptions {
    pub baseline: Option<PathBuf>,
    pub save: Option<PathBuf>,
    pub thresholds: Thresholds,
    pub force: bool,
    /// Models asked for on the command line (default: the baseline's, else the thesis models).
    pub specs: Vec<ModelSpec>,
    /// Lights asked for (default: the baseline's, else 8).
    pub lights: Option<u32>,
    pub callgrind: Option<CallgrindOptions>,
    /// Timing run shape (`lights` is filled in); rounds 0 skips timing.
    pub timing: TimingOptions,
}

/// The result of `check`: the report text and the exit status (0 no regression, 1 regression, 2 could not
/// measure).
pub struct Outcome {
    pub text: String,
    pub exit: u8,
}

/// The models and lights a check measures: those asked for, else the baseline's, else the defaults.
fn plan(options: &CheckOptions, old: Option<&Baseline>) -> Result<(Vec<ModelSpec>, u32)> {
    let lights = match (options.lights, old) {
        (Some(l), Some(b)) if l != b.inspect.lights => {
            bail!("--lights {l}: the baseline was measured with {} lights; a check compares like with like (save a new baseline instead)", b.inspect.lights)
        }
        (Some(l), _) => l,
        (None, Some(b)) => b.inspect.lights,
        (None, None) => 8,
    };
    if lights == 0 {
        bail!("--lights must be at least 1");
    }
    let specs = if !options.specs.is_empty() {
        options.specs.clone()
    } else if let Some(b) = old {
        b.inspect.rows.iter().filter_map(|r| r.spec.as_deref()).map(|s| ModelSpec::parse(s).map_err(|e| anyhow!("{s}: {e}"))).collect::<Result<_>>()?
    } else {
        spec::THESIS_MODELS.iter().map(|m| ModelSpec::preset(m).unwrap()).collect()
    };
    Ok((specs, lights))
}

/// Measures this build: every count, then the timing run.
pub fn measure(gpu: &Gpu, kernels: &KernelSet, specs: Vec<ModelSpec>, lights: u32, options: &CheckOptions) -> Result<Baseline> {
    eprintln!("brdfprof check: counting instructions ({} models + baseline kernel{})", specs.len(), if options.callgrind.is_some() { ", callgrind" } else { "" });
    let inspect = super::run(gpu, kernels, &InspectOptions { specs: specs.clone(), lights, callgrind: options.callgrind.clone() })?;
    let timing = if options.timing.rounds > 0 {
        eprintln!("brdfprof check: timing {} rounds", options.timing.rounds);
        Some(timing::run(gpu, kernels, &specs, &TimingOptions { lights, ..options.timing.clone() })?)
    } else {
        None
    };
    let environment = environment(&inspect, timing.as_ref());
    Ok(Baseline { format: FORMAT.into(), inspect, timing, environment })
}

/// Runs `check`: loads the baseline (before opening the device, so a bad file fails at once), measures,
/// compares, saves.
pub fn run(options: &CheckOptions, kernels: &KernelSet, open: impl FnOnce() -> Result<Gpu>) -> Result<Outcome> {
    if options.baseline.is_none() && options.save.is_none() {
        bail!("check needs --baseline FILE (and/or --save-baseline FILE to write one)");
    }
    let old = options.baseline.as_deref().map(load).transpose()?;
    let (specs, lights) = plan(options, old.as_ref())?;
    let gpu = open()?;
    let new = measure(&gpu, kernels, specs, lights, options)?;
    gpu.check_validation()?;
    let outcome = match (&old, &options.baseline) {
        (Some(old), Some(path)) => {
            let cmp = compare(old, &new, &options.thresholds, options.force);
            Outcome { text: cmp.report(path, &new), exit: cmp.exit_code() }
        }
        _ => Outcome { text: format!("{}\n\n{}", new.inspect.summary(), new.inspect.markdown()), exit: 0 },
    };
    if let Some(path) = &options.save {
        report::write_json(path, &new)?;
        eprintln!("brdfprof check: baseline saved to {}", path.display());
    }
    Ok(outcome)
}

/// How a group compares between the baseline and this run.
#[derive(Clone, Debug, PartialEq)]
pub enum GroupStatus {
    Compared,
    /// Compared although the environments differ (--force); the differences.
    Forced(String),
    /// Not compared; why.
    NotComparable(String),
    /// Neither side has figures for the group.
    Absent(String),
    /// The baseline has figures that this run should have measured but could not; why (exit 2).
    NotMeasured(String),
}

/// One statistic of one model, old and new.
#[derive(Clone, Debug, PartialEq)]
pub struct Change {
    pub model: String,
    pub key: String,
    pub old: f64,
    pub new: f64,
    /// (new - old) / |old|; +inf when a statistic appears.
    pub rel: f64,
    pub threshold: f64,
    pub gated: bool,
}

impl Change {
    pub fn is_regression(&self) -> bool {
        self.gated && self.new > self.old && self.rel > self.threshold
    }
}

/// One model's timing ratios, old and new.
#[derive(Clone, Debug, PartialEq)]
pub struct TimingChange {
    pub model: String,
    pub old_median: f64,
    pub new_median: f64,
    pub n_old: usize,
    pub n_new: usize,
    /// new median / old median - 1.
    pub change: f64,
    /// Mann-Whitney U, two-sided; None with fewer than MIN_TIMING_ROUNDS rounds on a side.
    pub p: Option<f64>,
    pub threshold: f64,
}

impl TimingChange {
    pub fn significant(&self) -> bool {
        self.p.is_some_and(|p| p < ALPHA)
    }
    pub fn is_regression(&self) -> bool {
        self.significant() && self.change > self.threshold
    }
    fn verdict(&self) -> &'static str {
        match (self.p, self.significant()) {
            (None, _) => "too few rounds to test",
            (_, false) => "no significant change",
            _ if self.is_regression() => "REGRESSION",
            _ if self.change > 0.0 => "slower, within the noise threshold",
            _ if self.change < -self.threshold => "faster",
            _ => "faster, within the noise threshold",
        }
    }
}

pub struct Comparison {
    pub groups: Vec<(String, GroupStatus)>,
    /// Every compared statistic of every model in both runs, changed or not.
    pub changes: Vec<Change>,
    pub timing: Vec<TimingChange>,
    pub timing_reference: String,
    /// Models in only one of the runs.
    pub only_old: Vec<String>,
    pub only_new: Vec<String>,
    /// Notes that do not change the verdict (e.g. naga's verdict changed).
    pub notes: Vec<String>,
}

/// Why two fingerprints differ, or None when they match.
fn differences(old: Option<&BTreeMap<String, String>>, new: Option<&BTreeMap<String, String>>) -> Option<String> {
    let (empty_old, empty_new) = (BTreeMap::new(), BTreeMap::new());
    let (old, new) = (old.unwrap_or(&empty_old), new.unwrap_or(&empty_new));
    let none = String::from("(none)");
    let diffs: Vec<String> = old
        .keys()
        .chain(new.keys())
        .collect::<std::collections::BTreeSet<_>>()
        .into_iter()
        .filter(|k| old.get(*k) != new.get(*k))
        .map(|k| format!("{k}: baseline `{}`, now `{}`", old.get(k).unwrap_or(&none), new.get(k).unwrap_or(&none)))
        .collect();
    (!diffs.is_empty()).then(|| diffs.join("; "))
}

fn has_group(b: &Baseline, group: &str) -> bool {
    if group == "timing" {
        return b.timing.is_some();
    }
    b.inspect.rows.iter().any(|r| r.stats.keys().any(|k| group_of(k) == group))
}

/// The status of each group.
fn group_status(old: &Baseline, new: &Baseline, force: bool) -> Vec<(String, GroupStatus)> {
    GROUPS
        .iter()
        .map(|&g| {
            let status = match (has_group(old, g), has_group(new, g)) {
                (false, false) => GroupStatus::Absent(absent_reason(new, g)),
                (false, true) => GroupStatus::Absent("the baseline has none".into()),
                (true, false) if g == "callgrind" && new_note(new, g).starts_with("could not measure") => {
                    // A failure only counts where the figures would have been comparable.
                    let mut known = old.environment.get(g).cloned().unwrap_or_default();
                    known.remove(JIT_FEATURES);
                    match differences(Some(&known), new.environment.get(g)) {
                        Some(d) if !force => GroupStatus::NotComparable(format!("{d}; besides, {}", new_note(new, g))),
                        _ => GroupStatus::NotMeasured(new_note(new, g)),
                    }
                }
                (true, false) => GroupStatus::Absent(absent_reason(new, g)),
                (true, true) => match differences(old.environment.get(g), new.environment.get(g)) {
                    None => GroupStatus::Compared,
                    Some(d) if force => GroupStatus::Forced(d),
                    Some(d) => GroupStatus::NotComparable(d),
                },
            };
            (g.to_string(), status)
        })
        .collect()
}

fn new_note(new: &Baseline, group: &str) -> String {
    new.inspect.section_notes.get(&format!("{group}/")).cloned().unwrap_or_default()
}

fn absent_reason(new: &Baseline, group: &str) -> String {
    match group {
        "timing" if new.timing.is_none() => "not measured now (--rounds 0)".into(),
        _ => {
            let note = new_note(new, group);
            if note.is_empty() { "not measured".into() } else { note }
        }
    }
}

fn rel_change(old: f64, new: f64) -> f64 {
    if old == new {
        0.0
    } else if old == 0.0 {
        f64::INFINITY.copysign(new)
    } else {
        (new - old) / old.abs()
    }
}

/// Compares two runs statistic by statistic.
pub fn compare(old: &Baseline, new: &Baseline, thresholds: &Thresholds, force: bool) -> Comparison {
    let groups = group_status(old, new, force);
    let compared = |g: &str| groups.iter().any(|(name, s)| name == g && matches!(s, GroupStatus::Compared | GroupStatus::Forced(_)));
    let mut changes = Vec::new();
    let mut notes = Vec::new();
    let new_models: Vec<&str> = new.inspect.rows.iter().map(|r| r.model.as_str()).collect();
    let only_old = old.inspect.rows.iter().map(|r| r.model.clone()).filter(|m| !new_models.contains(&m.as_str())).collect();
    let only_new = new.inspect.rows.iter().map(|r| r.model.clone()).filter(|m| old.inspect.row(m).is_none()).collect();
    // Column order: the new run's, then keys only the baseline has.
    let mut columns = new.inspect.columns.clone();
    columns.extend(old.inspect.columns.iter().filter(|c| !new.inspect.columns.contains(c)).cloned());
    for old_row in &old.inspect.rows {
        let Some(new_row) = new.inspect.row(&old_row.model) else { continue };
        for key in columns.iter().filter(|k| compared(group_of(k))) {
            // A SPIR-V count a kernel lacks is 0; elsewhere a missing statistic was not measured.
            let zero = key.starts_with("spirv").then_some(0.0);
            let (Some(o), Some(n)) = (old_row.stats.get(key).copied().or(zero), new_row.stats.get(key).copied().or(zero)) else { continue };
            changes.push(Change { model: old_row.model.clone(), key: key.clone(), old: o, new: n, rel: rel_change(o, n), threshold: thresholds.get(key), gated: is_gated(key) });
        }
        if compared("naga") && old_row.notes.get("naga") != new_row.notes.get("naga") {
            notes.push(format!("{}: naga's verdict changed from `{}` to `{}` (reported only)", old_row.model, old_row.notes.get("naga").map_or("-", |s| s), new_row.notes.get("naga").map_or("-", |s| s)));
        }
    }
    let timing = match (&old.timing, &new.timing, compared("timing")) {
        (Some(o), Some(n), true) => compare_timing(o, n, thresholds),
        _ => Vec::new(),
    };
    let timing_reference = new.timing.as_ref().map_or_else(String::new, |t| t.reference.clone());
    Comparison { groups, changes, timing, timing_reference, only_old, only_new, notes }
}

fn compare_timing(old: &TimingRun, new: &TimingRun, thresholds: &Thresholds) -> Vec<TimingChange> {
    old.ratios
        .iter()
        .filter_map(|(model, o)| {
            let n = new.ratios.get(model)?;
            let (om, nm) = (stats::median(o), stats::median(n));
            let enough = o.len() >= MIN_TIMING_ROUNDS && n.len() >= MIN_TIMING_ROUNDS;
            Some(TimingChange {
                model: model.clone(),
                old_median: om,
                new_median: nm,
                n_old: o.len(),
                n_new: n.len(),
                change: nm / om - 1.0,
                p: enough.then(|| stats::mann_whitney_p(o, n)),
                threshold: thresholds.get(TIMING_KEY),
            })
        })
        .collect()
}

fn percent(rel: f64) -> String {
    if rel.is_infinite() {
        return if rel > 0.0 { "+inf".into() } else { "-inf".into() };
    }
    format!("{:+.2}%", rel * 100.0)
}

impl Comparison {
    pub fn regressions(&self) -> Vec<String> {
        let counts = self
            .changes
            .iter()
            .filter(|c| c.is_regression())
            .map(|c| format!("{} {}: {} -> {} ({}, threshold {})", c.model, c.key, format_value(c.old), format_value(c.new), percent(c.rel), percent(c.threshold)));
        let timing = self.timing.iter().filter(|t| t.is_regression()).map(|t| {
            format!(
                "{} {TIMING_KEY}: {} -> {} ({}, p = {}, threshold {})",
                t.model,
                report::sig(t.old_median, 4),
                report::sig(t.new_median, 4),
                percent(t.change),
                report::sig(t.p.unwrap_or(1.0), 2),
                percent(t.threshold)
            )
        });
        counts.chain(timing).collect()
    }

    /// Groups that should have been measured and were not.
    pub fn not_measured(&self) -> Vec<String> {
        self.groups.iter().filter_map(|(g, s)| if let GroupStatus::NotMeasured(why) = s { Some(format!("{g}: {why}")) } else { None }).collect()
    }

    /// 1 on any regression, else 2 when a group could not be measured, else 0.
    pub fn exit_code(&self) -> u8 {
        if !self.regressions().is_empty() {
            1
        } else if !self.not_measured().is_empty() {
            2
        } else {
            0
        }
    }

    /// The shader-db-style report.
    pub fn report(&self, baseline_path: &Path, new: &Baseline) -> String {
        let mut out = format!("# brdfprof check against {}\n\n{}\n\n", baseline_path.display(), new.inspect.summary());
        out += &self.groups_section();
        out += &self.changes_section();
        out += &self.helped_hurt_section();
        out += &self.totals_section();
        out += &self.timing_section();
        for note in self.notes.iter().chain(self.only_old.iter().map(|m| format!("{m}: in the baseline only, not measured now")).collect::<Vec<_>>().iter()) {
            out += &format!("Note: {note}\n");
        }
        for m in &self.only_new {
            out += &format!("Note: {m}: no baseline figures (new model)\n");
        }
        out += &self.verdict_section();
        out
    }

    fn groups_section(&self) -> String {
        let mut t = Table::new(["group", "status"]);
        for (g, s) in &self.groups {
            let text = match s {
                GroupStatus::Compared => "compared".to_string(),
                GroupStatus::Forced(d) => format!("compared (--force) although the environment differs: {d}"),
                GroupStatus::NotComparable(d) => format!("not comparable: {d} (--force compares anyway)"),
                GroupStatus::Absent(why) => format!("not compared: {why}"),
                GroupStatus::NotMeasured(why) => format!("NOT MEASURED: {why}"),
            };
            t.row([g.clone(), text]);
        }
        format!("## Statistic groups\n\n{}\n", t.markdown())
    }

    fn changes_section(&self) -> String {
        let changed: Vec<&Change> = self.changes.iter().filter(|c| c.old != c.new).collect();
        let out = format!("## Changes\n\n{} statistics compared over {} models, {} changed.\n\n", self.changes.len(), self.models().len(), changed.len());
        if changed.is_empty() {
            return out;
        }
        let mut t = Table::new(["model", "statistic", "old", "new", "change", "threshold", "verdict"]);
        for c in changed {
            let verdict = if c.is_regression() {
                "REGRESSION"
            } else if !c.gated {
                "reported only"
            } else if c.new > c.old {
                "hurt, within threshold"
            } else {
                "helped"
            };
            t.row([c.model.clone(), c.key.clone(), format_value(c.old), format_value(c.new), percent(c.rel), percent(c.threshold), verdict.into()]);
        }
        out + &t.markdown() + "\n"
    }

    fn models(&self) -> Vec<&str> {
        let mut m: Vec<&str> = self.changes.iter().map(|c| c.model.as_str()).collect();
        m.dedup();
        m
    }

    fn helped_hurt_section(&self) -> String {
        let mut hurt: Vec<&Change> = self.changes.iter().filter(|c| c.new > c.old).collect();
        let mut helped: Vec<&Change> = self.changes.iter().filter(|c| c.new < c.old).collect();
        hurt.sort_by(|a, b| b.rel.total_cmp(&a.rel));
        helped.sort_by(|a, b| a.rel.total_cmp(&b.rel));
        let line = |c: &&Change| format!("- {} {}: {} -> {} ({})\n", c.model, c.key, format_value(c.old), format_value(c.new), percent(c.rel));
        let list = |cs: &[&Change]| if cs.is_empty() { "(none)\n".to_string() } else { cs.iter().map(line).collect() };
        format!("## Hurt ({}), largest change first\n\n{}\n## Helped ({}), largest change first\n\n{}\n", hurt.len(), list(&hurt), helped.len(), list(&helped))
    }

    /// Totals of every statistic that changed somewhere (and of the headline totals), over all models and
    /// over the models where it changed.
    fn totals_section(&self) -> String {
        const HEADLINES: [&str; 3] = ["spirv/total", "spirv-O/total", "callgrind/ir-per-eval"];
        let mut keys: Vec<&str> = Vec::new();
        for c in &self.changes {
            if (c.old != c.new || HEADLINES.contains(&c.key.as_str())) && !keys.contains(&c.key.as_str()) {
                keys.push(&c.key);
            }
        }
        let mut all = Table::new(["statistic", "models", "old", "new", "change"]);
        let mut affected = Table::new(["statistic", "models", "old", "new", "change"]);
        for key in keys {
            let of_key: Vec<&Change> = self.changes.iter().filter(|c| c.key == key).collect();
            let sum = |cs: &[&Change]| (cs.iter().map(|c| c.old).sum::<f64>(), cs.iter().map(|c| c.new).sum::<f64>());
            let (o, n) = sum(&of_key);
            all.row([key.to_string(), of_key.len().to_string(), format_value(o), format_value(n), percent(rel_change(o, n))]);
            let changed: Vec<&Change> = of_key.iter().copied().filter(|c| c.old != c.new).collect();
            if !changed.is_empty() {
                let (o, n) = sum(&changed);
                affected.row([key.to_string(), changed.len().to_string(), format_value(o), format_value(n), percent(rel_change(o, n))]);
            }
        }
        let mut out = format!("## Totals over all models\n\n{}\n", all.markdown());
        if !affected.rows.is_empty() {
            out += &format!("## Totals over affected models\n\n{}\n", affected.markdown());
        }
        out
    }

    fn timing_section(&self) -> String {
        if self.timing.is_empty() {
            return String::new();
        }
        let mut t = Table::new(["model", "old median [rounds]", "new median [rounds]", "change", "p", "threshold", "verdict"]);
        for c in &self.timing {
            t.row([
                c.model.clone(),
                format!("{} [{}]", report::sig(c.old_median, 4), c.n_old),
                format!("{} [{}]", report::sig(c.new_median, 4), c.n_new),
                percent(c.change),
                c.p.map_or("-".into(), |p| report::sig(p, 2)),
                percent(c.threshold),
                c.verdict().into(),
            ]);
        }
        format!(
            "## Timing: cost / reference, per round (Mann-Whitney U, alpha {ALPHA}, at least {MIN_TIMING_ROUNDS} rounds a side)\n\nReference: {}.\n\n{}\n",
            self.timing_reference,
            t.markdown()
        )
    }

    fn verdict_section(&self) -> String {
        let regressions = self.regressions();
        let missing = self.not_measured();
        let mut out = String::from("\n## Verdict\n\n");
        if !regressions.is_empty() {
            out += &format!("REGRESSION: {} statistic(s) beyond threshold:\n", regressions.len());
            out += &regressions.iter().map(|r| format!("- {r}\n")).collect::<String>();
        }
        if !missing.is_empty() {
            out += &format!("COULD NOT MEASURE: {}\n", missing.join("; "));
        }
        if regressions.is_empty() && missing.is_empty() {
            out += "no regression\n";
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::inspect::Row;

    fn row(model: &str, stats: &[(&str, f64)]) -> Row {
        Row {
            model: model.into(),
            spec: (model != "baseline").then(|| ModelSpec::preset(model).unwrap().canonical()),
            stats: stats.iter().map(|(k, v)| (k.to_string(), *v)).collect(),
            notes: BTreeMap::new(),
        }
    }

    fn baseline(rows: Vec<Row>, timing: Option<TimingRun>, host: &str) -> Baseline {
        let columns = rows.iter().flat_map(|r| r.stats.keys().cloned()).collect::<std::collections::BTreeSet<_>>().into_iter().collect();
        let inspect = InspectReport {
            provenance: serde_json::json!({"device": {"name": "llvmpipe (LLVM 15.0.6, 256 bits)"}}),
            kernels: "embedded spv/".into(),
            lights: 8,
            tools: BTreeMap::new(),
            columns,
            rows,
            section_notes: BTreeMap::new(),
            callgrind: None,
            callgrind_setup: BTreeMap::new(),
            vs_profile: None,
        };
        let mut environment = BTreeMap::new();
        for g in ["callgrind", "timing"] {
            environment.insert(g.to_string(), [("host-cpu".to_string(), host.to_string())].into());
        }
        Baseline { format: FORMAT.into(), inspect, timing, environment }
    }

    fn timing(ratios: &[(&str, Vec<f64>)]) -> TimingRun {
        TimingRun {
            reference: "test".into(),
            width: 8,
            height: 8,
            lights: 8,
            rounds: ratios[0].1.len(),
            reps: 1,
            ratios: ratios.iter().map(|(m, r)| (m.to_string(), r.clone())).collect(),
            round_ns: BTreeMap::new(),
            ns_per_eval: BTreeMap::new(),
        }
    }

    /// 15 ratios around `centre`, spread +-1%.
    fn around(centre: f64) -> Vec<f64> {
        (0..15).map(|i| centre * (1.0 + 0.01 * ((i * 7 % 15) as f64 / 7.0 - 1.0))).collect()
    }

    #[test]
    fn thresholds_prefer_the_key_then_the_group_then_the_default() {
        let t = Thresholds::parse(&["spirv=0.1".into(), "spirv/total=0.02".into(), "timing=0.2".into()]).unwrap();
        assert_eq!(t.get("spirv/total"), 0.02);
        assert_eq!(t.get("spirv/glsl.Pow"), 0.1);
        assert_eq!(t.get("callgrind/ir-per-eval"), DEFAULT_COUNT_THRESHOLD);
        assert_eq!(t.get(TIMING_KEY), 0.2);
        assert_eq!(Thresholds::default().get(TIMING_KEY), DEFAULT_TIMING_THRESHOLD);
        assert!(Thresholds::parse(&["bogus/x=0.1".into()]).unwrap_err().to_string().contains("unknown statistic `bogus/x`"));
        assert!(Thresholds::parse(&["spirv=abc".into()]).unwrap_err().to_string().contains("not a number"));
        assert!(Thresholds::parse(&["spirv=-1".into()]).is_err());
        assert!(Thresholds::parse(&["spirv".into()]).is_err());
    }

    #[test]
    fn counts_regress_beyond_their_threshold_only() {
        let old = baseline(vec![row("ggx", &[("spirv/total", 100.0), ("spirv/functions", 10.0), ("spirv/glsl.Exp", 1.0)])], None, "cpu");
        let new = baseline(vec![row("ggx", &[("spirv/total", 100.9), ("spirv/functions", 20.0), ("spirv/glsl.Pow", 1.0)])], None, "cpu");
        let cmp = compare(&old, &new, &Thresholds::default(), false);
        let regressions = cmp.regressions();
        // +0.9% total is within 1%; functions are reported only; Pow appeared (+inf); Exp went away (helped).
        assert_eq!(regressions.len(), 1, "{regressions:?}");
        assert!(regressions[0].starts_with("ggx spirv/glsl.Pow: 0 -> 1"), "{regressions:?}");
        assert_eq!(cmp.exit_code(), 1);
        let report = cmp.report(Path::new("b.json"), &new);
        assert!(report.contains("## Helped (1)") && report.contains("ggx spirv/glsl.Exp: 1 -> 0"), "{report}");
        let loose = compare(&old, &new, &Thresholds::parse(&["spirv/glsl.Pow=1e300".into()]).unwrap(), false);
        assert_eq!(loose.exit_code(), 1, "+inf exceeds any finite threshold");
        assert_eq!(compare(&old, &old, &Thresholds::default(), false).exit_code(), 0);
    }

    #[test]
    fn machine_dependent_groups_compare_only_in_the_same_environment() {
        let old = baseline(vec![row("ggx", &[("spirv/total", 100.0), ("callgrind/ir-per-eval", 60.0)])], Some(timing(&[("ggx", around(1.0))])), "cpu A");
        let mut new = baseline(vec![row("ggx", &[("spirv/total", 100.0), ("callgrind/ir-per-eval", 70.0)])], Some(timing(&[("ggx", around(1.5))])), "cpu B");
        let cmp = compare(&old, &new, &Thresholds::default(), false);
        assert_eq!(cmp.exit_code(), 0, "{:?}", cmp.regressions());
        let status = |c: &Comparison, g: &str| c.groups.iter().find(|(n, _)| n == g).unwrap().1.clone();
        assert!(matches!(status(&cmp, "callgrind"), GroupStatus::NotComparable(d) if d.contains("host-cpu: baseline `cpu A`, now `cpu B`")));
        assert!(matches!(status(&cmp, "timing"), GroupStatus::NotComparable(_)));
        assert!(matches!(status(&cmp, "spirv"), GroupStatus::Compared));
        // Forced, or in the same environment, both regress.
        assert_eq!(compare(&old, &new, &Thresholds::default(), true).regressions().len(), 2);
        new.environment = old.environment.clone();
        let same = compare(&old, &new, &Thresholds::default(), false);
        assert_eq!(same.regressions().len(), 2, "{:?}", same.regressions());
        assert_eq!(same.exit_code(), 1);
    }

    #[test]
    fn timings_need_significance_and_size() {
        let old = baseline(vec![row("ggx", &[])], Some(timing(&[("ggx", around(1.0)), ("blinn", around(1.2))])), "cpu");
        // ggx +10% (significant, beyond 5%): regression; blinn +2% (significant, within 5%): not.
        let new = baseline(vec![row("ggx", &[])], Some(timing(&[("ggx", around(1.1)), ("blinn", around(1.2 * 1.02))])), "cpu");
        let cmp = compare(&old, &new, &Thresholds::default(), false);
        let by = |m: &str| cmp.timing.iter().find(|t| t.model == m).unwrap().clone();
        assert!(by("ggx").is_regression() && by("ggx").p.unwrap() < 1e-3);
        assert!(by("blinn").significant() && !by("blinn").is_regression());
        assert_eq!(cmp.exit_code(), 1);
        // Fewer than 9 rounds: no test, no verdict.
        let short = |c: f64| timing(&[("ggx", around(c)[..8].to_vec())]);
        let cmp = compare(&baseline(vec![row("ggx", &[])], Some(short(1.0)), "cpu"), &baseline(vec![row("ggx", &[])], Some(short(2.0)), "cpu"), &Thresholds::default(), false);
        assert_eq!((cmp.timing[0].p, cmp.exit_code()), (None, 0));
    }

    #[test]
    fn a_failed_callgrind_run_is_could_not_measure() {
        let old = baseline(vec![row("ggx", &[("callgrind/ir-per-eval", 60.0)])], None, "cpu");
        let mut new = baseline(vec![row("ggx", &[])], None, "cpu");
        new.inspect.section_notes.insert("callgrind/".into(), "could not measure: valgrind crashed".into());
        let cmp = compare(&old, &new, &Thresholds::default(), false);
        assert_eq!(cmp.exit_code(), 2);
        assert!(cmp.report(Path::new("b.json"), &new).contains("COULD NOT MEASURE: callgrind: could not measure: valgrind crashed"));
        // On another machine the figures would not have been compared anyway: no failure.
        let elsewhere = baseline(vec![row("ggx", &[])], None, "another cpu");
        let mut new_elsewhere = elsewhere.clone();
        new_elsewhere.inspect.section_notes = new.inspect.section_notes.clone();
        assert_eq!(compare(&old, &new_elsewhere, &Thresholds::default(), false).exit_code(), 0);
        // Skipped on purpose: not compared, no failure.
        new.inspect.section_notes.insert("callgrind/".into(), "not measured (--no-callgrind)".into());
        assert_eq!(compare(&old, &new, &Thresholds::default(), false).exit_code(), 0);
    }

    #[test]
    fn bad_baselines_are_refused_with_the_reason() {
        let dir = tempfile::tempdir().unwrap();
        let missing = dir.path().join("missing.json");
        assert!(load(&missing).unwrap_err().to_string().contains("cannot read it"));
        let write = |name: &str, text: &str| {
            let p = dir.path().join(name);
            std::fs::write(&p, text).unwrap();
            p
        };
        let e = load(&write("trunc.json", "{\"format\": \"brdfprof-check")).unwrap_err().to_string();
        assert!(e.contains("corrupt, not valid JSON"), "{e}");
        let e = load(&write("other.json", "{\"rows\": []}")).unwrap_err().to_string();
        assert!(e.contains("not a brdfprof check baseline"), "{e}");
        let e = load(&write("old.json", "{\"format\": \"brdfprof-check-baseline/0\"}")).unwrap_err().to_string();
        assert!(e.contains("format `brdfprof-check-baseline/0`"), "{e}");
        let good = baseline(vec![row("ggx", &[("spirv/total", 1.0)])], None, "cpu");
        let p = dir.path().join("good.json");
        report::write_json(&p, &good).unwrap();
        assert_eq!(load(&p).unwrap().inspect.rows, good.inspect.rows);
        let e = load(&write("bad.json", &std::fs::read_to_string(&p).unwrap().replace("\"spirv/total\": 1.0", "\"spirv/total\": \"x\""))).unwrap_err().to_string();
        assert!(e.contains("corrupt") && e.contains("bad.json"), "{e}");
    }
}
