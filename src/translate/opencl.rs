//! The OpenCL C translation run through an OpenCL runtime: PoCL on this CPU by default (`--device opencl`),
//! so that the OpenCL dialect is executed, not only compiled, and a second implementation checks the same
//! translation's maths. The runtime is loaded at run time (`opencl3`'s dynamic loader: libOpenCL.so.1, the
//! ICD loader that Debian's ocl-icd-libopencl1 ships).

use super::{Dialect, Translation};
use crate::brdf::Sample;
use crate::kernels::EvalExtras;
use anyhow::{Context as _, Result, bail};

/// The platform `--device opencl` takes unless BRDFPROF_OPENCL_DEVICE names another (a substring of the
/// platform or device name).
pub const DEFAULT_PLATFORM: &str = "Portable Computing Language";

/// Build options: OpenCL C 1.2 (the precision freedom is in the prelude's native_ functions).
pub fn build_options(precise: bool) -> String {
    let mut o = String::from("-cl-std=CL1.2");
    if precise {
        o += " -DBRDFPROF_PRECISE";
    }
    o
}

/// A translation for an OpenCL device: built and run in a child process (`runner`), so that a runtime's
/// crash, an endless kernel or a build past the compile limit ends that child with a message.
pub struct ClKernel {
    dir: crate::cleanup::TempDir,
    options: String,
    wanted: String,
    local_size: [u32; 3],
    bindings: usize,
    device: std::sync::Mutex<String>,
}

impl ClKernel {
    pub fn build(t: &Translation, precise: bool) -> Result<Self> {
        let wanted = std::env::var("BRDFPROF_OPENCL_DEVICE")
            .ok()
            .filter(|s| !s.is_empty())
            .unwrap_or_else(|| DEFAULT_PLATFORM.into());
        let dir =
            crate::cleanup::TempDir::new().context("cannot create a temporary directory for the OpenCL kernel")?;
        std::fs::write(dir.path().join("kernel.cl"), t.source(Dialect::OpenCl))
            .context("cannot write the OpenCL source")?;
        Ok(ClKernel {
            dir,
            options: format!("{} -DBRDFPROF_EXECUTED", build_options(precise)),
            wanted: wanted.clone(),
            local_size: t.local_size,
            bindings: t.bindings.len(),
            device: std::sync::Mutex::new(wanted),
        })
    }

    /// The device of the last run (before one: the platform asked for).
    pub fn device(&self) -> String {
        self.device.lock().unwrap_or_else(|e| e.into_inner()).clone()
    }

    /// Builds the program and runs `groups` workgroups over `buffers` (the translation's binding order, push
    /// constants last), every buffer copied back.
    pub fn run(&self, buffers: &mut [&mut [u8]], groups: [u32; 3]) -> Result<()> {
        if buffers.len() != self.bindings {
            bail!("the OpenCL kernel takes {} bindings, {} given", self.bindings, buffers.len());
        }
        let engine = super::runner::Engine::OpenCl {
            source: self.dir.path().join("kernel.cl"),
            options: self.options.clone(),
            wanted: self.wanted.clone(),
        };
        let ran = super::runner::run(
            engine,
            self.local_size,
            buffers,
            groups,
            "the OpenCL C translation (built and run on OpenCL)",
        )?;
        *self.device.lock().unwrap_or_else(|e| e.into_inner()) = ran.device;
        Ok(())
    }
}

/// f_s of the translated eval kernel on the OpenCL device for every sample (as `kernels::eval_with`).
pub fn eval(kernel: &ClKernel, samples: &[Sample], extras: &EvalExtras) -> Result<Vec<[f32; 3]>> {
    let mut input = crate::kernels::pack_samples(samples, extras);
    let mut output = vec![0u8; samples.len() * 16];
    let mut push = (samples.len() as u32).to_ne_bytes().to_vec();
    let groups = (samples.len() as u32).div_ceil(kernel.local_size[0].max(1));
    kernel.run(&mut [&mut input, &mut output, &mut push], [groups, 1, 1])?;
    let floats: Vec<f32> = bytemuck::pod_collect_to_vec(&output);
    Ok(floats.chunks_exact(4).map(|c| [c[0], c[1], c[2]]).collect())
}
