//! One model through the suite: the hard cases, the grid, steps the f64 model does not take, reciprocity.

use super::catalogue::{Expect, HardCase};
use super::failures::{self, Failures};
use super::{CaseResult, SpecStability, Worst, base_tolerance, grid, tolerance};
use crate::accuracy::FLOOR;
use crate::brdf::{ModelSpec, Sample};
use crate::gpu::Gpu;
use crate::kernels::{self, RunLimits};
use crate::model::Model;
use anyhow::Result;
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
    fn add(&mut self, x: f32, valid: bool) {
        if !valid {
            self.poisoned += bad(x) as usize;
        } else if x.is_nan() {
            self.nan += 1;
        } else if x.is_infinite() {
            self.inf += 1;
        } else if x < 0.0 {
            self.negative += 1;
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

impl Checks<'_> {
    /// The spec whose f64 values a case's results are checked against: the twin of the case's model, else
    /// the reference (as it is: a file does not read the case's parameter values).
    fn expected(&self, model: &Model, case: Option<&HardCase>) -> Option<ModelSpec> {
        let twin = match case {
            Some(c) => case_model(model, c).twin().copied(),
            None => model.twin().copied(),
        };
        twin.or(self.reference.copied())
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
fn deviation(spec: &ModelSpec, s: &Sample, got: &[f32; 3], expected: [f64; 3], seed: u64) -> f64 {
    (0..3)
        .map(|c| {
            let d = (got[c] as f64 - expected[c]).abs() / tolerance(spec, s, c, expected[c], seed);
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

/// Each case's verdict: against the twin or reference (within tolerance) for valid input, finite and
/// non-negative for invalid input; without either, a valid case fails only on a NaN, Inf or negative value.
/// None for a valid case outside the roughness domain (not run as far as the report goes).
fn judge_cases(
    model: &Model,
    checks: &Checks,
    cases: &[HardCase],
    out: &[[f32; 3]],
    tally: &mut Tally,
    worst: &mut Worst,
) -> Vec<Option<CaseResult>> {
    cases
        .iter()
        .zip(out)
        .enumerate()
        .map(|(i, (case, got))| {
            let valid = case.expect == Expect::Twin;
            if valid && !checks.in_domain(&case.sample) {
                return None;
            }
            got.iter().for_each(|&x| tally.add(x, valid));
            let poisoned = if got.iter().any(|&x| bad(x)) { f64::INFINITY } else { 0.0 };
            let (expected, deviation) = match (valid, checks.expected(model, Some(case))) {
                (true, Some(s)) => {
                    let e = s.eval(&case.sample);
                    (Some(e), deviation(&s, &case.sample, got, e, i as u64))
                }
                (true, None) | (false, _) => (None, poisoned),
            };
            if let (Some(e), true) = (expected, deviation > worst.deviation) {
                *worst = worst_at(deviation, got, e, format!("case `{}`: {:?}", case.name, case.sample));
            }
            Some(CaseResult { case: case.name.clone(), expected, got: *got, deviation, ok: deviation <= 1.0 })
        })
        .collect()
}

/// Per grid point, the deviation from the twin in tolerances (the tolerance computed only where the base
/// tolerance is exceeded: it can only grow).
fn grid_deviations(spec: &ModelSpec, grid: &[Sample], out: &[[f32; 3]], twin: &[[f64; 3]]) -> Vec<f64> {
    grid.par_iter()
        .enumerate()
        .map(|(i, s)| {
            (0..3)
                .map(|c| {
                    let (g, e) = (out[i][c] as f64, twin[i][c]);
                    let diff = (g - e).abs();
                    if diff.is_nan() {
                        return f64::INFINITY;
                    }
                    let base = base_tolerance(spec.precision) * e.abs().max(FLOOR);
                    if diff <= base { diff / base } else { diff / tolerance(spec, s, c, e, i as u64) }
                })
                .fold(0.0, f64::max)
        })
        .collect()
}

/// Bad values (NaN, Inf, negative) per [roughness][NoV] grid cell, all tallied (points outside the domain
/// neither).
fn bad_cells(out: &[[f32; 3]], in_domain: &[bool], tally: &mut Tally) -> Vec<Vec<u32>> {
    let mut cells = vec![vec![0u32; grid::COSINES.len()]; grid::ROUGHNESS.len()];
    for (i, g) in out.iter().enumerate().filter(|(i, _)| in_domain[*i]) {
        g.iter().for_each(|&x| tally.add(x, true));
        if g.iter().any(|&x| bad(x)) {
            let r = i / (grid::AZIMUTHS * grid::COSINES.len() * grid::COSINES.len());
            let v = (i / grid::COSINES.len()) % grid::COSINES.len();
            cells[r][v] += 1;
        }
    }
    cells
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

/// Each grid sample's deviation from the expected values (`spec`'s, `twin` on the grid), 0 outside the domain
/// and where nothing is expected.
fn domain_deviations(
    spec: Option<&ModelSpec>,
    twin: Option<&[[f64; 3]]>,
    grid: &[Sample],
    grid_out: &[[f32; 3]],
    in_domain: &[bool],
) -> Vec<f64> {
    match (spec, twin) {
        (Some(s), Some(t)) => grid_deviations(s, grid, grid_out, t)
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

/// Checks one model: catalogue, grid, discontinuities, reciprocity and where it fails (energy is added by
/// `run`).
pub fn check_model(
    gpu: &Gpu,
    model: &Model,
    checks: &Checks,
    cases: &[HardCase],
    grid: &[Sample],
    reciprocity: &[Sample],
) -> Result<SpecStability> {
    let case_out = run_cases(gpu, model, cases)?;
    let mut all: Vec<Sample> = grid.to_vec();
    all.extend_from_slice(reciprocity);
    all.extend(reciprocity.iter().map(|s| Sample { v: s.l, l: s.v, ..*s }));
    let out = kernels::eval(gpu, model, &all, RunLimits::default())?;
    let (grid_out, rest) = out.split_at(grid.len());
    let (forward, backward) = rest.split_at(reciprocity.len());
    let in_domain: Vec<bool> = grid.iter().map(|s| checks.in_domain(s)).collect();

    let (mut tally, mut worst) = (Tally::default(), Worst::default());
    let judged = judge_cases(model, checks, cases, &case_out, &mut tally, &mut worst);
    let spec = checks.expected(model, None);
    let twin: Option<Vec<[f64; 3]>> = spec.map(|s| grid.par_iter().map(|x| s.eval(x)).collect());
    let deviations = domain_deviations(spec.as_ref(), twin.as_deref(), grid, grid_out, &in_domain);
    let cells = bad_cells(grid_out, &in_domain, &mut tally);
    if let (Some(t), Some((i, &d))) = (&twin, deviations.iter().enumerate().max_by(|a, b| a.1.total_cmp(b.1))) {
        if d > worst.deviation {
            worst = worst_at(d, &grid_out[i], t[i], format!("grid: {}", failures::describe(&grid[i])));
        }
    }
    let steps = scan_steps(grid, grid_out, twin.as_deref(), &deviations, &in_domain);
    let any_bad = cells.iter().flatten().any(|&n| n > 0);
    let (reciprocity, reciprocity_nonfinite) = reciprocity_error(forward, backward);
    let failures = locate_failures(gpu, model, cases, &case_out, &judged, grid, grid_out, &in_domain)?;
    let worst = worst_or_first_failure(worst, &failures);
    let results: Vec<CaseResult> = judged.iter().flatten().cloned().collect();
    Ok(SpecStability {
        label: model.label(),
        spec: model.name(),
        precision: model.precision().name().into(),
        has_twin: model.twin().is_some(),
        expected_from: expected_from(model, checks),
        domain: checks.has_domain().then(|| checks.domain_text()),
        cases_outside_domain: judged.iter().filter(|r| r.is_none()).count(),
        grid_outside_domain: in_domain.iter().filter(|d| !**d).count(),
        nan: tally.nan,
        inf: tally.inf,
        negative: tally.negative,
        invalid_input_poisoned: tally.poisoned,
        cases_run: results.len(),
        case_deviation: judged.iter().map(|r| r.as_ref().map_or(0.0, |r| r.deviation)).collect(),
        cases_out_of_tolerance: results.into_iter().filter(|r| !r.ok).collect(),
        grid_out_of_tolerance: deviations.iter().filter(|d| **d > 1.0).count(),
        worst,
        jumps_checked: twin.is_some(),
        discontinuities: steps.discontinuities,
        discontinuity_examples: steps.examples,
        model_jumps: steps.model_jumps,
        reciprocity,
        reciprocity_nonfinite,
        bad_cells: any_bad.then_some(cells),
        bad_cell_triples: None,
        failures,
        energy: None,
    })
}

/// Where the expected values come from, as the report says it.
fn expected_from(model: &Model, checks: &Checks) -> Option<String> {
    match (model.twin(), checks.reference) {
        (Some(_), _) => Some("twin".into()),
        (None, Some(r)) => Some(format!("reference `{}`", r.name())),
        (None, None) => None,
    }
}

/// The valid inputs in the domain with a NaN, Inf or negative result, and the input guards that remove them.
#[allow(clippy::too_many_arguments)]
fn locate_failures(
    gpu: &Gpu,
    model: &Model,
    cases: &[HardCase],
    case_out: &[[f32; 3]],
    judged: &[Option<CaseResult>],
    grid: &[Sample],
    grid_out: &[[f32; 3]],
    in_domain: &[bool],
) -> Result<Failures> {
    let case_models: Vec<(Model, &str, Sample)> =
        cases.iter().map(|c| (case_model(model, c), c.name.as_str(), c.sample)).collect();
    // Invalid-input cases and those outside the domain are not failures of a valid input.
    let counted = |i: usize| cases[i].expect == Expect::Twin && judged[i].is_some();
    let case_out: Vec<[f32; 3]> =
        case_out.iter().enumerate().map(|(i, g)| if counted(i) { *g } else { [0.0; 3] }).collect();
    let grid_out: Vec<[f32; 3]> =
        grid_out.iter().zip(in_domain).map(|(g, &inside)| if inside { *g } else { [0.0; 3] }).collect();
    failures::locate(gpu, &case_models, &case_out, model, grid, &grid_out)
}
