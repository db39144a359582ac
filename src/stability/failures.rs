//! Where a model fails: each NaN, Inf or negative result on a valid input, tied to its hard case (or grid
//! point) with the input values, and which of brdfprof's guards, applied to the inputs as an engine's caller
//! could (`guards::INPUT_GUARDS`), removes it. For a `.brdf` file, whose formula brdfprof cannot guard, this
//! is what `--unguarded`'s "what each guard saves" is for a built-in spec.

use crate::brdf::Sample;
use crate::brdf::guards::{INPUT_GUARDS, apply_all_input_guards, unit};
use crate::gpu::Gpu;
use crate::kernels::{self, RunLimits};
use crate::model::Model;
use anyhow::Result;
use serde::{Deserialize, Serialize};

/// Grid failures listed one by one (the rest are counted).
pub const GRID_EXAMPLES: usize = 5;
/// The name `Failure::removed_by` and `GridRemoval` give every input guard at once.
pub const ALL_GUARDS: &str = "all";

/// One failing input; read back from stability reports by what the Markdown and the HTML page show.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Failure {
    /// The hard case's name, or `grid` for a grid point.
    pub at: String,
    #[serde(skip_deserializing)]
    pub input: Sample,
    /// The input as a reader checks it: vectors, cosines, |V + L|, roughness, F0.
    pub inputs: String,
    /// The model's result (NaN and Inf written as null), and as text (NaN and Inf by name).
    #[serde(skip_deserializing)]
    pub got: [f32; 3],
    pub result: String,
    /// The input guards that each remove it alone, then `all` if all of them together do.
    pub removed_by: Vec<String>,
}

/// How many of the grid's failing points an input guard removes alone (or all of them at once: `all`).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct GridRemoval {
    pub guard: String,
    pub removes: usize,
}

/// Every failing input of one model.
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct Failures {
    /// Every hard case with a NaN, Inf or negative result, in catalogue order.
    pub cases: Vec<Failure>,
    /// Grid points with one, the first few of them, and what each guard removes of them.
    pub grid_points: usize,
    pub grid_examples: Vec<Failure>,
    pub grid_removed_by: Vec<GridRemoval>,
}

impl Failures {
    pub fn is_empty(&self) -> bool {
        self.cases.is_empty() && self.grid_points == 0
    }

    /// The first failing input, a case before the grid.
    pub fn first(&self) -> Option<&Failure> {
        self.cases.first().or(self.grid_examples.first())
    }
}

fn bad(g: &[f32; 3]) -> bool {
    g.iter().any(|x| !x.is_finite() || *x < 0.0)
}

/// Shortest text that reads back as the f32 (exponent form for the tiny and the huge).
fn num(x: f32) -> String {
    if x != 0.0 && x.is_finite() && !(1e-4..1e6).contains(&x.abs()) { format!("{x:e}") } else { format!("{x}") }
}

fn triple(v: [f32; 3]) -> String {
    format!("({}, {}, {})", num(v[0]), num(v[1]), num(v[2]))
}

/// A sample as a reader checks it: the vectors as given, then what the kernel's geometry sees.
pub fn describe(s: &Sample) -> String {
    let (n, v, l) = (unit(s.n), unit(s.v), unit(s.l));
    format!(
        "N {} V {} L {}: NoV {:.3e}, NoL {:.3e}, |V + L| {:.3e}; roughness {}, F0 {}",
        triple(s.n),
        triple(s.v),
        triple(s.l),
        n.dot(v),
        n.dot(l),
        (v + l).length(),
        num(s.roughness),
        triple(s.f0)
    )
}

/// A result as the report writes it.
pub fn result_text(g: &[f32; 3]) -> String {
    triple(*g)
}

/// Sample `s` under each input guard alone, then under all of them; None where a guard means no call.
fn guarded(s: &Sample, min_roughness: f64) -> Vec<Option<Sample>> {
    INPUT_GUARDS
        .iter()
        .map(|g| (g.apply)(s, min_roughness))
        .chain(std::iter::once(apply_all_input_guards(s, min_roughness)))
        .collect()
}

/// Adds sample `s` to model `m`'s job (a new one for a model not in `jobs` yet); returns (job, index in it).
fn queue_job(jobs: &mut Vec<(Model, Vec<Sample>)>, m: &Model, s: Sample) -> (usize, usize) {
    let k = match jobs.iter().position(|(j, _)| j == m) {
        Some(k) => k,
        None => {
            jobs.push((m.clone(), Vec::new()));
            jobs.len() - 1
        }
    };
    jobs[k].1.push(s);
    (k, jobs[k].1.len() - 1)
}

/// One model's failing inputs at each hard case (`case_models[i]` is the model case i ran) and grid point,
/// each run again under every input guard alone and all of them together.
pub fn locate(
    gpu: &Gpu,
    case_models: &[(Model, &str, Sample)],
    case_out: &[[f32; 3]],
    model: &Model,
    grid: &[Sample],
    grid_out: &[[f32; 3]],
) -> Result<Failures> {
    let min_roughness = model.precision().min_roughness();
    let failing_cases: Vec<usize> = (0..case_out.len()).filter(|&i| bad(&case_out[i])).collect();
    let failing_grid: Vec<usize> = (0..grid_out.len()).filter(|&i| bad(&grid_out[i])).collect();
    // (model, sample) per (failing input, guard), None where the guard means no call: batched per model.
    let variants = |s: &Sample| guarded(s, min_roughness);
    let names: Vec<String> =
        INPUT_GUARDS.iter().map(|g| g.name.to_string()).chain(std::iter::once(ALL_GUARDS.to_string())).collect();
    let mut jobs: Vec<(Model, Vec<Sample>)> = Vec::new();
    let mut queue = |m: &Model, s: Sample| queue_job(&mut jobs, m, s);
    let mut plan: Vec<Vec<Option<(usize, usize)>>> = Vec::new();
    for &i in &failing_cases {
        plan.push(variants(&case_models[i].2).into_iter().map(|v| v.map(|s| queue(&case_models[i].0, s))).collect());
    }
    for &i in &failing_grid {
        plan.push(variants(&grid[i]).into_iter().map(|v| v.map(|s| queue(model, s))).collect());
    }
    let mut results = Vec::new();
    for (m, samples) in &jobs {
        results.push(kernels::eval(gpu, m, samples, RunLimits::default())?);
    }
    // Removed: no call at all, or a finite non-negative result.
    let removed: Vec<Vec<bool>> =
        plan.iter().map(|p| p.iter().map(|at| at.is_none_or(|(k, j)| !bad(&results[k][j]))).collect()).collect();
    let failure = |at: &str, s: &Sample, got: &[f32; 3], removed: &[bool]| Failure {
        at: at.to_string(),
        input: *s,
        inputs: describe(s),
        got: *got,
        result: result_text(got),
        removed_by: names.iter().zip(removed).filter(|(_, r)| **r).map(|(n, _)| n.clone()).collect(),
    };
    let cases = failing_cases
        .iter()
        .zip(&removed)
        .map(|(&i, r)| failure(case_models[i].1, &case_models[i].2, &case_out[i], r))
        .collect();
    let grid_removed = &removed[failing_cases.len()..];
    Ok(Failures {
        cases,
        grid_points: failing_grid.len(),
        grid_examples: distinct(
            failing_grid.iter().zip(grid_removed).map(|(&i, r)| failure("grid", &grid[i], &grid_out[i], r)),
        )
        .into_iter()
        .take(GRID_EXAMPLES)
        .collect(),
        grid_removed_by: names
            .iter()
            .enumerate()
            .map(|(g, n)| GridRemoval { guard: n.clone(), removes: grid_removed.iter().filter(|r| r[g]).count() })
            .collect(),
    })
}

/// The failures with distinct inputs as written (grid points at N = V = L differ only in their azimuth's
/// rounding), in order.
fn distinct(all: impl Iterator<Item = Failure>) -> Vec<Failure> {
    let mut out: Vec<Failure> = Vec::new();
    for f in all {
        if !out.iter().any(|o| o.inputs == f.inputs) {
            out.push(f);
        }
    }
    out
}

/// The guards that remove a failure, as a sentence's end.
pub fn removed_text(f: &Failure) -> String {
    let alone: Vec<&str> = f.removed_by.iter().map(String::as_str).filter(|n| *n != ALL_GUARDS).collect();
    match (alone.as_slice(), f.removed_by.iter().any(|n| n == ALL_GUARDS)) {
        ([], false) => "no input guard removes it".into(),
        ([], true) => "removed only by all input guards together".into(),
        (some, _) => format!("removed by {}", some.iter().map(|n| format!("`{n}`")).collect::<Vec<_>>().join(", ")),
    }
}

impl Failures {
    /// One spec's failures as (depth, Markdown text) list items: each failing hard case (cases on the same
    /// inputs, a term parameter's cases for a model that reads none, share one), then the grid.
    pub fn lines(&self) -> Vec<(usize, String)> {
        let mut out = Vec::new();
        let same =
            |a: &Failure, b: &Failure| a.inputs == b.inputs && a.removed_by == b.removed_by && a.result == b.result;
        for (i, f) in self.cases.iter().enumerate() {
            if self.cases[..i].iter().any(|o| same(o, f)) {
                continue;
            }
            let names: Vec<String> = self.cases.iter().filter(|o| same(o, f)).map(|o| format!("`{}`", o.at)).collect();
            let which = if names.len() == 1 {
                format!("hard case {}", names[0])
            } else {
                format!("hard cases {}", names.join(", "))
            };
            out.push((0, format!("{which}: {} gives {}; {}", f.inputs, f.result, removed_text(f))));
        }
        if self.grid_points > 0 {
            let by: Vec<String> = self.grid_removed_by.iter().map(|g| format!("`{}` {}", g.guard, g.removes)).collect();
            out.push((
                0,
                format!(
                    "grid: {} points; removed by each input guard alone (and by all at once): {}",
                    self.grid_points,
                    by.join(", ")
                ),
            ));
            for f in &self.grid_examples {
                out.push((1, format!("{} gives {}; {}", f.inputs, f.result, removed_text(f))));
            }
        }
        out
    }

    /// The Markdown list of one spec's failures under `- `label`: counts`.
    pub fn markdown(&self, label: &str, counts: &str) -> String {
        let mut out = format!("- `{label}`: {counts}\n");
        for (depth, line) in self.lines() {
            out += &format!("{}- {line}\n", "  ".repeat(depth + 1));
        }
        out
    }
}
