//! `sweep --cost-device TARGET`: the sweep's accuracy-against-cost table, JSON and Pareto chart drawn again
//! with a compile-only target's modelled cost (cycles per evaluation, `targets::cost`) in place of the measured
//! time. Those figures are deterministic: no CI, no noise, the same on every machine with the same compiler.
//! The accuracy is the sweep's own (measured on the device that executed it).

use super::{SweepReport, pareto_front};
use crate::export::json;
use crate::export::markdown::{self, Table};
use crate::export::png::{self, Point};
use crate::schema::cost::TargetCost;
use anyhow::Result;
use serde::Serialize;
use std::path::{Path, PathBuf};

#[derive(Clone, Debug, Serialize)]
pub struct CostSweepRow {
    pub spec: String,
    pub canonical: String,
    pub label: String,
    /// The target's statistics the table shows (`TargetCost::columns` chosen by the vendor).
    pub stats: std::collections::BTreeMap<String, f64>,
    pub cycles_per_eval: f64,
    pub net_cycles_per_eval: Option<f64>,
    /// cycles/eval over the cheapest spec's.
    pub cost_vs_fastest: f64,
    /// The measured cost ratio of the sweep (median), for reading the two side by side.
    pub measured_cost_vs_fastest: f64,
    pub accuracy: crate::accuracy::Accuracy,
    /// On the target's frontier: no spec both cheaper (cycles) and more accurate (RMS vs exact).
    pub pareto: bool,
    /// On the measured sweep's frontier.
    pub measured_pareto: bool,
}

#[derive(Clone, Debug, Serialize)]
pub struct CostSweep {
    /// `radv:navi21`, `nvidia:sm_89`, and the family alone.
    pub target: String,
    pub family: String,
    pub architecture: String,
    pub device: String,
    pub compiler: String,
    pub model: String,
    pub unit: String,
    /// The statistics each row shows, in order.
    pub columns: Vec<String>,
    pub lights_per_kernel: u32,
    /// The measured sweep's device.
    pub measured_on: String,
    pub fastest: String,
    /// Sorted by cost.
    pub rows: Vec<CostSweepRow>,
    /// Specs the family cannot compile (fp16 without shaderFloat16), with the reason.
    pub skipped: Option<String>,
    /// The sweep's "vs exact" reference in words, and the chart's error axis.
    pub against: String,
    pub error_axis: String,
}

/// The target's cost of every spec of `sweep`, with the sweep's accuracy.
pub fn build(sweep: &SweepReport, target: &str, cost: &TargetCost, note: Option<&str>) -> Result<CostSweep> {
    let mut rows: Vec<CostSweepRow> = Vec::new();
    let mut skipped = Vec::new();
    let mut failed = Vec::new();
    for r in &sweep.rows {
        // The target's rows are named by the model's label (a file's `name=`, or its stem), as every table is.
        let Some(a) = cost.row(&r.label).or_else(|| cost.row(&r.spec)) else {
            match cost.failed.iter().find(|(m, _)| *m == r.label || *m == r.spec) {
                Some((_, why)) => failed.push(format!("{} failed on {target}: {why}", r.spec)),
                None => skipped.push(r.spec.clone()),
            }
            continue;
        };
        rows.push(CostSweepRow {
            spec: r.spec.clone(),
            canonical: r.canonical.clone(),
            label: r.label.clone(),
            stats: a.stats.clone(),
            cycles_per_eval: a.cycles_per_eval,
            net_cycles_per_eval: a.net_cycles_per_eval,
            cost_vs_fastest: 0.0,
            measured_cost_vs_fastest: r.cost_vs_fastest.median,
            accuracy: r.accuracy.clone(),
            pareto: false,
            measured_pareto: r.pareto,
        });
    }
    let fastest = rows.iter().map(|r| r.cycles_per_eval).fold(f64::INFINITY, f64::min);
    for r in &mut rows {
        r.cost_vs_fastest = r.cycles_per_eval / fastest;
    }
    let front = pareto_front(&rows.iter().map(|r| (r.cycles_per_eval, r.accuracy.vs_exact.rms)).collect::<Vec<_>>());
    for (r, f) in rows.iter_mut().zip(front) {
        r.pareto = f;
    }
    rows.sort_by(|a, b| a.cycles_per_eval.total_cmp(&b.cycles_per_eval).then(a.spec.cmp(&b.spec)));
    Ok(CostSweep {
        target: target.into(),
        family: cost.family.clone().unwrap_or_else(|| target.into()),
        architecture: cost.architecture.clone().unwrap_or_default(),
        device: cost.device.clone(),
        compiler: cost.compiler.clone(),
        model: cost.model.clone(),
        unit: cost.unit.clone(),
        columns: cost.columns.clone(),
        lights_per_kernel: cost.lights_per_kernel,
        measured_on: sweep.profile.provenance.device.name.clone(),
        fastest: rows.first().map(|r| r.spec.clone()).unwrap_or_default(),
        rows,
        // The child's note names each spec with the reason; without one, the specs alone.
        // A spec that failed on the target (its translation's check, its compile) is named with its reason.
        skipped: {
            let not_compiled = (!skipped.is_empty()).then(|| {
                note.map_or_else(|| format!("not compiled for {target}: {}", skipped.join(", ")), str::to_string)
            });
            let all: Vec<String> = not_compiled.into_iter().chain(failed).collect();
            (!all.is_empty()).then(|| all.join("; "))
        },
        against: sweep.against.clone(),
        error_axis: super::error_axis(sweep.exact, &sweep.rows),
    })
}

impl CostSweep {
    pub fn table(&self) -> Table {
        let mut headers: Vec<String> = vec!["spec".into()];
        headers.extend(self.columns.iter().cloned());
        headers.extend(
            [
                "cycles/eval",
                "net cycles/eval",
                "cost vs fastest",
                "measured cost vs fastest",
                "vs exact: max / RMS err",
                "Pareto (target)",
                "Pareto (measured)",
            ]
            .map(String::from),
        );
        let mut t = Table::new(headers);
        for r in &self.rows {
            // The model's label (`name=`, a file's stem) as every table names it; the spec is in the JSON.
            let mut cells = vec![r.label.clone()];
            cells.extend(
                self.columns.iter().map(|c| r.stats.get(c).map_or("-".into(), |v| crate::schema::format_value(*v))),
            );
            cells.extend([
                markdown::sig(r.cycles_per_eval, 4),
                r.net_cycles_per_eval.map_or("-".into(), |v| markdown::sig(v, 4)),
                format!("{:.3}", r.cost_vs_fastest),
                format!("{:.3}", r.measured_cost_vs_fastest),
                r.accuracy.vs_exact.cell(),
                if r.pareto { "yes".into() } else { String::new() },
                if r.measured_pareto { "yes".into() } else { String::new() },
            ]);
            t.row(cells);
        }
        t
    }

    pub fn markdown(&self) -> String {
        format!(
            "# brdfprof sweep: cost on {} ({})\n\n{} ({}); cost = {}'s estimate, {} per evaluation ({}; {} lights per kernel), \
             deterministic (no CI); relative to the cheapest spec ({}). Accuracy and the measured cost ratio: the sweep on {}. \
             vs exact: against {}. Pareto (target): no spec both fewer cycles and more accurate (RMS vs exact).\n\n{}",
            self.family,
            self.architecture,
            self.device,
            self.target,
            self.compiler,
            self.unit,
            self.model,
            self.lights_per_kernel,
            self.fastest,
            self.measured_on,
            self.against,
            self.table().markdown()
        ) + &self.skipped.as_ref().map_or(String::new(), |s| format!("\n{s}\n"))
    }

    /// Writes `<stem>.md`, `.json` and `.png`; returns their paths.
    pub fn write(&self, stem: &Path) -> Result<Vec<PathBuf>> {
        json::write_md_json_png(stem, json::Kind::SweepCost, self, &self.markdown(), |png| self.chart(png))
    }

    pub fn chart(&self, path: &Path) -> Result<()> {
        let thesis: Vec<String> = crate::brdf::THESIS_MODELS.iter().map(|m| m.to_string()).collect();
        let group = |r: &CostSweepRow| if r.canonical.contains("precision=f16") { 1 } else { 0 };
        let points: Vec<Point> = self
            .rows
            .iter()
            .map(|r| Point {
                x: r.cost_vs_fastest,
                x_lo: r.cost_vs_fastest,
                x_hi: r.cost_vs_fastest,
                y: r.accuracy.vs_exact.rms,
                label: r.label.clone(),
                group: group(r),
                highlight: r.pareto || thesis.contains(&r.spec),
                edge: false,
            })
            .collect();
        let front: Vec<(f64, f64)> =
            self.rows.iter().filter(|r| r.pareto).map(|r| (r.cost_vs_fastest, r.accuracy.vs_exact.rms)).collect();
        let legend = vec![(0, "fp32".to_string()), (1, "fp16".to_string())];
        let split =
            self.rows.iter().filter(|r| group(r) == 0).map(|r| r.cost_vs_fastest).fold(f64::NEG_INFINITY, f64::max);
        let title = format!("Accuracy against {}'s cost on {} ({})", self.compiler, self.target, self.architecture);
        let x_desc = format!("{} cycles per evaluation relative to the cheapest spec (deterministic)", self.compiler);
        let spec = png::Scatter {
            title: &title,
            x_desc: &x_desc,
            y_desc: &self.error_axis,
            line: &front,
            legend: &legend,
            split_x: (self.rows.iter().any(|r| group(r) == 1) && split.is_finite()).then_some(split * 1.02),
        };
        png::scatter_log_y(path, &spec, &points)
    }
}

/// The specs on the accuracy-cost frontier of several targets: with `sweep --cost-device A --cost-device B ...`,
/// which specs every target's frontier holds (a choice no vendor's compiler overturns), and which only some do
/// (where the choice depends on the GPU).
#[derive(Clone, Debug, Serialize)]
pub struct Frontiers {
    /// The targets, in `--cost-device` order.
    pub targets: Vec<String>,
    /// Every spec on at least one frontier, by label: on which targets' frontiers (in `targets` order).
    pub rows: Vec<FrontierRow>,
    /// Labels on every target's frontier, and on some but not all.
    pub on_every: Vec<String>,
    pub on_some: Vec<String>,
    /// The measured sweep's frontier (its device), for comparison.
    pub measured_on: String,
}

#[derive(Clone, Debug, Serialize)]
pub struct FrontierRow {
    pub label: String,
    pub spec: String,
    pub on: Vec<bool>,
    pub measured: bool,
}

impl Frontiers {
    /// The frontiers of `sweeps` (one per target, each built by `build`).
    pub fn of(sweeps: &[CostSweep]) -> Frontiers {
        let mut rows: Vec<FrontierRow> = Vec::new();
        for (k, s) in sweeps.iter().enumerate() {
            for r in s.rows.iter().filter(|r| r.pareto) {
                if !rows.iter().any(|x| x.label == r.label) {
                    rows.push(FrontierRow {
                        label: r.label.clone(),
                        spec: r.spec.clone(),
                        on: vec![false; sweeps.len()],
                        measured: r.measured_pareto,
                    });
                }
                rows.iter_mut().find(|x| x.label == r.label).expect("just added").on[k] = true;
            }
        }
        rows.sort_by(|a, b| {
            b.on.iter().filter(|o| **o).count().cmp(&a.on.iter().filter(|o| **o).count()).then(a.label.cmp(&b.label))
        });
        let on_every = rows.iter().filter(|r| r.on.iter().all(|o| *o)).map(|r| r.label.clone()).collect();
        let on_some = rows.iter().filter(|r| !r.on.iter().all(|o| *o)).map(|r| r.label.clone()).collect();
        Frontiers {
            targets: sweeps.iter().map(|s| s.target.clone()).collect(),
            rows,
            on_every,
            on_some,
            measured_on: sweeps.first().map(|s| s.measured_on.clone()).unwrap_or_default(),
        }
    }

    pub fn markdown(&self) -> String {
        let mut headers: Vec<String> = vec!["spec".into()];
        headers.extend(self.targets.iter().cloned());
        headers.push(format!("measured ({})", self.measured_on));
        let mut t = Table::new(headers);
        for r in &self.rows {
            let mut cells = vec![r.label.clone()];
            cells.extend(r.on.iter().map(|o| if *o { "yes".to_string() } else { String::new() }));
            cells.push(if r.measured { "yes".into() } else { String::new() });
            t.row(cells);
        }
        let list = |v: &[String]| if v.is_empty() { "none".to_string() } else { v.join(", ") };
        format!(
            "# brdfprof sweep: the accuracy-cost frontiers of {} targets

A spec is on a target's frontier when no other spec is both cheaper there (its compiler's cycles per evaluation) and more accurate (RMS vs exact, the same sample set for every target).

- On every target's frontier: {}
- On some targets' only: {}

{}",
            self.targets.len(),
            list(&self.on_every),
            list(&self.on_some),
            t.markdown()
        )
    }

    /// Writes `<stem>.md` and `.json`; returns their paths.
    pub fn write(&self, stem: &Path) -> Result<Vec<PathBuf>> {
        let (md, json) = (stem.with_extension("md"), stem.with_extension("json"));
        json::write_report_compact(&json, json::Kind::SweepFrontiers, self)?;
        crate::io::write_markdown(&md, &self.markdown())?;
        Ok(vec![md, json])
    }
}
