//! `brdfprof eval`: f_s of one model for every row of a CSV file.

use super::{on_device, DeviceArgs, ModelArgs};
use anyhow::{bail, Result};
use brdfprof::{io, kernels};
use clap::Args;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Args)]
pub struct EvalArgs {
    #[command(flatten)]
    pub model: ModelArgs,
    /// CSV with columns nx,ny,nz,vx,vy,vz,lx,ly,lz,roughness,f0r,f0g,f0b (any order; others ignored).
    #[arg(long)]
    pub input: PathBuf,
    /// CSV written with columns r,g,b, one row per input row (written atomically).
    #[arg(long)]
    pub output: PathBuf,
    #[command(flatten)]
    pub device: DeviceArgs,
}

pub fn eval(args: &EvalArgs) -> Result<ExitCode> {
    io::check_output_path("--output", &args.output)?;
    let models = args.model.models(&[])?;
    let [model] = models.as_slice() else {
        bail!("eval takes exactly one --model");
    };
    let samples = io::read_samples_csv(&args.input)?;
    let (gpu, values) = on_device(&args.device, |gpu, _| kernels::eval(gpu, model, &samples, kernels::RunLimits::default()))?;
    io::write_output(&args.output, io::format_rgb_csv(&values).as_bytes())?;
    eprintln!("brdfprof: {} rows of {model} on {} -> {}", values.len(), gpu.info.name, args.output.display());
    Ok(ExitCode::SUCCESS)
}
