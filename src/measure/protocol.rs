//! The measurement protocol. Every variant (a model's kernel, or the memory-only baseline) gets an untimed
//! warm-up dispatch (lavapipe JIT-compiles a pipeline at its first dispatch). Then rounds: each round is one
//! submission in which every variant runs `reps` times, interleaved (A B C, C A B, ...; a fresh seeded
//! permutation per repetition), each dispatch between a barrier-fenced pair of BOTTOM_OF_PIPE timestamps.
//! Costs are compared as ratios within a round, so the machine's drift between rounds cancels. All raw times
//! are kept, outliers included.

use crate::gpu::{Binding, Bindings, Commands, Gpu, Kernel, SpecConstants, Timestamps};
use crate::shaders::Spirv;
use anyhow::Result;
use rand::SeedableRng;
use rand::seq::SliceRandom;
use serde::Serialize;
use std::time::{Duration, Instant};

/// One dispatch of a pipeline instance: which of its kernels, the bindings (with the offsets of its dynamic
/// uniform buffers), push constants and invocations.
pub struct Dispatch {
    pub kernel: usize,
    pub set: Bindings,
    pub offsets: Vec<u32>,
    pub push: Vec<u8>,
    pub invocations: u64,
}

/// One piece of work compiled as one or more independent pipelines (instances): on lavapipe the same kernel
/// JIT-compiled twice has been seen to run 2x slower in every round of one process (code placement), and only
/// a second pipeline exposes that. An instance holds the kernels of the work and its dispatches in steps: the
/// dispatches of a step are independent (chunks of one picture), a barrier separates steps (a step reads what
/// the one before it wrote). `measure` times every instance.
pub struct Pipelines<'g> {
    gpu: &'g Gpu,
    instances: Vec<(Vec<Kernel<'g>>, Vec<Vec<Dispatch>>)>,
}

impl<'g> Pipelines<'g> {
    /// `count` instances, each compiling every (SPIR-V, constants) of `kernels` and planning its steps with
    /// `plan(kernels)`.
    pub fn compile(
        gpu: &'g Gpu,
        kernels: &[(Spirv, SpecConstants)],
        bindings: &[Binding],
        push_bytes: u32,
        count: usize,
        plan: impl Fn(&[Kernel<'g>]) -> Result<Vec<Vec<Dispatch>>>,
    ) -> Result<Self> {
        let instances = (0..count.max(1))
            .map(|_| {
                let compiled = kernels
                    .iter()
                    .map(|(spirv, c)| Kernel::new(gpu, &spirv.name, &spirv.words, c, bindings, push_bytes))
                    .collect::<Result<Vec<_>>>()?;
                let steps = plan(&compiled)?;
                Ok((compiled, steps))
            })
            .collect::<Result<Vec<_>>>()?;
        Ok(Pipelines { gpu, instances })
    }

    pub fn len(&self) -> usize {
        self.instances.len()
    }

    pub fn is_empty(&self) -> bool {
        self.instances.is_empty()
    }

    /// Records every step of pipeline `instance`, a barrier between steps.
    pub fn record(&self, cmd: &Commands, instance: usize) {
        let (kernels, steps) = &self.instances[instance];
        for (s, step) in steps.iter().enumerate() {
            if s > 0 {
                self.gpu.barrier(cmd);
            }
            for d in step {
                kernels[d.kernel].dispatch_at(cmd, d.set, &d.offsets, &d.push, d.invocations);
            }
        }
    }
}

#[derive(Clone, Debug)]
pub struct ProtocolOptions {
    pub min_rounds: usize,
    pub max_rounds: usize,
    /// Timed dispatches of every variant per round.
    pub reps: usize,
    /// Wall-clock budget of the whole command, counted from `started`: building the inputs, compiling and
    /// warming up spend it too. The run stops before a round that would overrun it (once it has
    /// `BUDGET_MIN_ROUNDS`).
    pub budget: Duration,
    /// When the command began.
    pub started: Instant,
    pub seed: u64,
}

/// Rounds a run keeps even past its budget: the fewest that give a ratio and a spread.
pub const BUDGET_MIN_ROUNDS: usize = 2;

/// Why the rounds stopped.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Stop {
    /// Every figure reached its CI target.
    Converged,
    /// The budget ran out first.
    #[default]
    Budget,
    MaxRounds,
}

/// Every timed dispatch, as measured.
#[derive(Clone, Debug, Default, Serialize)]
pub struct RawTimes {
    /// ns[variant][round][rep]: dispatch time in nanoseconds, of the variant's faster instance that round.
    pub ns: Vec<Vec<Vec<f64>>>,
    /// instance_ns[variant][round][instance]: each instance's median over its repetitions (the spread between
    /// instances is what code placement alone costs).
    pub instance_ns: Vec<Vec<Vec<f64>>>,
    /// The order of every repetition of every round, as (variant, instance) pairs.
    pub orders: Vec<Vec<Vec<(usize, usize)>>>,
    /// Wall time of each variant's first instance's untimed warm-up dispatch (includes JIT compilation).
    pub warmup_ms: Vec<f64>,
    /// Seconds from the command's start to the first timed round (inputs, compilation, warm-up).
    pub setup_s: f64,
    /// Seconds of timed rounds.
    pub elapsed_s: f64,
    pub stop: Stop,
}

impl RawTimes {
    pub fn rounds(&self) -> usize {
        self.orders.len()
    }

    /// The median of `variant`'s repetitions in each round: the figure every analysis starts from.
    pub fn round_medians(&self, variant: usize) -> Vec<f64> {
        self.ns[variant].iter().map(|reps| crate::stats::median(reps)).collect()
    }

    /// Median over rounds of (slowest instance / fastest instance) of `variant`: 1 when its pipelines agree.
    pub fn instance_spread(&self, variant: usize) -> f64 {
        let spreads: Vec<f64> = self.instance_ns[variant]
            .iter()
            .map(|r| {
                r.iter().copied().fold(f64::NEG_INFINITY, f64::max) / r.iter().copied().fold(f64::INFINITY, f64::min)
            })
            .collect();
        if spreads.is_empty() { 1.0 } else { crate::stats::median(&spreads) }
    }
}

/// Runs the protocol. After each round (from `min_rounds` on) `converged` sees the times so far; the run
/// stops when it returns true, at `max_rounds`, or when the budget is spent (even before `min_rounds`).
/// `measure`, showing its rounds on `progress` (position, seconds of rounds so far): what profile and scene
/// profile both show.
pub fn measure_with_progress<V: Timed>(
    gpu: &Gpu,
    variants: &[V],
    options: &ProtocolOptions,
    converged: impl FnMut(&RawTimes) -> bool,
    progress: &indicatif::ProgressBar,
) -> Result<RawTimes> {
    progress.set_length(options.max_rounds as u64);
    measure(gpu, variants, options, converged, |raw| {
        progress.set_position(raw.rounds() as u64);
        progress.set_message(format!("{:.0} s of rounds", raw.elapsed_s));
    })
}

pub fn measure<V: Timed>(
    gpu: &Gpu,
    variants: &[V],
    options: &ProtocolOptions,
    mut converged: impl FnMut(&RawTimes) -> bool,
    mut on_round: impl FnMut(&RawTimes),
) -> Result<RawTimes> {
    let v = variants.len();
    let mut raw = RawTimes { ns: vec![Vec::new(); v], instance_ns: vec![Vec::new(); v], ..Default::default() };
    let slots: Vec<(usize, usize)> =
        variants.iter().enumerate().flat_map(|(i, var)| (0..var.instances()).map(move |k| (i, k))).collect();
    for &(i, k) in &slots {
        let warm = variants[i].run_once(gpu, k)?;
        if k == 0 {
            raw.warmup_ms.push(warm.as_secs_f64() * 1e3);
        }
    }
    let timestamps = Timestamps::new(gpu, (2 * slots.len() * options.reps) as u32)?;
    let mut rng = rand_pcg::Pcg64::seed_from_u64(options.seed);
    let start = Instant::now();
    raw.setup_s = options.started.elapsed().as_secs_f64();
    raw.stop = Stop::MaxRounds;
    let mut slowest_round = Duration::ZERO;
    for round in 0..options.max_rounds {
        let round_start = Instant::now();
        time_round(gpu, variants, &timestamps, &slots, options.reps, &mut rng, &mut raw)?;
        raw.elapsed_s = start.elapsed().as_secs_f64();
        on_round(&raw);
        if round + 1 >= options.min_rounds && converged(&raw) {
            raw.stop = Stop::Converged;
            break;
        }
        // Stop before a round that would overrun the budget (as long as the slowest so far).
        slowest_round = slowest_round.max(round_start.elapsed());
        if round + 1 >= BUDGET_MIN_ROUNDS && options.started.elapsed() + slowest_round >= options.budget {
            raw.stop = Stop::Budget;
            break;
        }
    }
    Ok(raw)
}

/// One round: `reps` shuffled orders of every (variant, instance) slot in one submission; per variant the
/// faster instance's repetitions (by median) join `raw`, with every instance's median and the orders.
fn time_round<V: Timed>(
    gpu: &Gpu,
    variants: &[V],
    timestamps: &Timestamps,
    slots: &[(usize, usize)],
    reps: usize,
    rng: &mut rand_pcg::Pcg64,
    raw: &mut RawTimes,
) -> Result<()> {
    let orders: Vec<Vec<(usize, usize)>> = (0..reps)
        .map(|_| {
            let mut o = slots.to_vec();
            o.shuffle(rng);
            o
        })
        .collect();
    let mut pairs = Vec::new();
    gpu.submit(|cmd| {
        timestamps.reset(cmd);
        for order in &orders {
            for &(i, k) in order {
                let q = pairs.len() as u32 * 2;
                gpu.barrier(cmd);
                timestamps.write(cmd, q);
                variants[i].record(cmd, k);
                timestamps.write(cmd, q + 1);
                pairs.push((q, q + 1));
            }
        }
    })?;
    let times = timestamps.intervals_ns(&pairs)?;
    // Per variant: each instance's repetitions; keep the faster instance's (by median) for the round.
    let mut by_slot: Vec<Vec<Vec<f64>>> = variants.iter().map(|var| vec![Vec::new(); var.instances()]).collect();
    for (t, &(i, k)) in times.iter().zip(orders.iter().flatten()) {
        by_slot[i][k].push(*t);
    }
    for (i, instances) in by_slot.into_iter().enumerate() {
        let medians: Vec<f64> = instances.iter().map(|reps| crate::stats::median(reps)).collect();
        let fastest = (0..medians.len()).min_by(|&a, &b| medians[a].total_cmp(&medians[b])).unwrap();
        raw.ns[i].push(instances[fastest].clone());
        raw.instance_ns[i].push(medians);
    }
    raw.orders.push(orders);
    Ok(())
}

/// What the protocol can time: a variant that records its dispatches into a command buffer (the profile's
/// `workload::Variant`; the scene kernels of `scene::run`), as one or more independently compiled instances.
/// `measure` warms every instance up untimed first (lavapipe compiles a pipeline at its first dispatch).
pub trait Timed {
    /// Independently compiled pipelines of the same kernel.
    fn instances(&self) -> usize {
        1
    }
    /// Records instance `instance`'s dispatches (no barriers or timestamps: `measure` adds those).
    fn record(&self, cmd: &Commands, instance: usize);

    /// One untimed run of `instance`, waited for; its wall time (on lavapipe the first includes compilation).
    fn run_once(&self, gpu: &Gpu, instance: usize) -> Result<Duration> {
        let start = Instant::now();
        gpu.submit(|cmd| self.record(cmd, instance))?;
        Ok(start.elapsed())
    }
}
