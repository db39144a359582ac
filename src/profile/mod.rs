//! `brdfprof profile`: what each model costs per BRDF evaluation on a device, measured by the protocol in
//! `measure::protocol` over the synthetic G-buffer of `measure::gbuffer`, and reported with confidence intervals, as ratios to
//! a reference model measured in the same rounds, and net of a memory-only baseline kernel.

use crate::export::json::Provenance;
use crate::export::markdown::{self, Table};
use crate::gpu::Gpu;
use crate::host_cpu::HostCpu;
use crate::measure::{gbuffer, protocol, workload};
use crate::model::Model;
use crate::shaders::Shaders;
use crate::stats::{self, Estimate};
use anyhow::Result;
use gbuffer::GBufferFormat;
use indicatif::ProgressBar;
use protocol::{ProtocolOptions, RawTimes};
use serde::{Deserialize, Serialize};
use workload::{Variant, Workload};

pub use crate::brdf::spec::REFERENCE_MODEL;
/// The harness share above which `harness_warning` speaks.
pub const HARNESS_WARNING: f64 = 0.5;
/// Confidence level of every interval.
pub const LEVEL: f64 = 0.95;

#[derive(Clone, Debug)]
pub struct ProfileOptions {
    pub models: Vec<Model>,
    pub width: u32,
    pub height: u32,
    /// Light counts, each its own workload; all are timed in the same interleaved rounds.
    pub lights: Vec<u32>,
    pub format: GBufferFormat,
    pub protocol: ProtocolOptions,
    /// Stop once every ratio to the reference has a CI half-width below this fraction of the ratio (and every
    /// net ratio below twice it).
    pub target_rel_ci: f64,
    pub max_chunk: Option<u64>,
    /// Independently compiled pipelines per kernel, all timed every round; the faster one's time counts
    /// (see `protocol::Variant`).
    pub instances: usize,
    /// Compile the kernels from this GLSL directory instead of the embedded SPIR-V (`Shaders::from_glsl`).
    pub glsl: Option<std::path::PathBuf>,
}

/// One row of the table. Reports are read back (`report`, `compare`, `inspect --profile`) as these same types:
/// what no reader shows is not read (`skip_deserializing`, its default), so an older report's shape of it never
/// matters.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Row {
    /// The spec's name (a preset name where one matches), or "baseline".
    pub model: String,
    pub spec: Option<String>,
    /// Lights per pixel of this row's workload, and the evaluations one run of it makes.
    pub lights: u32,
    #[serde(default)]
    pub evaluations_per_dispatch: u64,
    pub ns_per_eval: Estimate,
    #[serde(skip_deserializing)]
    pub evals_per_second: f64,
    /// Cost / reference cost, per round.
    pub vs_reference: Estimate,
    /// (cost - baseline) per evaluation.
    pub net_ns_per_eval: Option<Estimate>,
    /// (cost - baseline) / (reference cost - baseline), per round.
    pub net_vs_reference: Option<Estimate>,
    /// baseline / cost, per round: the share of this kernel's time that the memory-only kernel (loads,
    /// decode, light loop, stores) takes.
    pub harness_share: Option<Estimate>,
    /// Why `net_vs_reference` is None for a model with a net cost: the reference's net interval contains 0,
    /// so no ratio to it is resolved (`unresolved_net_ratios`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub net_ratio_unresolved: Option<String>,
    /// Median over rounds of slowest / fastest instance: how much JIT code placement alone moved this kernel.
    #[serde(skip_deserializing)]
    pub instance_spread: f64,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct WorkloadSize {
    pub width: u32,
    pub height: u32,
    #[serde(skip_deserializing)]
    pub pixels: u64,
    /// Every light count measured (each row says which it is).
    pub lights: Vec<u32>,
    /// How the G-buffer is stored, and the bytes per pixel the kernel reads and writes.
    #[serde(skip_deserializing, default = "unread_gbuffer")]
    pub gbuffer: GBufferFormat,
    #[serde(default)]
    pub bytes_per_pixel: u64,
    #[serde(skip_deserializing)]
    pub output_bytes_per_pixel: u64,
    /// Lights per dispatch: the profile's lights run as blocks of at most this many (`workload::light_blocks`).
    #[serde(skip_deserializing)]
    pub light_block: u32,
    #[serde(skip_deserializing)]
    pub chunks: usize,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ProfileReport {
    pub provenance: Provenance,
    pub reference: String,
    pub workload: WorkloadSize,
    pub rounds: usize,
    #[serde(skip_deserializing)]
    pub reps_per_round: usize,
    /// Pipelines per kernel (see `ProfileOptions::instances`).
    #[serde(skip_deserializing)]
    pub instances: usize,
    pub confidence_level: f64,
    pub rows: Vec<Row>,
    /// Labels of the variants, indexing `raw.ns`.
    #[serde(skip_deserializing)]
    pub labels: Vec<String>,
    /// Model (and "baseline") -> SHA-256 of its kernel (`workload::kernel_hash`): `brdfprof compare` joins
    /// reports of the same kernels only.
    #[serde(default)]
    pub kernel_sha256: std::collections::BTreeMap<String, String>,
    #[serde(skip_deserializing)]
    pub raw: RawTimes,
}

/// The G-buffer format a read-back report's workload is given (no reader shows it).
fn unread_gbuffer() -> GBufferFormat {
    GBufferFormat::Packed
}

impl ProfileReport {
    /// Each model's ns/eval with its interval, as benchmark-dashboard entries named `<command>/<device>/<model>`.
    pub fn bench_entries(&self, command: &str) -> Vec<crate::export::bench::Entry> {
        let device = crate::export::name_slug(&self.provenance.device.name);
        self.rows
            .iter()
            .map(|r| {
                let e = &r.ns_per_eval;
                crate::export::bench::Entry {
                    name: format!("{command}/{device}/{}", r.model),
                    unit: "ns/eval".into(),
                    value: e.median,
                    range: crate::export::bench::Entry::range_of(e.median, e.lo, e.hi),
                    interval: Some((e.lo, e.hi)),
                    extra: format!(
                        "median of {} rounds, interval [{}, {}] of coverage {:.3}, {} lights, on {}",
                        e.n,
                        crate::export::markdown::sig(e.lo, 4),
                        crate::export::markdown::sig(e.hi, 4),
                        e.coverage,
                        r.lights,
                        self.provenance.device.name
                    ),
                }
            })
            .collect()
    }

    /// The rows of models (not the memory-only kernel), in report order.
    pub fn model_rows(&self) -> impl Iterator<Item = &Row> {
        self.rows.iter().filter(|r| r.spec.is_some())
    }
}

/// Per-round medians of a variant's dispatch times, per evaluation.
pub fn per_round(raw: &RawTimes, variant: usize, evals: f64) -> Vec<f64> {
    raw.round_medians(variant).iter().map(|t| t / evals).collect()
}

/// The variants of one light count: which variants of the run they are, and which of them is the reference
/// and the baseline.
struct Group {
    lights: u32,
    evaluations: u64,
    variants: std::ops::Range<usize>,
    reference: usize,
    baseline: usize,
}

/// Statistics of every variant of `group`; `reference` and `baseline` index variants.
fn analyse(raw: &RawTimes, specs: &[Option<Model>], group: &Group) -> Vec<Row> {
    let e = group.evaluations as f64;
    let (reference, baseline) = (group.reference, Some(group.baseline));
    let reference_t = per_round(raw, reference, e);
    let baseline_t = baseline.map(|b| per_round(raw, b, e));
    let rows: Vec<Row> = group
        .variants
        .clone()
        .map(|i| {
            let t = per_round(raw, i, e);
            let ratio: Vec<f64> = t.iter().zip(&reference_t).map(|(a, r)| a / r).collect();
            let ns = stats::median_ci(&t, LEVEL);
            let (net, net_ratio, share) = match (&baseline_t, Some(i) != baseline) {
                (Some(b), true) => {
                    let net: Vec<f64> = t.iter().zip(b).map(|(a, b)| a - b).collect();
                    let net_ratio: Vec<f64> =
                        net.iter().zip(reference_t.iter().zip(b)).map(|(n, (r, b))| n / (r - b)).collect();
                    let share: Vec<f64> = b.iter().zip(&t).map(|(b, a)| b / a).collect();
                    (
                        Some(stats::median_ci(&net, LEVEL)),
                        Some(stats::median_ci(&net_ratio, LEVEL)),
                        Some(stats::median_ci(&share, LEVEL)),
                    )
                }
                _ => (None, None, None),
            };
            Row {
                model: specs[i].as_ref().map_or_else(|| workload::BASELINE_LABEL.to_string(), Model::label),
                spec: specs[i].as_ref().map(Model::canonical),
                lights: group.lights,
                evaluations_per_dispatch: group.evaluations,
                ns_per_eval: ns,
                evals_per_second: 1e9 / ns.median,
                vs_reference: stats::median_ci(&ratio, LEVEL),
                net_ns_per_eval: net,
                net_vs_reference: net_ratio,
                harness_share: share,
                net_ratio_unresolved: None,
                instance_spread: raw.instance_spread(i),
            }
        })
        .collect();
    unresolved_net_ratios(rows, reference - group.variants.start)
}

/// Net ratios to the reference exist only where the reference's net cost is resolved: where its interval
/// contains 0 (or lies below it) the memory-only kernel is as slow as the reference within the noise, and a
/// ratio to that difference is noise over noise. Then every row's `net_vs_reference` is None, with the reason.
fn unresolved_net_ratios(mut rows: Vec<Row>, reference: usize) -> Vec<Row> {
    let Some(net) = rows.get(reference).and_then(|r| r.net_ns_per_eval) else { return rows };
    if net.lo > 0.0 {
        return rows;
    }
    let why = format!(
        "unresolved: {}'s net ns/eval interval [{}, {}] contains 0 (or lies below it)",
        rows[reference].model,
        markdown::sig(net.lo, 3),
        markdown::sig(net.hi, 3)
    );
    for r in rows.iter_mut().filter(|r| r.net_ns_per_eval.is_some()) {
        r.net_vs_reference = None;
        r.net_ratio_unresolved = Some(why.clone());
    }
    rows
}

/// True once every model's ratio is resolved to `target` (net ratios to twice that). The reference's and the
/// baseline's own ratios do not count (the first is 1, the second's noise is inside the net ratios).
fn resolved(rows: &[Row], target: f64) -> bool {
    rows.iter().filter(|r| r.spec.is_some() && r.model != REFERENCE_MODEL).all(|r| {
        r.vs_reference.rel_half_width() < target && r.net_vs_reference.is_none_or(|n| n.rel_half_width() < 2.0 * target)
    })
}

fn analyse_all(raw: &RawTimes, specs: &[Option<Model>], groups: &[Group]) -> Vec<Row> {
    groups.iter().flat_map(|g| analyse(raw, specs, g)).collect()
}

/// The size of the profiled workload: `options`' G-buffer and light counts, split as `work` (any one) is.
fn workload_size(options: &ProfileOptions, work: &Workload) -> WorkloadSize {
    WorkloadSize {
        width: options.width,
        height: options.height,
        pixels: work.pixel_count,
        lights: options.lights.clone(),
        gbuffer: options.format,
        bytes_per_pixel: options.format.bytes_in(),
        output_bytes_per_pixel: options.format.bytes_out(),
        light_block: workload::LIGHT_BLOCK,
        chunks: work.chunks(),
    }
}

/// Runs the profile: for each light count, the models (the reference added when missing) and the baseline,
/// all interleaved in the same rounds.
pub fn run(gpu: &Gpu, options: &ProfileOptions, progress: &ProgressBar) -> Result<ProfileReport> {
    let reference_model = Model::reference();
    let models = crate::model::with_reference(&options.models);
    workload::check_size(&gpu.info, options.width, options.height, options.format, options.lights.len())?;
    progress.set_message("building the G-buffer");
    let gbuffer = gbuffer::synthetic(options.width, options.height, options.format);
    let works = options
        .lights
        .iter()
        .map(|&l| Workload::upload(gpu, &gbuffer, &gbuffer::lights(l), options.max_chunk))
        .collect::<Result<Vec<_>>>()?;
    drop(gbuffer);
    let from_glsl = options.glsl.as_deref().map(Shaders::from_glsl).transpose()?;
    let shaders = from_glsl.as_ref().unwrap_or_else(|| crate::kernels::embedded());
    let several = works.len() > 1;
    let (mut variants, mut specs, mut labels, mut groups) = (Vec::new(), Vec::new(), Vec::new(), Vec::new());
    for work in &works {
        let first = variants.len();
        for spec in models.iter().map(Some).chain([None]) {
            progress.set_message(format!(
                "compiling kernels ({} of {})",
                variants.len() + 1,
                works.len() * (models.len() + 1)
            ));
            let v = Variant::new(gpu, work, spec, shaders, options.instances)?;
            labels.push(if several { format!("{} ({} lights)", v.label, work.light_count) } else { v.label.clone() });
            variants.push(v);
            specs.push(spec.cloned());
        }
        let reference = first + models.iter().position(|m| *m == reference_model).unwrap();
        groups.push(Group {
            lights: work.light_count,
            evaluations: work.evaluations(),
            variants: first..variants.len(),
            reference,
            baseline: variants.len() - 1,
        });
    }
    let raw = protocol::measure_with_progress(
        gpu,
        &variants,
        &options.protocol,
        |raw| resolved(&analyse_all(raw, &specs, &groups), options.target_rel_ci),
        progress,
    )?;
    let rows = analyse_all(&raw, &specs, &groups);
    let mut kernel_sha256 = std::collections::BTreeMap::new();
    for spec in models.iter().map(Some).chain([None]) {
        let label = spec.map_or_else(|| workload::BASELINE_LABEL.to_string(), Model::label);
        kernel_sha256.insert(label, workload::kernel_hash(spec, options.format, shaders)?);
    }
    Ok(ProfileReport {
        provenance: Provenance::new(&gpu.info),
        reference: REFERENCE_MODEL.into(),
        workload: workload_size(options, &works[0]),
        rounds: raw.rounds(),
        reps_per_round: options.protocol.reps,
        instances: options.instances,
        confidence_level: LEVEL,
        rows,
        labels,
        kernel_sha256,
        raw,
    })
}

impl ProfileReport {
    pub fn table(&self) -> Table {
        let r = &self.reference;
        let several = self.workload.lights.len() > 1;
        let ci = self.interval_label();
        let mut header = vec![
            "model".to_string(),
            format!("ns/eval [{ci}]"),
            "Meval/s".into(),
            format!("vs {r} [{ci}]"),
            format!("net ns/eval [{ci}]"),
            format!("net vs {r} [{ci}]"),
            "harness share".into(),
        ];
        if several {
            header.insert(1, "lights".into());
        }
        let mut t = Table::new(header);
        for row in &self.rows {
            let mut cells = vec![
                row.model.clone(),
                markdown::estimate(&row.ns_per_eval, 3),
                markdown::sig(row.evals_per_second / 1e6, 3),
                markdown::estimate(&row.vs_reference, 3),
                row.net_ns_per_eval.as_ref().map_or("-".into(), |e| markdown::estimate(e, 3)),
                match (&row.net_vs_reference, &row.net_ratio_unresolved) {
                    (Some(e), _) => markdown::estimate(e, 3),
                    (None, Some(_)) => "unresolved".into(),
                    (None, None) => "-".into(),
                },
                row.harness_share.as_ref().map_or("-".into(), |e| format!("{:.0}%", 100.0 * e.median)),
            ];
            if several {
                cells.insert(1, row.lights.to_string());
            }
            t.row(cells);
        }
        t
    }

    /// What the intervals are, as a column header says it: "95% CI" where every interval reaches the
    /// confidence level, else their real (smallest) coverage: a median's interval from n rounds by order
    /// statistics needs n >= 6 for 95%; below, it is the sample's extremes, of coverage 1 - 2^(1-n).
    pub fn interval_label(&self) -> String {
        let coverage = self.rows.iter().map(|r| r.ns_per_eval.coverage).fold(f64::INFINITY, f64::min);
        if coverage.is_finite() && coverage + 1e-9 < self.confidence_level {
            format!("interval of coverage {coverage:.2}, not {:.0}%", 100.0 * self.confidence_level)
        } else {
            format!("{:.0}% CI", 100.0 * self.confidence_level)
        }
    }

    /// Notes under the table: a net ratio that is unresolved, intervals short of their level.
    pub fn interval_notes(&self) -> String {
        let mut out = String::new();
        if let Some(why) = self.rows.iter().find_map(|r| r.net_ratio_unresolved.as_ref()) {
            out += &format!("note: net vs {}: {why}; no net ratio to it is given\n", self.reference);
        }
        let rounds = self.rows.first().map_or(0, |r| r.ns_per_eval.n);
        if self.interval_label().starts_with("interval of coverage") {
            out += &format!(
                "note: {rounds} rounds are too few for a {:.0}% interval of a median (6 are needed); the intervals are the rounds' extremes; give a longer --budget\n",
                100.0 * self.confidence_level
            );
        }
        out
    }

    /// With several light counts: net ns/eval of each model (the baseline's gross) at each count, one column
    /// per count, and the harness share of the reference: how the cost per light moves with the count.
    pub fn light_table(&self) -> Option<Table> {
        let counts = &self.workload.lights;
        if counts.len() < 2 {
            return None;
        }
        let mut header = vec!["model".to_string()];
        header.extend(counts.iter().map(|&l| format!("{l} light{}", if l == 1 { "" } else { "s" })));
        let mut t = Table::new(header);
        let mut names: Vec<&str> = Vec::new();
        for r in &self.rows {
            if !names.contains(&r.model.as_str()) {
                names.push(&r.model);
            }
        }
        for name in names {
            let mut cells = vec![if name == workload::BASELINE_LABEL {
                format!("{name} (gross)")
            } else {
                format!("{name} (net)")
            }];
            for &l in counts {
                let row = self.rows.iter().find(|r| r.model == name && r.lights == l);
                cells.push(row.map_or("-".into(), |r| {
                    markdown::estimate(r.net_ns_per_eval.as_ref().unwrap_or(&r.ns_per_eval), 3)
                }));
            }
            t.row(cells);
        }
        let mut share = vec![format!("harness share of {}", self.reference)];
        for &l in counts {
            let row = self.rows.iter().find(|r| r.model == self.reference && r.lights == l);
            share.push(row.and_then(|r| r.harness_share).map_or("-".into(), |e| format!("{:.0}%", 100.0 * e.median)));
        }
        t.row(share);
        Some(t)
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

    /// A warning when the memory-only kernel takes more than `HARNESS_WARNING` of a model's time: then the
    /// gross figures mostly measure loads and stores, and what helps.
    pub fn harness_warning(&self) -> String {
        let worst =
            self.rows.iter().filter_map(|r| r.harness_share.map(|s| (r, s.median))).max_by(|a, b| a.1.total_cmp(&b.1));
        match worst {
            Some((row, share)) if share > HARNESS_WARNING => format!(
                "warning: the memory-only kernel is {:.0}% of {}'s time (more than {:.0}%): the gross ns/eval mostly measure the harness (G-buffer loads and decode, light loads, stores), not the BRDF. Read the net columns; raise --lights to share the per-pixel cost among more evaluations{}.\n",
                100.0 * share,
                row.model,
                100.0 * HARNESS_WARNING,
                if self.workload.gbuffer == GBufferFormat::Float {
                    "; drop --gbuffer float (the packed G-buffer reads a third of the bytes)"
                } else {
                    ""
                }
            ),
            _ => String::new(),
        }
    }

    /// One line saying what was measured.
    pub fn summary(&self) -> String {
        let w = &self.workload;
        format!(
            "{} ({}, {}) on {}, {}, {} threads; {}x{} pixels ({} G-buffer) x {} lights; {} rounds x {} reps x {} pipelines per kernel, interleaved; {:.1} s to set up (G-buffer, compilation, warm-up), {:.1} s of rounds, stopped: {}",
            self.provenance.device.name,
            self.provenance.device.driver_name,
            self.provenance.device.driver_info,
            self.provenance.cpu.as_ref().map_or_else(String::new, HostCpu::describe),
            self.provenance.cpu.as_ref().map_or("", HostCpu::vector_width),
            self.provenance.host_threads,
            w.width,
            w.height,
            w.gbuffer.name(),
            w.lights.iter().map(u32::to_string).collect::<Vec<_>>().join(", "),
            self.rounds,
            self.reps_per_round,
            self.instances,
            self.raw.setup_s,
            self.raw.elapsed_s,
            match self.raw.stop {
                protocol::Stop::Converged => "every ratio resolved",
                protocol::Stop::Budget => "--budget spent",
                protocol::Stop::MaxRounds => "--max-rounds reached",
            }
        ) + &markdown::front_ends_line(&self.provenance.front_ends)
    }
}
