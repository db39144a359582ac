//! `brdfprof report RESULTS.json... --out report.html`: one self-contained HTML page of saved results (the
//! measuring commands' `--html FILE`, `args::HtmlArg`, draws the same page of what they just measured).

use super::args::DeviceArgs;
use anyhow::Result;
use brdfprof::io;
use brdfprof::report;
use clap::Args;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Args)]
pub struct ReportArgs {
    /// `profile`, `sweep`, `stability`, `inspect` (one device or several) or `compare` JSON reports.
    #[arg(required = true)]
    pub files: Vec<PathBuf>,
    /// The HTML page (written atomically; opens from file://, loads nothing).
    #[arg(long)]
    pub out: PathBuf,
    /// Leave out the lobes, lit spheres and albedo (they are evaluated on the device at report time).
    #[arg(long)]
    pub no_gpu: bool,
    #[command(flatten)]
    pub device: DeviceArgs,
}

impl super::Run for ReportArgs {
    fn run(&self) -> Result<ExitCode> {
        report(self)
    }
}

pub fn report(args: &ReportArgs) -> Result<ExitCode> {
    io::check_output_path("--out", &args.out)?;
    io::check_not_input("--out", &args.out, &args.files.iter().map(|f| ("RESULTS", f.as_path())).collect::<Vec<_>>())?;
    brdfprof::compare::refuse_repeated_reports(&args.files, "a report given twice would draw its sections twice")?;
    let inputs = args.files.iter().map(|f| report::load(f)).collect::<Result<Vec<_>>>()?;
    let gpu = if args.no_gpu { None } else { Some(args.device.open()?) };
    let bytes = report::write(&inputs, &args.out, gpu.as_ref())?;
    if let Some(gpu) = &gpu {
        gpu.check_validation()?;
    }
    outln!("{} ({bytes} bytes) from {} report(s)", args.out.display(), inputs.len());
    Ok(ExitCode::SUCCESS)
}
