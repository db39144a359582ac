//! `sweep --cost-device radv:FAMILY`: the sweep's accuracy-against-cost table, JSON and Pareto chart drawn
//! again with ACO's estimate of an AMD GPU's cost (SIMD cycles per evaluation, `inspect::aco`) in place of
//! the measured time. ACO's figures are deterministic: no CI, no noise, the same on every machine with the
//! same Mesa. The accuracy is the sweep's own (measured on the device that executed it).

use crate::chart::{self, Point};
use crate::gpu::targets::Target;
use crate::inspect::aco::AcoTable;
use crate::report::{self, Table};
use crate::sweep::{pareto_front, SweepReport};
use anyhow::Result;
use serde::Serialize;
use std::path::{Path, PathBuf};

#[derive(Clone, Debug, Serialize)]
pub struct AcoSweepRow {
    pub spec: String,
    pub canonical: String,
    pub label: String,
    pub instructions: f64,
    pub vgprs: f64,
    pub subgroups_per_simd: f64,
    pub cycles_per_eval: f64,
    pub net_cycles_per_eval: Option<f64>,
    /// cycles/eval over the cheapest spec's.
    pub cost_vs_fastest: f64,
    /// The measured cost ratio of the sweep (median), for reading the two side by side.
    pub measured_cost_vs_fastest: f64,
    pub accuracy: crate::accuracy::Accuracy,
    /// On ACO's frontier: no spec both cheaper (cycles) and more accurate (RMS vs exact).
    pub pareto: bool,
    /// On the measured sweep's frontier.
    pub measured_pareto: bool,
}

#[derive(Clone, Debug, Serialize)]
pub struct AcoSweep {
    pub family: String,
    pub architecture: String,
    pub device: String,
    pub driver: String,
    pub lights_per_kernel: u32,
    /// The measured sweep's device.
    pub measured_on: String,
    pub fastest: String,
    /// Sorted by cost.
    pub rows: Vec<AcoSweepRow>,
    /// Specs the family cannot compile (fp16 without shaderFloat16), with the reason.
    pub skipped: Option<String>,
}

/// ACO's cost of every spec of `sweep` for one family, with the sweep's accuracy.
pub fn build(sweep: &SweepReport, target: &Target, aco: &AcoTable, driver: &str, note: Option<&str>) -> Result<AcoSweep> {
    let mut rows: Vec<AcoSweepRow> = Vec::new();
    let mut skipped = Vec::new();
    for r in &sweep.rows {
        let Some(a) = aco.row(&r.spec) else {
            skipped.push(r.spec.clone());
            continue;
        };
        rows.push(AcoSweepRow {
            spec: r.spec.clone(),
            canonical: r.canonical.clone(),
            label: r.label.clone(),
            instructions: a.instructions,
            vgprs: a.vgprs,
            subgroups_per_simd: a.subgroups_per_simd,
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
    Ok(AcoSweep {
        family: target.family.into(),
        architecture: target.architecture.into(),
        device: aco.device.clone(),
        driver: driver.into(),
        lights_per_kernel: aco.lights_per_kernel,
        measured_on: sweep.profile.provenance.device.name.clone(),
        fastest: rows.first().map(|r| r.spec.clone()).unwrap_or_default(),
        rows,
        // The child's note names each spec with the reason; without one, the specs alone.
        skipped: (!skipped.is_empty()).then(|| note.map_or_else(|| format!("not compiled for {}: {}", target.family, skipped.join(", ")), str::to_string)),
    })
}

impl AcoSweep {
    pub fn table(&self) -> Table {
        let mut t = Table::new([
            "spec", "Instructions", "VGPRs", "Subgroups per SIMD", "cycles/eval", "net cycles/eval", "cost vs fastest", "measured cost vs fastest", "vs exact: max / RMS err", "Pareto (ACO)", "Pareto (measured)",
        ]);
        for r in &self.rows {
            t.row([
                r.spec.clone(),
                crate::inspect::format_value(r.instructions),
                crate::inspect::format_value(r.vgprs),
                crate::inspect::format_value(r.subgroups_per_simd),
                report::sig(r.cycles_per_eval, 4),
                r.net_cycles_per_eval.map_or("-".into(), |v| report::sig(v, 4)),
                format!("{:.3}", r.cost_vs_fastest),
                format!("{:.3}", r.measured_cost_vs_fastest),
                r.accuracy.vs_exact.cell(),
                if r.pareto { "yes".into() } else { String::new() },
                if r.measured_pareto { "yes".into() } else { String::new() },
            ]);
        }
        t
    }

    pub fn markdown(&self) -> String {
        format!(
            "# brdfprof sweep: cost on {} ({})\n\n{} ({}); cost = ACO's estimate, SIMD cycles per evaluation = Inverse Throughput / \
             (64 x {} lights per kernel), deterministic (no CI); relative to the cheapest spec ({}). Accuracy and the measured cost \
             ratio: the sweep on {}. Pareto (ACO): no spec both fewer cycles and more accurate (RMS vs exact).\n\n{}",
            self.family,
            self.architecture,
            self.device,
            self.driver,
            self.lights_per_kernel,
            self.fastest,
            self.measured_on,
            self.table().markdown()
        ) + &self.skipped.as_ref().map_or(String::new(), |s| format!("\n{s}\n"))
    }

    /// Writes `<stem>.md`, `.json` and `.png`; returns their paths.
    pub fn write(&self, stem: &Path) -> Result<Vec<PathBuf>> {
        report::write_md_json_png(stem, self, &self.markdown(), |png| self.chart(png))
    }

    pub fn chart(&self, path: &Path) -> Result<()> {
        let thesis: Vec<String> = crate::brdf::THESIS_MODELS.iter().map(|m| m.to_string()).collect();
        let group = |r: &AcoSweepRow| if r.canonical.contains("precision=f16") { 1 } else { 0 };
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
            })
            .collect();
        let front: Vec<(f64, f64)> = self.rows.iter().filter(|r| r.pareto).map(|r| (r.cost_vs_fastest, r.accuracy.vs_exact.rms)).collect();
        let legend = vec![(0, "fp32".to_string()), (1, "fp16".to_string())];
        let split = self.rows.iter().filter(|r| group(r) == 0).map(|r| r.cost_vs_fastest).fold(f64::NEG_INFINITY, f64::max);
        let title = format!("Accuracy against ACO's cost on {} ({}), {}", self.family, self.architecture, self.driver);
        let spec = chart::Scatter {
            title: &title,
            x_desc: "ACO cycles per evaluation relative to the cheapest spec (deterministic)",
            y_desc: "RMS relative error against the exact physical model",
            line: &front,
            legend: &legend,
            split_x: (self.rows.iter().any(|r| group(r) == 1) && split.is_finite()).then_some(split * 1.02),
        };
        chart::scatter_log_y(path, &spec, &points)
    }
}
