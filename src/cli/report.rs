//! `brdfprof report RESULTS.json... --out report.html`, and the `--html FILE` of the measuring commands: one
//! self-contained HTML page of saved (or just measured) results.

use super::DeviceArgs;
use anyhow::Result;
use brdfprof::gpu::Gpu;
use brdfprof::report_page::{self, Input};
use brdfprof::io;
use clap::Args;
use std::path::{Path, PathBuf};
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

/// `--html FILE`: the flag's help, shared by the commands that take it.
#[derive(Args, Clone, Default)]
pub struct HtmlArg {
    /// Also write the results as one self-contained HTML page (as `brdfprof report` draws it).
    #[arg(long, value_name = "FILE")]
    pub html: Option<PathBuf>,
}

impl HtmlArg {
    /// Refuses a bad path before anything is measured.
    pub fn check(&self) -> Result<()> {
        self.html.as_deref().map_or(Ok(()), |p| io::check_output_path("--html", p))
    }

    /// Writes the page of `inputs` (lobes and spheres on `gpu`) where asked; returns its path.
    pub fn write(&self, inputs: &[Input], gpu: Option<&Gpu>) -> Result<Option<PathBuf>> {
        let Some(path) = &self.html else { return Ok(None) };
        let bytes = report_page::write(inputs, path, gpu)?;
        brdfprof::messages::progress(format!("HTML report: {} ({bytes} bytes)", path.display()));
        Ok(Some(path.clone()))
    }
}

/// The report just measured, read back as its saved JSON would be.
pub fn just_measured(json: &Path, report: &impl serde::Serialize) -> Result<Input> {
    report_page::from_report(json, report)
}

pub fn report(args: &ReportArgs) -> Result<ExitCode> {
    io::check_output_path("--out", &args.out)?;
    io::check_not_input("--out", &args.out, &args.files.iter().map(|f| ("RESULTS", f.as_path())).collect::<Vec<_>>())?;
    brdfprof::compare::refuse_repeated_reports(&args.files, "a report given twice would draw its sections twice")?;
    let inputs = args.files.iter().map(|f| report_page::load(f)).collect::<Result<Vec<_>>>()?;
    let gpu = if args.no_gpu { None } else { Some(args.device.open()?) };
    let bytes = report_page::write(&inputs, &args.out, gpu.as_ref())?;
    if let Some(gpu) = &gpu {
        gpu.check_validation()?;
    }
    println!("{} ({bytes} bytes) from {} report(s)", args.out.display(), inputs.len());
    Ok(ExitCode::SUCCESS)
}
