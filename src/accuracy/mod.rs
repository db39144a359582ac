//! How accurate a model spec is, measured on the GPU: its numerical error (GPU result against the same
//! formula in f64) and its error against the exact physical reference (`brdf::exact`), as max and RMS relative
//! error over a fixed, seeded, stratified sample set, plus the error of its directional albedo.

pub mod albedo;

use crate::brdf::exact::{self, ExactFresnel, Lambda};
use crate::brdf::f0::F0Set;
use crate::brdf::samples::SampleDomain;
use crate::brdf::{D, F, ModelSpec, Sample, samples};
use crate::gpu::Gpu;
use crate::kernels::{self, AlbedoCell, RunLimits};
use crate::model::Model;
use anyhow::Result;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::collections::HashMap;

/// Relative error |x - reference| / max(|reference|, FLOOR), the measure used everywhere.
pub const FLOOR: f64 = 1e-3;

pub fn rel_err(x: f64, reference: f64) -> f64 {
    let e = (x - reference).abs() / reference.abs().max(FLOOR);
    if e.is_nan() { f64::INFINITY } else { e }
}

/// Read back from sweep reports too: an infinite error, written as null, reads as NaN (`io::finite`).
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct ErrorStats {
    /// Over every value; a NaN or Inf value counts as an infinite error (`nonfinite` says how many there are).
    #[serde(default = "crate::io::nan", deserialize_with = "crate::io::nan_if_null")]
    pub max: f64,
    #[serde(default = "crate::io::nan", deserialize_with = "crate::io::nan_if_null")]
    pub rms: f64,
    /// The sample with the largest error (not read back).
    #[serde(skip_deserializing)]
    pub worst: String,
    /// Values (samples x channels) that are NaN or Inf.
    #[serde(default)]
    pub nonfinite: usize,
    /// Values compared.
    #[serde(default)]
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

/// The sample set: 10 strata each in roughness, NoV, NoL and azimuth [0, pi] (10,000 samples, seed 2023), and
/// the albedo cells NoV x roughness, all within a domain (`standard`: roughness [0.1, 1], NoV and NoL
/// [0.05, 1]).
pub struct SampleSet {
    pub samples: Vec<Sample>,
    pub cells: Vec<AlbedoCell>,
    pub domain: SampleDomain,
    /// Where the samples' F0 comes from (`sweep --f0`); None: the two dielectric triples of `stratified_in`.
    pub f0: Option<F0Set>,
}

/// `stratified_in`'s F0, the sweep's default.
const DIELECTRIC_PAIR: &str = "dielectric F0 (0.02, 0.04, 0.08) or (0.03, 0.05, 0.045)";

pub const ALBEDO_NOV: [f32; 6] = [0.1, 0.3, 0.5, 0.7, 0.9, 1.0];
pub const ALBEDO_ROUGHNESS: [f32; 5] = [0.1, 0.25, 0.5, 0.75, 1.0];

/// The sweep's default domain: roughness [0.1, 1] (above every precision's floor), NoV and NoL [0.05, 1].
pub const STANDARD_DOMAIN: SampleDomain = SampleDomain { roughness: (0.1, 1.0), nov: (0.05, 1.0), nol: (0.05, 1.0) };

/// The grid values within `range`, or its two ends where none is (a narrow domain still gets albedo cells).
fn grid_within(grid: &[f32], range: (f64, f64)) -> Vec<f32> {
    let inside: Vec<f32> = grid.iter().copied().filter(|&x| (range.0..=range.1).contains(&(x as f64))).collect();
    if !inside.is_empty() {
        return inside;
    }
    let mut ends = vec![range.0 as f32, range.1 as f32];
    ends.dedup();
    ends
}

impl SampleSet {
    pub fn standard() -> Self {
        Self::within(STANDARD_DOMAIN, None)
    }

    /// The stratified set over `domain`, F0 from `f0` where given; the albedo cells are the standard grid's
    /// within it.
    pub fn within(domain: SampleDomain, f0: Option<F0Set>) -> Self {
        let noves = grid_within(&ALBEDO_NOV, domain.nov);
        let cells = grid_within(&ALBEDO_ROUGHNESS, domain.roughness)
            .into_iter()
            .flat_map(|roughness| noves.iter().map(move |&nov| AlbedoCell { nov, roughness, f0: [0.04; 3] }))
            .collect();
        let mut samples = samples::stratified_in(10, 2023, domain.nov, domain.nol, domain.roughness);
        if let Some(set) = f0 {
            set.apply(&mut samples, 2023);
        }
        SampleSet { samples, cells, domain, f0 }
    }

    /// The words that say what the set is.
    pub fn describe(&self) -> String {
        let (r, v, l) = (self.domain.roughness, self.domain.nov, self.domain.nol);
        let distinct = |pick: fn(&AlbedoCell) -> f32| {
            let mut v: Vec<f32> = self.cells.iter().map(pick).collect();
            v.sort_by(f32::total_cmp);
            v.dedup();
            v.iter().map(f32::to_string).collect::<Vec<_>>().join(", ")
        };
        format!(
            "10 strata each of roughness [{}, {}], NoV [{}, {}] and NoL [{}, {}], azimuth [0, pi]; {} samples, seed 2023; \
             {}; albedo cells NoV {{{}}} x r {{{}}}, F0 0.04",
            r.0,
            r.1,
            v.0,
            v.1,
            l.0,
            l.1,
            self.samples.len(),
            self.f0.map_or(DIELECTRIC_PAIR.to_string(), |f| f.describe()),
            distinct(|c| c.nov),
            distinct(|c| c.roughness)
        )
    }
}

/// What the exact reference of a spec depends on: its D with the parameters it reads, and the Fresnel it uses
/// (`ExactFresnel`) with the parameters that reads (a dielectric from F0, or a given metal). Specs differing
/// only in Vis (or, with the physical Fresnel, in their Fresnel approximation) share it.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
struct ExactKey {
    d: D,
    f: F,
    params: Vec<u64>,
}

impl ExactKey {
    fn of(spec: &ModelSpec, fresnel: ExactFresnel) -> Self {
        let f = fresnel.term(spec);
        let reads = spec.d.row().reads.iter().chain(f.row().reads);
        ExactKey { d: spec.d, f, params: reads.map(|&p| spec.params.get(p).bits()).collect() }
    }
}

/// Exact values and albedos over a sample set, computed once per `ExactKey`, with one Fresnel choice.
#[derive(Default)]
pub struct ExactCache {
    pub fresnel: ExactFresnel,
    values: HashMap<ExactKey, Vec<[f64; 3]>>,
    albedo: HashMap<ExactKey, Vec<[f64; 3]>>,
}

impl ExactCache {
    pub fn new(fresnel: ExactFresnel) -> Self {
        ExactCache { fresnel, ..Default::default() }
    }

    fn values(&mut self, spec: &ModelSpec, set: &SampleSet) -> &Vec<[f64; 3]> {
        let fresnel = self.fresnel;
        self.values
            .entry(ExactKey::of(spec, fresnel))
            .or_insert_with(|| set.samples.par_iter().map(|s| exact::eval_with(spec, fresnel, s)).collect())
    }

    fn albedo(&mut self, spec: &ModelSpec, set: &SampleSet) -> &Vec<[f64; 3]> {
        let fresnel = self.fresnel;
        self.albedo
            .entry(ExactKey::of(spec, fresnel))
            .or_insert_with(|| set.cells.par_iter().map(|cell| albedo_exact_with(spec, fresnel, cell)).collect())
    }

    /// The values and albedos a model is measured against: a spec's exact model, or a `.brdf` file's GPU results.
    fn reference(&mut self, gpu: &Gpu, reference: &Model, set: &SampleSet) -> Result<(Vec<[f64; 3]>, Vec<[f64; 3]>)> {
        Ok(match reference.twin() {
            Some(r) => (self.values(r, set).clone(), self.albedo(r, set).clone()),
            None => (
                kernels::eval(gpu, reference, &set.samples, RunLimits::default())?
                    .iter()
                    .map(|g| g.map(f64::from))
                    .collect(),
                kernels::albedo(gpu, reference, &set.cells)?.iter().map(|a| a.e).collect(),
            ),
        })
    }
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Accuracy {
    /// GPU result against the same formula in f64; for a model without a twin (a `.brdf` file) measured
    /// against a spec (`reference`), against that spec's own f64 formula; None against another `.brdf` file.
    pub numerical: Option<ErrorStats>,
    /// GPU result against the exact reference: what a user of the spec gets. Against `reference` where one
    /// was given (always for a model without a twin).
    pub vs_exact: ErrorStats,
    /// The formula itself (f64) against the same reference: the approximation alone (None without a twin).
    pub formula_vs_exact: Option<ErrorStats>,
    /// max over cells and channels of |E_gpu - E_exact| (absolute; albedo is in [0, 1]).
    #[serde(default = "crate::io::nan", deserialize_with = "crate::io::nan_if_null")]
    pub albedo_vs_exact: f64,
    /// The largest integration-error bound of the GPU albedos (not read back).
    #[serde(skip_deserializing)]
    pub albedo_error_bound: f64,
    /// What the model was measured against where not its own exact model: a spec (its exact f64 model) or
    /// another `.brdf` file (evaluated on the GPU).
    pub reference: Option<String>,
}

/// Measures `model` on the GPU over `set`: against its twin (numerical error) and against `reference` where
/// given (a spec's exact model, or another file's GPU values and albedo), else against its own exact model. A
/// model without a twin (a `.brdf` file) needs a reference.
pub fn measure(
    gpu: &Gpu,
    model: &Model,
    set: &SampleSet,
    cache: &mut ExactCache,
    reference: Option<&Model>,
) -> Result<Accuracy> {
    let got: Vec<[f64; 3]> =
        kernels::eval(gpu, model, &set.samples, RunLimits::default())?.iter().map(|g| g.map(f64::from)).collect();
    let gpu_albedo = kernels::albedo(gpu, model, &set.cells)?;
    // A NaN difference is an infinite one, not none (f64::max would drop it).
    let albedo_diff = |exact: &[[f64; 3]]| {
        gpu_albedo
            .iter()
            .zip(exact)
            .flat_map(|(g, x)| (0..3).map(move |c| (g.e[c] - x[c]).abs()))
            .map(|d| if d.is_nan() { f64::INFINITY } else { d })
            .fold(0.0, f64::max)
    };
    let albedo_error_bound = gpu_albedo.iter().map(|a| a.error).fold(0.0, f64::max);
    let (values, albedo) = match (reference, model.twin()) {
        (Some(r), _) => cache.reference(gpu, r, set)?,
        (None, Some(spec)) => (cache.values(spec, set).clone(), cache.albedo(spec, set).clone()),
        (None, None) => anyhow::bail!(
            "{}: a model without an f64 twin is measured against a reference; none was given",
            model.name()
        ),
    };
    let twin: Option<Vec<[f64; 3]>> = model.twin().map(|spec| set.samples.par_iter().map(|s| spec.eval(s)).collect());
    // A file against a spec: the numerical error is against that spec's own f64 formula (its twin), what a
    // file that transcribes the spec's formula should match to fp32 rounding.
    let numerical_against = twin
        .clone()
        .or_else(|| reference.and_then(Model::twin).map(|r| set.samples.par_iter().map(|s| r.eval(s)).collect()));
    Ok(Accuracy {
        numerical: numerical_against.map(|t| ErrorStats::of(&set.samples, &got, &t)),
        vs_exact: ErrorStats::of(&set.samples, &got, &values),
        formula_vs_exact: twin.map(|t| ErrorStats::of(&set.samples, &t, &values)),
        albedo_vs_exact: albedo_diff(&albedo),
        albedo_error_bound,
        reference: reference.map(Model::name),
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
    albedo_exact_with(spec, ExactFresnel::Physical, cell)
}

/// `albedo_exact` with the Fresnel `fresnel` chooses.
pub fn albedo_exact_with(spec: &ModelSpec, fresnel: ExactFresnel, cell: &AlbedoCell) -> [f64; 3] {
    let a = exact::alpha(cell.roughness as f64);
    let lambda = Lambda::new(spec.d, a, &spec.params);
    let f0 = cell.f0.map(f64::from);
    albedo::albedo_f64(&|c| exact::from_cosines_with(spec, fresnel, &lambda, c, a, f0), cell.nov as f64, a)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_sweep_set_keeps_every_f0_within_its_f0_set() {
        let plain = SampleSet::standard();
        let set = SampleSet::within(STANDARD_DOMAIN, Some(F0Set::parse("0.5..0.6").unwrap()));
        assert!(set.samples.iter().all(|s| s.f0.iter().all(|&c| (0.5..=0.6).contains(&c))));
        assert!(set.describe().contains("F0 in [0.5, 0.6]^3") && plain.describe().contains(DIELECTRIC_PAIR));
        let same = |a: &Sample, b: &Sample| a.n == b.n && a.v == b.v && a.l == b.l && a.roughness == b.roughness;
        assert!(plain.samples.iter().zip(&set.samples).all(|(a, b)| same(a, b)), "only F0 changes");
    }
}
