//! `brdfprof render`: a scene rendered per model, with the comparison grid, difference maps and lobes.

use super::args::DeviceArgs;
use super::{on_device, written};
use anyhow::Result;
use brdfprof::{io, scene};
use clap::Args;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Args)]
pub struct RenderArgs {
    #[arg(long)]
    pub scene: PathBuf,
    #[arg(long)]
    pub out: Option<PathBuf>,
    #[command(flatten)]
    pub device: DeviceArgs,
}

impl super::Run for RenderArgs {
    fn run(&self) -> Result<ExitCode> {
        render(self)
    }
}

pub fn render(args: &RenderArgs) -> Result<ExitCode> {
    let scene = scene::Scene::load(&args.scene)?;
    let out = args.out.clone().unwrap_or_else(|| PathBuf::from("results/scenes").join(scene.name()));
    io::check_output_dir(
        if args.out.is_some() { "--out" } else { "--out (default results/scenes/<scene name>)" },
        &out,
    )?;
    if args.out.is_none() {
        io::refuse_tracked_default("--out", &out, &["*".to_string()])?;
    }
    let (_, result) = on_device(&args.device, |gpu, progress| scene::render::render(gpu, &scene, &out, progress))?;
    for n in &result.notes {
        brdfprof::messages::note(n);
    }
    for w in &result.warnings {
        brdfprof::messages::warning(w);
    }
    outln!("{}", written(&result.files));
    Ok(ExitCode::SUCCESS)
}
