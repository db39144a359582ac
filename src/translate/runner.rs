//! Translated kernels run in a child process (`brdfprof __run-translation DIR`), never in brdfprof's own: the
//! host build and the OpenCL program are a user's shader compiled by brdfprof, and a fault in them (an access
//! the translation does not guard, a runtime's own crash) must end that child with a message, not brdfprof
//! with SIGSEGV. The child runs under the compile limit, so an endless kernel or a slow OpenCL build stops
//! with exit 2 as a slow compiler does. Buffers travel as files in a temporary directory of the parent's,
//! removed with it (and by the signal handler).

use crate::cleanup;
use anyhow::{Context, Result, anyhow, bail};
use opencl3::command_queue::CommandQueue;
use opencl3::context::Context as ClContext;
use opencl3::device::{CL_DEVICE_TYPE_ALL, Device};
use opencl3::kernel::{ExecuteKernel, Kernel};
use opencl3::memory::{Buffer, CL_MEM_COPY_HOST_PTR, CL_MEM_READ_WRITE, ClMem};
use opencl3::program::Program;
use opencl3::types::CL_BLOCKING;
use serde::{Deserialize, Serialize};
use std::ffi::c_void;
use std::path::{Path, PathBuf};

/// The hidden subcommand of the child.
pub const CHILD_COMMAND: &str = "__run-translation";

/// What the child runs.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub enum Engine {
    /// The host build (`host::HostKernel`): a shared library with `brdfprof_host_run`.
    Host { library: PathBuf },
    /// The OpenCL C translation, built and run on the first OpenCL device whose platform or name contains
    /// `wanted`.
    OpenCl { source: PathBuf, options: String, wanted: String },
}

#[derive(Serialize, Deserialize)]
struct Request {
    engine: Engine,
    local_size: [u32; 3],
    groups: [u32; 3],
    /// Byte lengths of the buffers `in-K.bin`, in the translation's binding order, push constants last.
    buffers: Vec<usize>,
}

/// What the child answers on its last stdout line.
#[derive(Serialize, Deserialize)]
struct Reply {
    /// The invocations' flags (bit 0: one stopped at the loop limit).
    flags: u32,
    /// The device it ran on ("host" for the host build).
    device: String,
    /// Loop headers passed, over every invocation (the host build counts them; 0 elsewhere).
    #[serde(default)]
    loop_passes: u64,
}

/// What a run returned besides the buffers.
#[derive(Debug)]
pub struct Ran {
    pub flags: u32,
    pub device: String,
    pub loop_passes: u64,
}

/// Runs `engine` over `buffers` (copied back in place) in a child, `what` naming the kernel in messages.
pub fn run(
    engine: Engine,
    local_size: [u32; 3],
    buffers: &mut [&mut [u8]],
    groups: [u32; 3],
    what: &str,
) -> Result<Ran> {
    let dir = cleanup::TempDir::new().context("cannot create a temporary directory for a translated kernel's run")?;
    for (k, b) in buffers.iter().enumerate() {
        let path = dir.path().join(format!("in-{k}.bin"));
        std::fs::write(&path, &**b).with_context(|| format!("cannot write {}", path.display()))?;
    }
    let request = Request { engine, local_size, groups, buffers: buffers.iter().map(|b| b.len()).collect() };
    std::fs::write(dir.path().join("request.json"), serde_json::to_vec(&request)?)
        .context("cannot write a translated kernel's request")?;
    let mut cmd = cleanup::self_command(CHILD_COMMAND)?;
    // PoCL's kernel cache too: it leaves empty `tempfile_*` behind in it on every build, which would pile up
    // in the user's ~/.cache/pocl; in the run's directory they go with it.
    cmd.arg(dir.path()).env("TMPDIR", dir.path()).env("POCL_CACHE_DIR", dir.path().join("pocl"));
    crate::launch::export(&mut cmd);
    let out = crate::launch::output(&mut cmd, what).with_context(|| format!("{what}: cannot run the child process"))?;
    if !out.status.success() {
        bail!(failure(what, &out));
    }
    let stdout = String::from_utf8_lossy(&out.stdout);
    let reply: Reply = stdout
        .lines()
        .rev()
        .find_map(|l| serde_json::from_str(l).ok())
        .ok_or_else(|| anyhow!("{what}: the child process answered no report"))?;
    for (k, b) in buffers.iter_mut().enumerate() {
        let path = dir.path().join(format!("out-{k}.bin"));
        let bytes = crate::io::read_bounded(&path, b.len() as u64)
            .with_context(|| format!("{what}: the child's buffer {k}"))?;
        if bytes.len() != b.len() {
            bail!("{what}: the child wrote {} bytes of buffer {k}, {} expected", bytes.len(), b.len());
        }
        b.copy_from_slice(&bytes);
    }
    Ok(Ran { flags: reply.flags, device: reply.device, loop_passes: reply.loop_passes })
}

/// The message of a child that failed: a fault by its signal, an error by the child's own words.
fn failure(what: &str, out: &std::process::Output) -> String {
    use std::os::unix::process::ExitStatusExt;
    let stderr = String::from_utf8_lossy(&out.stderr);
    if let Some(signal) = out.status.signal() {
        return format!(
            "{what}: the kernel crashed the child process that ran it ({}): the translated code reached outside its memory or the runtime failed; this is a translator defect, please report it with the model",
            signal_name(signal)
        );
    }
    let said: Vec<&str> = stderr.lines().filter(|l| !l.trim().is_empty()).collect();
    let tail = said
        .iter()
        .rev()
        .take(20)
        .rev()
        .map(|l| l.strip_prefix("brdfprof: error: ").unwrap_or(l))
        .collect::<Vec<_>>()
        .join("\n");
    format!("{what}: {}", if tail.is_empty() { format!("the child process failed ({})", out.status) } else { tail })
}

fn signal_name(signal: i32) -> String {
    let name = match signal {
        libc::SIGSEGV => "SIGSEGV",
        libc::SIGBUS => "SIGBUS",
        libc::SIGFPE => "SIGFPE",
        libc::SIGILL => "SIGILL",
        libc::SIGABRT => "SIGABRT",
        libc::SIGKILL => "SIGKILL",
        _ => "",
    };
    if name.is_empty() { format!("signal {signal}") } else { format!("signal {signal}, {name}") }
}

/// The child: reads `DIR/request.json` and the buffers, runs the engine, writes `out-K.bin` and its reply.
pub fn child_main(dir: &str) -> Result<()> {
    let dir = Path::new(dir);
    let request: Request = serde_json::from_slice(
        &crate::io::read_bounded(&dir.join("request.json"), 1 << 20).context("cannot read the request")?,
    )?;
    let mut owned = Vec::new();
    for (k, &len) in request.buffers.iter().enumerate() {
        let bytes = crate::io::read_bounded(&dir.join(format!("in-{k}.bin")), len as u64)?;
        if bytes.len() != len {
            bail!("buffer {k} holds {} bytes, {len} expected", bytes.len());
        }
        owned.push(bytes);
    }
    let mut buffers: Vec<&mut [u8]> = owned.iter_mut().map(Vec::as_mut_slice).collect();
    let reply = match &request.engine {
        Engine::Host { library } => {
            let (flags, loop_passes) = run_host(library, &mut buffers, request.groups)?;
            Reply { flags, device: "host".into(), loop_passes }
        }
        Engine::OpenCl { source, options, wanted } => {
            let text = String::from_utf8_lossy(
                &crate::io::read_bounded(source, crate::io::MAX_INPUT_BYTES)
                    .context("cannot read the OpenCL source")?,
            )
            .into_owned();
            let device = run_opencl(&text, options, wanted, request.local_size, &mut buffers, request.groups)?;
            Reply { flags: 0, device, loop_passes: 0 }
        }
    };
    for (k, b) in owned.iter().enumerate() {
        std::fs::write(dir.join(format!("out-{k}.bin")), b).with_context(|| format!("cannot write buffer {k}"))?;
    }
    println!("{}", serde_json::to_string(&reply)?);
    Ok(())
}

fn no_runtime(e: impl std::fmt::Display) -> anyhow::Error {
    anyhow!(
        "no OpenCL runtime ({e}): install PoCL and the ICD loader (Debian: apt-get install pocl-opencl-icd ocl-icd-libopencl1), or run `make setup`"
    )
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
    bail!(
        "no OpenCL device matches `{wanted}` (devices: {}); install PoCL (apt-get install pocl-opencl-icd) or set BRDFPROF_OPENCL_DEVICE",
        if seen.is_empty() { "none".into() } else { seen.join(", ") }
    )
}

/// The child's half of `opencl::ClKernel::run`: builds `source` on the device `wanted` names and runs it over
/// `buffers`; returns the device's name.
fn run_opencl(
    source: &str,
    options: &str,
    wanted: &str,
    local_size: [u32; 3],
    buffers: &mut [&mut [u8]],
    groups: [u32; 3],
) -> Result<String> {
    let (dev, name) = device(wanted)?;
    let context = ClContext::from_device(&dev).map_err(|e| anyhow!("{name}: cannot create an OpenCL context ({e})"))?;
    #[allow(deprecated)]
    let queue =
        CommandQueue::create_default(&context, 0).map_err(|e| anyhow!("{name}: cannot create a queue ({e})"))?;
    let program = Program::create_and_build_from_source(&context, source, options).map_err(|log| {
        anyhow!(
            "{name} cannot build the OpenCL C translation (a translator defect):\n{}",
            log.lines().take(20).collect::<Vec<_>>().join("\n")
        )
    })?;
    let kernel =
        Kernel::create(&program, "brdfprof_kernel").map_err(|e| anyhow!("{name}: no brdfprof_kernel ({e})"))?;
    // SAFETY: each buffer is created from (and read back into) a live host slice of its own size; the
    // kernel's arguments are these buffers in its parameter order.
    unsafe {
        let device_buffers = buffers
            .iter_mut()
            .map(|b| {
                Buffer::<u8>::create(
                    &context,
                    CL_MEM_READ_WRITE | CL_MEM_COPY_HOST_PTR,
                    b.len().max(1),
                    b.as_mut_ptr() as *mut c_void,
                )
            })
            .collect::<Result<Vec<_>, _>>()
            .map_err(|e| anyhow!("{name}: cannot create buffers ({e})"))?;
        let mut exec = ExecuteKernel::new(&kernel);
        for b in &device_buffers {
            exec.set_arg(&b.get());
        }
        let global: Vec<usize> = (0..3).map(|k| (groups[k] * local_size[k]) as usize).collect();
        let local: Vec<usize> = local_size.iter().map(|&l| l as usize).collect();
        exec.set_global_work_sizes(&global)
            .set_local_work_sizes(&local)
            .enqueue_nd_range(&queue)
            .map_err(|e| anyhow!("{name}: cannot run the kernel ({e})"))?;
        for (b, host) in device_buffers.iter().zip(buffers.iter_mut()) {
            queue
                .enqueue_read_buffer(b, CL_BLOCKING, 0, host, &[])
                .map_err(|e| anyhow!("{name}: cannot read a buffer back ({e})"))?;
        }
        queue.finish().context("clFinish")?;
    }
    Ok(name)
}

type RunFn = unsafe extern "C" fn(*const *mut u8, u32, u32, u32, *mut u64) -> u32;

/// The child's half of `host::HostKernel::run`: loads `library` and runs its kernel over `buffers`.
/// The invocations' flags and the loop headers they passed.
fn run_host(library: &std::path::Path, buffers: &mut [&mut [u8]], groups: [u32; 3]) -> Result<(u32, u64)> {
    // SAFETY: the library is the one `HostKernel::compile` built from the translation; loading runs no
    // constructors of ours (the prelude defines none).
    let lib =
        unsafe { libloading::Library::new(library) }.with_context(|| format!("cannot load {}", library.display()))?;
    let pointers: Vec<*mut u8> = buffers.iter_mut().map(|b| b.as_mut_ptr()).collect();
    // SAFETY: `brdfprof_host_run` is the wrapper `entry::host_wrapper` writes, with this signature; every
    // pointer is a live buffer of the size the kernel's own bounds (its push-constant count) allow. A fault
    // ends this child process only.
    unsafe {
        let run: libloading::Symbol<RunFn> =
            lib.get(b"brdfprof_host_run\0").context("the host build has no brdfprof_host_run")?;
        let mut loop_passes = 0u64;
        let flags = run(pointers.as_ptr(), groups[0], groups[1], groups[2], &mut loop_passes);
        Ok((flags, loop_passes))
    }
}
