//! A translation is run before its cost is believed. For each model: its translated eval kernel evaluates a
//! fixed set of well-conditioned samples on the host and the Vulkan eval kernel evaluates them on a device;
//! its translated profiling kernel (the very kernel a compile-only target costs, apart from the dialect's
//! prelude) shades a small packed G-buffer on the host and the Vulkan kernel shades it on the device. Both
//! must agree within tolerances wide enough for the two maths libraries (and the R11G11B10F target's
//! rounding) and far too narrow for a wrong translation.

use super::{host, prepare};
use crate::brdf::samples::well_conditioned;
use crate::brdf::Precision;
use crate::gpu::Gpu;
use crate::kernels::{self, EvalExtras, RunLimits};
use crate::model::Model;
use crate::kernels::shade::GBufferFormat;
use crate::profile::gbuffer;
use crate::profile::protocol::Timed;
use crate::profile::workload::{self, Variant, Workload};
use crate::shaders::Shaders;
use anyhow::{bail, Result};
use serde::{Deserialize, Serialize};

/// Samples of the eval comparison (NoV, NoL >= 0.05, roughness in [0.2, 1), the accuracy tests' set).
pub const EVAL_SAMPLES: usize = 4096;
/// The G-buffer of the shading comparison.
pub const SHADE_SIZE: (u32, u32) = (64, 32);

/// How one translated kernel agreed with its Vulkan kernel.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct Agreement {
    /// "eval" or "shade".
    pub kernel: String,
    /// Values compared (samples or pixels, times channels).
    pub values: usize,
    /// The largest relative difference (eval: |host - device| / max(|device|, 1e-3); shade: over the pixel's
    /// brightest channel).
    pub worst: f64,
    pub tolerance: f64,
    /// The device the Vulkan kernel ran on.
    pub device: String,
    /// The difference is the device's, not the translation's: it vanishes when the host computes OpSMod as
    /// srem, as lavapipe does (`srem_note`).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub srem: bool,
}

impl Agreement {
    /// Why the difference is the device's, when it is.
    pub fn note(&self) -> Option<String> {
        self.srem.then(|| srem_note(&self.device, self.worst))
    }
}

/// The version of `Agreement`'s cached form (2: `srem`; 3: an f_nol entry's host values divided by N.L as the
/// device's are), part of the cache key.
const AGREEMENT_SCHEMA: &str = "3";

/// The prelude variant that computes OpSMod as lavapipe does (srem).
const SMOD_AS_SREM: &str = "BRDFPROF_SMOD_AS_SREM";

/// The shading comparison's tolerance: two steps of R11G11B10F's 5-bit blue mantissa.
const SHADE_TOLERANCE: f64 = 2.0 / 32.0;

/// Whether a disagreement (`worst` over `tolerance`) of a kernel that takes OpSMod vanishes when the host
/// computes it as srem (`compare` run with `SMOD_AS_SREM`): then it is the device's, not the translation's.
pub fn srem_explains(t: &super::Translation, worst: f64, tolerance: f64, compare: impl Fn(&[&str]) -> Result<f64>) -> Result<bool> {
    Ok(!(worst <= tolerance) && t.body().contains("m_smod(") && compare(&[SMOD_AS_SREM])? <= tolerance)
}

/// The warning for a kernel whose disagreement `srem_explains` (once per kernel and command).
pub fn warn_srem(label: &str, kernel: &str, device: &str, worst: f64) {
    crate::messages::warning_once(format!("{label} ({kernel} kernel): {}; its cost is reported for the SPIR-V semantics", srem_note(device, worst)));
}

/// What a disagreement that vanishes with `SMOD_AS_SREM` means.
pub fn srem_note(device: &str, worst: f64) -> String {
    format!(
        "the kernel takes integer `%` (SPIR-V OpSMod) of a negative value: {device} computes it with the dividend's sign (srem: -7 % 3 = -1) where SPIR-V's OpSMod and the translation take the divisor's (2); GLSL leaves `%` of negative operands undefined. With srem on the host the two agree; as compiled they differ by up to {worst:.1e} relative, so this model's results differ between drivers"
    )
}

/// Relative eval tolerance: fp32 maths libraries differ by a few ulps, amplified in exp(m log x) forms; fp16
/// transcendentals differ by ulps of fp16.
pub fn eval_tolerance(model: &Model) -> f64 {
    match model.precision() {
        Precision::F32 => 1e-4,
        Precision::F16 => 5e-2,
    }
}

/// The largest relative difference over every channel of every value (a NaN or an infinity against a number
/// counts as infinite).
pub fn worst_relative(host: &[[f32; 3]], device: &[[f32; 3]], scale: impl Fn(usize, usize) -> f64) -> f64 {
    let mut worst = 0f64;
    for (i, (h, d)) in host.iter().zip(device).enumerate() {
        for c in 0..3 {
            // Equal values (the same infinity included) and two NaNs agree; a NaN against a number does not.
            let e = if h[c] == d[c] || (h[c].is_nan() && d[c].is_nan()) { 0.0 } else { (f64::from(h[c]) - f64::from(d[c])).abs() / scale(i, c) };
            worst = if e.is_nan() { f64::INFINITY } else { worst.max(e) };
        }
    }
    worst
}

/// `worst_relative` over each device value's brightest channel (at least 1e-3): the measure for kernels that
/// write radiance, whose dim channels carry no precision of their own.
pub fn worst_relative_to_brightest(host: &[[f32; 3]], device: &[[f32; 3]]) -> f64 {
    let brightest: Vec<f64> = device.iter().map(|p| p.iter().fold(1e-3f64, |a, &b| a.max(f64::from(b).abs()))).collect();
    worst_relative(host, device, |i, _| brightest[i])
}

/// The eval kernel of `model`, translated and run on the host, against `gpu`.
pub fn eval_agreement(gpu: &Gpu, model: &Model, shaders: &Shaders) -> Result<Agreement> {
    let samples = well_conditioned(EVAL_SAMPLES, 0x7e57, 0.05, 0.2..1.0);
    let translation = prepare::eval_kernel(model, shaders)?;
    let on_device = kernels::eval_from(gpu, model, shaders, &samples, &EvalExtras::default(), RunLimits::default())?;
    let compare = |defines: &[&str]| -> Result<f64> {
        // As f_s, as `eval_from` gives the device's (a `returns f_nol` entry divided by N.L on the host).
        let on_host = kernels::as_f(model, host::eval(&host::HostKernel::compile_with(&translation, defines)?, &samples, &EvalExtras::default())?, &samples);
        Ok(worst_relative(&on_host, &on_device, |i, c| f64::from(on_device[i][c]).abs().max(1e-3)))
    };
    let (worst, tolerance) = (compare(&[])?, eval_tolerance(model));
    let srem = srem_explains(&translation, worst, tolerance, compare)?;
    Ok(Agreement { kernel: "eval".into(), values: 3 * samples.len(), worst, tolerance, device: gpu.info.name.clone(), srem })
}

/// The packed profiling kernel of `model` (None: the memory-only kernel) with `lights` lights, translated and
/// run on the host, against `gpu`: a pixel agrees when every channel is within two steps of R11G11B10F's
/// 5-bit blue mantissa of its brightest channel.
pub fn shade_agreement(gpu: &Gpu, model: Option<&Model>, lights: u32, shaders: &Shaders) -> Result<Agreement> {
    let (w, h) = SHADE_SIZE;
    let (per_dispatch, _) = crate::kernels::shade::steady_block(lights);
    let g = gbuffer::synthetic(w, h, GBufferFormat::Packed);
    let light_data = gbuffer::lights(per_dispatch);
    let work = Workload::upload(gpu, &g, &light_data, None)?;
    let variant = Variant::new(gpu, &work, model, shaders, 1)?;
    gpu.submit(|cmd| variant.record(cmd, 0))?;
    let on_device = work.radiance()?;
    let translation = prepare::shade_kernel(model, lights, shaders)?;
    let compare = |defines: &[&str]| -> Result<f64> {
        let kernel = host::HostKernel::compile_with(&translation, defines)?;
        let mut words: Vec<u8> = bytemuck::cast_slice(&workload::padded_words(&g)).to_vec();
        let pixels = words.len() / 16;
        let mut radiance = vec![0u8; pixels * 4];
        let mut light_bytes: Vec<u8> = bytemuck::cast_slice(&workload::light_buffer(&light_data)).to_vec();
        let c = g.camera;
        let mut push = workload::push_constants(0, w, [c.scale[0], c.offset[0], c.scale[1], c.offset[1]]);
        let groups = (pixels as u32).div_ceil(kernel.local_size()[0]);
        kernel.run(&mut [&mut words, &mut radiance, &mut light_bytes, &mut push], [groups, 1, 1])?;
        let words: Vec<u32> = bytemuck::pod_collect_to_vec(&radiance);
        let on_host: Vec<[f32; 3]> = words.into_iter().take(on_device.len()).map(gbuffer::unpack_r11g11b10).collect();
        Ok(worst_relative_to_brightest(&on_host, &on_device))
    };
    let (worst, tolerance) = (compare(&[])?, SHADE_TOLERANCE);
    let srem = srem_explains(&translation, worst, tolerance, compare)?;
    Ok(Agreement { kernel: "shade".into(), values: 3 * on_device.len(), worst, tolerance, device: gpu.info.name.clone(), srem })
}

/// Both comparisons for `model` (the shade one alone for the memory-only kernel).
pub fn measure(gpu: &Gpu, model: Option<&Model>, lights: u32, shaders: &Shaders) -> Result<Vec<Agreement>> {
    let mut out = Vec::new();
    if let Some(m) = model {
        out.push(eval_agreement(gpu, m, shaders)?);
    }
    out.push(shade_agreement(gpu, model, lights, shaders)?);
    Ok(out)
}

/// The verdict on `measure`'s comparisons: an error when one is beyond its tolerance, naming the kernel and
/// the difference; a warning for one the device's srem explains.
pub fn verdict(model: Option<&Model>, agreements: &[Agreement]) -> Result<()> {
    let label = model.map_or_else(|| crate::model::BASELINE_LABEL.to_string(), Model::label);
    for a in agreements {
        if a.srem {
            warn_srem(&label, &a.kernel, &a.device, a.worst);
            continue;
        }
        if !(a.worst <= a.tolerance) {
            bail!(
                "{label}: the C translation of the {} kernel disagrees with the Vulkan kernel on {} (worst relative difference {:.3e}, tolerance {:.1e}): its cost is not reported. This is a translator defect; please report it with the model",
                a.kernel, a.device, a.worst, a.tolerance
            );
        }
    }
    Ok(())
}

/// `measure` and its `verdict`.
pub fn check(gpu: &Gpu, model: Option<&Model>, lights: u32, shaders: &Shaders) -> Result<Vec<Agreement>> {
    let out = measure(gpu, model, lights, shaders)?;
    verdict(model, &out)?;
    Ok(out)
}

/// `check`, its measurement from the cache: the key covers the host translations (their whole source), the
/// Vulkan kernels' SPIR-V and constants, the device and its driver, and the comparison's set-up.
pub fn check_cached(gpu: &Gpu, model: Option<&Model>, lights: u32, shaders: &Shaders) -> Result<Vec<Agreement>> {
    let (per_dispatch, accumulate) = crate::kernels::shade::steady_block(lights);
    let shade = crate::kernels::shade::shade_kernel(model, GBufferFormat::Packed, per_dispatch, accumulate, shaders)?;
    let mut key = crate::cache::KeyBuilder::new("agreement")
        .part("brdfprof", env!("CARGO_PKG_VERSION"))
        .part("schema", AGREEMENT_SCHEMA)
        .part("device", format!("{} {} {} {}", gpu.info.name, gpu.info.driver_name, gpu.info.driver_info, gpu.info.driver_version))
        .part("setup", format!("{EVAL_SAMPLES} {SHADE_SIZE:?} {lights} {}", host::build_identity()))
        .part("shade-spirv", bytemuck::cast_slice::<u32, u8>(&shade.spirv.words))
        .part("shade-constants", format!("{:?}", shade.constants))
        .part("shade-host", prepare::shade_kernel(model, lights, shaders)?.source(super::Dialect::Host));
    if let Some(m) = model {
        let eval = m.kernel(crate::model::KernelKind::Eval, shaders)?;
        key = key
            .part("eval-spirv", bytemuck::cast_slice::<u32, u8>(&eval.spirv.words))
            .part("eval-constants", format!("{:?}", eval.constants))
            .part("eval-host", prepare::eval_kernel(m, shaders)?.source(super::Dialect::Host));
    }
    let key = key.finish();
    let label = model.map_or_else(|| crate::model::BASELINE_LABEL.to_string(), Model::label);
    let what = format!("the check of {label}'s translation");
    let valid = |bytes: &[u8]| serde_json::from_slice::<Vec<Agreement>>(bytes).map(|_| ()).map_err(anyhow::Error::from);
    let bytes = crate::cache::get_or_build(crate::cache::Store::open_default().as_ref(), "agreement", &key, &what, valid, || Ok(serde_json::to_vec(&measure(gpu, model, lights, shaders)?)?))?;
    // The verdict on every use, cached or not: the same warning or refusal each time.
    let out: Vec<Agreement> = serde_json::from_slice(&bytes)?;
    verdict(model, &out)?;
    Ok(out)
}
