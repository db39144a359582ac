//! `profile --scene FILE --cost-device TARGET`: the scene's kernels as its profile times them (each kernel of
//! the plan as compiled, and without each effect it compiles in) compiled by compile-only targets' compilers
//! (`targets::compile_raw_all`): modelled cycles per shaded pixel, every light of the plan included, and what
//! each effect adds, beside the measured ns/pixel. RADV compiles the frozen SPIR-V; NVIDIA and Intel compile
//! its C translation, which first shades the scene's own pixels on the host (g++) and must agree with the Vulkan
//! kernel on the measuring device before its cost is reported (only when such a target is asked for).

use super::plan::{Effect, ScenePlan};
use super::run::{HostInputs, PUSH_BYTES, RADIANCE, STORAGE_BUFFERS, SceneVariant, SceneWork};
use super::terms::Switches;
use crate::export::markdown::Table;
use crate::gpu::Gpu;
use crate::kernels;
use crate::measure::protocol::Timed;
use crate::model::KernelKind;
use crate::targets::{self, CheckedTranslation, RawKernel, Target};
use crate::translate::{self, host::HostKernel, verify};
use anyhow::{Result, anyhow, bail};
use serde::{Deserialize, Serialize};

/// Relative tolerance of the host run against the Vulkan kernel, over each pixel's brightest channel: the float
/// output has no quantisation, so this is the two maths libraries' difference (a few ulps, amplified by the
/// pow and exp forms and summed over the lights) with a wide margin, and far below a wrong translation's; an
/// fp16 model's terms differ by ulps of fp16 (measured 3.7e-3 on a Burley fp16 kernel), as in the eval check.
pub fn tolerance(precision: crate::brdf::Precision) -> f64 {
    match precision {
        crate::brdf::Precision::F32 => 1e-3,
        crate::brdf::Precision::F16 => 5e-2,
    }
}

/// How a scene kernel's translation agreed with the Vulkan kernel over the kernel's pixels.
#[derive(Clone, Copy, Debug, Serialize, Deserialize)]
struct Agreement {
    worst: f64,
    pixels: usize,
    /// Pixels the device's kernel lit (any channel not 0): the comparison says nothing about the others.
    lit: usize,
}

/// One kernel the profile times: kernel `kernel` of the plan with `switches` (as planned, or without `without`).
#[derive(Clone, Debug)]
pub struct VariantSpec {
    pub kernel: usize,
    pub without: Option<Effect>,
    pub switches: Switches,
    pub label: String,
}

/// Every kernel of the plan as compiled and, for each effect it compiles in, without that effect.
pub fn variant_specs(p: &ScenePlan) -> Vec<VariantSpec> {
    let mut out = Vec::new();
    for (k, kp) in p.kernels.iter().enumerate() {
        let name = kp.model.label();
        out.push(VariantSpec { kernel: k, without: None, switches: kp.switches, label: name.clone() });
        for e in Effect::ALL.into_iter().filter(|e| e.is_on(&kp.switches)) {
            out.push(VariantSpec {
                kernel: k,
                without: Some(e),
                switches: e.off(kp.switches),
                label: format!("{name} without {}", e.name()),
            });
        }
    }
    out
}

/// A kernel's modelled cost on one target.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct TargetKernelRow {
    pub model: String,
    pub cycles_per_pixel: f64,
    /// The statistics the target's cost table shows (registers, instructions, ...), by name.
    pub stats: std::collections::BTreeMap<String, f64>,
}

/// What an effect adds on one target.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct TargetEffectRow {
    pub model: String,
    pub effect: String,
    pub extra_cycles_per_pixel: f64,
    /// The same difference over the cycles without the effect.
    pub extra_fraction: f64,
}

/// One compile-only target's report on the scene's kernels.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct SceneTargetReport {
    /// `radv:navi21`.
    pub target: String,
    pub device: String,
    pub compiler: String,
    /// The compiler's options (empty for ACO, which a Vulkan pipeline drives with none).
    pub options: String,
    /// The cost rule and its unit, as the target's cost table states them (one light per kernel: a scene
    /// kernel's own light loops are in its cost, so cycles/eval is cycles per shaded pixel).
    pub model: String,
    pub unit: String,
    pub kernels: Vec<TargetKernelRow>,
    pub effects: Vec<TargetEffectRow>,
    /// Per variant label: how its translation agreed with the Vulkan kernel (translating targets only).
    pub translation: std::collections::BTreeMap<String, String>,
    /// Compiler output written under `--isa` (RADV's; NVIDIA's and Intel's are under DIR/<vendor>-<family>/).
    #[serde(skip_serializing_if = "Vec::is_empty", default)]
    pub isa_files: Vec<std::path::PathBuf>,
    pub notes: Vec<String>,
}

/// The variants compiled for every target: RADV from the frozen SPIR-V, the others from the translation,
/// checked on the host against `gpu` first.
pub fn reports(
    gpu: &Gpu,
    work: &SceneWork,
    p: &ScenePlan,
    targets: &[Target],
    validate: bool,
    isa_dir: Option<&std::path::Path>,
) -> Result<Vec<SceneTargetReport>> {
    if targets.is_empty() {
        return Ok(Vec::new());
    }
    let specs = variant_specs(p);
    let translate = targets.iter().any(|t| t.vendor.needs_verification());
    if translate {
        // One verdict for a model whatever the path: the checks `inspect` makes of the model's own kernels
        // (its eval kernel compares values a scene's clamped radiance would hide), once per model, before the
        // scene kernels' own.
        let mut checked: Vec<String> = Vec::new();
        for k in &p.kernels {
            if !checked.contains(&k.model.canonical()) {
                verify::check_cached(gpu, Some(&k.model), MODEL_CHECK_LIGHTS, kernels::embedded())?;
                checked.push(k.model.canonical());
            }
        }
    }
    let raw = specs.iter().map(|v| raw_kernel(gpu, work, p, v, translate)).collect::<Result<Vec<_>>>()?;
    let shaders = crate::shaders::Shaders::embedded();
    let request = targets::Request {
        models: &[],
        lights: 1,
        shaders: &shaders,
        validate,
        isa_dir,
        precise: false,
        verify_on: Some(gpu),
        lines: false,
    };
    let runs = targets::compile_raw_all(targets, &raw, &request)?;
    runs.into_iter().map(|run| target_report(run, &specs, p)).collect()
}

/// The lights of the model check a scene shares with `inspect` (its default, so the check is cached once).
const MODEL_CHECK_LIGHTS: u32 = 8;

/// One variant as a raw kernel: its frozen SPIR-V and, when `translate`, its checked translation.
fn raw_kernel(gpu: &Gpu, work: &SceneWork, p: &ScenePlan, v: &VariantSpec, translate: bool) -> Result<RawKernel> {
    let model = p.kernels[v.kernel].model.clone();
    let mk = model.kernel(KernelKind::Scene, kernels::embedded())?;
    let constants = p.constants(mk.constants, v.switches);
    let spirv = crate::spirv::specialise(&mk.spirv.words, &constants)?;
    let translation =
        if translate { Some(checked_translation(gpu, work, p, v, &mk.spirv.words, &constants)?) } else { None };
    Ok(RawKernel {
        label: v.label.clone(),
        model,
        spirv,
        storage_buffers: STORAGE_BUFFERS,
        push_bytes: PUSH_BYTES,
        translation,
    })
}

/// The variant's translation, after it agreed with the Vulkan kernel over the kernel's pixels.
fn checked_translation(
    gpu: &Gpu,
    work: &SceneWork,
    p: &ScenePlan,
    v: &VariantSpec,
    words: &[u32],
    constants: &crate::gpu::SpecConstants,
) -> Result<CheckedTranslation> {
    let translation = translate::translate(&translate::prepare::prepared(words, constants)?, &Default::default())
        .map_err(|e| anyhow!("{}: {e}", v.label))?;
    let a = agreement_cached(gpu, work, p, v, &translation, words, &format!("{constants:?}"))?;
    let (worst, tolerance) = (a.worst, tolerance(p.kernels[v.kernel].model.precision()));
    let srem = verify::srem_explains(&translation, worst, tolerance, |defines| {
        Ok(agreement(gpu, work, p, v, &translation, work.host_inputs(v.kernel)?, defines)?.worst)
    })?;
    if srem {
        verify::warn_srem(&v.label, "scene", &gpu.info.name, worst);
    } else if !(worst <= tolerance) {
        bail!(
            "{}: the C translation of the scene kernel disagrees with the Vulkan kernel on {} (worst relative difference {worst:.3e}, tolerance {tolerance:.0e}): its cost is not reported. This is a translator defect; please report it with the scene",
            v.label,
            gpu.info.name
        );
    }
    let agreement = format!(
        "translation checked on the host against {} over the kernel's {} pixels ({} lit): worst relative difference {worst:.1e} (tolerance {tolerance:.0e})",
        gpu.info.name, a.pixels, a.lit
    );
    Ok(CheckedTranslation { translation, agreement })
}

/// `agreement`, or its result from the cache: the key covers the host translation, the Vulkan kernel's SPIR-V
/// and constants, the device and its driver, and the kernel's inputs.
fn agreement_cached(
    gpu: &Gpu,
    work: &SceneWork,
    p: &ScenePlan,
    v: &VariantSpec,
    t: &translate::Translation,
    words: &[u32],
    constants: &str,
) -> Result<Agreement> {
    let inputs = work.host_inputs(v.kernel)?;
    let (buffers, push, invocations) = &inputs;
    let mut key = crate::cache::KeyBuilder::new("scene_agreement")
        .part("brdfprof", env!("CARGO_PKG_VERSION"))
        .part(
            "device",
            format!("{} {} {} {}", gpu.info.name, gpu.info.driver_name, gpu.info.driver_info, gpu.info.driver_version),
        )
        .part("host", format!("{} {}", t.source(translate::Dialect::Host), translate::host::build_identity()))
        .part("spirv", bytemuck::cast_slice::<u32, u8>(words))
        .part("constants", constants)
        .part("push", &push)
        .part("invocations", invocations.to_string());
    for (slot, bytes) in buffers {
        key = key.part(&format!("binding {slot:?}"), bytes);
    }
    let what = format!("the check of {}'s translation", v.label);
    let valid = |bytes: &[u8]| serde_json::from_slice::<Agreement>(bytes).map(|_| ()).map_err(anyhow::Error::from);
    let bytes = crate::cache::get_or_build(
        crate::cache::Store::open_default().as_ref(),
        "scene_agreement",
        &key.finish(),
        &what,
        valid,
        || Ok(serde_json::to_vec(&agreement(gpu, work, p, v, t, inputs.clone(), &[])?)?),
    )?;
    Ok(serde_json::from_slice(&bytes)?)
}

/// The worst relative difference between the translation run on the host over `inputs` (the kernel's buffers,
/// `SceneWork::host_inputs`) and the Vulkan kernel on `gpu`, over every pixel of the kernel and each pixel's
/// brightest channel.
fn agreement(
    gpu: &Gpu,
    work: &SceneWork,
    p: &ScenePlan,
    v: &VariantSpec,
    t: &translate::Translation,
    inputs: HostInputs,
    defines: &[&str],
) -> Result<Agreement> {
    SceneVariant::new(gpu, work, p, v.kernel, v.switches, v.label.clone(), 1)?.run_once(gpu, 0)?;
    let on_device = work.radiance(v.kernel)?;
    let (mut inputs, mut push, invocations) = inputs;
    let host = HostKernel::compile_with(t, defines)?;
    // The translation's bindings in its order (those the specialised kernel still uses), push constants last.
    let mut owned: Vec<Vec<u8>> = Vec::new();
    for b in t.bindings.iter().filter(|b| b.slot.0 != u32::MAX) {
        owned.push(inputs.remove(&b.slot).ok_or_else(|| {
            anyhow!("{}: the translation binds {:?}, which the scene kernel has not", v.label, b.slot)
        })?);
    }
    let radiance_at = t
        .bindings
        .iter()
        .position(|b| b.slot == RADIANCE)
        .ok_or_else(|| anyhow!("{}: the translation writes no radiance", v.label))?;
    let groups = (invocations as u32).div_ceil(host.local_size()[0].max(1));
    let mut buffers: Vec<&mut [u8]> = owned.iter_mut().map(Vec::as_mut_slice).collect();
    buffers.push(push.as_mut_slice());
    if host.run(&mut buffers, [groups, 1, 1])? & 1 != 0 {
        bail!("{}: the host run stopped a pixel at its loop limit", v.label);
    }
    let floats: Vec<f32> = bytemuck::pod_collect_to_vec(&owned[radiance_at]);
    let on_host: Vec<[f32; 3]> = floats.chunks_exact(4).take(on_device.len()).map(|c| [c[0], c[1], c[2]]).collect();
    let lit = on_device.iter().filter(|p| p.iter().any(|&c| c != 0.0)).count();
    Ok(Agreement { worst: verify::worst_relative_to_brightest(&on_host, &on_device), pixels: on_device.len(), lit })
}

/// A target's run as the scene's kernel and effect rows (a kernel the family left out has neither, and the
/// reason is in the notes).
fn target_report(run: targets::Run, specs: &[VariantSpec], p: &ScenePlan) -> Result<SceneTargetReport> {
    let name = run.target.name();
    let models: Vec<crate::model::Model> = p.kernels.iter().map(|k| k.model.clone()).collect();
    let loops = targets::trips::counted_once_note(&models);
    let cost = run
        .report
        .cost
        .clone()
        .ok_or_else(|| anyhow!("{name}: the compiler reported no statistics the cost model reads"))?;
    let cycles = |label: &str| cost.row(label).map(|r| r.cycles_per_eval);
    let mut kernels = Vec::new();
    let mut effects = Vec::new();
    for v in specs {
        let kernel = p.kernels[v.kernel].model.label();
        match (v.without, cycles(&v.label), cycles(&kernel)) {
            (None, Some(c), _) => kernels.push(TargetKernelRow {
                model: v.label.clone(),
                cycles_per_pixel: c,
                stats: cost.row(&v.label).map(|r| r.stats.clone()).unwrap_or_default(),
            }),
            (Some(e), Some(without), Some(with)) => effects.push(TargetEffectRow {
                model: kernel,
                effect: e.name().into(),
                extra_cycles_per_pixel: with - without,
                extra_fraction: (with - without) / without,
            }),
            _ => {}
        }
    }
    let translation =
        run.report.rows.iter().filter_map(|r| Some((r.model.clone(), r.notes.get("translation")?.clone()))).collect();
    let p = &run.report.provenance;
    // RADV's reports carry Mesa's version where the translating targets name their compiler and options.
    let version =
        p["compiler"]["name"].as_str().or_else(|| p["mesa_version"].as_str().map(|m| m.trim_start_matches("Mesa ")));
    let mut notes: Vec<String> = run
        .report
        .section_notes
        .get("driver/")
        .filter(|n| n.starts_with("not compiled"))
        .cloned()
        .into_iter()
        .collect();
    notes.extend(run.note);
    notes.extend(loops);
    Ok(SceneTargetReport {
        target: name,
        device: cost.device.clone(),
        compiler: version.map_or_else(|| cost.compiler.clone(), |v| format!("{} ({v})", cost.compiler)),
        options: p["compiler"]["options"].as_str().unwrap_or_default().to_string(),
        model: cost.model.clone(),
        unit: cost.unit.clone(),
        kernels,
        effects,
        translation,
        isa_files: run.isa_files,
        notes,
    })
}

/// The kernels' and the effects' tables across targets, beside the measured figures (`measured(kernel)`:
/// ns/pixel; `measured_effect(kernel, effect)`: extra ns/pixel), as Markdown; "-" where a target left a kernel
/// out.
pub fn markdown(
    reports: &[SceneTargetReport],
    measured: impl Fn(&str) -> String,
    measured_effect: impl Fn(&str, &str) -> String,
    device: &str,
) -> String {
    if reports.is_empty() {
        return String::new();
    }
    let mut kernels: Vec<&str> = Vec::new();
    let mut effects: Vec<(&str, &str)> = Vec::new();
    for r in reports {
        kernels.extend(r.kernels.iter().map(|k| k.model.as_str()).filter(|m| !kernels.contains(m)).collect::<Vec<_>>());
        effects.extend(
            r.effects
                .iter()
                .map(|e| (e.model.as_str(), e.effect.as_str()))
                .filter(|x| !effects.contains(x))
                .collect::<Vec<_>>(),
        );
    }
    let mut head = vec!["kernel".to_string(), format!("{device} ns/pixel")];
    head.extend(reports.iter().map(|r| format!("{} cycles/pixel", r.target)));
    let mut t = Table::new(head);
    for k in &kernels {
        let mut row = vec![k.to_string(), measured(k)];
        row.extend(reports.iter().map(|r| {
            r.kernels.iter().find(|x| x.model == *k).map_or("-".into(), |x| format!("{:.2}", x.cycles_per_pixel))
        }));
        t.row(row);
    }
    let mut out = format!(
        "\nOn compile-only targets (modelled cycles per shaded pixel, every light included; each target's cost rule, compiler and options in the JSON):\n\n{}",
        t.markdown()
    );
    if !effects.is_empty() {
        let mut head = vec!["kernel".to_string(), "effect".to_string(), format!("{device} +ns/pixel")];
        head.extend(reports.iter().map(|r| format!("{} +cycles/pixel (+fraction)", r.target)));
        let mut e = Table::new(head);
        for (model, effect) in &effects {
            let mut row = vec![model.to_string(), effect.to_string(), measured_effect(model, effect)];
            let cell = |r: &SceneTargetReport| {
                r.effects
                    .iter()
                    .find(|x| x.model == *model && x.effect == *effect)
                    .map_or("-".into(), |x| format!("{:+.2} ({:+.2})", x.extra_cycles_per_pixel, x.extra_fraction))
            };
            row.extend(reports.iter().map(cell));
            e.row(row);
        }
        out += &format!(
            "\nWhat each effect adds on each target (kernel as compiled minus the kernel without it):\n\n{}",
            e.markdown()
        );
    }
    for r in reports {
        for n in &r.notes {
            out += &format!("\nnote ({}): {n}\n", r.target);
        }
    }
    out
}
