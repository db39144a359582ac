//! Executed CPU instructions per BRDF evaluation of lavapipe's JIT-compiled kernels, under valgrind's
//! callgrind: a deterministic cost figure where wall time is noise.
//!
//! brdfprof runs itself under `valgrind --tool=callgrind` as children (`brdfprof __callgrind-child`), with
//! one compute thread (LP_NUM_THREADS=0) and Mesa's shader cache off. Instrumentation starts off; for each
//! kernel the child makes an untimed dispatch (llvmpipe JIT-compiles at the first dispatch), then turns
//! instrumentation on, zeroes the counters, dispatches again and dumps the counters under the kernel's
//! label, through callgrind's client requests. The JIT code has no symbol, so callgrind files it under
//! the object `???`: the anonymous functions that lavapipe's driver calls in each dump, and those they call,
//! are the kernel. Their exclusive Ir (instructions executed), divided by the evaluations of the dispatch,
//! is the figure. Everything else (the driver's dispatch and queue code, the per-workgroup helpers the
//! kernel calls back into) is left out.

use crate::cleanup;
use crate::gpu::{Gpu, GpuOptions};
use crate::kernels::shade::{GBufferFormat, kernel_hash};
use crate::measure::gbuffer;
use crate::measure::protocol::Timed;
use crate::measure::workload::{Variant, Workload};
use crate::model::Model;
use crate::schema::callgrind::{CallgrindRun, KernelIr};
use crate::shaders::Shaders;
use anyhow::{Context, Result, anyhow, bail};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The hidden subcommand the child runs.
pub const CHILD_COMMAND: &str = "__callgrind-child";
/// How many times the compile limit a compilation in the callgrind child may take (valgrind slows the JIT's
/// LLVM about this much; docs/limits.md).
pub const VALGRIND_SLOWDOWN: u32 = 20;
/// The object callgrind files code without symbols under (the JIT-compiled kernel).
const ANONYMOUS_OBJECT: &str = "???";
/// Prefix of each dump's label; the kernel's index follows.
const DUMP_LABEL: &str = "brdfprof-kernel-";

/// valgrind's client requests (valgrind.h, callgrind.h).
mod request {
    pub const RUNNING_ON_VALGRIND: usize = 0x1001;
    const CALLGRIND_BASE: usize = ((b'C' as usize) << 24) | ((b'T' as usize) << 16);
    pub const ZERO_STATS: usize = CALLGRIND_BASE + 1;
    pub const DUMP_STATS_AT: usize = CALLGRIND_BASE + 3;
    pub const START_INSTRUMENTATION: usize = CALLGRIND_BASE + 4;
    pub const STOP_INSTRUMENTATION: usize = CALLGRIND_BASE + 5;
}

/// Issues a valgrind client request; natively it does nothing and returns `default`.
#[cfg(target_arch = "x86_64")]
fn client_request(default: usize, code: usize, arg1: usize) -> usize {
    let block: [usize; 6] = [code, arg1, 0, 0, 0, 0];
    let mut result = default;
    // SAFETY: valgrind's documented amd64 "special instruction" sequence (valgrind.h). The four rotations of
    // rdi add up to 128 bits, so rdi is unchanged, and `xchg rbx, rbx` changes nothing: natively the sequence
    // is a no-op that leaves `result` at `default`. Under valgrind it performs the request described by the
    // six words at rax (which outlive the asm) and writes the result to rdx. Flags are clobbered (asm! assumes
    // so by default) and memory may be read (no `nomem`/`readonly`).
    unsafe {
        std::arch::asm!(
            "rol rdi, 3",
            "rol rdi, 13",
            "rol rdi, 61",
            "rol rdi, 51",
            "xchg rbx, rbx",
            in("rax") block.as_ptr(),
            inout("rdx") result,
            options(nostack),
        );
    }
    result
}

#[cfg(not(target_arch = "x86_64"))]
fn client_request(default: usize, _code: usize, _arg1: usize) -> usize {
    default
}

fn running_on_valgrind() -> bool {
    client_request(0, request::RUNNING_ON_VALGRIND, 0) > 0
}

/// What the parent asks the child to measure (passed as one JSON argument).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ChildRequest {
    /// Models by `Model::name` (label included, so the child labels them alike); the memory-only baseline kernel is measured after them
    /// where `baseline` says so.
    pub models: Vec<String>,
    #[serde(default = "measures_the_baseline")]
    pub baseline: bool,
    pub lights: u32,
    pub width: u32,
    pub height: u32,
    pub device: Option<String>,
    pub validate: bool,
    pub glsl: Option<PathBuf>,
}

/// What the child reports back on stdout.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ChildReply {
    /// Kernel labels in dump order (`DUMP_LABEL` + index).
    pub labels: Vec<String>,
    pub evaluations: u64,
    /// CPU features as the JIT sees them under valgrind (valgrind hides some, e.g. AVX-512).
    pub jit_cpu_features: Vec<String>,
    /// Each model's kernel hash (`kernel_hash`, packed) as the child composed it from the files it read.
    #[serde(default)]
    pub kernels: Vec<String>,
}

fn measures_the_baseline() -> bool {
    true
}

pub use crate::host_cpu::cpu_features;

/// The child: measures each kernel between client requests. Runs only under valgrind.
pub fn child_main(request_json: &str) -> Result<()> {
    let req: ChildRequest = serde_json::from_str(request_json).context("bad callgrind child request")?;
    if !running_on_valgrind() {
        bail!("`brdfprof {CHILD_COMMAND}` only measures under valgrind; `brdfprof inspect` runs it there");
    }
    // LLVM runs many times slower under valgrind: each compilation gets that much more time.
    crate::launch::scale(VALGRIND_SLOWDOWN);
    let models =
        req.models.iter().map(|s| Model::parse(s).map_err(|e| anyhow!("{s}: {e:#}"))).collect::<Result<Vec<_>>>()?;
    let shaders = match &req.glsl {
        Some(dir) => Shaders::from_glsl(dir)?,
        None => Shaders::embedded(),
    };
    let gpu = Gpu::new(&GpuOptions { device: req.device.clone(), validation: req.validate, ..Default::default() })?;
    let work = Workload::upload(
        &gpu,
        &gbuffer::synthetic(req.width, req.height, GBufferFormat::Packed),
        &gbuffer::lights(req.lights),
        None,
    )?;
    let mut all: Vec<Option<&Model>> = models.iter().map(Some).collect();
    if req.baseline {
        all.push(None);
    }
    let mut labels = Vec::new();
    for (i, model) in all.into_iter().enumerate() {
        let variant = Variant::new(&gpu, &work, model, &shaders, 1)?;
        variant.run_once(&gpu, 0)?; // JIT compilation, not counted
        let label = format!("{DUMP_LABEL}{i}\0");
        client_request(0, request::START_INSTRUMENTATION, 0);
        client_request(0, request::ZERO_STATS, 0);
        variant.run_once(&gpu, 0)?;
        client_request(0, request::DUMP_STATS_AT, label.as_ptr() as usize);
        client_request(0, request::STOP_INSTRUMENTATION, 0);
        labels.push(label.trim_end_matches('\0').to_string());
    }
    gpu.check_validation()?;
    let kernels =
        models.iter().map(|m| kernel_hash(Some(m), GBufferFormat::Packed, &shaders)).collect::<Result<_>>()?;
    let reply = ChildReply { labels, evaluations: work.evaluations(), jit_cpu_features: cpu_features(), kernels };
    println!("{}", serde_json::to_string(&reply)?);
    Ok(())
}

/// How the parent runs the child.
#[derive(Clone, Debug)]
pub struct CallgrindOptions {
    /// Size of the synthetic G-buffer the measured dispatch shades.
    pub width: u32,
    pub height: u32,
    pub device: Option<String>,
    pub validate: bool,
}

impl Default for CallgrindOptions {
    fn default() -> Self {
        CallgrindOptions { width: 64, height: 64, device: None, validate: false }
    }
}

/// `valgrind --version`, or why valgrind cannot be used.
pub fn valgrind_version() -> Result<String> {
    crate::shaders::first_line_of(cleanup::command("valgrind").arg("--version"))
        .filter(|v| v.starts_with("valgrind"))
        .ok_or_else(|| {
            anyhow!("valgrind not found: install valgrind (Debian: `apt-get install valgrind`), or run `make setup`")
        })
}

/// Runs the children under callgrind and reads what they dumped. Labels follow `Model::name`. The kernels are
/// split between one child per core (contiguous groups, the baseline kernel in the last): each kernel's count is
/// its own dispatch's, whatever else its process measured, and valgrind runs one thread, so one child left a
/// core idle (docs/gate.md). At most `MAX_CHILDREN`: each holds a Vulkan device and LLVM under valgrind.
pub fn run(models: &[Model], lights: u32, shaders: &Shaders, options: &CallgrindOptions) -> Result<CallgrindRun> {
    if !cfg!(target_arch = "x86_64") {
        bail!("callgrind client requests are implemented for x86-64 only");
    }
    let valgrind = valgrind_version()?;
    let cores = std::thread::available_parallelism().map_or(1, usize::from).min(MAX_CHILDREN);
    let groups = split(models.len() + 1, cores);
    let runs: Vec<Result<ChildRun>> = std::thread::scope(|scope| {
        let handles: Vec<_> = groups
            .iter()
            .enumerate()
            .map(|(k, range)| {
                let last = k + 1 == groups.len();
                let chunk = &models[range.start..range.end.min(models.len())];
                scope.spawn(move || run_child(chunk, last, lights, shaders, options))
            })
            .collect();
        handles.into_iter().map(|h| h.join().unwrap_or_else(|_| Err(anyhow!("a callgrind run panicked")))).collect()
    });
    let mut kernels = Vec::new();
    let mut first: Option<ChildRun> = None;
    for run in runs {
        let run = run?;
        if let Some(f) = &first
            && (f.evaluations != run.evaluations || f.jit_cpu_features != run.jit_cpu_features)
        {
            bail!("the callgrind children measured different workloads or CPU features; run again");
        }
        kernels.extend(run.kernels.iter().cloned());
        first.get_or_insert(run);
    }
    let first = first.ok_or_else(|| anyhow!("no callgrind run"))?;
    Ok(CallgrindRun { kernels, evaluations: first.evaluations, jit_cpu_features: first.jit_cpu_features, valgrind })
}

/// The most callgrind children one run starts, whatever the cores.
const MAX_CHILDREN: usize = 4;

/// `n` kernels in at most `parts` contiguous groups of sizes differing by at most one, the larger first.
fn split(n: usize, parts: usize) -> Vec<std::ops::Range<usize>> {
    let parts = parts.clamp(1, n.max(1));
    let (size, extra) = (n / parts, n % parts);
    let mut start = 0;
    (0..parts)
        .map(|k| {
            let len = size + usize::from(k < extra);
            let r = start..start + len;
            start += len;
            r
        })
        .collect()
}

/// What one callgrind child measured.
struct ChildRun {
    kernels: Vec<KernelIr>,
    evaluations: u64,
    jit_cpu_features: Vec<String>,
}

/// One child under callgrind: `models`' kernels, then the baseline kernel's where `baseline`.
fn run_child(
    models: &[Model],
    baseline: bool,
    lights: u32,
    shaders: &Shaders,
    options: &CallgrindOptions,
) -> Result<ChildRun> {
    // Registered, so that an interrupted run leaves no callgrind files behind.
    let dir = cleanup::TempDir::new().context("cannot create a directory for callgrind's output")?;
    let out_file = dir.path().join("callgrind.out");
    let req = ChildRequest {
        models: models.iter().map(Model::name).collect(),
        baseline,
        lights,
        width: options.width,
        height: options.height,
        device: options.device.clone(),
        validate: options.validate,
        glsl: shaders.glsl_dir().map(Path::to_path_buf),
    };
    // valgrind runs brdfprof itself (the one executable `cleanup::own_executable` finds).
    let exe = cleanup::own_executable()?;
    // --vgdb=no: no vgdb FIFOs in TMPDIR, which a killed valgrind would leave behind.
    let mut cmd = cleanup::command("valgrind");
    cmd.args([
        "--tool=callgrind",
        "--vgdb=no",
        "--instr-atstart=no",
        "--dump-line=no",
        "--dump-instr=no",
        "--compress-strings=no",
        "--compress-pos=no",
    ])
    .arg(format!("--callgrind-out-file={}", out_file.display()))
    .arg(&exe)
    .arg(CHILD_COMMAND)
    .arg(serde_json::to_string(&req)?)
    .env("LP_NUM_THREADS", "0")
    .env("MESA_SHADER_CACHE_DISABLE", "true");
    crate::launch::export(&mut cmd);
    let _tmp = cleanup::child_tmpdir(&mut cmd)?;
    // The child compiles and runs every kernel under valgrind, each compilation under the scaled limit.
    let limit = crate::launch::limit() * VALGRIND_SLOWDOWN * (models.len() as u32 + 2);
    let names = crate::messages::escape_line(&kernel_names(models, baseline).join(", "));
    let what = format!("the callgrind run of {names} (valgrind)");
    let output = crate::launch::output_within(&mut cmd, &what, limit).context("cannot run valgrind")?;
    let stdout = String::from_utf8_lossy(&output.stdout);
    let stderr = String::from_utf8_lossy(&output.stderr);
    if !output.status.success() {
        let tail: Vec<&str> = stderr.lines().rev().take(15).collect::<Vec<_>>().into_iter().rev().collect();
        bail!("{what} failed ({}):\n{}", output.status, tail.join("\n"));
    }
    let reply: ChildReply = stdout
        .lines()
        .rev()
        .find_map(|l| serde_json::from_str(l).ok())
        .ok_or_else(|| anyhow!("the callgrind child printed no reply; its output:\n{stdout}"))?;
    // The child reads the model files again: a file edited during the run gave it another kernel.
    for (model, theirs) in models.iter().zip(&reply.kernels) {
        if *theirs != kernel_hash(Some(model), GBufferFormat::Packed, shaders)? {
            bail!(
                "{}: the callgrind child measured another kernel than brdfprof composed (the child read the model file again and it had changed: was it edited during the run?); run again",
                model.file().map_or_else(|| model.label(), |f| f.path.clone())
            );
        }
    }
    let dumps = read_dumps(dir.path())?;
    let kernels = kernel_irs(models, baseline, &reply.labels, &dumps)?;
    Ok(ChildRun { kernels, evaluations: reply.evaluations, jit_cpu_features: reply.jit_cpu_features })
}

/// Each kernel's Ir of JIT code: the dump labelled `labels[i]` is `models[i]`'s (the baseline's last where measured).
fn kernel_irs(
    models: &[Model],
    baseline: bool,
    labels: &[String],
    dumps: &BTreeMap<String, u64>,
) -> Result<Vec<KernelIr>> {
    let names = kernel_names(models, baseline);
    if labels.len() != names.len() {
        bail!("the callgrind child measured {} kernels where {} were asked", labels.len(), names.len());
    }
    labels
        .iter()
        .zip(names)
        .map(|(dump_label, label)| {
            let jit_ir =
                *dumps.get(dump_label).ok_or_else(|| anyhow!("callgrind wrote no dump `{dump_label}` ({label})"))?;
            if jit_ir == 0 {
                bail!(
                    "callgrind's dump for {label} has no JIT code (no call from {DRIVER_OBJECT} into anonymous code)"
                );
            }
            Ok(KernelIr { label, jit_ir })
        })
        .collect()
}

/// The labels of a child's kernels: `models`', then the baseline's where it measures it.
fn kernel_names(models: &[Model], baseline: bool) -> Vec<String> {
    let base = baseline.then(|| super::BASELINE_LABEL.to_string());
    models.iter().map(Model::label).chain(base).collect()
}

/// Every client-request dump in `dir`: its label -> Ir of the JIT code.
fn read_dumps(dir: &Path) -> Result<BTreeMap<String, u64>> {
    let mut dumps = BTreeMap::new();
    for entry in std::fs::read_dir(dir)? {
        let path = entry?.path();
        // A tool's file, read as its output is: a regular file within the launcher's bound.
        let text = String::from_utf8_lossy(
            &crate::io::read_bounded(&path, crate::launch::MAX_OUTPUT_BYTES as u64)
                .with_context(|| format!("callgrind's dump {}", path.display()))?,
        )
        .into_owned();
        let dump = parse_dump(&text).with_context(|| format!("{}", path.display()))?;
        if let Some(label) = dump.trigger.as_deref().and_then(|l| l.strip_prefix("Client Request: ")) {
            dumps.insert(label.to_string(), dump.jit_ir());
        }
    }
    Ok(dumps)
}

/// A function in a dump: (object, function name).
type Func = (String, String);

/// One callgrind output file (written with --compress-strings=no): its trigger, the exclusive Ir of every
/// function, and the calls between functions.
#[derive(Debug, Default)]
pub struct Dump {
    pub trigger: Option<String>,
    pub exclusive: BTreeMap<Func, u64>,
    pub calls: Vec<(Func, Func)>,
}

/// File name of lavapipe's Vulkan driver, whose compute workers call the JIT-compiled kernel.
const DRIVER_OBJECT: &str = "libvulkan_lvp";

fn file_name(object: &str) -> &str {
    object.rsplit('/').next().unwrap_or(object)
}

impl Dump {
    /// Exclusive Ir of the JIT code: anonymous functions that lavapipe's driver calls, and the anonymous
    /// functions they call. Other anonymous code (e.g. a symbol-less stub that the validation layer's
    /// allocator goes through: one instruction per dump) is not the kernel and is left out.
    pub fn jit_ir(&self) -> u64 {
        let mut kernel: Vec<&Func> = self
            .calls
            .iter()
            .filter(|(caller, callee)| callee.0 == ANONYMOUS_OBJECT && file_name(&caller.0).starts_with(DRIVER_OBJECT))
            .map(|(_, callee)| callee)
            .collect();
        let mut i = 0;
        while i < kernel.len() {
            let caller = kernel[i];
            for (_, callee) in self.calls.iter().filter(|(c, callee)| c == caller && callee.0 == ANONYMOUS_OBJECT) {
                if !kernel.contains(&callee) {
                    kernel.push(callee);
                }
            }
            i += 1;
        }
        kernel.sort();
        kernel.dedup();
        kernel.iter().map(|f| self.exclusive.get(*f).copied().unwrap_or(0)).sum()
    }
}

/// Parses one callgrind output file.
pub fn parse_dump(text: &str) -> Result<Dump> {
    let mut dump = Dump::default();
    let (mut object, mut function) = (String::new(), String::new());
    // The target of the next `calls=` line; the called object defaults to the caller's.
    let (mut call_object, mut call_function): (Option<String>, Option<String>) = (None, None);
    let mut after_calls = false;
    for line in text.lines() {
        if let Some(t) = line.strip_prefix("desc: Trigger: ") {
            dump.trigger = Some(t.trim().to_string());
        } else if let Some(v) = line.strip_prefix("ob=") {
            object = v.trim().to_string();
        } else if let Some(v) = line.strip_prefix("fn=") {
            function = v.trim().to_string();
        } else if let Some(v) = line.strip_prefix("cob=") {
            call_object = Some(v.trim().to_string());
        } else if let Some(v) = line.strip_prefix("cfn=") {
            call_function = Some(v.trim().to_string());
        } else if line.starts_with("calls=") {
            let callee = call_function.take().ok_or_else(|| anyhow!("`{line}` without a cfn= line before it"))?;
            let callee_object = call_object.take().unwrap_or_else(|| object.clone());
            dump.calls.push(((object.clone(), function.clone()), (callee_object, callee)));
            after_calls = true;
        } else if line.starts_with(|c: char| c.is_ascii_digit() || c == '+' || c == '-' || c == '*') {
            // The cost line after `calls=` is the call's inclusive cost: counted where the callee runs.
            if std::mem::take(&mut after_calls) {
                continue;
            }
            let cost = line.split_whitespace().nth(1).ok_or_else(|| anyhow!("cost line without a cost: `{line}`"))?;
            let cost: u64 = cost.parse().map_err(|_| anyhow!("bad cost in `{line}`"))?;
            *dump.exclusive.entry((object.clone(), function.clone())).or_default() += cost;
        }
    }
    Ok(dump)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kernels_split_into_contiguous_groups_one_per_core() {
        assert_eq!(split(5, 2), [0..3, 3..5]);
        assert_eq!(split(5, 1), [0..5]);
        assert_eq!(split(2, 8), [0..1, 1..2]);
        assert_eq!(split(7, 3), [0..3, 3..5, 5..7]);
    }

    #[test]
    fn natively_client_requests_do_nothing() {
        assert!(!running_on_valgrind());
        assert_eq!(client_request(7, request::ZERO_STATS, 0), 7);
    }

    #[test]
    fn counts_the_anonymous_code_the_driver_calls() {
        let text = "version: 1\ncreator: callgrind-3.19.0\ndesc: Trigger: Client Request: brdfprof-kernel-0\nevents: Ir\n\
                    ob=/usr/lib/x86_64-linux-gnu/libvulkan_lvp.so\nfn=0x2996f0\n0 100\ncob=???\ncfn=0x1000\ncalls=64 0\n0 9999\n\
                    ob=???\nfn=0x1000\n0 300\ncfn=0x11b0\ncalls=512 0\n0 900\n\
                    cob=/usr/lib/x86_64-linux-gnu/libvulkan_lvp.so\ncfn=0x250da0\ncalls=64 0\n0 5000\n\
                    fn=0x11b0\n0 850\n0 50\n\
                    ob=/usr/lib/x86_64-linux-gnu/libstdc++.so.6\nfn=operator delete[](void*)\n0 7\ncob=???\ncfn=0x9108\ncalls=1 0\n0 1\n\
                    ob=???\nfn=0x9108\n0 1\ntotals: 11000\n";
        let dump = parse_dump(text).unwrap();
        assert_eq!(dump.trigger.as_deref(), Some("Client Request: brdfprof-kernel-0"));
        // 0x1000 (called by the driver) and 0x11b0 (called by it); not the stub reached from libstdc++, not
        // the driver helper the kernel calls, not inclusive call costs.
        assert_eq!(dump.jit_ir(), 300 + 850 + 50);
    }
}
