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
use crate::profile::gbuffer::{self, GBufferFormat};
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
}

/// Relative eval tolerance: fp32 maths libraries differ by a few ulps, amplified in exp(m log x) forms; fp16
/// transcendentals differ by ulps of fp16.
fn eval_tolerance(model: &Model) -> f64 {
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
    let kernel = host::HostKernel::compile(&prepare::eval_kernel(model, shaders)?)?;
    let on_host = host::eval(&kernel, &samples, &EvalExtras::default())?;
    let on_device = kernels::eval_from(gpu, model, shaders, &samples, &EvalExtras::default(), RunLimits::default())?;
    let worst = worst_relative(&on_host, &on_device, |i, c| f64::from(on_device[i][c]).abs().max(1e-3));
    Ok(Agreement { kernel: "eval".into(), values: 3 * samples.len(), worst, tolerance: eval_tolerance(model), device: gpu.info.name.clone() })
}

/// The packed profiling kernel of `model` (None: the memory-only kernel) with `lights` lights, translated and
/// run on the host, against `gpu`: a pixel agrees when every channel is within two steps of R11G11B10F's
/// 5-bit blue mantissa of its brightest channel.
pub fn shade_agreement(gpu: &Gpu, model: Option<&Model>, lights: u32, shaders: &Shaders) -> Result<Agreement> {
    let (w, h) = SHADE_SIZE;
    let (per_dispatch, _) = workload::steady_block(lights);
    let g = gbuffer::synthetic(w, h, GBufferFormat::Packed);
    let light_data = gbuffer::lights(per_dispatch);
    let work = Workload::upload(gpu, &g, &light_data, None)?;
    let variant = Variant::new(gpu, &work, model, shaders, 1)?;
    gpu.submit(|cmd| variant.record(cmd, 0))?;
    let on_device = work.radiance()?;
    let kernel = host::HostKernel::compile(&prepare::shade_kernel(model, lights, shaders)?)?;
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
    let worst = worst_relative_to_brightest(&on_host, &on_device);
    Ok(Agreement { kernel: "shade".into(), values: 3 * on_device.len(), worst, tolerance: 2.0 / 32.0, device: gpu.info.name.clone() })
}

/// Both comparisons for `model` (the shade one alone for the memory-only kernel); an error when either is
/// beyond its tolerance, naming the kernel and the difference.
pub fn check(gpu: &Gpu, model: Option<&Model>, lights: u32, shaders: &Shaders) -> Result<Vec<Agreement>> {
    let mut out = Vec::new();
    if let Some(m) = model {
        out.push(eval_agreement(gpu, m, shaders)?);
    }
    out.push(shade_agreement(gpu, model, lights, shaders)?);
    let label = model.map_or_else(|| workload::BASELINE_LABEL.to_string(), Model::label);
    for a in &out {
        if !(a.worst <= a.tolerance) {
            bail!(
                "{label}: the C translation of the {} kernel disagrees with the Vulkan kernel on {} (worst relative difference {:.3e}, tolerance {:.1e}): its cost is not reported. This is a translator defect; please report it with the model",
                a.kernel, a.device, a.worst, a.tolerance
            );
        }
    }
    Ok(out)
}

/// `check`, or its result from the cache: the key covers the host translations (their whole source), the
/// Vulkan kernels' SPIR-V and constants, the device and its driver, and the comparison's set-up.
pub fn check_cached(gpu: &Gpu, model: Option<&Model>, lights: u32, shaders: &Shaders) -> Result<Vec<Agreement>> {
    let (per_dispatch, accumulate) = workload::steady_block(lights);
    let shade = workload::shade_kernel(model, GBufferFormat::Packed, per_dispatch, accumulate, shaders)?;
    let mut key = crate::cache::KeyBuilder::new("agreement")
        .part("brdfprof", env!("CARGO_PKG_VERSION"))
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
    let label = model.map_or_else(|| workload::BASELINE_LABEL.to_string(), Model::label);
    let what = format!("the check of {label}'s translation");
    let valid = |bytes: &[u8]| serde_json::from_slice::<Vec<Agreement>>(bytes).map(|_| ()).map_err(anyhow::Error::from);
    let bytes = crate::cache::get_or_build(crate::cache::Store::open_default().as_ref(), "agreement", &key, &what, valid, || Ok(serde_json::to_vec(&check(gpu, model, lights, shaders)?)?))?;
    Ok(serde_json::from_slice(&bytes)?)
}
