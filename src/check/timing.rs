//! The timing half of `check`: the profile protocol (an untimed warm-up per kernel, then interleaved rounds
//! in a fresh random order) over a small synthetic G-buffer. Per round, each model's cost is divided by a
//! reference measured in the same round, so that the machine's drift cancels; the per-round ratios are what
//! `check` compares with a Mann-Whitney U test.
//!
//! The reference is the geometric mean of the models' costs in the round (with one model, the memory-only
//! kernel's cost). Measured on this project's shared 2-core VM, five runs each at two G-buffer sizes under
//! varying load: the round medians of ratios to the geometric mean stayed within 2% of each other, ratios
//! to the memory-only kernel moved by up to 14% (its time, dominated by per-lane loads, drifts differently
//! from the models' arithmetic). The price: a change that slows every model by the same factor cancels in
//! these ratios; the instruction counts (SPIR-V, callgrind) catch that kind of change.

use crate::gpu::Gpu;
use crate::kernels::shade::GBufferFormat;
use crate::measure::gbuffer;
use crate::measure::protocol::{self, ProtocolOptions};
use crate::measure::workload::{Variant, Workload};
use crate::model::BASELINE_LABEL;
use crate::model::Model;
use crate::shaders::Shaders;
use crate::stats;
use anyhow::{Result, bail};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::time::Duration;

#[derive(Clone, Debug)]
pub struct TimingOptions {
    pub width: u32,
    pub height: u32,
    pub lights: u32,
    pub rounds: usize,
    pub reps: usize,
    pub seed: u64,
}

#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct TimingRun {
    /// What every ratio divides by (see `reference_of`).
    pub reference: String,
    pub width: u32,
    pub height: u32,
    pub lights: u32,
    pub rounds: usize,
    pub reps: usize,
    /// Model -> its cost / the reference's cost, one ratio per round.
    pub ratios: BTreeMap<String, Vec<f64>>,
    /// Kernel (models and "baseline") -> its median dispatch time in each round, ns: the raw figures.
    pub round_ns: BTreeMap<String, Vec<f64>>,
    /// Kernel -> median ns per evaluation over rounds (for reading only: absolute times drift, ratios do not).
    pub ns_per_eval: BTreeMap<String, f64>,
}

/// The reference of a timing run over `models` (in order): its description, and its cost in each round.
pub fn reference_of(models: &[String], round_ns: &BTreeMap<String, Vec<f64>>) -> (String, Vec<f64>) {
    if models.len() < 2 {
        return (format!("the memory-only kernel ({BASELINE_LABEL})"), round_ns[BASELINE_LABEL].clone());
    }
    let rounds = round_ns[&models[0]].len();
    let geomean = (0..rounds)
        .map(|r| (models.iter().map(|m| round_ns[m][r].ln()).sum::<f64>() / models.len() as f64).exp())
        .collect();
    (format!("the geometric mean of the models' costs in the round ({})", models.join(", ")), geomean)
}

/// Times every model's shading kernel and the baseline kernel, interleaved.
pub fn run(gpu: &Gpu, shaders: &Shaders, models: &[Model], options: &TimingOptions) -> Result<TimingRun> {
    if options.rounds == 0 {
        bail!("a timing run needs at least one round");
    }
    let work = Workload::upload(
        gpu,
        &gbuffer::synthetic(options.width, options.height, GBufferFormat::Packed),
        &gbuffer::lights(options.lights),
        None,
    )?;
    let mut all: Vec<Option<&Model>> = models.iter().map(Some).collect();
    all.push(None);
    let variants = all.iter().map(|m| Variant::new(gpu, &work, *m, shaders, 1)).collect::<Result<Vec<_>>>()?;
    let protocol_options = ProtocolOptions {
        min_rounds: options.rounds,
        max_rounds: options.rounds,
        reps: options.reps.max(1),
        budget: Duration::from_secs(3600),
        started: std::time::Instant::now(),
        seed: options.seed,
    };
    let raw = protocol::measure(gpu, &variants, &protocol_options, |_| false, |_| {})?;
    let base = variants.len() - 1;
    let evals = work.evaluations() as f64;
    let label = |i: usize| if i == base { BASELINE_LABEL.to_string() } else { variants[i].label.clone() };
    let round_ns: BTreeMap<String, Vec<f64>> = (0..variants.len()).map(|i| (label(i), raw.round_medians(i))).collect();
    let ns_per_eval = round_ns.iter().map(|(k, t)| (k.clone(), stats::median(t) / evals)).collect();
    let models: Vec<String> = (0..base).map(label).collect();
    let (reference, reference_ns) = reference_of(&models, &round_ns);
    let ratios = models
        .iter()
        .map(|m| (m.clone(), round_ns[m].iter().zip(&reference_ns).map(|(a, r)| a / r).collect()))
        .collect();
    Ok(TimingRun {
        reference,
        width: options.width,
        height: options.height,
        lights: options.lights,
        rounds: raw.rounds(),
        reps: protocol_options.reps,
        ratios,
        round_ns,
        ns_per_eval,
    })
}
