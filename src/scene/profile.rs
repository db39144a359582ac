//! `brdfprof profile --scene FILE`: what the scene compiles in, and what each effect costs, measured by toggling
//! it. Every kernel of the plan runs as compiled and, for each effect it compiles in, compiled without that
//! effect; all variants run interleaved in rounds under the profile protocol (`measure::protocol::measure`),
//! and an effect's cost is, per round, (time with it - time without it) / pixels of its kernel, reported as a
//! median with a distribution-free 95% CI over rounds.

use super::compile;
use super::format::Scene;
use super::gbuffer::{self, GBuffer};
use super::plan::{self, Effect, ScenePlan};
use super::run::{self, SceneVariant, SceneWork};
use super::spirv;
use crate::export::json::Provenance;
use crate::export::markdown::{self, Table};
use crate::gpu::Gpu;
use crate::kernels::{self, RunLimits};
use crate::measure::protocol::{self, ProtocolOptions, RawTimes};
use crate::model::KernelKind;
use crate::profile::LEVEL;
use crate::stats::{self, Estimate};
use anyhow::Result;
use indicatif::ProgressBar;
use serde::Serialize;

#[derive(Clone, Debug)]
pub struct SceneProfileOptions {
    pub protocol: ProtocolOptions,
    /// Stop once every kernel's ns/pixel CI half-width, and every effect's, is below this fraction of the
    /// kernel's ns/pixel.
    pub target_rel_ci: f64,
    pub max_chunk: Option<u64>,
    /// Independently compiled pipelines per variant, all timed every round; the faster one counts.
    pub instances: usize,
    /// Compile-only targets that also compile every variant (`compile`), with validation as the device has it.
    pub cost_targets: Vec<crate::targets::Target>,
    pub validate: bool,
    /// Where the targets write each kernel's compiler output (`--isa`).
    pub isa_dir: Option<std::path::PathBuf>,
}

#[derive(Clone, Debug, Serialize)]
pub struct KernelRow {
    pub model: String,
    pub spec: String,
    pub materials: Vec<String>,
    pub pixels: u64,
    pub dispatches: usize,
    pub compiled_in: String,
    /// Instructions in the kernel after spirv-opt specialised it (None without spirv-opt).
    pub spirv_instructions: Option<usize>,
    pub ns_per_pixel: Estimate,
    /// This kernel's time over the whole frame's (all kernels), per round.
    pub frame_share: Estimate,
}

#[derive(Clone, Debug, Serialize)]
pub struct EffectRow {
    pub model: String,
    pub effect: String,
    /// (time with the effect - time without it) / pixels of the kernel, per round.
    pub extra_ns_per_pixel: Estimate,
    /// The same difference over the time without the effect.
    pub extra_fraction: Estimate,
    pub extra_spirv_instructions: Option<i64>,
}

#[derive(Clone, Debug, Serialize)]
pub struct SceneProfileReport {
    pub provenance: Provenance,
    pub scene: String,
    pub width: u32,
    pub height: u32,
    pub lights: plan::LightCounts,
    pub compiled: Vec<String>,
    pub notes: Vec<String>,
    pub kernels: Vec<KernelRow>,
    pub effects: Vec<EffectRow>,
    /// All kernels of the frame, ns per shaded pixel.
    pub frame_ns_per_pixel: Estimate,
    pub rounds: usize,
    pub reps_per_round: usize,
    pub confidence_level: f64,
    pub labels: Vec<String>,
    pub raw: RawTimes,
    /// The same kernels on compile-only targets (`--cost-device`).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub targets: Vec<compile::SceneTargetReport>,
}

/// One timed variant: kernel index, the effect compiled out (None: as planned).
struct Slot {
    kernel: usize,
    without: Option<Effect>,
}

struct Analysis {
    kernels: Vec<(Estimate, Estimate)>,
    effects: Vec<(usize, Effect, Estimate, Estimate)>,
    frame: Estimate,
}

fn analyse(raw: &RawTimes, slots: &[Slot], pixels: &[u64]) -> Analysis {
    let full: Vec<usize> =
        (0..pixels.len()).map(|k| slots.iter().position(|s| s.kernel == k && s.without.is_none()).unwrap()).collect();
    let full_t: Vec<Vec<f64>> = full.iter().map(|&v| raw.round_medians(v)).collect();
    let rounds = raw.rounds();
    let frame_t: Vec<f64> = (0..rounds).map(|r| full_t.iter().map(|t| t[r]).sum()).collect();
    let total_pixels: u64 = pixels.iter().sum();
    let kernels = (0..pixels.len())
        .map(|k| {
            let ns: Vec<f64> = full_t[k].iter().map(|t| t / pixels[k] as f64).collect();
            let share: Vec<f64> = full_t[k].iter().zip(&frame_t).map(|(t, f)| t / f).collect();
            (stats::median_ci(&ns, LEVEL), stats::median_ci(&share, LEVEL))
        })
        .collect();
    let effects = slots
        .iter()
        .enumerate()
        .filter_map(|(v, s)| s.without.map(|e| (v, s.kernel, e)))
        .map(|(v, k, e)| {
            let without = raw.round_medians(v);
            let extra: Vec<f64> = full_t[k].iter().zip(&without).map(|(a, b)| (a - b) / pixels[k] as f64).collect();
            let frac: Vec<f64> = full_t[k].iter().zip(&without).map(|(a, b)| (a - b) / b).collect();
            (k, e, stats::median_ci(&extra, LEVEL), stats::median_ci(&frac, LEVEL))
        })
        .collect();
    let frame: Vec<f64> = frame_t.iter().map(|t| t / total_pixels as f64).collect();
    Analysis { kernels, effects, frame: stats::median_ci(&frame, LEVEL) }
}

fn resolved(a: &Analysis, target: f64) -> bool {
    a.kernels.iter().all(|(ns, _)| ns.rel_half_width() < target)
        && a.effects.iter().all(|(k, _, extra, _)| (extra.hi - extra.lo) / 2.0 < target * a.kernels[*k].0.median)
}

/// Every kernel of the plan as compiled and, for each effect it compiles in, without that effect.
fn variants<'g>(
    gpu: &'g Gpu,
    work: &SceneWork<'g>,
    p: &ScenePlan,
    instances: usize,
) -> Result<(Vec<Slot>, Vec<SceneVariant<'g>>)> {
    let (mut slots, mut variants) = (Vec::new(), Vec::new());
    for v in compile::variant_specs(p) {
        slots.push(Slot { kernel: v.kernel, without: v.without });
        variants.push(SceneVariant::new(gpu, work, p, v.kernel, v.switches, v.label, instances)?);
    }
    Ok((slots, variants))
}

/// What spirv-opt leaves of each variant, where spirv-opt is installed.
fn instructions(p: &ScenePlan, variants: &[SceneVariant]) -> Vec<Option<usize>> {
    if !spirv::available() {
        return vec![None; variants.len()];
    }
    variants
        .iter()
        .map(|v| {
            let mk = p.kernels[v.kernel_index].model.kernel(KernelKind::Scene, kernels::embedded()).ok()?;
            spirv::specialise(&mk.spirv, &p.constants(mk.constants, v.switches)).ok().map(|s| s.instructions)
        })
        .collect()
}

/// The variant timing kernel `k` as planned, and without effect `e`.
fn slot_of(slots: &[Slot], k: usize, without: Option<Effect>) -> usize {
    slots.iter().position(|s| s.kernel == k && s.without == without).expect("every kernel and effect has a slot")
}

/// The rows of the effects table: what each effect of each kernel costs, in time and in SPIR-V instructions
/// (`instructions` per slot).
fn effect_rows(p: &ScenePlan, a: &Analysis, slots: &[Slot], instructions: &[Option<usize>]) -> Vec<EffectRow> {
    a.effects
        .iter()
        .map(|&(k, e, extra, frac)| EffectRow {
            model: p.kernels[k].model.label(),
            effect: e.name().into(),
            extra_ns_per_pixel: extra,
            extra_fraction: frac,
            extra_spirv_instructions: instructions[slot_of(slots, k, None)]
                .zip(instructions[slot_of(slots, k, Some(e))])
                .map(|(a, b)| a as i64 - b as i64),
        })
        .collect()
}

/// Loads the G-buffer, plans, compiles and times the scene.
pub fn run(
    gpu: &Gpu,
    scene: &Scene,
    options: &SceneProfileOptions,
    progress: &ProgressBar,
) -> Result<SceneProfileReport> {
    progress.set_message("building the G-buffer");
    let g: GBuffer = gbuffer::build_for(scene, &gpu.info)?;
    let p: ScenePlan = plan::plan(scene, &g, None);
    p.check_device(&gpu.info)?;
    progress.set_message("E tables");
    let tables = run::e_tables(gpu, &p)?;
    let work = SceneWork::upload(gpu, scene, &g, &p, &tables, RunLimits { max_chunk: options.max_chunk })?;
    // The targets' figures first (seconds): a missing compiler fails before the long measurement.
    progress.set_message("compile-only targets");
    let targets =
        compile::reports(gpu, &work, &p, &options.cost_targets, options.validate, options.isa_dir.as_deref())?;
    progress.set_message("compiling kernels");
    let (slots, variants) = variants(gpu, &work, &p, options.instances)?;
    let pixels: Vec<u64> = work.kernels.iter().map(|k| k.count).collect();
    let raw = protocol::measure_with_progress(
        gpu,
        &variants,
        &options.protocol,
        |raw| resolved(&analyse(raw, &slots, &pixels), options.target_rel_ci),
        progress,
    )?;
    let a = analyse(&raw, &slots, &pixels);
    let instructions = instructions(&p, &variants);
    let compiled = p.describe(scene);
    let kernels = p
        .kernels
        .iter()
        .enumerate()
        .map(|(k, kp)| KernelRow {
            model: kp.model.label(),
            spec: kp.model.canonical(),
            materials: kp.materials.iter().map(|&i| scene.file.materials[i].name.clone()).collect(),
            pixels: pixels[k],
            dispatches: work.chunks(k),
            compiled_in: compiled[k].clone(),
            spirv_instructions: instructions[slot_of(&slots, k, None)],
            ns_per_pixel: a.kernels[k].0,
            frame_share: a.kernels[k].1,
        })
        .collect();
    let effects = effect_rows(&p, &a, &slots, &instructions);
    Ok(SceneProfileReport {
        provenance: Provenance::new(&gpu.info),
        scene: scene.name(),
        width: g.width,
        height: g.height,
        lights: p.counts,
        compiled,
        notes: p.notes.clone(),
        kernels,
        effects,
        frame_ns_per_pixel: a.frame,
        rounds: raw.rounds(),
        reps_per_round: options.protocol.reps,
        confidence_level: LEVEL,
        labels: variants.iter().map(|v| v.label.clone()).collect(),
        raw,
        targets,
    })
}

impl SceneProfileReport {
    pub fn summary(&self) -> String {
        let l = &self.lights;
        format!(
            "scene {} on {} ({}); {}x{} G-buffer, {} lights ({} directional, {} point, {} spot, {} sphere) in one dispatch per kernel; {} rounds x {} reps, interleaved; {:.0} s",
            self.scene,
            self.provenance.device.name,
            self.provenance.device.driver_info,
            self.width,
            self.height,
            l.total(),
            l.directional,
            l.point,
            l.spot,
            l.sphere,
            self.rounds,
            self.reps_per_round,
            self.raw.elapsed_s
        ) + &markdown::front_ends_line(&self.provenance.front_ends)
    }

    pub fn markdown(&self) -> String {
        let mut out = String::from("Compiled in (one kernel per model present):\n\n");
        for c in &self.compiled {
            out += &format!("- {c}\n");
        }
        for n in &self.notes {
            out += &format!("- note: {n}\n");
        }
        let mut t = Table::new([
            "kernel",
            "pixels",
            "dispatches",
            "SPIR-V instr.",
            "ns/pixel [95% CI]",
            "share of frame [95% CI]",
        ]);
        for k in &self.kernels {
            t.row([
                k.model.clone(),
                k.pixels.to_string(),
                k.dispatches.to_string(),
                k.spirv_instructions.map_or("-".into(), |n| n.to_string()),
                markdown::estimate(&k.ns_per_pixel, 3),
                markdown::estimate(&k.frame_share, 2),
            ]);
        }
        out += &format!(
            "\n{}\nwhole frame: {} ns per shaded pixel\n",
            t.markdown(),
            markdown::estimate(&self.frame_ns_per_pixel, 3)
        );
        if self.effects.is_empty() {
            out += "\nNo material calls for an effect: none is compiled in.\n";
        } else {
            let mut e = Table::new([
                "kernel",
                "effect",
                "+ns/pixel [95% CI]",
                "+fraction of kernel [95% CI]",
                "+SPIR-V instr.",
            ]);
            for r in &self.effects {
                e.row([
                    r.model.clone(),
                    r.effect.clone(),
                    markdown::estimate(&r.extra_ns_per_pixel, 3),
                    markdown::estimate(&r.extra_fraction, 2),
                    r.extra_spirv_instructions.map_or("-".into(), |n| format!("{n:+}")),
                ]);
            }
            out += &format!(
                "\nCost of each effect (kernel as compiled minus the kernel without it, per round):\n\n{}",
                e.markdown()
            );
        }
        let measured = |model: &str| {
            self.kernels
                .iter()
                .find(|k| k.model == model)
                .map_or("-".into(), |k| markdown::estimate(&k.ns_per_pixel, 3))
        };
        let measured_effect = |model: &str, effect: &str| {
            self.effects
                .iter()
                .find(|e| e.model == model && e.effect == effect)
                .map_or("-".into(), |e| markdown::estimate(&e.extra_ns_per_pixel, 3))
        };
        out + &compile::markdown(&self.targets, measured, measured_effect, &self.provenance.device.name)
    }
}
