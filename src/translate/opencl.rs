//! The OpenCL C translation run through an OpenCL runtime: PoCL on this CPU by default (`--device opencl`),
//! so that the OpenCL dialect is executed, not only compiled, and a second implementation checks the same
//! translation's maths. The runtime is loaded at run time (`opencl3`'s dynamic loader: libOpenCL.so.1, the
//! ICD loader that Debian's ocl-icd-libopencl1 ships).

use super::{Dialect, Translation};
use crate::brdf::Sample;
use crate::kernels::EvalExtras;
use anyhow::{anyhow, bail, Context as _, Result};
use opencl3::command_queue::CommandQueue;
use opencl3::context::Context;
use opencl3::device::{Device, CL_DEVICE_TYPE_ALL};
use opencl3::kernel::{ExecuteKernel, Kernel};
use opencl3::memory::{Buffer, ClMem, CL_MEM_COPY_HOST_PTR, CL_MEM_READ_WRITE};
use opencl3::program::Program;
use opencl3::types::CL_BLOCKING;
use std::ffi::c_void;

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

fn no_runtime(e: impl std::fmt::Display) -> anyhow::Error {
    anyhow!("no OpenCL runtime ({e}): install PoCL and the ICD loader (Debian: apt-get install pocl-opencl-icd ocl-icd-libopencl1), or run `make setup`")
}

/// The OpenCL device: the first one whose platform or name contains `wanted`.
fn device(wanted: &str) -> Result<(Device, String)> {
    let platforms = opencl3::platform::get_platforms().map_err(no_runtime)?;
    let mut seen = Vec::new();
    for p in &platforms {
        let pname = p.name().unwrap_or_default();
        for id in p.get_devices(CL_DEVICE_TYPE_ALL).unwrap_or_default() {
            let d = Device::new(id);
            let dname = d.name().unwrap_or_default();
            if pname.contains(wanted) || dname.contains(wanted) {
                return Ok((d, format!("{dname} ({pname})")));
            }
            seen.push(format!("{dname} ({pname})"));
        }
    }
    bail!("no OpenCL device matches `{wanted}` (devices: {}); install PoCL (apt-get install pocl-opencl-icd) or set BRDFPROF_OPENCL_DEVICE", if seen.is_empty() { "none".into() } else { seen.join(", ") })
}

/// A translation built for an OpenCL device.
pub struct ClKernel {
    // Field order: the kernel and program before the queue and context they belong to.
    kernel: Kernel,
    _program: Program,
    queue: CommandQueue,
    context: Context,
    pub device: String,
    local_size: [u32; 3],
    bindings: usize,
}

impl ClKernel {
    pub fn build(t: &Translation, precise: bool) -> Result<Self> {
        let wanted = std::env::var("BRDFPROF_OPENCL_DEVICE").ok().filter(|s| !s.is_empty()).unwrap_or_else(|| DEFAULT_PLATFORM.into());
        let (dev, name) = device(&wanted)?;
        let context = Context::from_device(&dev).map_err(|e| anyhow!("{name}: cannot create an OpenCL context ({e})"))?;
        #[allow(deprecated)]
        let queue = CommandQueue::create_default(&context, 0).map_err(|e| anyhow!("{name}: cannot create a queue ({e})"))?;
        let program = Program::create_and_build_from_source(&context, &t.source(Dialect::OpenCl), &build_options(precise))
            .map_err(|log| anyhow!("{name} cannot build the OpenCL C translation (a translator defect):\n{}", log.lines().take(20).collect::<Vec<_>>().join("\n")))?;
        let kernel = Kernel::create(&program, "brdfprof_kernel").map_err(|e| anyhow!("{name}: no brdfprof_kernel ({e})"))?;
        Ok(ClKernel { kernel, _program: program, queue, context, device: name, local_size: t.local_size, bindings: t.bindings.len() })
    }

    /// Runs `groups` workgroups over `buffers` (the translation's binding order, push constants last) and
    /// copies every buffer back.
    pub fn run(&self, buffers: &mut [&mut [u8]], groups: [u32; 3]) -> Result<()> {
        if buffers.len() != self.bindings {
            bail!("the OpenCL kernel takes {} bindings, {} given", self.bindings, buffers.len());
        }
        // SAFETY: each buffer is created from (and read back into) a live host slice of its own size; the
        // kernel's arguments are these buffers in its parameter order.
        unsafe {
            let device_buffers = buffers
                .iter_mut()
                .map(|b| Buffer::<u8>::create(&self.context, CL_MEM_READ_WRITE | CL_MEM_COPY_HOST_PTR, b.len().max(1), b.as_mut_ptr() as *mut c_void))
                .collect::<Result<Vec<_>, _>>()
                .map_err(|e| anyhow!("{}: cannot create buffers ({e})", self.device))?;
            let mut exec = ExecuteKernel::new(&self.kernel);
            for b in &device_buffers {
                exec.set_arg(&b.get());
            }
            let global: Vec<usize> = (0..3).map(|k| (groups[k] * self.local_size[k]) as usize).collect();
            let local: Vec<usize> = self.local_size.iter().map(|&l| l as usize).collect();
            exec.set_global_work_sizes(&global).set_local_work_sizes(&local).enqueue_nd_range(&self.queue).map_err(|e| anyhow!("{}: cannot run the kernel ({e})", self.device))?;
            for (b, host) in device_buffers.iter().zip(buffers.iter_mut()) {
                self.queue.enqueue_read_buffer(b, CL_BLOCKING, 0, host, &[]).map_err(|e| anyhow!("{}: cannot read a buffer back ({e})", self.device))?;
            }
            self.queue.finish().context("clFinish")?;
        }
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
