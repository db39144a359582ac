//! The hidden commands: the child processes brdfprof starts of itself (callgrind, Mesa's noop drivers, a
//! translated kernel's runner, the Vulkan probe) and the GLSL generator `make spv` runs.

use super::Run;
use anyhow::{Context, Result};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

/// `__callgrind-child REQUEST`: each kernel measured under valgrind's callgrind (`inspect::callgrind`).
#[derive(clap::Args)]
pub struct CallgrindChild {
    request: String,
}

/// `__noop-child REQUEST`: every kernel compiled by a Mesa driver on its noop drm-shim (`targets::mesa_noop`).
#[derive(clap::Args)]
pub struct NoopChild {
    request: String,
}

/// `__run-translation DIR`: a translated kernel run (g++ build or PoCL) outside brdfprof's process
/// (`translate::runner`).
#[derive(clap::Args)]
pub struct RunTranslation {
    dir: String,
}

/// `__probe-vulkan`: the devices enumerated, where RADV might abort the process (`targets::radv::env`).
#[derive(clap::Args)]
pub struct ProbeVulkan {}

/// `__generate-glsl [DIR]`: writes glsl/generated/ (`make spv`).
#[derive(clap::Args)]
pub struct GenerateGlsl {
    #[arg(default_value = "glsl/generated")]
    dir: PathBuf,
}

/// `__man DIR` (run from main.rs, which has the whole command line to render: `man`).
#[derive(clap::Args)]
pub struct Man {
    pub dir: PathBuf,
}

impl Run for CallgrindChild {
    fn run(&self) -> Result<ExitCode> {
        brdfprof::inspect::callgrind::child_main(&self.request).map(|_| ExitCode::SUCCESS)
    }
    fn child(&self) -> bool {
        true
    }
}

impl Run for NoopChild {
    fn run(&self) -> Result<ExitCode> {
        brdfprof::targets::mesa_noop::child::child_main(&self.request).map(|_| ExitCode::SUCCESS)
    }
    fn child(&self) -> bool {
        true
    }
}

impl Run for RunTranslation {
    fn run(&self) -> Result<ExitCode> {
        brdfprof::translate::runner::child_main(&self.dir).map(|_| ExitCode::SUCCESS)
    }
    fn child(&self) -> bool {
        true
    }
}

impl Run for ProbeVulkan {
    fn run(&self) -> Result<ExitCode> {
        brdfprof::targets::radv::env::probe_main().map(|_| ExitCode::SUCCESS)
    }
    fn child(&self) -> bool {
        true
    }
}

impl Run for GenerateGlsl {
    fn run(&self) -> Result<ExitCode> {
        let dir = &self.dir;
        std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
        for (name, text) in brdfprof::kernels::generated_glsl() {
            let path = dir.join(name);
            brdfprof::io::write_output(&path, text.as_bytes())?;
            outln!("{}", path.display());
        }
        Ok(ExitCode::SUCCESS)
    }
}

/// `__man DIR`: brdfprof.1 and a page per command (`brdfprof-COMMAND.1`), from the same argument definitions
/// as `--help` (clap_mangen).
pub fn man(cmd: clap::Command, dir: &Path) -> Result<ExitCode> {
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    let mut pages = vec![("brdfprof.1".to_string(), cmd.clone())];
    for sub in cmd.get_subcommands().filter(|s| !s.is_hide_set()) {
        // clap names commands by &'static str; a page's name lives as long as the process, once.
        let name: &'static str = Box::leak(format!("brdfprof-{}", sub.get_name()).into_boxed_str());
        let named = sub.clone().name(name);
        pages.push((format!("brdfprof-{}.1", sub.get_name()), named));
    }
    for (name, page) in pages {
        let mut bytes = Vec::new();
        clap_mangen::Man::new(page).render(&mut bytes).with_context(|| format!("cannot render {name}"))?;
        brdfprof::io::write_output(&dir.join(&name), &bytes)?;
    }
    Ok(ExitCode::SUCCESS)
}
