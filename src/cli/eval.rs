//! `brdfprof eval`: f_s of one model for every row of a CSV file.

use super::args::{DeviceArgs, ModelArgs};
use super::on_device;
use anyhow::{Result, bail};
use brdfprof::model::{Model, csv_rows};
use brdfprof::{io, kernels, messages};
use clap::Args;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Args)]
pub struct EvalArgs {
    #[command(flatten)]
    pub model: ModelArgs,
    /// CSV with columns nx,ny,nz,vx,vy,vz,lx,ly,lz, and roughness and f0r,f0g,f0b where the model reads them
    /// (a conductor's Fresnel reads no F0; a model file what its bindings read) (any order; others ignored). For
    /// a model file (.brdf, .hlsl, .ush, .wgsl, ...): optional tx,ty,tz (the tangent X, made orthogonal to N; Y = N x X; without them X is
    /// Duff et al. 2017's basis), and a column named like a parameter (NAMEr,NAMEg,NAMEb for a colour) sets
    /// it per row.
    #[arg(long)]
    pub input: PathBuf,
    /// CSV written with columns r,g,b, one row per input row (written atomically).
    #[arg(long)]
    pub output: PathBuf,
    #[command(flatten)]
    pub device: DeviceArgs,
}

impl super::Run for EvalArgs {
    fn run(&self) -> Result<ExitCode> {
        eval(self)
    }
}

pub fn eval(args: &EvalArgs) -> Result<ExitCode> {
    io::check_output_path("--output", &args.output)?;
    let models = args.model.models(&[])?;
    let [model] = models.as_slice() else {
        bail!("eval takes exactly one --model");
    };
    let mut inputs = vec![("--input", args.input.as_path())];
    inputs.extend(model.file().map(|f| ("--model", std::path::Path::new(&f.path))));
    io::check_not_input("--output", &args.output, &inputs)?;
    let shown = model.name();
    let (model, input, rows) = csv_rows::read_rows(model, &args.input, &args.model.params)?;
    let extras =
        kernels::EvalExtras { tangents: input.tangents.as_deref(), rows: &rows.values, row_floats: rows.floats };
    let (device, values) = if args.device.device.as_deref() == Some(OPENCL_DEVICE) {
        let (device, values, smod) = on_opencl(&model, &input.samples, &extras)?;
        // Two executions of one source: where they disagree, the user is told.
        let vulkan = DeviceArgs { device: None, validate: args.device.validate };
        let (gpu, on_vulkan) = on_device(&vulkan, |gpu, _| {
            kernels::eval_with(gpu, &model, &input.samples, &extras, kernels::RunLimits::default())
        })?;
        if let Some(w) = disagreement(&model, &values, &on_vulkan, &input.lines, (&device, &gpu.info.name), smod) {
            messages::warning(w);
        }
        (device, values)
    } else {
        let (gpu, values) = on_device(&args.device, |gpu, _| {
            kernels::eval_with(gpu, &model, &input.samples, &extras, kernels::RunLimits::default())
        })?;
        (gpu.info.name.clone(), values)
    };
    io::write_output(&args.output, io::format_rgb_csv(&values).as_bytes())?;
    let bad = values.iter().filter(|v| v.iter().any(|x| !x.is_finite())).count();
    if bad > 0 {
        messages::warning(format!("{bad} of {} rows of {shown} are not finite (written as NaN or inf)", values.len()));
    }
    messages::progress(format!("{} rows of {shown} on {device} -> {}", values.len(), args.output.display()));
    Ok(ExitCode::SUCCESS)
}

/// `eval --device opencl`: the eval kernel's OpenCL C translation (the one Intel's compiler gets) run through
/// OpenCL, PoCL on this CPU unless BRDFPROF_OPENCL_DEVICE names another: a second execution of the same BRDF
/// source, independent of Vulkan, with the same CSV in and out.
pub const OPENCL_DEVICE: &str = "opencl";

/// The warning when the OpenCL and Vulkan executions of `model` differ beyond the translation check's
/// tolerance (`verify::eval_tolerance`) on any row; None when they agree.
fn disagreement(
    model: &Model,
    opencl: &[[f32; 3]],
    vulkan: &[[f32; 3]],
    lines: &[usize],
    (cl, vk): (&str, &str),
    smod: bool,
) -> Option<String> {
    let tolerance = brdfprof::translate::verify::eval_tolerance(model);
    let row_worst = |i: usize| {
        brdfprof::translate::verify::worst_relative(&opencl[i..=i], &vulkan[i..=i], |_, c| {
            f64::from(vulkan[i][c]).abs().max(1e-3)
        })
    };
    let over: Vec<usize> = (0..opencl.len()).filter(|&i| !(row_worst(i) <= tolerance)).collect();
    let &first = over.first()?;
    let srem = if !smod {
        ""
    } else {
        "; the kernel takes integer `%`, which lavapipe computes as srem (the dividend's sign) where SPIR-V's OpSMod and the translation take the divisor's: on negative operands the two differ by design (docs/translation.md)"
    };
    Some(format!(
        "{} of {} rows differ between {cl} and Vulkan on {vk} by more than {tolerance:.0e} relative (first: line {}, OpenCL {:?}, Vulkan {:?}){srem}",
        over.len(),
        opencl.len(),
        lines.get(first).copied().unwrap_or(first + 2),
        opencl[first],
        vulkan[first]
    ))
}

fn on_opencl(
    model: &Model,
    samples: &[brdfprof::brdf::Sample],
    extras: &kernels::EvalExtras,
) -> Result<(String, Vec<[f32; 3]>, bool)> {
    use brdfprof::translate::{opencl, prepare};
    let translation = prepare::eval_kernel(model, kernels::embedded())?;
    let kernel = opencl::ClKernel::build(&translation, false)?;
    let values = kernels::as_f(model, opencl::eval(&kernel, samples, extras)?, samples);
    Ok((format!("{} (OpenCL)", kernel.device()), values, translation.body().contains("m_smod(")))
}
