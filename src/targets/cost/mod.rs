//! The cost rule: a compile-only target's cost table (`schema::cost`) from a report's statistics, by a
//! per-kernel rule of the vendor's or by the one rule of `schedule`, and each instruction's cost attributed
//! to its source line (`lines`). Each vendor supplies its figures (ACO's inverse throughput, NVIDIA's and
//! Intel's pipes and schedules, ...); this module turns them into the table every report shows.

pub mod lines;
pub mod measured;

pub use brdfprof_isa_cost::{driver_stat, schedule};

use crate::kernels::shade::steady_block;
use crate::model::BASELINE_LABEL;
use crate::schema::cost::{CostRow, TargetCost};
use crate::schema::{InspectReport, Row};
use schedule::{LATENCY, RESIDENT_WAVES, Schedule};

/// A row's statistics by key.
type Stats = std::collections::BTreeMap<String, f64>;

/// A cost table of `report` from a per-kernel rule: `cycles(stats, lights per kernel)` (None: the kernel has no
/// figure, e.g. the driver reported none) and the statistics `columns` shown beside it.
pub fn table(
    report: &InspectReport,
    header: TargetCost,
    cycles: impl Fn(&Row, u32) -> Option<f64>,
) -> Option<TargetCost> {
    let lights = steady_block(report.lights).0;
    let checked = header.target.as_deref().and_then(measured::line);
    let mut t = TargetCost { lights_per_kernel: lights, rows: Vec::new(), checked, ..header };
    for r in &report.rows {
        let Some(c) = cycles(r, lights) else { continue };
        let stats = t.columns.iter().map(|name| (name.clone(), driver_stat(&r.stats, name).unwrap_or(0.0))).collect();
        t.rows.push(CostRow {
            model: r.model.clone(),
            stats,
            cycles_per_eval: c,
            net_cycles_per_eval: None,
            bound: None,
            terms: Vec::new(),
            net_terms: Vec::new(),
        });
    }
    if t.rows.is_empty() {
        return None;
    }
    if let Some(base) = t.rows.iter().find(|r| r.model == BASELINE_LABEL).map(|r| r.cycles_per_eval) {
        for r in t.rows.iter_mut().filter(|r| r.model != BASELINE_LABEL) {
            r.net_cycles_per_eval = Some(r.cycles_per_eval - base);
        }
    }
    Some(t)
}

/// Columns `schedule_table` adds to a row's statistics: the rule's figures per wave.
pub const BUSIEST_PIPE: &str = "busiest pipe (cycles/wave)";
pub const HIDDEN_LATENCY: &str = "latency / waves";

/// A cost table under `schedule`'s rule (`schedule::RULE`): per kernel, cycles per wave = max(busiest pipe,
/// schedule latency / resident waves) over the figures `schedule_of(stats)` gives with the lanes of one wave,
/// divided by those lanes and the lights per kernel (`bound_table`).
pub fn schedule_table(
    report: &InspectReport,
    header: TargetCost,
    schedule_of: impl Fn(&Stats) -> Option<(Schedule, f64)>,
) -> Option<TargetCost> {
    bound_table(report, header, |stats, lights| schedule_of(stats).map(|(s, lanes)| (s, lanes * f64::from(lights))))
}

/// A cost table of bounds over terms: `evaluations_of(stats, lights per kernel)` gives a kernel's figures and
/// the BRDF evaluations they stand for (lanes x lights, or fewer where a loop's body is counted once); per
/// evaluation, cycles = the largest term; net = the kernel's cycles/eval minus the memory-only kernel's
/// (kernels may differ in width), the term binding the kernel named in `bound` and each term's difference in
/// `net_terms`. The latency columns appear where some kernel has a schedule latency.
pub fn bound_table(
    report: &InspectReport,
    mut header: TargetCost,
    evaluations_of: impl Fn(&Stats, u32) -> Option<(Schedule, f64)>,
) -> Option<TargetCost> {
    let lights = steady_block(report.lights).0;
    let evaluations_of = |stats: &Stats| evaluations_of(stats, lights);
    let per_eval = |row: &Row| priced(report, row, &evaluations_of);
    let figures = |model: &str| report.rows.iter().find(|r| r.model == model).and_then(per_eval);
    let base = figures(BASELINE_LABEL).map(|(e, _)| e);
    let latency = report.rows.iter().any(|r| per_eval(r).is_some_and(|(_, w)| w.latency.is_some()));
    let added: &[&str] =
        if latency { &[BUSIEST_PIPE, LATENCY, RESIDENT_WAVES, HIDDEN_LATENCY] } else { &[BUSIEST_PIPE] };
    for c in added {
        if !header.columns.iter().any(|x| x == c) {
            header.columns.push(c.to_string());
        }
    }
    let mut t = table(report, header, |row, _| per_eval(row).map(|(e, _)| e.cycles().1))?;
    for row in &mut t.rows {
        let Some((eval, wave)) = figures(&row.model) else { continue };
        row.stats.insert(BUSIEST_PIPE.into(), wave.throughput().1);
        if latency {
            row.stats.insert(LATENCY.into(), wave.latency.unwrap_or(f64::NAN));
            row.stats.insert(RESIDENT_WAVES.into(), wave.resident_waves.unwrap_or(f64::NAN));
            row.stats.insert(HIDDEN_LATENCY.into(), wave.hidden_latency().unwrap_or(f64::NAN));
        }
        let (bound, net) = match &base {
            Some(b) if row.model != BASELINE_LABEL => {
                row.net_terms = eval.added_terms(b);
                let (name, v) = eval.net(b);
                (name, Some(v))
            }
            _ => (eval.cycles().0, None),
        };
        row.net_cycles_per_eval = net;
        row.bound = Some(bound);
        row.terms = wave.terms();
    }
    Some(t)
}

/// A row's figures per evaluation and per wave: its own, or where the report prices its loops at their trip
/// count (`InspectReport::loop_trips`, `targets::trips`), each term per evaluation extrapolated from the two
/// fixed-pass compiles to the model's passes, the resident waves its own.
fn priced(
    report: &InspectReport,
    row: &Row,
    evaluations_of: &impl Fn(&Stats) -> Option<(Schedule, f64)>,
) -> Option<(Schedule, Schedule)> {
    let (own, evals) = evaluations_of(&row.stats)?;
    // Two compiles of one width (Intel's SIMD width may differ between compiles) at two counts of passes.
    let at_passes = report.loop_trips.iter().find(|t| t.model == row.model).and_then(|trips| {
        let fixed: Vec<(f64, Schedule, f64)> = trips
            .fixed
            .iter()
            .filter_map(|f| evaluations_of(&f.stats).map(|(s, e)| (f.passes, s.scaled(1.0 / e), e)))
            .collect();
        match fixed.as_slice() {
            [(pa, a, ea), (pb, b, eb)] if pa != pb && ea == eb => {
                Some(Schedule::extrapolated((*pa, a), (*pb, b), trips.passes, own.resident_waves))
            }
            _ => None,
        }
    });
    let Some(eval) = at_passes else { return Some((own.scaled(1.0 / evals), own)) };
    let wave = eval.scaled(evals);
    Some((eval, wave))
}
