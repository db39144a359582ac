//! `brdfprof stability`: the hard-case catalogue, dense grids, reciprocity and energy checks on the GPU.

use super::args::{DeviceArgs, HtmlArg, ModelArgs, cosine_range, reference_spec, roughness_range};
use super::{checked_outputs, just_measured, model_inputs, on_device, out_dir, written};
use anyhow::Result;
use brdfprof::model::Model;
use brdfprof::stability;
use clap::Args;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Args)]
pub struct StabilityArgs {
    #[command(flatten)]
    pub model: ModelArgs,
    /// Skip the directional-albedo (energy) part.
    #[arg(long)]
    pub no_energy: bool,
    /// Also check each spec without brdfprof's guards (`guards=off`, docs/guards.md) and with each guard off
    /// alone (`guards=off:NAME`), listed next to it: the hard cases it then fails are the ones its guards save
    /// (the report's "What each guard saves").
    #[arg(long)]
    pub unguarded: bool,
    /// Check the models that have no f64 twin (`.brdf` files) against this built-in spec's f64 values: their
    /// tolerances and jumps then mean what a built-in spec's do (e.g. `--reference ggx`).
    #[arg(long, value_parser = reference_spec)]
    pub reference: Option<brdfprof::brdf::ModelSpec>,
    /// Perceptual roughness range checked, MIN..MAX within [0, 1]: hard cases and grid points outside it are
    /// not counted (default: each `.brdf` file's `domain roughness`, else all).
    #[arg(long, value_parser = roughness_range)]
    pub roughness: Option<(f64, f64)>,
    /// N.V range checked, MIN..MAX within [0, 1] (default: each `.brdf` file's `domain nov`, else all).
    #[arg(long, value_parser = cosine_range)]
    pub nov: Option<(f64, f64)>,
    /// N.L range checked, MIN..MAX within [0, 1] (default: each `.brdf` file's `domain nol`, else all).
    #[arg(long, value_parser = cosine_range)]
    pub nol: Option<(f64, f64)>,
    /// Directory for stability-<device>.md/.json and the furnace, albedo and failure PNGs (default results/,
    /// refused where that would overwrite a file git tracks).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Also write the JSON report to FILE (as the other commands' `--json`; --out still holds its copy).
    #[arg(long, value_name = "FILE")]
    pub json: Option<PathBuf>,
    /// Also write the Markdown report to FILE.
    #[arg(long, value_name = "FILE")]
    pub markdown: Option<PathBuf>,
    #[command(flatten)]
    pub html: HtmlArg,
    #[command(flatten)]
    pub device: DeviceArgs,
}

impl super::Run for StabilityArgs {
    fn run(&self) -> Result<ExitCode> {
        stability(self)
    }
}

pub fn stability(args: &StabilityArgs) -> Result<ExitCode> {
    let out = out_dir(args.out.as_deref(), &["stability-*", "furnace-*.png", "albedo-*.png"])?;
    let models = if args.model.models.is_empty() {
        stability::default_specs().into_iter().map(Model::spec).collect()
    } else {
        args.model.models(&[])?
    };
    let asked = [
        ("--json", args.json.as_deref()),
        ("--markdown", args.markdown.as_deref()),
        ("--html", args.html.html.as_deref()),
    ];
    let outs = checked_outputs(&asked, &model_inputs(&models))?;
    let options = stability::StabilityOptions {
        models: if args.unguarded { stability::with_guard_variants(models) } else { models },
        energy: !args.no_energy,
        reference: args.reference,
        roughness: args.roughness,
        nov: args.nov,
        nol: args.nol,
    };
    let (gpu, result) = on_device(&args.device, |gpu, progress| stability::run(gpu, &options, progress))?;
    let slug = brdfprof::targets::device_slug(&gpu.info);
    let mut files = result.write(&out, &slug)?;
    for (flag, path) in &outs {
        match *flag {
            "--json" => {
                brdfprof::export::json::write_report_compact(path, brdfprof::export::json::Kind::Stability, &result)?
            }
            "--markdown" => brdfprof::io::write_markdown(path, &result.markdown())?,
            _ => continue,
        }
        files.push(path.clone());
    }
    files.extend(args.html.write(&[just_measured(&out.join(format!("stability-{slug}.json")), &result)?], Some(&gpu))?);
    out!("{}", result.markdown());
    outln!("\n{}", written(&files));
    let failing = result.failing();
    if failing.is_empty() {
        return Ok(ExitCode::SUCCESS);
    }
    brdfprof::messages::progress(format!("{} spec(s) give NaN, Inf or negative values on valid inputs", failing.len()));
    Ok(ExitCode::from(1))
}
