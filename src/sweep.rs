//! `brdfprof sweep`: what accuracy costs in time. A set of model specs is timed in one interleaved run (the
//! profile protocol) and measured for accuracy (`accuracy`), and the result is a table, a JSON file and a chart
//! of error against cost with the Pareto frontier.

pub mod view;

use crate::accuracy::{self, Accuracy, ExactCache, SampleSet};
use crate::brdf::spec::with_each_param_sample;
use crate::brdf::{ModelSpec, Precision, Vis, D, F, THESIS_MODELS};
use crate::chart::{self, Point};
use crate::gpu::Gpu;
use crate::model::Model;
use crate::profile::{self, ProfileOptions, ProfileReport};
use crate::results::{self, Table};
use crate::stats::{self, Estimate};
use anyhow::Result;
use indicatif::ProgressBar;
use serde::Serialize;
use std::path::Path;

/// The default set: every D with each of its sensible visibility terms and Schlick's Fresnel; every Fresnel
/// term on the reference preset (with each metal where it reads one); the exact physical models where the
/// library has the exact Smith term of a D (exact height-correlated Smith and the exact dielectric Fresnel),
/// which anchor the frontier at zero approximation error; the thesis models in fp16.
pub fn default_specs() -> Vec<ModelSpec> {
    let mut specs: Vec<ModelSpec> = Vec::new();
    let mut push = |s: ModelSpec| {
        if !specs.contains(&s) {
            specs.push(s);
        }
    };
    for &d in D::ALL {
        for vis in d.sensible_visibilities() {
            push(ModelSpec::new(d, vis, F::Schlick));
        }
    }
    let reference = ModelSpec::reference();
    for &f in F::ALL {
        for s in with_each_param_sample(ModelSpec { f, ..reference }) {
            push(s);
        }
    }
    let exact_dielectric = F::ALL.iter().copied().find(|f| f.row().is_exact && f.row().reads.is_empty()).expect("the table has an exact dielectric Fresnel");
    for &vis in Vis::ALL {
        if let Some(d) = vis.row().exact_for {
            push(ModelSpec::new(d, vis, exact_dielectric));
        }
    }
    for name in THESIS_MODELS {
        push(ModelSpec { precision: Precision::F16, ..ModelSpec::preset(name).unwrap() });
    }
    specs
}

/// A short label for charts: the model's `name=` label or a file's stem; else the preset name where one
/// matches, else d/vis/f.
pub fn label(model: &Model) -> String {
    let Some(spec) = model.twin().filter(|_| model.label() == model.name()) else { return model.label() };
    let name = spec.name();
    if !name.starts_with("d=") {
        return name.replace(",precision=f16", " f16");
    }
    let mut s = format!("{}/{}/{}", spec.d.name(), spec.vis.name(), spec.f_label());
    if spec.precision == Precision::F16 {
        s += " f16";
    }
    s
}

#[derive(Clone, Debug)]
pub struct SweepOptions {
    pub profile: ProfileOptions,
    /// What models without an f64 twin (`.brdf` files) are measured against (`--reference`; default ggx).
    pub reference: Model,
}

#[derive(Clone, Debug, Serialize)]
pub struct SweepRow {
    pub spec: String,
    pub canonical: String,
    pub label: String,
    pub ns_per_eval: Estimate,
    pub net_ns_per_eval: Option<Estimate>,
    /// Per-round cost over the fastest spec's.
    pub cost_vs_fastest: Estimate,
    /// 1 + the number of specs whose cost CI lies wholly below this one's.
    pub rank: usize,
    /// Another spec's cost CI overlaps this one's, so the two cannot be ranked.
    pub tied: bool,
    pub accuracy: Accuracy,
    /// No other spec is both cheaper (median cost) and more accurate (RMS error against the exact reference).
    pub pareto: bool,
}

#[derive(Clone, Debug, Serialize)]
pub struct SweepReport {
    pub fastest: String,
    /// Rows sorted by rank, then median cost.
    pub rows: Vec<SweepRow>,
    pub sample_set: String,
    pub profile: ProfileReport,
}

/// Indices of the points not dominated in (cost, error), both to be minimised.
pub fn pareto_front(points: &[(f64, f64)]) -> Vec<bool> {
    points
        .iter()
        .map(|&(c, e)| !points.iter().any(|&(c2, e2)| c2 <= c && e2 <= e && (c2 < c || e2 < e)))
        .collect()
}

pub fn run(gpu: &Gpu, options: &SweepOptions, progress: &ProgressBar) -> Result<SweepReport> {
    if options.profile.lights.len() != 1 {
        anyhow::bail!("--lights: a sweep ranks specs at one light count (`brdfprof profile --lights 1,8,64` compares counts)");
    }
    // Accuracy first, so that the profile's budget (the whole command's) accounts for it.
    let set = SampleSet::standard();
    if options.profile.models.iter().any(|m| m.twin().is_none()) {
        accuracy::check_reference(gpu, &options.reference, &set, &format!("--reference {}", options.reference.name()))?;
    }
    let mut cache = ExactCache::default();
    let n = options.profile.models.len();
    let mut accuracies = Vec::with_capacity(n);
    for (k, spec) in options.profile.models.iter().enumerate() {
        let against = if spec.twin().is_some() { "its f64 twin and exact references".to_string() } else { options.reference.name() };
        progress.set_message(format!("accuracy {}/{n}: {} against {against}", k + 1, spec.name()));
        accuracies.push(accuracy::measure(gpu, spec, &set, &mut cache, &options.reference)?);
    }
    let profile = profile::run(gpu, &options.profile, progress)?;
    let specs: Vec<(usize, Model)> = options
        .profile
        .models
        .iter()
        .map(|m| (profile.labels.iter().position(|l| *l == m.label()).expect("every spec was timed"), m.clone()))
        .collect();
    let evals = profile.rows[0].evaluations_per_dispatch as f64;
    let costs: Vec<Vec<f64>> = specs.iter().map(|(i, _)| profile::per_round(&profile.raw, *i, evals)).collect();
    let medians: Vec<f64> = specs.iter().map(|(i, _)| profile.rows[*i].vs_reference.median).collect();
    let fastest = (0..specs.len()).min_by(|&a, &b| medians[a].total_cmp(&medians[b])).unwrap();
    let mut rows = Vec::new();
    for (k, ((i, spec), accuracy)) in specs.iter().zip(accuracies).enumerate() {
        let ratio: Vec<f64> = costs[k].iter().zip(&costs[fastest]).map(|(a, f)| a / f).collect();
        let row = &profile.rows[*i];
        rows.push(SweepRow {
            spec: spec.name(),
            canonical: spec.canonical(),
            label: label(spec),
            ns_per_eval: row.ns_per_eval,
            net_ns_per_eval: row.net_ns_per_eval,
            cost_vs_fastest: stats::median_ci(&ratio, profile::LEVEL),
            rank: 0,
            tied: false,
            accuracy,
            pareto: false,
        });
    }
    let front = pareto_front(&rows.iter().map(|r| (r.cost_vs_fastest.median, r.accuracy.vs_exact.rms)).collect::<Vec<_>>());
    let cis: Vec<Estimate> = rows.iter().map(|r| r.cost_vs_fastest).collect();
    for (k, row) in rows.iter_mut().enumerate() {
        row.pareto = front[k];
        row.rank = 1 + cis.iter().filter(|c| c.hi < cis[k].lo).count();
        row.tied = cis.iter().enumerate().any(|(j, c)| j != k && c.overlaps(&cis[k]));
    }
    rows.sort_by(|a, b| a.rank.cmp(&b.rank).then(a.cost_vs_fastest.median.total_cmp(&b.cost_vs_fastest.median)));
    Ok(SweepReport {
        fastest: specs[fastest].1.name(),
        rows,
        sample_set: "10 strata each of roughness [0.1, 1], NoV and NoL [0.05, 1], azimuth [0, pi]; 10,000 samples, seed 2023; \
                     dielectric F0 (0.02, 0.04, 0.08) or (0.03, 0.05, 0.045); albedo cells NoV {0.1, 0.3, 0.5, 0.7, 0.9, 1} x r \
                     {0.1, 0.25, 0.5, 0.75, 1}, F0 0.04"
            .into(),
        profile,
    })
}

/// The numerical error's cell: max error against the spec's own f64 formula; for a `.brdf` file, against the
/// `--reference` spec's f64 formula, saying so (`- (vs FILE)` against another file, which has no formula).
fn numerical_cell(a: &accuracy::Accuracy) -> String {
    let against = a.reference.as_deref().map_or(String::new(), |r| format!(" (vs {r} f64)"));
    match &a.numerical {
        None => format!("- (vs {})", a.reference.as_deref().unwrap_or("?")),
        Some(n) if n.nonfinite > 0 => format!("{} NaN/Inf{against}", n.nonfinite),
        Some(n) => format!("{:.1e}{against}", n.max),
    }
}

impl SweepReport {
    pub fn table(&self) -> Table {
        let mut t = Table::new([
            "rank", "spec", "ns/eval [95% CI]", "net ns/eval", "cost vs fastest [95% CI]", "numerical max err", "vs exact: max / RMS err", "albedo err", "Pareto",
        ]);
        for r in &self.rows {
            let a = &r.accuracy;
            t.row([
                format!("{}{}", r.rank, if r.tied { "=" } else { "" }),
                r.spec.clone(),
                results::estimate(&r.ns_per_eval, 3),
                r.net_ns_per_eval.as_ref().map_or("-".into(), |e| results::sig(e.median, 3)),
                results::estimate(&r.cost_vs_fastest, 3),
                numerical_cell(a),
                a.vs_exact.cell(),
                format!("{:.1e}", a.albedo_vs_exact),
                if r.pareto { "yes".into() } else { String::new() },
            ]);
        }
        t
    }

    pub fn markdown(&self) -> String {
        format!(
            "# brdfprof sweep\n\n{}\n\nCost: per-round ratio to the fastest spec ({}), median and distribution-free 95% CI over {} rounds; \
             rank = 1 + the number of specs whose CI lies wholly below; `=` marks specs whose CI overlaps another's, so they \
             cannot be told apart. Errors are relative errors |x - ref| / max(|ref|, 1e-3) over the sample set ({}); numerical: \
             GPU against the same formula in f64 (a .brdf file: against the --reference spec's formula in f64, `vs SPEC f64`); \
             vs exact: GPU against the exact physical model (same D, exact height-correlated Smith G2, exact Fresnel; a .brdf \
             file: the --reference spec's exact model, or another file's GPU values); albedo: max |E_gpu - E_exact| over the albedo cells. Pareto: no spec is both cheaper and \
             more accurate (RMS vs exact).\n\n{}{}",
            self.profile.summary(),
            self.fastest,
            self.profile.rounds,
            self.sample_set,
            self.table().markdown(),
            self.profile.placement_notes()
        )
    }

    /// Writes sweep-<device>.md, .json and .png under `out`; returns their paths.
    pub fn write(&self, out: &Path, device: &str) -> Result<Vec<std::path::PathBuf>> {
        results::write_md_json_png(&out.join(format!("sweep-{device}")), results::Kind::Sweep, self, &self.markdown(), |png| self.chart(png))
    }

    /// Approximation error (RMS vs exact, log) against cost, every point labelled, the frontier drawn.
    pub fn chart(&self, path: &Path) -> Result<()> {
        // Colour by D, fp16 specs apart.
        let group = |r: &SweepRow| match Model::parse(&r.canonical).ok().as_ref().and_then(Model::twin) {
            Some(spec) if spec.precision == Precision::F32 => spec.d as usize,
            _ => D::ALL.len(),
        };
        let thesis: Vec<String> = THESIS_MODELS.iter().map(|m| m.to_string()).collect();
        let points: Vec<Point> = self
            .rows
            .iter()
            .map(|r| Point {
                x: r.cost_vs_fastest.median,
                x_lo: r.cost_vs_fastest.lo,
                x_hi: r.cost_vs_fastest.hi,
                y: r.accuracy.vs_exact.rms,
                label: r.label.clone(),
                group: group(r),
                highlight: r.pareto || thesis.contains(&r.spec),
            })
            .collect();
        let mut front: Vec<(f64, f64)> = self.rows.iter().filter(|r| r.pareto).map(|r| (r.cost_vs_fastest.median, r.accuracy.vs_exact.rms)).collect();
        front.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut legend: Vec<(usize, String)> = D::ALL.iter().map(|d| (*d as usize, format!("D = {}", d.name()))).collect();
        legend.push((D::ALL.len(), "fp16, other models".into()));
        // fp16 (and anything beyond the costliest fp32 spec) goes to the side panel.
        let split = self
            .rows
            .iter()
            .filter(|r| !r.canonical.contains("precision=f16"))
            .map(|r| r.cost_vs_fastest.median)
            .fold(f64::NEG_INFINITY, f64::max);
        let title = format!("Accuracy against cost on {} ({} evaluations per dispatch)", self.profile.provenance.device.name, self.profile.rows[0].evaluations_per_dispatch);
        let spec = chart::Scatter {
            title: &title,
            x_desc: "cost relative to the fastest spec (median of per-round ratios, 95% CI whiskers)",
            y_desc: "RMS relative error against the exact physical model",
            line: &front,
            legend: &legend,
            split_x: Some(split * 1.02),
        };
        chart::scatter_log_y(path, &spec, &points)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_sweep_covers_every_term() {
        let specs = default_specs();
        for d in D::ALL {
            assert!(specs.iter().any(|s| s.d == *d), "{d:?}");
        }
        for v in Vis::ALL {
            assert!(specs.iter().any(|s| s.vis == *v), "{v:?}");
        }
        for f in F::ALL {
            for variant in with_each_param_sample(ModelSpec { f: *f, ..ModelSpec::reference() }) {
                assert!(specs.contains(&variant), "{}", variant.name());
            }
        }
        for name in THESIS_MODELS {
            let s = ModelSpec { precision: Precision::F16, ..ModelSpec::preset(name).unwrap() };
            assert!(specs.contains(&s));
        }
        let mut names: Vec<String> = specs.iter().map(|s| s.name()).collect();
        names.sort();
        names.dedup();
        assert_eq!(names.len(), specs.len(), "no spec twice");
    }

    #[test]
    fn pareto_front_keeps_only_undominated_points() {
        let front = pareto_front(&[(1.0, 0.5), (2.0, 0.1), (1.5, 0.6), (3.0, 0.1), (0.9, 0.9)]);
        assert_eq!(front, vec![true, true, false, false, true]);
    }
}
