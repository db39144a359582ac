//! How accurate a model spec is, measured on the GPU: its numerical error (GPU result against the same
//! formula in f64) and its error against the exact physical reference (`brdf::exact`), as max and RMS relative
//! error over a fixed, seeded, stratified sample set, plus the error of its directional albedo.

pub mod albedo;

use crate::brdf::exact::{self, Lambda};
use crate::brdf::{samples, ModelSpec, Sample, D, F};
use crate::gpu::Gpu;
use crate::kernels::{self, AlbedoCell, RunLimits};
use crate::model::Model;
use anyhow::Result;
use rayon::prelude::*;
use serde::Serialize;
use std::collections::HashMap;

/// Relative error |x - reference| / max(|reference|, FLOOR), the measure used everywhere.
pub const FLOOR: f64 = 1e-3;

pub fn rel_err(x: f64, reference: f64) -> f64 {
    let e = (x - reference).abs() / reference.abs().max(FLOOR);
    if e.is_nan() { f64::INFINITY } else { e }
}

#[derive(Clone, Debug, Default, Serialize)]
pub struct ErrorStats {
    /// Over every value; a NaN or Inf value counts as an infinite error (`nonfinite` says how many there are).
    pub max: f64,
    pub rms: f64,
    /// The sample with the largest error.
    pub worst: String,
    /// Values (samples x channels) that are NaN or Inf.
    pub nonfinite: usize,
    /// Values compared.
    pub values: usize,
}

impl ErrorStats {
    /// Over every channel of every sample.
    pub fn of(samples: &[Sample], got: &[[f64; 3]], reference: &[[f64; 3]]) -> Self {
        let mut stats = ErrorStats::default();
        let mut sum_sq = 0.0;
        for (i, (g, r)) in got.iter().zip(reference).enumerate() {
            for c in 0..3 {
                stats.values += 1;
                stats.nonfinite += !g[c].is_finite() as usize;
                let e = rel_err(g[c], r[c]);
                sum_sq += e * e;
                if e > stats.max || stats.worst.is_empty() {
                    stats.max = e;
                    stats.worst = format!("{:?} channel {c}: {} vs {}", samples[i], g[c], r[c]);
                }
            }
        }
        stats.rms = (sum_sq / (3 * got.len()).max(1) as f64).sqrt();
        stats
    }

    /// "max / RMS" as a table cell, or how many values are NaN or Inf (which make both infinite).
    pub fn cell(&self) -> String {
        if self.nonfinite > 0 {
            format!("{} of {} values NaN/Inf", self.nonfinite, self.values)
        } else {
            format!("{:.1e} / {:.1e}", self.max, self.rms)
        }
    }
}

/// Refuses a reference that is not finite on the sample set or the albedo cells: every error against it
/// would be NaN or infinite. `what` names it (`--reference FILE`).
pub fn check_reference(gpu: &Gpu, reference: &Model, set: &SampleSet, what: &str) -> Result<()> {
    if reference.twin().is_some() {
        return Ok(()); // a spec's exact f64 model
    }
    let values = kernels::eval(gpu, reference, &set.samples, RunLimits::default())?;
    let bad = values.iter().flatten().filter(|x| !x.is_finite()).count();
    let albedo = kernels::albedo(gpu, reference, &set.cells)?;
    let bad_albedo = albedo.iter().flat_map(|a| a.e).filter(|x| !x.is_finite()).count();
    if bad + bad_albedo > 0 {
        anyhow::bail!(
            "{what}: the reference is not finite: {bad} of {} values on the sample set and {bad_albedo} of {} albedo values are NaN or Inf, so every error against it would be too. Give a reference that is finite everywhere",
            3 * values.len(),
            3 * albedo.len()
        );
    }
    Ok(())
}

/// The fixed sample set: 10 strata each in roughness [0.1, 1], NoV and NoL [0.05, 1] and azimuth [0, pi]
/// (10,000 samples, seed 2023), and the albedo cells NoV x roughness.
pub struct SampleSet {
    pub samples: Vec<Sample>,
    pub cells: Vec<AlbedoCell>,
}

pub const ALBEDO_NOV: [f32; 6] = [0.1, 0.3, 0.5, 0.7, 0.9, 1.0];
pub const ALBEDO_ROUGHNESS: [f32; 5] = [0.1, 0.25, 0.5, 0.75, 1.0];

impl SampleSet {
    pub fn standard() -> Self {
        let cells = ALBEDO_ROUGHNESS
            .iter()
            .flat_map(|&roughness| ALBEDO_NOV.iter().map(move |&nov| AlbedoCell { nov, roughness, f0: [0.04; 3] }))
            .collect();
        SampleSet { samples: samples::stratified(10, 2023, 0.05, 0.1..1.0), cells }
    }
}

/// What the exact reference of a spec depends on: its D with the parameters it reads, and its exact Fresnel
/// with the parameters that reads (a dielectric from F0, or a given metal). Specs differing only in Vis or in
/// their Fresnel approximation share it.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
struct ExactKey {
    d: D,
    f: F,
    params: Vec<u64>,
}

impl ExactKey {
    fn of(spec: &ModelSpec) -> Self {
        let f = spec.exact_fresnel();
        let reads = spec.d.row().reads.iter().chain(f.row().reads);
        ExactKey { d: spec.d, f, params: reads.map(|&p| spec.params.get(p).bits()).collect() }
    }
}

/// Exact values and albedos over a sample set, computed once per `ExactKey`.
#[derive(Default)]
pub struct ExactCache {
    values: HashMap<ExactKey, Vec<[f64; 3]>>,
    albedo: HashMap<ExactKey, Vec<[f64; 3]>>,
}

impl ExactCache {
    fn values(&mut self, spec: &ModelSpec, set: &SampleSet) -> &Vec<[f64; 3]> {
        self.values.entry(ExactKey::of(spec)).or_insert_with(|| set.samples.par_iter().map(|s| exact::eval(spec, s)).collect())
    }

    fn albedo(&mut self, spec: &ModelSpec, set: &SampleSet) -> &Vec<[f64; 3]> {
        self.albedo.entry(ExactKey::of(spec)).or_insert_with(|| set.cells.par_iter().map(|cell| albedo_exact(spec, cell)).collect())
    }
}

#[derive(Clone, Debug, Serialize)]
pub struct Accuracy {
    /// GPU result against the same formula in f64; for a model without a twin (a `.brdf` file) measured
    /// against a spec (`reference`), against that spec's own f64 formula; None against another `.brdf` file.
    pub numerical: Option<ErrorStats>,
    /// GPU result against the exact physical reference: what a user of the spec gets. For a model without a
    /// twin: against `reference`.
    pub vs_exact: ErrorStats,
    /// The formula itself (f64) against the exact reference: the approximation alone (None without a twin).
    pub formula_vs_exact: Option<ErrorStats>,
    /// max over cells and channels of |E_gpu - E_exact| (absolute; albedo is in [0, 1]).
    pub albedo_vs_exact: f64,
    /// The largest integration-error bound of the GPU albedos.
    pub albedo_error_bound: f64,
    /// What a model without a twin was measured against: a spec (its exact f64 model) or another `.brdf`
    /// file (evaluated on the GPU); None for a model with a twin (its own exact model).
    pub reference: Option<String>,
}

/// Measures `model` on the GPU over `set` against its twin and exact reference; a model without a twin (a
/// `.brdf` file) against `reference`: a spec's exact model, or another file's GPU values and albedo.
pub fn measure(gpu: &Gpu, model: &Model, set: &SampleSet, cache: &mut ExactCache, reference: &Model) -> Result<Accuracy> {
    let got: Vec<[f64; 3]> = kernels::eval(gpu, model, &set.samples, RunLimits::default())?.iter().map(|g| g.map(f64::from)).collect();
    let gpu_albedo = kernels::albedo(gpu, model, &set.cells)?;
    // A NaN difference is an infinite one, not none (f64::max would drop it).
    let albedo_diff = |exact: &[[f64; 3]]| gpu_albedo.iter().zip(exact).flat_map(|(g, x)| (0..3).map(move |c| (g.e[c] - x[c]).abs())).map(|d| if d.is_nan() { f64::INFINITY } else { d }).fold(0.0, f64::max);
    let albedo_error_bound = gpu_albedo.iter().map(|a| a.error).fold(0.0, f64::max);
    let Some(spec) = model.twin() else {
        let (values, albedo): (Vec<[f64; 3]>, Vec<[f64; 3]>) = match reference.twin() {
            Some(r) => (cache.values(r, set).clone(), cache.albedo(r, set).clone()),
            None => (
                kernels::eval(gpu, reference, &set.samples, RunLimits::default())?.iter().map(|g| g.map(f64::from)).collect(),
                kernels::albedo(gpu, reference, &set.cells)?.iter().map(|a| a.e).collect(),
            ),
        };
        // Against a spec, the numerical error is against that spec's own f64 formula (its twin): what a file that
        // transcribes the spec's formula should match to fp32 rounding.
        let numerical = reference.twin().map(|r| ErrorStats::of(&set.samples, &got, &set.samples.par_iter().map(|s| r.eval(s)).collect::<Vec<_>>()));
        return Ok(Accuracy {
            numerical,
            vs_exact: ErrorStats::of(&set.samples, &got, &values),
            formula_vs_exact: None,
            albedo_vs_exact: albedo_diff(&albedo),
            albedo_error_bound,
            reference: Some(reference.name()),
        });
    };
    let twin: Vec<[f64; 3]> = set.samples.par_iter().map(|s| spec.eval(s)).collect();
    let exact_values = cache.values(spec, set).clone();
    let exact_albedo = cache.albedo(spec, set).clone();
    Ok(Accuracy {
        numerical: Some(ErrorStats::of(&set.samples, &got, &twin)),
        vs_exact: ErrorStats::of(&set.samples, &got, &exact_values),
        formula_vs_exact: Some(ErrorStats::of(&set.samples, &twin, &exact_values)),
        albedo_vs_exact: albedo_diff(&exact_albedo),
        albedo_error_bound,
        reference: None,
    })
}

/// E of `spec` (its own formula, f64) for one cell: the CPU reference for the GPU's albedo kernel.
pub fn albedo_twin(spec: &ModelSpec, cell: &AlbedoCell) -> [f64; 3] {
    let a = spec.alpha(cell.roughness as f64);
    let f0 = cell.f0.map(|x| (x as f64).clamp(0.0, 1.0));
    albedo::albedo_f64(&|c| spec.from_cosines(c, a, f0), cell.nov as f64, a)
}

/// E of the exact counterpart of `spec` for one cell.
pub fn albedo_exact(spec: &ModelSpec, cell: &AlbedoCell) -> [f64; 3] {
    let a = exact::alpha(cell.roughness as f64);
    let lambda = Lambda::new(spec.d, a, &spec.params);
    let f0 = cell.f0.map(f64::from);
    albedo::albedo_f64(&|c| exact::from_cosines(spec, &lambda, c, a, f0), cell.nov as f64, a)
}
