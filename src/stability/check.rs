//! One model through the suite: the hard cases, the grid, steps the f64 model does not take, reciprocity.

use super::catalogue::{Expect, HardCase};
use super::failures::{self, Failures};
use super::{BoundCase, CaseResult, SpecStability, Worst, base_tolerance, grid, tolerance};
use crate::accuracy::FLOOR;
use crate::brdf::{ModelSpec, Precision, Sample};
use crate::gpu::Gpu;
use crate::kernels::{self, RunLimits};
use crate::model::Model;
use anyhow::Result;
use glam::DVec3;
use rayon::prelude::*;

/// NaN, Inf and negative results on valid inputs, and non-finite or negative ones from invalid inputs.
#[derive(Default)]
struct Tally {
    nan: usize,
    inf: usize,
    negative: usize,
    poisoned: usize,
}

fn bad(x: f32) -> bool {
    !x.is_finite() || x < 0.0
}

impl Tally {
    /// One valid input's channels: NaN and negative values always count, Inf ones unless the exact value is
    /// beyond fp32's range (`counts_bad`).
    fn add(&mut self, got: &[f32; 3], value: &Result<[f64; 3], NoValue>) {
        let inf_ok = matches!(value, Err(NoValue::BeyondFp32(_)));
        for &x in got {
            if x.is_nan() {
                self.nan += 1;
            } else if x.is_infinite() {
                self.inf += usize::from(!inf_ok);
            } else if x < 0.0 {
                self.negative += 1;
            }
        }
    }
}

/// The model a hard case runs: `model` with the case's parameter values where its terms read them.
fn case_model(model: &Model, case: &HardCase) -> Model {
    match model.twin() {
        Some(spec) => Model::spec(case.overrides.iter().fold(*spec, |s, &(p, v)| s.with_param(p, v))),
        None => model.clone(),
    }
}

/// What a model's results are checked against, and on which inputs.
#[derive(Clone, Copy, Debug, Default)]
pub struct Checks<'a> {
    /// The expected values of a model without an f64 twin (`--reference`; a twin always comes first).
    pub reference: Option<&'a ModelSpec>,
    /// Perceptual roughness range of the valid inputs checked (`--roughness`, a file's `domain roughness`):
    /// cases and grid points outside it are not counted.
    pub roughness: Option<(f64, f64)>,
    /// N.V and N.L ranges of the valid inputs checked (`--nov`, `--nol`, a file's `domain nov|nol`), of the
    /// unit vectors.
    pub nov: Option<(f64, f64)>,
    pub nol: Option<(f64, f64)>,
    /// The model returns f N.L: inputs with |N.L| below `F_NOL_ZERO` are left out (`in_domain`).
    pub f_nol: bool,
}

/// Where a model returns f N.L (`returns f_nol`), its f is that value over N.L: at N.L = 0 the value is 0
/// whatever f is, and the quotient measures rounding, not the model (deviations of 1e15 tolerances). Its
/// inputs at N.L = 0, up to the rounding of unit vectors (|N.L| below this; the grid's next cosine is 1e-7),
/// are left out of the checks and counted as outside its domain.
pub const F_NOL_ZERO: f64 = 1e-9;

/// What a model's results are checked against: its f64 twin (its guards and floors: the limit brdfprof defines
/// for a built-in spec), or a reference's formula exactly at the inputs the model was given
/// (`ModelSpec::eval_reference`: no roughness or cosine floor, the evaluation `diff --reference` uses), with the
/// tolerance of the checked model's precision.
#[derive(Clone, Copy, Debug)]
pub struct Expected {
    pub spec: ModelSpec,
    /// The reference's formula (`eval_reference`) rather than a twin (`eval`).
    pub formula: bool,
    /// The precision of the model checked, which sets the tolerance.
    pub precision: Precision,
}

/// Why an input has no value to check against: none exists, or fp32 cannot hold it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum NoValue {
    /// Roughness 0: the reference's D is a Dirac delta.
    Singular,
    /// The exact value is beyond fp32's range (an Inf result is then no failure of the model).
    BeyondFp32(f64),
}

impl NoValue {
    pub fn why(self) -> String {
        match self {
            NoValue::Singular => "no exact value: the reference's D is a Dirac delta at roughness 0".into(),
            NoValue::BeyondFp32(x) => format!("the exact value {x:.3e} is beyond fp32's range (3.4e38)"),
        }
    }
}

impl Expected {
    pub fn twin(spec: ModelSpec) -> Self {
        Expected { spec, formula: false, precision: spec.precision }
    }

    /// The expected values at `s`, or why there are none to check a fp32 or fp16 result against. A twin's values
    /// are always expected (an infinite one is the spec's own formula failing, which its guards are for); a
    /// reference's formula beyond fp32's range is not a value fp32 code can be held to.
    pub fn at(&self, s: &Sample) -> Result<[f64; 3], NoValue> {
        let (n, v, l) =
            (crate::brdf::guards::unit(s.n), crate::brdf::guards::unit(s.v), crate::brdf::guards::unit(s.l));
        let e = self.at_unit(n, v, l, f64::from(s.roughness), s.f0.map(f64::from)).ok_or(NoValue::Singular)?;
        match e.iter().copied().find(|x| !(x.abs() <= f64::from(f32::MAX))).filter(|_| self.formula) {
            Some(x) => Err(NoValue::BeyondFp32(x)),
            None => Ok(e),
        }
    }

    /// The expected values for unit vectors as given (None where the reference has none).
    pub fn at_unit(&self, n: DVec3, v: DVec3, l: DVec3, roughness: f64, f0: [f64; 3]) -> Option<[f64; 3]> {
        if self.formula {
            self.spec.eval_reference_unit(n, v, l, roughness, f0)
        } else {
            Some(self.spec.eval_unit(n, v, l, roughness, f0))
        }
    }
}

impl Checks<'_> {
    /// What a case's results are checked against: the twin of the case's model, else the reference's formula
    /// (as it is: a file does not read the case's parameter values).
    pub fn expected(&self, model: &Model, case: Option<&HardCase>) -> Option<Expected> {
        let twin = match case {
            Some(c) => case_model(model, c).twin().copied(),
            None => model.twin().copied(),
        };
        twin.map(Expected::twin).or(self.reference.map(|&spec| Expected {
            spec,
            formula: true,
            precision: model.precision(),
        }))
    }

    fn in_domain(&self, s: &Sample) -> bool {
        let within = |range: Option<(f64, f64)>, x: f64| range.is_none_or(|(lo, hi)| (lo..=hi).contains(&x));
        let n = crate::brdf::guards::unit(s.n);
        if self.f_nol && n.dot(crate::brdf::guards::unit(s.l)).abs() < F_NOL_ZERO {
            return false;
        }
        within(self.roughness, f64::from(s.roughness))
            && (self.nov.is_none() && self.nol.is_none()
                || within(self.nov, n.dot(crate::brdf::guards::unit(s.v)))
                    && within(self.nol, n.dot(crate::brdf::guards::unit(s.l))))
    }

    /// Why nothing is left to check where the ranges leave no hard case with an expected value and no grid
    /// point (a range between grid values, or one the file's inputs never reach); None otherwise.
    pub fn leaves_nothing(&self, cases: &[HardCase], grid: &[Sample]) -> Option<String> {
        let cases_in = cases.iter().filter(|c| c.expect == Expect::Twin && self.in_domain(&c.sample)).count();
        let grid_in = grid.iter().filter(|s| self.in_domain(s)).count();
        (self.has_domain() && cases_in == 0 && grid_in == 0).then(|| {
            format!(
                "{}: none of the {} hard cases and {} grid points lies in it, so nothing would be checked; widen it",
                self.domain_text(),
                cases.iter().filter(|c| c.expect == Expect::Twin).count(),
                grid.len()
            )
        })
    }

    /// Whether any range narrows the inputs checked.
    pub fn has_domain(&self) -> bool {
        self.roughness.is_some() || self.nov.is_some() || self.nol.is_some() || self.f_nol
    }

    /// The ranges as the report says them.
    pub fn domain_text(&self) -> String {
        let mut text = [("roughness", self.roughness), ("NoV", self.nov), ("NoL", self.nol)]
            .iter()
            .filter_map(|(n, r)| r.map(|(lo, hi)| format!("{n} in [{lo}, {hi}]")))
            .collect::<Vec<_>>()
            .join(", ");
        if self.f_nol {
            let and = if text.is_empty() { "" } else { ", " };
            text += &format!("{and}NoL not 0 (the model returns f N.L, which is 0 at N.L = 0 whatever f is)");
        }
        text
    }
}

/// Every hard case on the GPU, one kernel run per distinct model the cases' parameter values make.
fn run_cases(gpu: &Gpu, model: &Model, cases: &[HardCase]) -> Result<Vec<[f32; 3]>> {
    let mut out = vec![[0f32; 3]; cases.len()];
    let mut groups: Vec<(Model, Vec<usize>)> = Vec::new();
    for (i, c) in cases.iter().enumerate() {
        let m = case_model(model, c);
        match groups.iter_mut().find(|(k, _)| *k == m) {
            Some((_, v)) => v.push(i),
            None => groups.push((m, vec![i])),
        }
    }
    for (m, idx) in &groups {
        let got =
            kernels::eval(gpu, m, &idx.iter().map(|&i| cases[i].sample).collect::<Vec<_>>(), RunLimits::default())?;
        for (k, &i) in idx.iter().enumerate() {
            out[i] = got[k];
        }
    }
    Ok(out)
}

/// |got - expected| / tolerance, the largest over the channels (NaN counts as infinite).
fn deviation(expected: &Expected, s: &Sample, got: &[f32; 3], value: [f64; 3], seed: u64) -> f64 {
    (0..3)
        .map(|c| {
            let d = (got[c] as f64 - value[c]).abs() / tolerance(expected, s, c, value[c], seed);
            if d.is_nan() { f64::INFINITY } else { d }
        })
        .fold(0.0, f64::max)
}

/// The channel where got and expected differ most, as a `Worst`.
fn worst_at(deviation: f64, got: &[f32; 3], expected: [f64; 3], input: String) -> Worst {
    let c = (0..3)
        .max_by(|&a, &b| (got[a] as f64 - expected[a]).abs().total_cmp(&(got[b] as f64 - expected[b]).abs()))
        .unwrap();
    Worst { deviation, got: got[c], expected: expected[c], input }
}

/// Whether a result counts as NaN, Inf or negative on a valid input: an Inf where the exact value is beyond
/// fp32's range is what fp32 holds of it, not a failure.
fn counts_bad(got: &[f32; 3], value: &Result<[f64; 3], NoValue>) -> bool {
    let inf_ok = matches!(value, Err(NoValue::BeyondFp32(_)));
    got.iter().any(|x| x.is_nan() || *x < 0.0 || x.is_infinite() && !inf_ok)
}

/// The hard cases' verdicts, and which of them count as a NaN, Inf or negative result on a valid input.
struct Judged {
    /// Per case: None for a valid case outside the domain (not run as far as the report goes).
    results: Vec<Option<CaseResult>>,
    bad: Vec<bool>,
    /// Valid cases with nothing to check their value against, and why (`NoValue`).
    without_value: Vec<String>,
}

/// Each case's verdict: against the twin or reference (within tolerance) for valid input, finite and
/// non-negative for invalid input; without either, a valid case fails only on a NaN, Inf or negative value.
/// Cases from `first_bound` on sit at the domain's own bounds and are always counted.
fn judge_cases(
    model: &Model,
    checks: &Checks,
    cases: &[HardCase],
    first_bound: usize,
    out: &[[f32; 3]],
    tally: &mut Tally,
    worst: &mut Worst,
) -> Judged {
    let mut judged = Judged { results: Vec::new(), bad: Vec::new(), without_value: Vec::new() };
    for (i, (case, got)) in cases.iter().zip(out).enumerate() {
        let valid = case.expect == Expect::Twin;
        if valid && i < first_bound && !checks.in_domain(&case.sample) {
            judged.results.push(None);
            judged.bad.push(false);
            continue;
        }
        let poisoned = if got.iter().any(|&x| bad(x)) { f64::INFINITY } else { 0.0 };
        let expected = checks.expected(model, Some(case)).filter(|_| valid);
        let value = expected.map(|x| x.at(&case.sample));
        let value_or_none = value.as_ref().unwrap_or(&Ok([0.0; 3]));
        let is_bad = counts_bad(got, value_or_none);
        if valid {
            tally.add(got, value_or_none);
        } else {
            tally.poisoned += got.iter().filter(|&&x| bad(x)).count();
        }
        let (shown, deviation) = match (expected, value) {
            (Some(x), Some(Ok(e))) => (Some(e), deviation(&x, &case.sample, got, e, i as u64)),
            (Some(_), Some(Err(why))) => {
                judged.without_value.push(format!("case `{}`: {}", case.name, why.why()));
                (None, if is_bad { f64::INFINITY } else { 0.0 })
            }
            _ => (None, poisoned),
        };
        let inputs = failures::describe(&case.sample);
        if let (Some(e), true) = (shown, deviation > worst.deviation) {
            *worst = worst_at(deviation, got, e, format!("case `{}`: {inputs}", case.name));
        }
        judged.bad.push(valid && is_bad);
        judged.results.push(Some(CaseResult {
            case: case.name.clone(),
            inputs,
            expected: shown,
            got: *got,
            deviation,
            ok: deviation <= 1.0,
        }));
    }
    judged
}

/// Per grid point, the deviation from the expected values in tolerances (the tolerance computed only where
/// the base tolerance is exceeded: it can only grow); 0 where there is no value to check against.
fn grid_deviations(
    expected: &Expected,
    grid: &[Sample],
    out: &[[f32; 3]],
    values: &[Result<[f64; 3], NoValue>],
) -> Vec<f64> {
    grid.par_iter()
        .enumerate()
        .map(|(i, s)| {
            let Ok(value) = values[i] else { return 0.0 };
            (0..3)
                .map(|c| {
                    let (g, e) = (out[i][c] as f64, value[c]);
                    let diff = (g - e).abs();
                    if diff.is_nan() {
                        return f64::INFINITY;
                    }
                    let base = base_tolerance(expected.precision) * e.abs().max(FLOOR);
                    if diff <= base { diff / base } else { diff / tolerance(expected, s, c, e, i as u64) }
                })
                .fold(0.0, f64::max)
        })
        .collect()
}

/// Bad values (NaN, Inf, negative) per [roughness][NoV] grid cell, all tallied (points outside the domain
/// neither), and whether each point counts as one.
fn bad_cells(
    out: &[[f32; 3]],
    in_domain: &[bool],
    values: Option<&[Result<[f64; 3], NoValue>]>,
    tally: &mut Tally,
) -> (Vec<Vec<u32>>, Vec<bool>) {
    let mut cells = vec![vec![0u32; grid::COSINES.len()]; grid::ROUGHNESS.len()];
    let mut is_bad = vec![false; out.len()];
    for (i, g) in out.iter().enumerate().filter(|(i, _)| in_domain[*i]) {
        let value = values.map_or(&Ok([0.0; 3]), |v| &v[i]);
        is_bad[i] = counts_bad(g, value);
        tally.add(g, value);
        if is_bad[i] {
            let r = i / (grid::AZIMUTHS * grid::COSINES.len() * grid::COSINES.len());
            let v = (i / grid::COSINES.len()) % grid::COSINES.len();
            cells[r][v] += 1;
        }
    }
    (cells, is_bad)
}

/// Steps in f_s NoL (the radiance a renderer accumulates) along NoV, NoL and roughness (channel 0, lit points
/// only: at a cosine of 0 the light is masked by definition), which the f64 model (`twin`, where there is
/// one) does not take, at values out of tolerance: (discontinuities, the model's own jumps, examples). Without
/// an expectation every step of a finely sampled lobe would count: nothing is counted then. Series run over the
/// points in the roughness domain.
struct Steps {
    discontinuities: usize,
    model_jumps: usize,
    examples: Vec<String>,
}

fn scan_steps(
    grid: &[Sample],
    out: &[[f32; 3]],
    twin: Option<&[[f64; 3]]>,
    deviations: &[f64],
    in_domain: &[bool],
) -> Steps {
    let mut steps = Steps { discontinuities: 0, model_jumps: 0, examples: Vec::new() };
    let Some(twin) = twin else { return steps };
    let radiance = |vals: &dyn Fn(usize) -> f64, idx: &[usize]| {
        idx.iter().map(|&i| vals(i) * (grid[i].l[2] as f64).max(0.0)).collect::<Vec<f64>>()
    };
    let mut scan = |idx: Vec<usize>, axis: &str| {
        let idx: Vec<usize> = idx.into_iter().filter(|&i| in_domain[i]).collect();
        let g = radiance(&|i| out[i][0] as f64, &idx);
        let model = grid::jumps(&radiance(&|i| twin[i][0], &idx));
        steps.model_jumps += model.len();
        // Where both joined values are within tolerance of the twin, a step is rounding in an ill-conditioned
        // corner, not a break.
        let off = |j: usize| deviations[idx[j]] > 1.0 || deviations[idx[j + 1]] > 1.0;
        for j in grid::jumps(&g).into_iter().filter(|j| !model.contains(j) && off(*j)) {
            steps.discontinuities += 1;
            if steps.examples.len() < 5 {
                steps.examples.push(format!(
                    "along {axis} between {} and {}: {:.4e} -> {:.4e}",
                    super::failures::describe(&grid[idx[j]]),
                    super::failures::describe(&grid[idx[j + 1]]),
                    g[j],
                    g[j + 1]
                ));
            }
        }
    };
    let n = grid::COSINES.len();
    for r in 0..grid::ROUGHNESS.len() {
        for az in 0..grid::AZIMUTHS {
            for k in 1..n {
                scan((1..n).map(|v| grid::index(r, az, v, k)).collect(), "NoV");
                scan((1..n).map(|l| grid::index(r, az, k, l)).collect(), "NoL");
            }
        }
    }
    for az in 0..grid::AZIMUTHS {
        for v in 1..n {
            for l in 1..n {
                scan((0..grid::ROUGHNESS.len()).map(|r| grid::index(r, az, v, l)).collect(), "roughness");
            }
        }
    }
    steps
}

/// max |f(v, l) - f(l, v)| / max(|f|, FLOOR) over the pairs whose values are both finite (None when none
/// is), and how many pairs are not: a NaN says nothing about reciprocity, least of all that it holds.
fn reciprocity_error(forward: &[[f32; 3]], backward: &[[f32; 3]]) -> (Option<f64>, usize) {
    let (mut worst, mut nonfinite) = (None, 0);
    for (a, b) in forward.iter().zip(backward) {
        for c in 0..3 {
            if !(a[c].is_finite() && b[c].is_finite()) {
                nonfinite += 1;
                continue;
            }
            let e = (a[c] as f64 - b[c] as f64).abs() / (a[c].abs().max(b[c].abs()) as f64).max(FLOOR);
            worst = Some(worst.map_or(e, |w: f64| w.max(e)));
        }
    }
    (worst, nonfinite)
}

/// Each grid sample's deviation from the expected values (`values`, of `expected`), 0 outside the domain and
/// where nothing is expected.
fn domain_deviations(
    expected: Option<&Expected>,
    values: Option<&[Result<[f64; 3], NoValue>]>,
    grid: &[Sample],
    grid_out: &[[f32; 3]],
    in_domain: &[bool],
) -> Vec<f64> {
    match (expected, values) {
        (Some(x), Some(v)) => grid_deviations(x, grid, grid_out, v)
            .into_iter()
            .zip(in_domain)
            .map(|(d, &inside)| if inside { d } else { 0.0 })
            .collect(),
        _ => vec![0.0; grid.len()],
    }
}

/// `worst`, or where no case or grid value deviated, the first failure found (its first non-finite or negative
/// value).
fn worst_or_first_failure(worst: Worst, failures: &Failures) -> Worst {
    if worst.input.is_empty() {
        if let Some(f) = failures.first() {
            return Worst {
                deviation: f64::INFINITY,
                got: f.got.into_iter().find(|x| !x.is_finite() || *x < 0.0).unwrap_or(f.got[0]),
                expected: f64::NAN,
                input: format!("{}: {}", f.at, f.inputs),
            };
        }
    }
    worst
}

/// Checks one model: catalogue, the cases at its domain's bounds, grid, discontinuities, reciprocity and where
/// it fails (energy is added by `run`).
pub fn check_model(
    gpu: &Gpu,
    model: &Model,
    checks: &Checks,
    cases: &[HardCase],
    grid: &[Sample],
    reciprocity: &[Sample],
) -> Result<SpecStability> {
    let mut cases_here = cases.to_vec();
    cases_here.extend(super::catalogue::at_domain_bounds(checks));
    let case_out = run_cases(gpu, model, &cases_here)?;
    let mut all: Vec<Sample> = grid.to_vec();
    all.extend_from_slice(reciprocity);
    all.extend(reciprocity.iter().map(|s| Sample { v: s.l, l: s.v, ..*s }));
    let out = kernels::eval(gpu, model, &all, RunLimits::default())?;
    let (grid_out, rest) = out.split_at(grid.len());
    let (forward, backward) = rest.split_at(reciprocity.len());
    let in_domain: Vec<bool> = grid.iter().map(|s| checks.in_domain(s)).collect();

    let (mut tally, mut worst) = (Tally::default(), Worst::default());
    let judged = judge_cases(model, checks, &cases_here, cases.len(), &case_out, &mut tally, &mut worst);
    let expected = checks.expected(model, None);
    let values: Option<Vec<Result<[f64; 3], NoValue>>> = expected.map(|x| grid.par_iter().map(|s| x.at(s)).collect());
    let deviations = domain_deviations(expected.as_ref(), values.as_deref(), grid, grid_out, &in_domain);
    let (cells, grid_bad) = bad_cells(grid_out, &in_domain, values.as_deref(), &mut tally);
    let plain: Option<Vec<[f64; 3]>> = values.as_ref().map(|v| v.iter().map(|x| x.unwrap_or([f64::NAN; 3])).collect());
    worst_of_grid(&mut worst, plain.as_deref(), &deviations, grid, grid_out);
    let steps = scan_steps(grid, grid_out, plain.as_deref(), &deviations, &in_domain);
    let any_bad = cells.iter().flatten().any(|&n| n > 0);
    let (reciprocity, reciprocity_nonfinite) = reciprocity_error(forward, backward);
    let failures = locate_failures(gpu, model, &cases_here, &case_out, &judged.bad, grid, grid_out, &grid_bad)?;
    let worst = worst_or_first_failure(worst, &failures);
    let bounds = bound_results(expected.as_ref(), &cases_here[cases.len()..], &judged.results[cases.len()..]);
    let results: Vec<CaseResult> = judged.results.iter().flatten().cloned().collect();
    let grid_without_value =
        values.as_ref().map_or(0, |v| v.iter().zip(&in_domain).filter(|(x, inside)| **inside && x.is_err()).count());
    Ok(SpecStability {
        label: model.label(),
        spec: model.name(),
        precision: model.precision().name().into(),
        has_twin: model.twin().is_some(),
        expected_from: expected_from(model, checks),
        domain: checks.has_domain().then(|| checks.domain_text()),
        cases_outside_domain: judged.results.iter().filter(|r| r.is_none()).count(),
        grid_outside_domain: in_domain.iter().filter(|d| !**d).count(),
        nan: tally.nan,
        inf: tally.inf,
        negative: tally.negative,
        invalid_input_poisoned: tally.poisoned,
        cases_run: results.len(),
        case_deviation: judged.results[..cases.len()].iter().map(|r| r.as_ref().map_or(0.0, |r| r.deviation)).collect(),
        cases_out_of_tolerance: results.into_iter().filter(|r| !r.ok).collect(),
        cases_without_value: judged.without_value,
        grid_without_value,
        grid_out_of_tolerance: deviations.iter().filter(|d| **d > 1.0).count(),
        worst,
        jumps_checked: plain.is_some(),
        discontinuities: steps.discontinuities,
        discontinuity_examples: steps.examples,
        model_jumps: steps.model_jumps,
        reciprocity,
        reciprocity_nonfinite,
        bad_cells: any_bad.then_some(cells),
        bad_cell_triples: None,
        at_domain_bounds: bounds,
        failures,
        energy: None,
    })
}

/// `worst` where a grid point deviates more than every hard case.
fn worst_of_grid(
    worst: &mut Worst,
    values: Option<&[[f64; 3]]>,
    deviations: &[f64],
    grid: &[Sample],
    out: &[[f32; 3]],
) {
    if let (Some(t), Some((i, &d))) = (values, deviations.iter().enumerate().max_by(|a, b| a.1.total_cmp(b.1))) {
        if d > worst.deviation {
            *worst = worst_at(d, &out[i], t[i], format!("grid: {}", failures::describe(&grid[i])));
        }
    }
}

/// The cases at the domain's bounds as the report gives them: each result with its signed difference from the
/// formula's exact value (what fp32 or fp16 loses there, said even within tolerance).
fn bound_results(expected: Option<&Expected>, cases: &[HardCase], results: &[Option<CaseResult>]) -> Vec<BoundCase> {
    cases
        .iter()
        .zip(results)
        .filter_map(|(case, r)| {
            let r = r.as_ref()?;
            let exact = expected.and_then(|x| x.spec.eval_reference(&case.sample));
            let c = (0..3).max_by(|&a, &b| {
                let rel = |k: usize| exact.map_or(0.0, |e| ((r.got[k] as f64 - e[k]) / e[k]).abs());
                rel(a).total_cmp(&rel(b))
            })?;
            Some(BoundCase {
                case: case.name.clone(),
                inputs: r.inputs.clone(),
                got: f64::from(r.got[c]),
                exact: exact.map(|e| e[c]),
                loss: exact.map(|e| r.got[c] as f64 / e[c] - 1.0).filter(|x| x.is_finite()),
                deviation: r.deviation,
                ok: r.ok,
            })
        })
        .collect()
}

/// Where the expected values come from, as the report says it.
fn expected_from(model: &Model, checks: &Checks) -> Option<String> {
    match (model.twin(), checks.reference) {
        (Some(_), _) => Some("twin".into()),
        (None, Some(r)) => Some(format!("reference `{}` (its formula exactly, no floor)", r.name())),
        (None, None) => None,
    }
}

/// The valid inputs in the domain that count as a NaN, Inf or negative result (`case_bad`, `grid_bad`), and
/// the input guards that remove them.
#[allow(clippy::too_many_arguments)]
fn locate_failures(
    gpu: &Gpu,
    model: &Model,
    cases: &[HardCase],
    case_out: &[[f32; 3]],
    case_bad: &[bool],
    grid: &[Sample],
    grid_out: &[[f32; 3]],
    grid_bad: &[bool],
) -> Result<Failures> {
    let case_models: Vec<(Model, &str, Sample)> =
        cases.iter().map(|c| (case_model(model, c), c.name.as_str(), c.sample)).collect();
    let only_bad = |out: &[[f32; 3]], bad: &[bool]| -> Vec<[f32; 3]> {
        out.iter().zip(bad).map(|(g, &b)| if b { *g } else { [0.0; 3] }).collect()
    };
    failures::locate(gpu, &case_models, &only_bad(case_out, case_bad), model, grid, &only_bad(grid_out, grid_bad))
}
