//! `brdfprof profile`: what each model costs per BRDF evaluation on a device, measured by the protocol in
//! `protocol` over the synthetic G-buffer of `gbuffer`, and reported with confidence intervals, as ratios to
//! a reference model measured in the same rounds, and net of a memory-only baseline kernel.

pub mod gbuffer;
pub mod protocol;

use crate::gpu::Gpu;
use crate::model::Model;
use crate::shaders::Shaders;
use crate::report::{self, Provenance, Table};
use crate::stats::{self, Estimate};
use anyhow::Result;
use indicatif::ProgressBar;
use protocol::{ProtocolOptions, RawTimes, Variant, Workload};
use serde::Serialize;

pub use crate::brdf::spec::REFERENCE_MODEL;
/// Confidence level of every interval.
pub const LEVEL: f64 = 0.95;

#[derive(Clone, Debug)]
pub struct ProfileOptions {
    pub models: Vec<Model>,
    pub width: u32,
    pub height: u32,
    pub lights: u32,
    pub protocol: ProtocolOptions,
    /// Stop once every ratio to the reference has a CI half-width below this fraction of the ratio (and every
    /// net ratio below twice it).
    pub target_rel_ci: f64,
    pub max_chunk: Option<u64>,
    /// Independently compiled pipelines per kernel, all timed every round; the faster one's time counts
    /// (see `protocol::Variant`).
    pub instances: usize,
}

/// One row of the table.
#[derive(Clone, Debug, Serialize)]
pub struct Row {
    /// The spec's name (a preset name where one matches), or "baseline".
    pub model: String,
    pub spec: Option<String>,
    pub ns_per_eval: Estimate,
    pub evals_per_second: f64,
    /// Cost / reference cost, per round.
    pub vs_reference: Estimate,
    /// (cost - baseline) per evaluation.
    pub net_ns_per_eval: Option<Estimate>,
    /// (cost - baseline) / (reference cost - baseline), per round.
    pub net_vs_reference: Option<Estimate>,
    /// Median over rounds of slowest / fastest instance: how much JIT code placement alone moved this kernel.
    pub instance_spread: f64,
}

#[derive(Clone, Debug, Serialize)]
pub struct WorkloadSize {
    pub width: u32,
    pub height: u32,
    pub pixels: u64,
    pub lights: u32,
    pub evaluations_per_dispatch: u64,
    pub bytes_per_pixel: usize,
    pub chunks: usize,
}

#[derive(Clone, Debug, Serialize)]
pub struct ProfileReport {
    pub provenance: Provenance,
    pub reference: String,
    pub workload: WorkloadSize,
    pub rounds: usize,
    pub reps_per_round: usize,
    /// Pipelines per kernel (see `ProfileOptions::instances`).
    pub instances: usize,
    pub confidence_level: f64,
    pub rows: Vec<Row>,
    /// Labels of the variants, indexing `raw.ns`.
    pub labels: Vec<String>,
    pub raw: RawTimes,
}

/// Per-round medians of a variant's dispatch times, per evaluation.
pub fn per_round(raw: &RawTimes, variant: usize, evals: f64) -> Vec<f64> {
    raw.round_medians(variant).iter().map(|t| t / evals).collect()
}

/// Statistics of every variant; `reference` and `baseline` index variants.
pub fn analyse(raw: &RawTimes, labels: &[String], specs: &[Option<Model>], evals: u64, reference: usize, baseline: Option<usize>) -> Vec<Row> {
    let e = evals as f64;
    let reference_t = per_round(raw, reference, e);
    let baseline_t = baseline.map(|b| per_round(raw, b, e));
    (0..labels.len())
        .map(|i| {
            let t = per_round(raw, i, e);
            let ratio: Vec<f64> = t.iter().zip(&reference_t).map(|(a, r)| a / r).collect();
            let ns = stats::median_ci(&t, LEVEL);
            let (net, net_ratio) = match (&baseline_t, Some(i) != baseline) {
                (Some(b), true) => {
                    let net: Vec<f64> = t.iter().zip(b).map(|(a, b)| a - b).collect();
                    let net_ratio: Vec<f64> = net.iter().zip(reference_t.iter().zip(b)).map(|(n, (r, b))| n / (r - b)).collect();
                    (Some(stats::median_ci(&net, LEVEL)), Some(stats::median_ci(&net_ratio, LEVEL)))
                }
                _ => (None, None),
            };
            Row {
                model: labels[i].clone(),
                spec: specs[i].as_ref().map(Model::canonical),
                ns_per_eval: ns,
                evals_per_second: 1e9 / ns.median,
                vs_reference: stats::median_ci(&ratio, LEVEL),
                net_ns_per_eval: net,
                net_vs_reference: net_ratio,
                instance_spread: raw.instance_spread(i),
            }
        })
        .collect()
}

/// True once every model's ratio is resolved to `target` (net ratios to twice that). The baseline's own
/// ratio does not count: its noise is already inside the net ratios.
fn resolved(rows: &[Row], reference: usize, target: f64) -> bool {
    rows.iter().enumerate().filter(|(i, r)| *i != reference && r.spec.is_some()).all(|(_, r)| {
        r.vs_reference.rel_half_width() < target && r.net_vs_reference.is_none_or(|n| n.rel_half_width() < 2.0 * target)
    })
}

/// Runs the profile: the models (the reference added when missing) and the baseline, interleaved.
pub fn run(gpu: &Gpu, options: &ProfileOptions, progress: &ProgressBar) -> Result<ProfileReport> {
    let reference_model = Model::reference();
    let mut models = options.models.clone();
    if !models.contains(&reference_model) {
        models.insert(0, reference_model.clone());
    }
    progress.set_message("building the G-buffer");
    let gbuffer = gbuffer::synthetic(options.width, options.height);
    let lights = gbuffer::lights(options.lights);
    let work = Workload::upload(gpu, &gbuffer, &lights, options.max_chunk)?;
    drop(gbuffer);
    let mut specs: Vec<Option<Model>> = models.iter().cloned().map(Some).collect();
    specs.push(None);
    progress.set_message("compiling kernels");
    let shaders = Shaders::embedded();
    let variants = specs.iter().map(|s| Variant::new(gpu, &work, s.as_ref(), &shaders, options.instances)).collect::<Result<Vec<_>>>()?;
    let labels: Vec<String> = variants.iter().map(|v| v.label.clone()).collect();
    let reference = models.iter().position(|m| *m == reference_model).unwrap();
    let baseline = Some(variants.len() - 1);
    let evals = work.evaluations();
    progress.set_length(options.protocol.max_rounds as u64);
    let raw = protocol::measure(
        gpu,
        &variants,
        &options.protocol,
        |raw| resolved(&analyse(raw, &labels, &specs, evals, reference, baseline), reference, options.target_rel_ci),
        |raw| {
            progress.set_position(raw.rounds() as u64);
            progress.set_message(format!("{:.0} s", raw.elapsed_s));
        },
    )?;
    let rows = analyse(&raw, &labels, &specs, evals, reference, baseline);
    Ok(ProfileReport {
        provenance: Provenance::new(&gpu.info),
        reference: REFERENCE_MODEL.into(),
        workload: WorkloadSize {
            width: options.width,
            height: options.height,
            pixels: work.pixel_count,
            lights: work.light_count,
            evaluations_per_dispatch: evals,
            bytes_per_pixel: gbuffer::PIXEL_FLOATS * 4,
            chunks: work.chunks(),
        },
        rounds: raw.rounds(),
        reps_per_round: options.protocol.reps,
        instances: options.instances,
        confidence_level: LEVEL,
        rows,
        labels,
        raw,
    })
}

impl ProfileReport {
    pub fn table(&self) -> Table {
        let r = &self.reference;
        let mut t = Table::new([
            "model".to_string(),
            "ns/eval [95% CI]".into(),
            "Meval/s".into(),
            format!("vs {r} [95% CI]"),
            "net ns/eval [95% CI]".into(),
            format!("net vs {r} [95% CI]"),
        ]);
        for row in &self.rows {
            t.row([
                row.model.clone(),
                report::estimate(&row.ns_per_eval, 3),
                report::sig(row.evals_per_second / 1e6, 3),
                report::estimate(&row.vs_reference, 3),
                row.net_ns_per_eval.as_ref().map_or("-".into(), |e| report::estimate(e, 3)),
                row.net_vs_reference.as_ref().map_or("-".into(), |e| report::estimate(e, 3)),
            ]);
        }
        t
    }

    /// A line per kernel whose independently compiled pipelines differed by more than 10% (code placement):
    /// its figures are the faster pipeline's.
    pub fn placement_notes(&self) -> String {
        self.rows
            .iter()
            .filter(|r| r.instance_spread > 1.10)
            .map(|r| format!("note: {}'s {} pipelines differed by {:.0}% (median over rounds); its figures are the faster one's\n", r.model, self.instances, (r.instance_spread - 1.0) * 100.0))
            .collect()
    }

    /// One line saying what was measured.
    pub fn summary(&self) -> String {
        let w = &self.workload;
        format!(
            "{} ({}, {}); {}x{} pixels x {} lights = {} evaluations per dispatch; {} rounds x {} reps x {} pipelines per kernel, interleaved; {:.0} s",
            self.provenance.device.name,
            self.provenance.device.driver_name,
            self.provenance.device.driver_info,
            w.width,
            w.height,
            w.lights,
            w.evaluations_per_dispatch,
            self.rounds,
            self.reps_per_round,
            self.instances,
            self.raw.elapsed_s
        )
    }
}
