//! `brdfprof sweep`: what accuracy costs in time. A set of model specs is timed in one interleaved run (the
//! profile protocol) and measured for accuracy (`accuracy`), and the result is a table, a JSON file and a chart
//! of error against cost with the Pareto frontier.

pub mod cost;

use crate::accuracy::{self, Accuracy, ExactCache, SampleSet};
use crate::brdf::exact::ExactFresnel;
use crate::brdf::samples::SampleDomain;
use crate::brdf::spec::with_each_param_sample;
use crate::brdf::{D, F, ModelSpec, Precision, THESIS_MODELS, Vis};
use crate::export::json;
use crate::export::markdown::{self, Table};
use crate::export::png::{self, Point};
use crate::gpu::Gpu;
use crate::model::Model;
use crate::profile::{self, ProfileOptions, ProfileReport};
use crate::stats::{self, Estimate};
use anyhow::Result;
use indicatif::ProgressBar;
use serde::{Deserialize, Serialize};
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
    let exact_dielectric = F::ALL
        .iter()
        .copied()
        .find(|f| f.row().is_exact && f.row().reads.is_empty())
        .expect("the table has an exact dielectric Fresnel");
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
    pub accuracy: AccuracyOptions,
}

/// What the accuracy half of a sweep measures against, and where.
#[derive(Clone, Debug)]
pub struct AccuracyOptions {
    /// What every model is measured against (`--reference`); None: a spec against its own exact model, a
    /// `.brdf` file against the reference it declares, else `DEFAULT_FILE_REFERENCE`.
    pub reference: Option<Model>,
    pub exact_fresnel: ExactFresnel,
    /// The sample set's ranges, and the words saying where each comes from (a flag, the files' domains).
    pub domain: SampleDomain,
    pub domain_why: [String; 3],
    /// `--f0`: None keeps the set's dielectric F0.
    pub f0: Option<crate::brdf::f0::F0Set>,
}

impl Default for AccuracyOptions {
    fn default() -> Self {
        AccuracyOptions {
            reference: None,
            exact_fresnel: ExactFresnel::Physical,
            domain: accuracy::STANDARD_DOMAIN,
            domain_why: Default::default(),
            f0: None,
        }
    }
}

/// A `.brdf` file that names no reference, with no `--reference`, is measured against this preset's exact model.
pub const DEFAULT_FILE_REFERENCE: &str = "ggx";

impl AccuracyOptions {
    /// The sample set, with where its ranges come from.
    pub fn sample_set_words(&self) -> String {
        let why: Vec<String> = ["roughness", "NoV", "NoL"]
            .iter()
            .zip(&self.domain_why)
            .filter(|(_, w)| !w.trim().is_empty())
            .map(|(axis, w)| format!("{axis}: {}", w.trim().trim_start_matches('(').trim_end_matches(')')))
            .collect();
        let set = SampleSet::within(self.domain, self.f0).describe();
        if why.is_empty() { set } else { format!("{set}; {}", why.join("; ")) }
    }

    /// What "vs exact" measures against, in words.
    pub fn against_words(&self) -> String {
        let exact = self.exact_fresnel.describe();
        match &self.reference {
            Some(r) if r.twin().is_some() => format!("{}'s {exact}, for every model (--reference)", r.label()),
            Some(r) => format!("{}'s GPU values, for every model (--reference)", r.label()),
            None => format!(
                "each spec's {exact}; a .brdf file: the {exact} of the reference it names, else of {DEFAULT_FILE_REFERENCE}"
            ),
        }
    }

    /// What `model` is measured against: None for its own exact model.
    pub fn reference_of(&self, model: &Model) -> Option<Model> {
        if let Some(r) = &self.reference {
            return Some(r.clone());
        }
        if model.twin().is_some() {
            return None;
        }
        Some(
            model
                .declared_reference()
                .map(Model::spec)
                .unwrap_or_else(|| Model::parse(DEFAULT_FILE_REFERENCE).expect("the default reference is a preset")),
        )
    }
}

/// A sweep report is read back (`report`, `--html`) as these same types.
#[derive(Clone, Debug, Serialize, Deserialize)]
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

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct SweepReport {
    pub fastest: String,
    /// Rows sorted by rank, then median cost.
    pub rows: Vec<SweepRow>,
    pub sample_set: String,
    /// What "vs exact" is against (`--reference`, `--exact-fresnel`), in words; empty in a report written
    /// before the sweep took a reference for every model.
    #[serde(default)]
    pub against: String,
    #[serde(skip_deserializing)]
    pub exact: ExactFresnel,
    pub profile: ProfileReport,
}

/// Indices of the points not dominated in (cost, error), both to be minimised.
pub fn pareto_front(points: &[(f64, f64)]) -> Vec<bool> {
    points.iter().map(|&(c, e)| !points.iter().any(|&(c2, e2)| c2 <= c && e2 <= e && (c2 < c || e2 < e))).collect()
}

pub fn run(gpu: &Gpu, options: &SweepOptions, progress: &ProgressBar) -> Result<SweepReport> {
    if options.profile.lights.len() != 1 {
        anyhow::bail!(
            "--lights: a sweep ranks specs at one light count (`brdfprof profile --lights 1,8,64` compares counts)"
        );
    }
    // Accuracy first, so that the profile's budget (the whole command's) accounts for it.
    let accuracies = measure_accuracy(gpu, &options.profile.models, &options.accuracy, progress)?;
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
    let front =
        pareto_front(&rows.iter().map(|r| (r.cost_vs_fastest.median, r.accuracy.vs_exact.rms)).collect::<Vec<_>>());
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
        sample_set: options.accuracy.sample_set_words(),
        against: options.accuracy.against_words(),
        exact: options.accuracy.exact_fresnel,
        profile,
    })
}

/// The error axis's words: against the exact models with the Fresnel chosen, or the one reference every row
/// names.
pub fn error_axis(exact: ExactFresnel, rows: &[SweepRow]) -> String {
    let mut named: Vec<&str> = rows.iter().filter_map(|r| r.accuracy.reference.as_deref()).collect();
    named.sort_unstable();
    named.dedup();
    match (named.as_slice(), rows.iter().all(|r| r.accuracy.reference.is_some())) {
        ([one], true) => format!("RMS relative error against {one}'s exact model"),
        _ if exact == ExactFresnel::Own => {
            "RMS relative error against the exact model with each spec's own Fresnel".into()
        }
        _ => "RMS relative error against the exact physical model".into(),
    }
}

/// Every model's accuracy over the options' sample set, each against what `reference_of` says.
fn measure_accuracy(
    gpu: &Gpu,
    models: &[Model],
    options: &AccuracyOptions,
    progress: &ProgressBar,
) -> Result<Vec<Accuracy>> {
    let set = SampleSet::within(options.domain, options.f0);
    let references: Vec<Option<Model>> = models.iter().map(|m| options.reference_of(m)).collect();
    let mut checked: Vec<String> = Vec::new();
    for r in references.iter().flatten() {
        if !checked.contains(&r.name()) {
            let flag = if options.reference.is_some() { "--reference" } else { "reference" };
            accuracy::check_reference(gpu, r, &set, &format!("{flag} {}", r.name()))?;
            checked.push(r.name());
        }
    }
    let mut cache = ExactCache::new(options.exact_fresnel);
    let n = models.len();
    let mut out = Vec::with_capacity(n);
    for (k, (model, reference)) in models.iter().zip(&references).enumerate() {
        let against = reference.as_ref().map_or("its f64 twin and exact model".to_string(), Model::name);
        progress.set_message(format!("accuracy {}/{n}: {} against {against}", k + 1, model.name()));
        out.push(accuracy::measure(gpu, model, &set, &mut cache, reference.as_ref())?);
    }
    Ok(out)
}

/// The numerical error's cell: max error against the spec's own f64 formula; for a `.brdf` file, against the
/// `--reference` spec's f64 formula, saying so (`- (vs FILE)` against another file, which has no formula).
fn numerical_cell(a: &accuracy::Accuracy) -> String {
    // A spec's numerical error is against its own twin whatever its reference; a file's against the reference's.
    let against = a
        .reference
        .as_deref()
        .filter(|_| a.formula_vs_exact.is_none())
        .map_or(String::new(), |r| format!(" (vs {r} f64)"));
    match &a.numerical {
        None => format!("- (vs {})", a.reference.as_deref().unwrap_or("?")),
        Some(n) if n.nonfinite > 0 => format!("{} NaN/Inf{against}", n.nonfinite),
        Some(n) => format!("{:.1e}{against}", n.max),
    }
}

impl SweepReport {
    pub fn table(&self) -> Table {
        let mut t = Table::new([
            "rank",
            "spec",
            "ns/eval [95% CI]",
            "net ns/eval",
            "cost vs fastest [95% CI]",
            "numerical max err",
            "vs exact: max / RMS err",
            "albedo err",
            "Pareto",
        ]);
        for r in &self.rows {
            let a = &r.accuracy;
            t.row([
                format!("{}{}", r.rank, if r.tied { "=" } else { "" }),
                r.spec.clone(),
                markdown::estimate(&r.ns_per_eval, 3),
                r.net_ns_per_eval.as_ref().map_or("-".into(), |e| markdown::sig(e.median, 3)),
                markdown::estimate(&r.cost_vs_fastest, 3),
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
             vs exact: GPU against {}; albedo: max |E_gpu - E_exact| over the albedo cells. Pareto: no spec is both cheaper and \
             more accurate (RMS vs exact).\n\n{}{}",
            self.profile.summary(),
            self.fastest,
            self.profile.rounds,
            self.sample_set,
            self.against,
            self.table().markdown(),
            self.profile.placement_notes()
        )
    }

    /// Writes sweep-<device>.md, .json and .png under `out`; returns their paths.
    pub fn write(&self, out: &Path, device: &str) -> Result<Vec<std::path::PathBuf>> {
        json::write_md_json_png(
            &out.join(format!("sweep-{device}")),
            json::Kind::Sweep,
            self,
            &self.markdown(),
            |png| self.chart(png),
        )
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
                edge: false,
            })
            .collect();
        let mut front: Vec<(f64, f64)> = self
            .rows
            .iter()
            .filter(|r| r.pareto)
            .map(|r| (r.cost_vs_fastest.median, r.accuracy.vs_exact.rms))
            .collect();
        front.sort_by(|a, b| a.0.total_cmp(&b.0));
        let mut legend: Vec<(usize, String)> =
            D::ALL.iter().map(|d| (*d as usize, format!("D = {}", d.name()))).collect();
        legend.push((D::ALL.len(), "fp16, other models".into()));
        // fp16 (and anything beyond the costliest fp32 spec) goes to the side panel.
        let split = self
            .rows
            .iter()
            .filter(|r| !r.canonical.contains("precision=f16"))
            .map(|r| r.cost_vs_fastest.median)
            .fold(f64::NEG_INFINITY, f64::max);
        let title = format!(
            "Accuracy against cost on {} ({} evaluations per dispatch)",
            self.profile.provenance.device.name, self.profile.rows[0].evaluations_per_dispatch
        );
        let y_desc = error_axis(self.exact, &self.rows);
        let spec = png::Scatter {
            title: &title,
            x_desc: "cost relative to the fastest spec (median of per-round ratios, 95% CI whiskers)",
            y_desc: &y_desc,
            line: &front,
            legend: &legend,
            split_x: Some(split * 1.02),
        };
        png::scatter_log_y(path, &spec, &points)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The committed sweep chart, drawn from the committed JSON (`BLESS=1` writes it back to
    /// results/, so the picture always shows the JSON's figures).
    #[test]
    fn the_committed_sweep_chart_draws_from_its_json() {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
        let text = std::fs::read_to_string(root.join("results/sweep-llvmpipe.json")).unwrap();
        let report: SweepReport = serde_json::from_str(&text).unwrap();
        let dir = tempfile::tempdir().unwrap();
        let out = crate::export::png::blessed_or_scratch("sweep-llvmpipe.png", dir.path());
        report.chart(&out).unwrap();
        let img = image::open(&out).unwrap();
        assert!(img.width() > 1000 && img.height() > 800);
    }

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
