//! A translation is run before its cost is believed, and judged against an f64 evaluation, not against one
//! device: for each kernel, the translation's host build in double (`host::HostKernel::compile_reference`:
//! the kernel's own operations in f64, each value with the bound the Vulkan precision rules of the operations
//! that made it put on a conforming implementation, prelude/reference.h) is the reference; the Vulkan kernel
//! on a device must be within that bound on every value the rules bound (`judge`), and so must the fp32
//! translation on the host (its maths library follows the same rules). A Vulkan kernel outside the bound where
//! the fp32 translation is within means the two compute different things: the translation is refused.
//!
//! What the check covers is what the model reads: the eval kernel over directions from back-facing through
//! grazing to normal (N.V and N.L in [-0.1, 1]) and roughness in [0, 1], with a `.brdf` file's parameters
//! (those not bound to an input) read per row and drawn over their declared ranges; the profiling kernel (the
//! very kernel a compile-only target costs) over a G-buffer whose every pixel has its own normal, roughness,
//! metallic and base colour. Each `Agreement` states its kernel's tolerance: the per-value bound (its median
//! and largest relative size) and the values it could not bound.
//!
//! One known deviation is named, not refused: lavapipe computes OpSMod (GLSL's `%`) as srem; when the device
//! is outside the bound only until the reference computes srem too, the difference is the device's
//! (`srem_explains`).

use super::host::{self, Bounded};
use super::judge::{self, Tally};
use super::prepare;
use crate::brdf::samples::well_conditioned_in;
use crate::brdf::{Precision, Sample};
use crate::gpu::Gpu;
use crate::kernels::shade::GBufferFormat;
use crate::kernels::{self, EvalExtras, RunLimits};
use crate::measure::gbuffer::{self, GBuffer};
use crate::measure::protocol::Timed;
use crate::measure::workload::{self, Variant, Workload};
use crate::model::Model;
use crate::shaders::Shaders;
use anyhow::{Result, bail};
use serde::{Deserialize, Serialize};

/// Samples of the eval comparison.
pub const EVAL_SAMPLES: usize = 4096;
/// The G-buffer of the shading comparison.
pub const SHADE_SIZE: (u32, u32) = (64, 32);
/// The range of N.V and N.L the eval comparison draws from: back-facing, grazing and normal directions.
pub const CHECK_COSINES: (f64, f64) = (-0.1, 1.0);
/// The largest distance from the reference, in units of the Vulkan precision bound, that agrees.
pub const TOLERANCE: f64 = 1.0;

/// How one translated kernel and its Vulkan kernel compared with the translation's f64 reference.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct Agreement {
    /// "eval" or "shade".
    pub kernel: String,
    /// Values compared (samples or pixels, times channels).
    pub values: usize,
    /// The Vulkan kernel's largest distance from the reference, in units of the bound (`judge`).
    #[serde(with = "super::judge::any_f64")]
    pub worst: f64,
    /// The largest that agrees (`TOLERANCE`).
    #[serde(with = "super::judge::any_f64")]
    pub tolerance: f64,
    /// The fp32 translation's (host build) largest distance, in the same units.
    #[serde(with = "super::judge::any_f64")]
    pub translation_worst: f64,
    /// Where the Vulkan kernel's worst was.
    pub worst_at: String,
    /// The median and largest relative bound over the values judged: the kernel's tolerance.
    #[serde(with = "super::judge::any_f64")]
    pub bound_median: f64,
    #[serde(with = "super::judge::any_f64")]
    pub bound_max: f64,
    /// Values not judged: the rules bound nothing there (a comparison within rounding of its threshold, a
    /// divisor that may be 0) or SPIR-V leaves them undefined.
    pub unbounded: usize,
    /// The device the Vulkan kernel ran on.
    pub device: String,
    /// The difference is the device's, not the translation's: it vanishes when the reference computes OpSMod
    /// as srem, as lavapipe does (`srem_note`).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub srem: bool,
    /// Where the fp32 translation's worst was (`worst_at`'s form).
    #[serde(default)]
    pub translation_worst_at: String,
    /// The kernel reads a value nothing wrote: what shows it (`reads_undefined`), where the translation is
    /// beyond its bound.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub undefined: Option<String>,
}

impl Agreement {
    /// Why the difference is the device's, when it is.
    pub fn note(&self) -> Option<String> {
        self.srem.then(|| srem_note(&self.device, self.worst))
    }

    /// One line for a report's `translation` note.
    pub fn summary(&self) -> String {
        format!(
            "{}: Vulkan at {:.2} and the fp32 translation at {:.2} of the Vulkan precision bound (relative bound median {:.1e}, largest {:.1e}; {} of {} values unbounded)",
            self.kernel,
            self.worst,
            self.translation_worst,
            self.bound_median,
            self.bound_max,
            self.unbounded,
            self.values
        )
    }

    fn of(kernel: &str, device: &Tally, translation: &Tally, gpu: &Gpu, srem: bool) -> Self {
        Agreement {
            kernel: kernel.into(),
            values: device.values,
            worst: device.worst,
            tolerance: TOLERANCE,
            translation_worst: translation.worst,
            worst_at: device.worst_at.clone(),
            bound_median: device.bound_median,
            bound_max: device.bound_max,
            unbounded: device.unbounded,
            device: gpu.info.name.clone(),
            srem,
            translation_worst_at: translation.worst_at.clone(),
            undefined: None,
        }
    }
}

/// The version of `Agreement`'s cached form (5: where the translation's worst was, undefined reads), part of
/// the cache key.
const AGREEMENT_SCHEMA: &str = "5";

/// The prelude variant that computes OpSMod as lavapipe does (srem).
const SMOD_AS_SREM: &str = "BRDFPROF_SMOD_AS_SREM";

/// Whether a disagreement (`worst` over `tolerance`) of a kernel that takes OpSMod vanishes when the host
/// computes it as srem (`compare` run with `SMOD_AS_SREM`): then it is the device's, not the translation's.
pub fn srem_explains(
    t: &super::Translation,
    worst: f64,
    tolerance: f64,
    compare: impl Fn(&[&str]) -> Result<f64>,
) -> Result<bool> {
    Ok(!(worst <= tolerance) && t.body().contains("m_smod(") && compare(&[SMOD_AS_SREM])? <= tolerance)
}

/// The warning for a kernel whose disagreement `srem_explains` (once per kernel and command).
pub fn warn_srem(label: &str, kernel: &str, device: &str, worst: f64) {
    crate::messages::warning_once(format!(
        "{label} ({kernel} kernel): {}; its cost is reported for the SPIR-V semantics",
        srem_note(device, worst)
    ));
}

/// What a disagreement that vanishes with `SMOD_AS_SREM` means.
pub fn srem_note(device: &str, worst: f64) -> String {
    format!(
        "the kernel takes integer `%` (SPIR-V OpSMod) of a negative value: {device} computes it with the dividend's sign (srem: -7 % 3 = -1) where SPIR-V's OpSMod and the translation take the divisor's (2); GLSL leaves `%` of negative operands undefined. With srem in the reference the two agree; as compiled {device} is {worst:.1e} times the precision bound away, so this model's results differ between drivers"
    )
}

/// Relative tolerance between two fp32 executions of one eval kernel (`eval --device opencl` against Vulkan):
/// fp32 maths libraries differ by a few ulps, amplified in exp(m log x) forms; fp16 transcendentals differ by
/// ulps of fp16.
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
            let e = if h[c] == d[c] || (h[c].is_nan() && d[c].is_nan()) {
                0.0
            } else {
                (f64::from(h[c]) - f64::from(d[c])).abs() / scale(i, c)
            };
            worst = if e.is_nan() { f64::INFINITY } else { worst.max(e) };
        }
    }
    worst
}

/// `worst_relative` over each device value's brightest channel (at least 1e-3): the measure for kernels that
/// write radiance, whose dim channels carry no precision of their own.
pub fn worst_relative_to_brightest(host: &[[f32; 3]], device: &[[f32; 3]]) -> f64 {
    let brightest: Vec<f64> =
        device.iter().map(|p| p.iter().fold(1e-3f64, |a, &b| a.max(f64::from(b).abs()))).collect();
    worst_relative(host, device, |i, _| brightest[i])
}

/// The eval check's samples and, for a `.brdf` model, the model with each parameter not bound to an input read
/// per row, its values drawn over the parameter's range (a float's declared min..max, a colour's [0, 1]^3, a
/// bool's 0 and 1): the rows and floats per row.
pub fn check_inputs(model: &Model) -> (Model, Vec<Sample>, Vec<f32>, usize) {
    use rand::{Rng, SeedableRng};
    let samples = well_conditioned_in(EVAL_SAMPLES, 0x7e57, CHECK_COSINES, CHECK_COSINES, 0.0..1.0);
    let Some(file) = model.file() else { return (model.clone(), samples, Vec::new(), 0) };
    let params: Vec<_> = file
        .file
        .params
        .iter()
        .zip(&file.bindings)
        .filter(|(_, b)| matches!(b, crate::model::file_model::Binding::Value(_)))
        .map(|(p, _)| p)
        .collect();
    let names: Vec<&str> = params.iter().map(|p| p.name.as_str()).collect();
    let (with_rows, floats) = file.with_rows(&names);
    let mut rng = rand_pcg::Pcg64::seed_from_u64(0x7e58);
    let mut rows = Vec::with_capacity(samples.len() * floats);
    for _ in &samples {
        for p in &params {
            match p.kind {
                crate::model::brdf_file::FileParamKind::Float { min, max, .. } => {
                    rows.push(if max > min { rng.random_range(min..=max) } else { min } as f32)
                }
                crate::model::brdf_file::FileParamKind::Bool { .. } => rows.push(rng.random_range(0..2u32) as f32),
                crate::model::brdf_file::FileParamKind::Color { .. } => {
                    rows.extend((0..3).map(|_| rng.random::<f32>()))
                }
            }
        }
    }
    (Model::File(std::sync::Arc::new(with_rows)), samples, rows, floats)
}

/// The reference's values as f_s, as `kernels::as_f` gives the device's: a `returns f_nol` entry divided by N.L
/// (in f64; the f32 rounding of that division, one ULP, added to the bound).
fn reference_as_f(model: &Model, values: Vec<[Bounded; 3]>, samples: &[Sample]) -> Vec<[Bounded; 3]> {
    if !model.file().is_some_and(|f| f.returns_f_nol()) {
        return values;
    }
    let unit = |v: [f32; 3]| glam::DVec3::new(v[0].into(), v[1].into(), v[2].into()).normalize_or_zero();
    let divide = |b: Bounded, nol: f64| {
        let value = b.value / nol;
        Bounded { value, bound: b.bound / nol.abs() + value.abs() * f64::from(f32::EPSILON) }
    };
    values
        .into_iter()
        .zip(samples)
        .map(|(g, s)| g.map(|b| if b.value == 0.0 && b.bound == 0.0 { b } else { divide(b, unit(s.n).dot(unit(s.l))) }))
        .collect()
}

fn flat<T: Copy>(v: &[[T; 3]]) -> Vec<T> {
    v.iter().flatten().copied().collect()
}

/// Loop headers `model`'s eval kernel passes per evaluation on the check's samples, counted by its fp32
/// translation on the host (no Vulkan device needed).
pub fn loop_passes(model: &Model, shaders: &Shaders) -> Result<f64> {
    let (checked, samples, rows, row_floats) = check_inputs(model);
    let extras = EvalExtras { tangents: None, rows: &rows, row_floats };
    let kernel = host::HostKernel::compile(&prepare::eval_kernel(&checked, shaders)?)?;
    host::loop_passes(&kernel, &samples, &extras)
}

/// The eval kernel of `model` against its f64 reference, on `gpu` and as the fp32 translation on the host.
pub fn eval_agreement(gpu: &Gpu, model: &Model, shaders: &Shaders) -> Result<Agreement> {
    let (checked, samples, rows, row_floats) = check_inputs(model);
    let extras = EvalExtras { tangents: None, rows: &rows, row_floats };
    let translation = prepare::eval_kernel(&checked, shaders)?;
    let on_device = flat(&kernels::eval_from(gpu, &checked, shaders, &samples, &extras, RunLimits::default())?);
    let (fp32, f64_build) = host::HostKernel::compile_with_reference(&translation)?;
    let on_host = flat(&kernels::as_f(&checked, host::eval(&fp32, &samples, &extras)?, &samples));
    let run_reference = |kernel: &host::HostKernel| -> Result<Vec<Bounded>> {
        Ok(flat(&reference_as_f(&checked, host::eval_reference(kernel, &samples, &extras)?, &samples)))
    };
    let reference = |defines: &[&str]| run_reference(&host::HostKernel::compile_reference(&translation, defines)?);
    let r = run_reference(&f64_build)?;
    let device = judge::tally(&on_device, &r, |_| 0.0, 3);
    let host = judge::tally(&on_host, &r, |_| 0.0, 3);
    let srem = srem_explains(&translation, device.worst, TOLERANCE, |d| {
        Ok(judge::tally(&on_device, &reference(d)?, |_| 0.0, 3).worst)
    })?;
    Ok(Agreement::of("eval", &device, &host, gpu, srem))
}

/// The shading comparison's G-buffer: every pixel its own unit normal (over the whole sphere, so some face
/// away from the camera), roughness, metallic and base colour, uniform over their ranges.
pub fn check_gbuffer(width: u32, height: u32) -> GBuffer {
    use rand::{Rng, SeedableRng};
    let camera = gbuffer::Camera::new(width, height);
    let mut rng = rand_pcg::Pcg64::seed_from_u64(0x5ade);
    let mut words = Vec::with_capacity((width * height * 4) as usize);
    for y in 0..height {
        for x in 0..width {
            let n =
                glam::Vec3::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0))
                    .normalize_or(glam::Vec3::Z);
            let base = glam::Vec3::new(rng.random(), rng.random(), rng.random());
            let s = gbuffer::Surface {
                normal: n,
                view: camera.view(x, y).normalize(),
                roughness: rng.random(),
                metallic: rng.random(),
                base,
            };
            words.extend(gbuffer::pack(&s));
        }
    }
    GBuffer { width, height, format: GBufferFormat::Packed, camera, words }
}

/// Runs a host build of the profiling kernel over `g` and `lights`; returns its radiance binding's bytes
/// (`scale` bytes a pixel: 4 for the fp32 build's R11G11B10F, 64 for the reference's pairs).
pub fn shade_on_host(kernel: &host::HostKernel, g: &GBuffer, lights: &[f32], scale: usize) -> Result<Vec<u8>> {
    let mut words: Vec<u8> = bytemuck::cast_slice(&workload::padded_words(g)).to_vec();
    let pixels = words.len() / 16;
    let mut radiance = vec![0u8; pixels * scale];
    let mut light_bytes: Vec<u8> = bytemuck::cast_slice(&workload::light_buffer(lights)).to_vec();
    let c = g.camera;
    let mut push = workload::push_constants(0, g.width, [c.scale[0], c.offset[0], c.scale[1], c.offset[1]]);
    let groups = (pixels as u32).div_ceil(kernel.local_size()[0]);
    kernel.run(&mut [&mut words, &mut radiance, &mut light_bytes, &mut push], [groups, 1, 1])?;
    Ok(radiance)
}

/// The packed profiling kernel of `model` (None: the memory-only kernel) with `lights` lights against its f64
/// reference, on `gpu` and as the fp32 translation on the host; the R11G11B10F output's rounding added to
/// each channel's bound.
pub fn shade_agreement(gpu: &Gpu, model: Option<&Model>, lights: u32, shaders: &Shaders) -> Result<Agreement> {
    let (w, h) = SHADE_SIZE;
    let (per_dispatch, _) = crate::kernels::shade::steady_block(lights);
    let g = check_gbuffer(w, h);
    let light_data = gbuffer::lights(per_dispatch);
    let work = Workload::upload(gpu, &g, &light_data, None)?;
    let variant = Variant::new(gpu, &work, model, shaders, 1)?;
    gpu.submit(|cmd| variant.record(cmd, 0))?;
    let on_device = flat(&work.radiance()?);
    let translation = prepare::shade_kernel(model, lights, shaders)?;
    let (fp32, f64_build) = host::HostKernel::compile_with_reference(&translation)?;
    let packed: Vec<u32> = bytemuck::pod_collect_to_vec(&shade_on_host(&fp32, &g, &light_data, 4)?);
    let on_host = flat(&packed.into_iter().map(gbuffer::unpack_r11g11b10).collect::<Vec<_>>());
    let run_reference = |kernel: &host::HostKernel| -> Result<Vec<Bounded>> {
        let bytes = shade_on_host(kernel, &g, &light_data, 64)?;
        let rgb = host::pairs(&bytes).chunks_exact(4).flat_map(|p| [p[0], p[1], p[2]]).collect::<Vec<_>>();
        Ok(rgb
            .into_iter()
            .enumerate()
            .map(|(i, b)| judge::r11g11b10_saturated(b, if i % 3 == 2 { 5 } else { 6 }))
            .collect())
    };
    let reference = |defines: &[&str]| run_reference(&host::HostKernel::compile_reference(&translation, defines)?);
    let r = run_reference(&f64_build)?;
    let n = on_device.len();
    let step = |r: &[Bounded]| -> Vec<f64> {
        r.iter().enumerate().map(|(i, b)| judge::r11g11b10_step(*b, if i % 3 == 2 { 5 } else { 6 })).collect()
    };
    let steps = step(&r);
    let device = judge::tally(&on_device, &r[..n], |i| steps[i], 3);
    let host = judge::tally(&on_host[..n], &r[..n], |i| steps[i], 3);
    let srem = srem_explains(&translation, device.worst, TOLERANCE, |d| {
        let r = reference(d)?;
        let steps = step(&r);
        Ok(judge::tally(&on_device, &r[..n], |i| steps[i], 3).worst)
    })?;
    Ok(Agreement::of("shade", &device, &host, gpu, srem))
}

/// Both comparisons for `model` (the shade one alone for the memory-only kernel); where the translation is
/// beyond its bound, whether the kernel reads a value nothing wrote (`reads_undefined`).
pub fn measure(gpu: &Gpu, model: Option<&Model>, lights: u32, shaders: &Shaders) -> Result<Vec<Agreement>> {
    let mut out = Vec::new();
    if let Some(m) = model {
        out.push(eval_agreement(gpu, m, shaders)?);
    }
    out.push(shade_agreement(gpu, model, lights, shaders)?);
    if out.iter().any(|a| !(a.translation_worst <= a.tolerance)) {
        let undefined = reads_undefined(model, lights, shaders)?;
        out.iter_mut().for_each(|a| a.undefined.clone_from(&undefined));
    }
    Ok(out)
}

/// Whether the profiling kernel of `model` reads memory nothing wrote (an uninitialised variable or struct
/// field of the model's code): its fp32 host build run twice over the check's G-buffer, g++ filling every
/// uninitialised local with zeros and then with a pattern (`-ftrivial-auto-var-init`); C gives such a read no
/// value, as SPIR-V gives OpUndef none, so the f32 and f64 builds may differ by anything there. Some(what
/// changed) where the two runs differ.
pub fn reads_undefined(model: Option<&Model>, lights: u32, shaders: &Shaders) -> Result<Option<String>> {
    let (w, h) = SHADE_SIZE;
    let g = check_gbuffer(w, h);
    let light_data = gbuffer::lights(crate::kernels::shade::steady_block(lights).0);
    let translation = prepare::shade_kernel(model, lights, shaders)?;
    let run = |init: &str| -> Result<Vec<u32>> {
        let flag = format!("-ftrivial-auto-var-init={init}");
        let kernel = host::HostKernel::compile_with_flags(&translation, &[&flag])?;
        Ok(bytemuck::pod_collect_to_vec(&shade_on_host(&kernel, &g, &light_data, 4)?))
    };
    let (zero, pattern) = (run("zero")?, run("pattern")?);
    let differ = zero.iter().zip(&pattern).filter(|(a, b)| a != b).count();
    Ok((differ > 0).then(|| {
        format!(
            "{differ} of {} pixels change when the host build's uninitialised locals start as zeros instead of a fill pattern (g++ -ftrivial-auto-var-init)",
            zero.len()
        )
    }))
}

/// The verdict on `measure`'s comparisons: an error when one is beyond its tolerance, naming the kernel, the
/// distance and what it means; a warning for one the device's srem explains.
pub fn verdict(model: Option<&Model>, agreements: &[Agreement]) -> Result<()> {
    let label = model.map_or_else(|| crate::model::BASELINE_LABEL.to_string(), Model::label);
    for a in agreements {
        if let (false, Some(undefined)) = (a.translation_worst <= a.tolerance, &a.undefined) {
            bail!(
                "{label}: the {} kernel reads a value the model's code never wrote (an uninitialised variable or struct field; {undefined}), so its fp32 and f64 evaluations differ by anything ({:.3e} times the Vulkan precision bound; worst {}): initialise it; not costed",
                a.kernel,
                a.translation_worst,
                a.translation_worst_at
            );
        }
        if !(a.translation_worst <= a.tolerance) {
            bail!(
                "{label}: the fp32 C translation of the {} kernel, run on the host, is {:.3e} times the Vulkan precision bound away from its own f64 evaluation (worst {}), and no uninitialised read explains it: brdfprof's translation or its bound is wrong (a translator defect); its cost is not reported. Please report it with the model",
                a.kernel,
                a.translation_worst,
                a.translation_worst_at
            );
        }
        if a.srem {
            warn_srem(&label, &a.kernel, &a.device, a.worst);
            continue;
        }
        if !(a.worst <= a.tolerance) {
            bail!(
                "{label}: the Vulkan {} kernel on {} is {:.3e} times the Vulkan precision bound of its operations away from their f64 evaluation, where the fp32 C translation is within it ({}): the translation does not compute what the Vulkan kernel computes (a translator defect); its cost is not reported. Please report it with the model",
                a.kernel,
                a.device,
                a.worst,
                a.worst_at
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

/// `check`, its measurement from the cache: the key covers the host translations and their f64 references
/// (their whole source), the Vulkan kernels' SPIR-V and constants, the device and its driver, and the
/// comparison's set-up.
pub fn check_cached(gpu: &Gpu, model: Option<&Model>, lights: u32, shaders: &Shaders) -> Result<Vec<Agreement>> {
    let (per_dispatch, accumulate) = crate::kernels::shade::steady_block(lights);
    let shade = crate::kernels::shade::shade_kernel(model, GBufferFormat::Packed, per_dispatch, accumulate, shaders)?;
    let shade_t = prepare::shade_kernel(model, lights, shaders)?;
    let mut key = crate::cache::KeyBuilder::new("agreement")
        .part("brdfprof", env!("CARGO_PKG_VERSION"))
        .part("schema", AGREEMENT_SCHEMA)
        .part(
            "device",
            format!("{} {} {} {}", gpu.info.name, gpu.info.driver_name, gpu.info.driver_info, gpu.info.driver_version),
        )
        .part("setup", format!("{EVAL_SAMPLES} {SHADE_SIZE:?} {CHECK_COSINES:?} {lights} {}", host::build_identity()))
        .part("shade-spirv", bytemuck::cast_slice::<u32, u8>(&shade.spirv.words))
        .part("shade-constants", format!("{:?}", shade.constants))
        .part("shade-host", shade_t.source(super::Dialect::Host))
        .part("shade-reference", shade_t.reference_source());
    if let Some(m) = model {
        let (checked, ..) = check_inputs(m);
        let eval = checked.kernel(crate::model::KernelKind::Eval, shaders)?;
        let eval_t = prepare::eval_kernel(&checked, shaders)?;
        key = key
            .part("eval-spirv", bytemuck::cast_slice::<u32, u8>(&eval.spirv.words))
            .part("eval-constants", format!("{:?}", eval.constants))
            .part("eval-host", eval_t.source(super::Dialect::Host))
            .part("eval-reference", eval_t.reference_source());
    }
    let key = key.finish();
    let label = model.map_or_else(|| crate::model::BASELINE_LABEL.to_string(), Model::label);
    let what = format!("the check of {label}'s translation");
    let valid = |bytes: &[u8]| serde_json::from_slice::<Vec<Agreement>>(bytes).map(|_| ()).map_err(anyhow::Error::from);
    let bytes = crate::cache::get_or_build(
        crate::cache::Store::open_default().as_ref(),
        "agreement",
        &key,
        &what,
        valid,
        || Ok(serde_json::to_vec(&measure(gpu, model, lights, shaders)?)?),
    )?;
    // The verdict on every use, cached or not: the same warning or refusal each time.
    let out: Vec<Agreement> = serde_json::from_slice(&bytes)?;
    verdict(model, &out)?;
    Ok(out)
}
