//! `--device intel:FAMILY`: Intel's production GPU compiler (IGC, through `ocloc`, see `ocloc`) on the kernels'
//! OpenCL C translation (`translate`), Gen9 to Xe-HPC, with no Intel GPU or driver. Per kernel: the SIMD width
//! IGC chose, its GRF count and mode, scratch space (spills and private memory), IGA's ISA listing counted by
//! class, the binary's size, and a documented cost model: EU (vector engine) cycles from the instruction mix
//! at the issue rates of Intel's public architecture documents and of IGC's own scheduling model
//! (`THROUGHPUT`, the one place those figures live). These are "Intel's OpenCL compiler (IGC), same maths" figures: Mesa's ANV, Intel's Vulkan driver on
//! Linux, compiles SPIR-V with its own compiler (brw); Intel's Windows Vulkan driver uses IGC.

pub mod ocloc;

pub use brdfprof_isa_cost::intel::*;

use super::cost;
use super::translated::{Compilation, LineCompile, Translated, Translator};
use crate::gpu::DriverStat;
use crate::model::Model;
use crate::translate::Dialect;
use anyhow::{Result, anyhow, bail};
use std::collections::BTreeMap;

/// ocloc's `-options`: OpenCL C 1.2 and the freedom a Vulkan driver has over SPIR-V without NoContraction or
/// float controls: contraction into mad and denormals flushed. The translation's prelude writes GLSL's
/// transcendentals, division and square root as OpenCL's native_ forms (Vulkan's precision for them) unless
/// `precise`, which builds the IEEE library forms with no contraction (`-DBRDFPROF_PRECISE`).
pub fn options(precise: bool) -> String {
    if precise {
        crate::translate::opencl::build_options(true)
    } else {
        format!("{} -cl-mad-enable -cl-denorms-are-zero", crate::translate::opencl::build_options(false))
    }
}

/// Compiles the OpenCL C `source` for `family` and lists its ISA, under the compile limit, or takes both
/// from the cache: the key covers the source, the options, ocloc's and IGC's versions and brdfprof's.
pub fn compile(source: &str, family: &Family, precise: bool) -> Result<ocloc::Binary> {
    compile_as(source, family, precise, false)
}

/// `compile`, with IGC's listing naming each instruction's source line (line tables, its shader dump) where
/// `lines`.
pub fn compile_as(source: &str, family: &Family, precise: bool, lines: bool) -> Result<ocloc::Binary> {
    let tools = ocloc::tools()?;
    let options = options(precise);
    let key = crate::cache::KeyBuilder::new("igc")
        .part("brdfprof", env!("CARGO_PKG_VERSION"))
        .part("ocloc", &tools.version)
        .part("device", family.device)
        .part("options", &options)
        .part("lines", if lines { ocloc::LINE_TABLES } else { "" })
        .part("source", source)
        .finish();
    let what = format!("the OpenCL C translation for intel:{} (ocloc -device {})", family.name, family.device);
    let valid = |bytes: &[u8]| -> Result<()> {
        let binary: ocloc::Binary = serde_json::from_slice(bytes)?;
        isa_stats(&binary, family).map(|_| ())
    };
    let bytes =
        crate::cache::get_or_build(crate::cache::Store::open_default().as_ref(), "igc", &key, &what, valid, || {
            let binary = if lines {
                tools.compile_with_lines(source, family.device, &options, &what)?
            } else {
                tools.compile(source, family.device, &options, &what)?
            };
            Ok(serde_json::to_vec(&binary)?)
        })?;
    Ok(serde_json::from_slice(&bytes)?)
}

/// The kernel ocloc compiled, counted (`IsaStats`).
pub fn isa_stats(binary: &ocloc::Binary, family: &Family) -> Result<IsaStats> {
    IsaStats::of(&binary.tokens, &binary.listing, binary.bytes, family)
}

/// Cost per source line of a kernel compiled with `compile_as(.., lines)`: each instruction of IGC's listing on
/// its pipes (`pipe_cycles`), its schedule cycles (the wait for its registers and pipe, and its issue cycle in
/// `IsaStats::schedule_latency`'s schedule), summed per line; the translation's own lines and IGC's prologue
/// name none. Lines are ranked on the pipe that binds the kernel.
pub fn line_costs(model: &str, binary: &ocloc::Binary, family: &Family) -> Result<crate::schema::lines::KernelLines> {
    use super::cost::lines::{Attributed, per_line};
    let stats = isa_stats(binary, family)?;
    let listing = binary.lines_listings.get(&stats.simd).ok_or_else(|| {
        anyhow!(
            "IGC's shader dump has no SIMD{} listing (it has {:?})",
            stats.simd,
            binary.lines_listings.keys().collect::<Vec<_>>()
        )
    })?;
    let sourced = gen_isa::sourced_instructions(listing, family.grf_bytes);
    if sourced.is_empty() {
        bail!("IGC's listing with line information has no instructions");
    }
    let instructions: Vec<gen_isa::Instruction> = sourced.iter().map(|(i, _)| i.clone()).collect();
    let binding = stats
        .pipes(family)?
        .into_iter()
        .fold(("-".to_string(), f64::NEG_INFINITY), |b, p| if p.1 > b.1 { p } else { b })
        .0;
    let times = gen_isa::issue_times(&instructions, |i| {
        let pipe = occupancy(i, family)?.map(|(p, c)| (p as usize, c));
        Ok(gen_isa::Timing { latency: latency(i, family), pipe })
    })?;
    let mut attributed = Vec::new();
    let mut previous = -1.0;
    for (k, (i, source)) in sourced.into_iter().enumerate() {
        // The cycles since the previous instruction started: its one issue cycle and any wait before it.
        let schedule = times[k] - previous;
        previous = times[k];
        let pipes = pipe_cycles(&i, family)?.into_iter().map(|(p, c)| (p.name(family.pipes).to_string(), c)).collect();
        attributed.push(Attributed {
            source: super::translated::user_source(source.as_slice()),
            pipes,
            schedule,
            issue: 0.0,
        });
    }
    Ok(per_line(model, &attributed, &binding))
}

/// Intel's translated targets: `FAMILIES` and `THROUGHPUT`, IGC through ocloc, and IGA's listing parser
/// (`IsaStats`).
pub struct Intel;
pub static INTEL: Translated<Intel> = Translated::new();

impl Translator for Intel {
    type Family = Family;
    type Binary = ocloc::Binary;
    type Tools = ocloc::Tools;

    const PREFIX: &'static str = "intel";
    const NAME: &'static str = "Intel";
    const TITLE: &'static str = "Intel: IGC through ocloc (Debian's intel-opencl-icd) on the kernels' OpenCL C translation, checked on the host first (no Intel GPU or driver needed)";
    const DIALECT: Dialect = Dialect::OpenCl;
    const COMPILER: &'static str = "IGC";
    const UNIT: &'static str = "EU cycles";
    const RULE: &'static str = "a thread's pipes at THROUGHPUT's lanes per clock (Intel's documents; extended math: IGC's scheduling model), its latency in IGC's instruction order at IGC's scheduler latencies, threads per EU from the registers; / (SIMD width x lights per kernel); Issue Cycles: the old serial sum";
    const SHOWN: &'static [&'static str] =
        &["SIMD Width", "Register Count", "Scratch Memory Size", "Instruction Count", "Extended math", "Issue Cycles"];
    const ISA_EXTENSIONS: (&'static str, &'static str) = ("cl", "asm");

    fn families() -> &'static [Family] {
        &FAMILIES
    }

    fn family(f: &Family) -> super::Family {
        super::Family {
            name: f.name,
            architecture: f.architecture,
            products: f.products,
            detail: format!("ocloc -device {}", f.device),
            default: true,
        }
    }

    fn tools() -> Result<&'static ocloc::Tools> {
        ocloc::tools()
    }

    fn status() -> Result<String> {
        let t = ocloc::tools()?;
        Ok(format!("{} at {}, IGA from {}", t.version, t.ocloc.display(), t.iga_dir.display()))
    }

    fn vendor() -> &'static dyn super::Vendor {
        &INTEL
    }

    fn compile(source: &str, family: &Family, precise: bool) -> Result<ocloc::Binary> {
        compile(source, family, precise)
    }

    /// A family without what a kernel needs (fp64).
    fn unsupported(error: &anyhow::Error) -> Option<String> {
        error.downcast_ref::<ocloc::Unsupported>().map(|u| u.reason.clone())
    }

    fn driver_stats(binary: &ocloc::Binary, family: &Family) -> Result<Vec<DriverStat>> {
        Ok(super::driver_stats("IGC", isa_stats(binary, family)?.driver_stats(family)?))
    }

    fn lanes(stats: &BTreeMap<String, f64>) -> Option<f64> {
        cost::driver_stat(stats, "SIMD Width")
    }

    fn compilation(family: &Family, device: String, tools: &ocloc::Tools, precise: bool) -> Compilation {
        let options = options(precise);
        Compilation {
            target: format!("intel:{}", family.name),
            device: serde_json::json!({"name": device, "driver_name": "IGC (ocloc)", "driver_info": format!("{} (-device {}; {options})", tools.version, family.device), "driver_version": tools.version}),
            compiler: serde_json::json!({"name": tools.version, "options": options, "device": family.device, "translation": "brdfprof's SPIR-V to OpenCL C translation"}),
            driver_note: format!(
                "Intel's OpenCL compiler (IGC, {}) on the kernels' OpenCL C translation, same maths; -device {}; options: {options}",
                tools.version, family.device
            ),
            tool: ("ocloc".to_string(), tools.version.clone()),
        }
    }

    fn isa_listing(family: &Family, label: &str, binary: &ocloc::Binary, tools: &ocloc::Tools) -> Result<String> {
        let stats = isa_stats(binary, family)?;
        let header = format!(
            "// {label}: Gen ISA for {} (ocloc -device {}) by {}, listed by IGA\n// SIMD{}, {} GRF, {} bytes scratch per thread\n",
            family.name, family.device, tools.version, stats.simd, stats.grf, stats.scratch_bytes
        );
        Ok(format!("{header}{}", binary.listing))
    }

    fn line_compile(m: &Model, source: &str, costed: &str, family: &Family, precise: bool) -> Result<LineCompile> {
        let binary = compile_as(source, family, precise, true)?;
        let lines = line_costs(&m.label(), &binary, family)?;
        let shape =
            |i: gen_isa::Instruction| format!("{}.{} ({}) :{}", i.mnemonic, i.function, i.exec_size, i.dst_type);
        let costed = gen_isa::instructions(&compile(costed, family, precise)?.listing, family.grf_bytes)
            .into_iter()
            .map(shape)
            .collect();
        let simd = isa_stats(&binary, family)?.simd;
        let annotated = gen_isa::sourced_instructions(
            binary.lines_listings.get(&simd).map_or("", String::as_str),
            family.grf_bytes,
        )
        .into_iter()
        .map(|(i, _)| shape(i))
        .collect();
        Ok(LineCompile { lines, costed, annotated })
    }
}
