//! The translation run on the CPU: its CUDA C++ text compiled by g++ (with the host prelude) into a shared
//! library, loaded, and every invocation of a dispatch run in order, over the same bytes the Vulkan kernel
//! reads and writes.

use super::{BindingKind, Dialect, Translation};
use crate::brdf::Sample;
use crate::kernels::EvalExtras;
use anyhow::{Context, Result, anyhow, bail};

/// The host compiler and its flags: precise maths (no -ffast-math), no FMA contraction beyond what the
/// source writes.
pub const HOST_COMPILER: &str = "g++";
pub const HOST_FLAGS: [&str; 6] =
    ["-std=c++17", "-O2", "-fPIC", "-shared", "-ffp-contract=off", "-fno-strict-aliasing"];

/// The f64 reference's optimisation level, after HOST_FLAGS': its builds are the check's cold cost (g++ -O2
/// took 2.8 s for the 8-light profiling kernel's reference on a 2-core AMD EPYC VM, -O0 0.5 s) and it runs a few
/// thousand invocations; IEEE double arithmetic without contraction is the same at every level.
pub const REFERENCE_FLAGS: [&str; 1] = ["-O0"];

/// What a host build depends on besides the source, for cache keys: the compiler's version line and the flags
/// (another g++ may round the maths libraries differently).
pub fn build_identity() -> String {
    static IDENTITY: std::sync::OnceLock<String> = std::sync::OnceLock::new();
    IDENTITY
        .get_or_init(|| {
            let out =
                crate::launch::output_quick(crate::cleanup::command(HOST_COMPILER).arg("--version"), "g++ --version");
            let version = out
                .ok()
                .and_then(|o| String::from_utf8_lossy(&o.stdout).lines().next().map(str::to_string))
                .unwrap_or_else(|| format!("{HOST_COMPILER} (version unknown)"));
            format!("{version} {} (reference: {})", HOST_FLAGS.join(" "), REFERENCE_FLAGS.join(" "))
        })
        .clone()
}

/// A translation compiled for the host; it runs in a child process (`runner`).
pub struct HostKernel {
    library: std::path::PathBuf,
    _dir: crate::cleanup::TempDir,
    bindings: Vec<BindingKind>,
    local_size: [u32; 3],
}

impl HostKernel {
    pub fn compile(t: &Translation) -> Result<Self> {
        Self::compile_with(t, &[])
    }

    /// `compile` with preprocessor definitions (`-DNAME`) for the prelude's variants.
    pub fn compile_with(t: &Translation, defines: &[&str]) -> Result<Self> {
        Self::build(t, &t.source(Dialect::Host), defines, &[])
    }

    /// `compile` with further compiler flags (`-ftrivial-auto-var-init=zero`).
    pub fn compile_with_flags(t: &Translation, flags: &[&str]) -> Result<Self> {
        Self::build(t, &t.source(Dialect::Host), &[], flags)
    }

    /// `compile` and `compile_reference(t, &[])`, built side by side (two g++ processes: the check's cold
    /// cost is mostly these builds).
    pub fn compile_with_reference(t: &Translation) -> Result<(Self, Self)> {
        let (fp32, reference) = rayon::join(|| Self::compile(t), || Self::compile_reference(t, &[]));
        Ok((fp32?, reference?))
    }

    /// The f64 reference of `t` (`Translation::reference_source`): every f32 value computed in double with its
    /// Vulkan precision bound; a writable binding takes 4 x its bytes (`eval_reference`).
    pub fn compile_reference(t: &Translation, defines: &[&str]) -> Result<Self> {
        Self::build(t, &t.reference_source(), defines, &REFERENCE_FLAGS)
    }

    fn build(t: &Translation, source: &str, defines: &[&str], flags: &[&str]) -> Result<Self> {
        let dir = crate::cleanup::TempDir::new().context("cannot create a temporary directory for the host build")?;
        let src = dir.path().join("kernel.cpp");
        let lib = dir.path().join("kernel.so");
        std::fs::write(&src, source).with_context(|| format!("cannot write {}", src.display()))?;
        let mut cmd = crate::cleanup::command(HOST_COMPILER);
        crate::launch::bound_memory(&mut cmd)?;
        // g++'s own temporaries (cc*.s) go into the build's directory, removed with it even on a signal.
        cmd.args(HOST_FLAGS)
            .args(flags)
            .args(defines.iter().map(|d| format!("-D{d}")))
            .arg("-o")
            .arg(&lib)
            .arg(&src)
            .env("TMPDIR", dir.path());
        let out = crate::launch::output(&mut cmd, "the host build of the translation (g++)").map_err(|e| {
            if e.downcast_ref::<std::io::Error>().is_some() {
                anyhow!(
                    "cannot run {HOST_COMPILER} ({e}): install g++ (Debian: apt-get install g++), or run `make setup`"
                )
            } else {
                e
            }
        })?;
        if !out.status.success() {
            let log = String::from_utf8_lossy(&out.stderr);
            let head: Vec<&str> = log.lines().take(20).collect();
            bail!("{HOST_COMPILER} cannot compile the host translation (a translator defect):\n{}", head.join("\n"));
        }
        if !lib.is_file() {
            bail!("{HOST_COMPILER} exited 0 but wrote no {}", lib.display());
        }
        Ok(HostKernel {
            library: lib,
            _dir: dir,
            bindings: t.bindings.iter().map(|b| b.kind.clone()).collect(),
            local_size: t.local_size,
        })
    }

    /// Runs `groups` workgroups over `buffers` (one per binding, in the translation's binding order, push
    /// constants last) in a child process; returns the invocations' flags (1: one stopped at the host's loop
    /// limit).
    pub fn run(&self, buffers: &mut [&mut [u8]], groups: [u32; 3]) -> Result<u32> {
        Ok(self.run_counted(buffers, groups)?.0)
    }

    /// `run`, with the loop headers every invocation passed, summed.
    pub fn run_counted(&self, buffers: &mut [&mut [u8]], groups: [u32; 3]) -> Result<(u32, u64)> {
        if buffers.len() != self.bindings.len() {
            bail!("the host kernel takes {} bindings, {} given", self.bindings.len(), buffers.len());
        }
        let engine = super::runner::Engine::Host { library: self.library.clone() };
        let ran = super::runner::run(engine, self.local_size, buffers, groups, "the translated kernel on the host")?;
        Ok((ran.flags, ran.loop_passes))
    }

    pub fn local_size(&self) -> [u32; 3] {
        self.local_size
    }
}

/// Runs the translated eval kernel over `samples` with `value_bytes` of output per sample; its output and the
/// loop headers its invocations passed. `what` names the build in the loop-limit error.
fn run_eval(
    kernel: &HostKernel,
    samples: &[Sample],
    extras: &EvalExtras,
    value_bytes: usize,
    what: &str,
) -> Result<(Vec<u8>, u64)> {
    let mut input = crate::kernels::pack_samples(samples, extras);
    let mut output = vec![0u8; samples.len() * value_bytes];
    let mut push = (samples.len() as u32).to_ne_bytes().to_vec();
    let groups = (samples.len() as u32).div_ceil(kernel.local_size[0].max(1));
    let (flags, passes) = kernel.run_counted(&mut [&mut input, &mut output, &mut push], [groups, 1, 1])?;
    if flags & 1 != 0 {
        bail!("{what} stopped an evaluation at its loop limit (2^20 iterations)");
    }
    Ok((output, passes))
}

/// f_s of the translated eval kernel on the host for every sample (as `kernels::eval_with` on a device).
pub fn eval(kernel: &HostKernel, samples: &[Sample], extras: &EvalExtras) -> Result<Vec<[f32; 3]>> {
    let (output, _) = run_eval(kernel, samples, extras, 16, "the host run")?;
    let floats: Vec<f32> = bytemuck::pod_collect_to_vec(&output);
    Ok(floats.chunks_exact(4).map(|c| [c[0], c[1], c[2]]).collect())
}

/// Loop headers the translated eval kernel passes per evaluation over `samples` (every pass: each iteration's
/// and the exit test's): how often the kernel's loops run, which no compiler's listing states.
pub fn loop_passes(kernel: &HostKernel, samples: &[Sample], extras: &EvalExtras) -> Result<f64> {
    let (_, passes) = run_eval(kernel, samples, extras, 16, "the host run")?;
    Ok(passes as f64 / samples.len().max(1) as f64)
}

/// One value of the f64 reference: the kernel's own operations in double, and the bound the Vulkan precision
/// rules of those operations put on an implementation's distance from it (infinite: no bound).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bounded {
    pub value: f64,
    pub bound: f64,
}

/// The (value, bound) pairs of a reference kernel's output bytes (`HostKernel::compile_reference`'s layout: 16
/// bytes a value).
pub fn pairs(bytes: &[u8]) -> Vec<Bounded> {
    let doubles: Vec<f64> = bytemuck::pod_collect_to_vec(bytes);
    doubles.chunks_exact(2).map(|p| Bounded { value: p[0], bound: p[1] }).collect()
}

/// f_s of the translated eval kernel's f64 reference for every sample (`eval` in double, with bounds).
pub fn eval_reference(kernel: &HostKernel, samples: &[Sample], extras: &EvalExtras) -> Result<Vec<[Bounded; 3]>> {
    let (output, _) = run_eval(kernel, samples, extras, 16 * 4, "the f64 reference")?;
    Ok(pairs(&output).chunks_exact(4).map(|c| [c[0], c[1], c[2]]).collect())
}
