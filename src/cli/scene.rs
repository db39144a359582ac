//! `brdfprof scene`: a scene file checked, or the scene format explained (`render` draws a scene, `profile
//! --scene` times it).

use anyhow::{Result, bail};
use brdfprof::scene;
use clap::Args;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Args)]
pub struct SceneArgs {
    /// Scene file to check.
    pub file: Option<PathBuf>,
    #[arg(long)]
    pub explain: bool,
}

impl super::Run for SceneArgs {
    fn run(&self) -> Result<ExitCode> {
        scene(self)
    }
}

pub fn scene(args: &SceneArgs) -> Result<ExitCode> {
    match (&args.file, args.explain) {
        (_, true) => out!("{}", scene::explain()),
        (Some(f), false) => out!("{}", scene::check(f)?),
        (None, false) => bail!("give a scene file to check, or --explain"),
    }
    Ok(ExitCode::SUCCESS)
}
