//! Two runs compared statistic by statistic and group by group.

use super::baseline::Baseline;
use super::environment::{JIT_FEATURES, MESA};
use super::lines::LineChange;
use super::thresholds::{ALPHA, COST_KEYS, GROUPS, MIN_TIMING_ROUNDS, TIMING_KEY, Thresholds, group_of, is_gated};
use crate::check::timing::TimingRun;
use crate::stats;
use std::collections::BTreeMap;

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
    pub(super) fn verdict(&self) -> &'static str {
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
    /// Each regressed model's source lines before and after, largest rise first, where both runs have
    /// per-line cost (`lines::changes`), with the pipe they are counted on.
    pub lines: Vec<ModelLines>,
}

impl Comparison {
    /// How large a model's regression is, for ordering findings (the largest first): the change of its modelled
    /// cycles per evaluation where it has one (what the cost tables headline), else its largest regressed
    /// statistic's change with a finite rule for one that appears (0 -> n counts as n, not +inf: a first `pow`
    /// is no larger than a tripled loop), else its timing change.
    pub fn size(&self, model: &str) -> f64 {
        let cmp = self;
        let mine = || cmp.changes.iter().filter(move |c| c.model == model);
        if let Some(c) = mine().find(|c| c.key == COST_KEYS[0] && c.new > c.old) {
            return c.rel;
        }
        let finite = |c: &Change| (c.new - c.old) / c.old.abs().max(1.0);
        let counts = mine().filter(|c| c.is_regression()).map(finite).fold(f64::NEG_INFINITY, f64::max);
        let timing = cmp
            .timing
            .iter()
            .filter(|t| t.model == model && t.is_regression())
            .map(|t| t.change)
            .fold(f64::NEG_INFINITY, f64::max);
        counts.max(timing)
    }
}

/// One model's per-line changes.
#[derive(Clone, Debug, PartialEq)]
pub struct ModelLines {
    pub model: String,
    /// The new kernel's binding pipe, whose cycles per wave the lines are counted in.
    pub pipe: String,
    pub changes: Vec<LineChange>,
}

/// Why two fingerprints differ, or None when they match.
fn differences(old: Option<&BTreeMap<String, String>>, new: Option<&BTreeMap<String, String>>) -> Option<String> {
    let (empty_old, empty_new) = (BTreeMap::new(), BTreeMap::new());
    let (old, new) = (old.unwrap_or(&empty_old), new.unwrap_or(&empty_new));
    let none = String::from("(none)");
    // A key the baseline does not hold was not recorded when it was saved (a tool version added since): no
    // difference to name.
    let diffs: Vec<String> = old
        .keys()
        .chain(new.keys())
        .collect::<std::collections::BTreeSet<_>>()
        .into_iter()
        .filter(|k| old.contains_key(*k) && old.get(*k) != new.get(*k))
        .map(|k| match k.as_str() {
            MESA => format!("Mesa {} vs {}", old.get(k).unwrap_or(&none), new.get(k).unwrap_or(&none)),
            _ => format!("{k}: baseline `{}`, now `{}`", old.get(k).unwrap_or(&none), new.get(k).unwrap_or(&none)),
        })
        .collect();
    (!diffs.is_empty()).then(|| diffs.join("; "))
}

/// The environment a group's figures depend on: the cost group's are the compiler's (`driver`).
fn env_group(group: &str) -> &str {
    if group == "cost" { "driver" } else { group }
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
                // The cost rule reads the compiler's listing: comparable where the compiler's figures are.
                (true, true) => match differences(old.environment.get(env_group(g)), new.environment.get(env_group(g)))
                {
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
        "timing" if new.timing.is_none() && !new_note(new, group).is_empty() => new_note(new, group),
        "timing" if new.timing.is_none() => "not measured now (--rounds 0)".into(),
        _ => {
            let note = new_note(new, group);
            if note.is_empty() { "not measured".into() } else { note }
        }
    }
}

pub(super) fn rel_change(old: f64, new: f64) -> f64 {
    if old == new {
        0.0
    } else if old == 0.0 {
        f64::INFINITY.copysign(new)
    } else {
        (new - old) / old.abs()
    }
}

/// `b` with its cost table's figures as the `cost` group's statistics of each row (`COST_KEYS`), so that they
/// are compared, gated and reported as every other statistic is (a baseline saved before they were stats has
/// them in its cost table too).
fn with_cost_stats(b: &Baseline) -> Baseline {
    let mut b = b.clone();
    let Some(cost) = b.inspect.cost.clone() else { return b };
    // To 9 significant digits: a rule's sums over pipes may differ in their last bits between runs, which is
    // no change of the kernel.
    let round = |x: f64| if x == 0.0 || !x.is_finite() { x } else { format!("{x:.8e}").parse().unwrap_or(x) };
    for row in &mut b.inspect.rows {
        let Some(c) = cost.row(&row.model) else { continue };
        row.stats.insert(COST_KEYS[0].into(), round(c.cycles_per_eval));
        if let Some(net) = c.net_cycles_per_eval {
            row.stats.insert(COST_KEYS[1].into(), round(net));
        }
    }
    let mut columns: Vec<String> = COST_KEYS.iter().map(|k| k.to_string()).collect();
    columns.extend(b.inspect.columns.iter().filter(|c| !COST_KEYS.contains(&c.as_str())).cloned());
    b.inspect.columns = columns;
    b
}

/// Compares two runs statistic by statistic.
pub fn compare(old: &Baseline, new: &Baseline, thresholds: &Thresholds, force: bool) -> Comparison {
    let (old, new) = (&with_cost_stats(old), &with_cost_stats(new));
    let groups = group_status(old, new, force);
    let compared = |g: &str| {
        groups.iter().any(|(name, s)| name == g && matches!(s, GroupStatus::Compared | GroupStatus::Forced(_)))
    };
    let mut changes = Vec::new();
    let mut notes = Vec::new();
    let new_models: Vec<&str> = new.inspect.rows.iter().map(|r| r.model.as_str()).collect();
    let only_old =
        old.inspect.rows.iter().map(|r| r.model.clone()).filter(|m| !new_models.contains(&m.as_str())).collect();
    let only_new = new.inspect.rows.iter().map(|r| r.model.clone()).filter(|m| old.inspect.row(m).is_none()).collect();
    // Column order: the new run's, then keys only the baseline has.
    let mut columns = new.inspect.columns.clone();
    columns.extend(old.inspect.columns.iter().filter(|c| !new.inspect.columns.contains(c)).cloned());
    for old_row in &old.inspect.rows {
        let Some(new_row) = new.inspect.row(&old_row.model) else { continue };
        for key in columns.iter().filter(|k| compared(group_of(k))) {
            // A SPIR-V count a kernel lacks is 0; elsewhere a missing statistic was not measured.
            let zero = key.starts_with("spirv").then_some(0.0);
            let (Some(o), Some(n)) =
                (old_row.stats.get(key).copied().or(zero), new_row.stats.get(key).copied().or(zero))
            else {
                continue;
            };
            changes.push(Change {
                model: old_row.model.clone(),
                key: key.clone(),
                old: o,
                new: n,
                rel: rel_change(o, n),
                threshold: thresholds.get(key),
                // A net at or below 0 is harness-bound: no ratio to gate on.
                gated: is_gated(key) && !(key == COST_KEYS[1] && o <= 0.0),
            });
        }
        if compared("naga") && old_row.notes.get("naga") != new_row.notes.get("naga") {
            notes.push(format!(
                "{}: naga's verdict changed from `{}` to `{}` (reported only)",
                old_row.model,
                old_row.notes.get("naga").map_or("-", |s| s),
                new_row.notes.get("naga").map_or("-", |s| s)
            ));
        }
    }
    let timing = match (&old.timing, &new.timing, compared("timing")) {
        (Some(o), Some(n), true) => compare_timing(o, n, thresholds),
        _ => Vec::new(),
    };
    let timing_reference = new.timing.as_ref().map_or_else(String::new, |t| t.reference.clone());
    let mut regressed: Vec<&str> = Vec::new();
    let counted = changes.iter().filter(|c| c.is_regression()).map(|c| c.model.as_str());
    for model in counted.chain(timing.iter().filter(|t| t.is_regression()).map(|t| t.model.as_str())) {
        if !regressed.contains(&model) {
            regressed.push(model);
        }
    }
    // Per-line cost is a target's own: lines measured on another target (an nvidia: baseline checked on
    // intel:) would read as new cost on every line.
    let lines = regressed
        .iter()
        .filter(|_| old.measured_on().0 == new.measured_on().0)
        .filter_map(|&model| {
            let changes = super::lines::changes(&old.inspect.lines, &new.inspect.lines, model)?;
            let pipe = new.inspect.lines.iter().find(|k| k.model == model)?.binding_pipe.clone();
            Some(ModelLines { model: model.to_string(), pipe, changes })
        })
        .collect();
    Comparison { groups, changes, timing, timing_reference, only_old, only_new, notes, lines }
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
