//! `--device nvidia:sm_XX`: NVIDIA's production compiler (NVRTC and ptxas, `nvrtc`) on the kernels' CUDA C++
//! translation (`translate`), for five GPU generations, with no NVIDIA GPU or driver. Per kernel: ptxas'
//! registers, stack and spills, the SASS nvdisasm lists counted by class, the cubin's size, occupancy, and a
//! documented cost model: issue-limited SM cycles from the throughput table of NVIDIA's CUDA C++ Programming
//! Guide (`THROUGHPUT`, the one place those figures live). These are "NVIDIA's CUDA compiler (ptxas), same
//! maths" figures: NVIDIA's Vulkan driver compiles SPIR-V with its own front end, and no public comparison of
//! the two exists.

pub mod nvrtc;

pub use brdfprof_isa_cost::nvidia::*;

use super::translated::{Compilation, LineCompile, Translated, Translator};
use crate::gpu::DriverStat;
use crate::model::Model;
use crate::translate::Dialect;
use anyhow::{Result, bail};
use std::collections::BTreeMap;

/// NVRTC's options: the architecture, ptxas' resource report, no warnings, and (unless `precise`)
/// `-use_fast_math`, which gives NVIDIA the precision freedom a Vulkan driver has (approximate division and
/// square root, exp2/log2-based transcendentals, denormals flushed: `--ftz=true --prec-div=false
/// --prec-sqrt=false --fmad=true`).
pub fn options(family: &Family, precise: bool) -> Vec<String> {
    let mut o = vec![format!("-arch={}", family.name), "--ptxas-options=-v".into(), "-w".into()];
    if !precise {
        o.push("-use_fast_math".into());
    }
    o
}

/// NVRTC's option that keeps each instruction's source line in the cubin (`inspect --lines`).
pub const LINE_INFO: &str = "-lineinfo";

/// A kernel compiled for `family`: the SASS listing, ptxas' log and the cubin's size.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize, PartialEq)]
pub struct Sass {
    pub listing: String,
    pub log: String,
    pub cubin_bytes: usize,
}

/// Compiles the CUDA C++ `source` for `family` and disassembles it, under the compile limit, or takes both from
/// the cache: the key covers the source, the options, NVRTC's and nvdisasm's versions and brdfprof's.
pub fn compile(source: &str, family: &Family, precise: bool) -> Result<Sass> {
    compile_as(source, family, precise, false)
}

/// `compile`, with each instruction's source line (`-lineinfo`, nvdisasm `--print-line-info`) where `lines`.
pub fn compile_as(source: &str, family: &Family, precise: bool, lines: bool) -> Result<Sass> {
    let tools = nvrtc::tools()?;
    let mut options = options(family, precise);
    if lines {
        options.push(LINE_INFO.into());
    }
    let key = crate::cache::KeyBuilder::new("sass")
        .part("brdfprof", env!("CARGO_PKG_VERSION"))
        .part("nvrtc", &tools.version)
        .part("nvdisasm", &tools.nvdisasm_version)
        .part(
            "nvdisasm options",
            format!("{}{}", nvrtc::DISASSEMBLE_OPTIONS.join(" "), if lines { nvrtc::LINE_INFO } else { "" }),
        )
        .part("options", options.join(" "))
        .part("source", source)
        .finish();
    let what = format!("the CUDA C++ translation for nvidia:{} (NVRTC)", family.name);
    let valid = |bytes: &[u8]| -> Result<()> {
        let sass: Sass = serde_json::from_slice(bytes)?;
        if !sass.listing.contains("EXIT") {
            bail!("a SASS listing without EXIT");
        }
        Ok(())
    };
    let bytes =
        crate::cache::get_or_build(crate::cache::Store::open_default().as_ref(), "sass", &key, &what, valid, || {
            let compiled = crate::launch::bounded(&what, || tools.compile(source, "brdfprof_kernel.cu", &options))?;
            let listing = tools.disassemble(&compiled.cubin, lines)?;
            Ok(serde_json::to_vec(&Sass { listing, log: compiled.log, cubin_bytes: compiled.cubin.len() })?)
        })?;
    Ok(serde_json::from_slice(&bytes)?)
}

/// Cost per source line of a kernel compiled with line information (`compile_as` with `lines`): each SASS
/// instruction on its pipe at its row's rate and its issue slot, its schedule cycles (the scoreboard wait before
/// it and its stall), summed per line; the translation's own lines and NVRTC's prologue name none.
pub fn line_costs(model: &str, sass: &Sass, family: &Family) -> Result<crate::schema::lines::KernelLines> {
    use super::cost::lines::{Attributed, per_line};
    let instructions = sass::instructions(&sass.listing)?;
    let stats = SassStats::of(&sass.listing, &sass.log, sass.cubin_bytes, family)?;
    let binding = stats
        .pipes(family)?
        .into_iter()
        .fold(("-".to_string(), f64::NEG_INFINITY), |b, p| if p.1 > b.1 { p } else { b })
        .0;
    let times = sass::issue_times(&instructions, family.memory);
    let mut attributed = Vec::new();
    let mut previous_end = 0.0;
    for (k, i) in instructions.iter().enumerate() {
        let stall = f64::from(i.control.stall.max(1));
        let schedule = times[k] - previous_end + stall;
        previous_end = times[k] + stall;
        let (_, row, pipe) = classify(&i.opcode);
        let counted = i.mnemonic() != "NOP";
        let pipes = match (pipe, counted) {
            (Some(p), true) => vec![(p.on(family).name().to_string(), SassStats::cycles_per_instruction(row, family)?)],
            _ => vec![],
        };
        let issue = if counted { 32.0 / f64::from(ISSUE_PER_CLOCK) } else { 0.0 };
        attributed.push(Attributed { source: super::translated::user_source(&i.sources), pipes, schedule, issue });
    }
    Ok(per_line(model, &attributed, &binding))
}

/// NVIDIA's translated targets: `FAMILIES` and `THROUGHPUT`, NVRTC and ptxas, and the SASS parser (`SassStats`).
pub struct Nvidia;
pub static NVIDIA: Translated<Nvidia> = Translated::new();

impl Translator for Nvidia {
    type Family = Family;
    type Binary = Sass;
    type Tools = nvrtc::Tools;

    const PREFIX: &'static str = "nvidia";
    const NAME: &'static str = "NVIDIA";
    const TITLE: &'static str = "NVIDIA: NVRTC and ptxas (NVIDIA's PyPI wheels) on the kernels' CUDA C++ translation, checked on the host first (no NVIDIA GPU or driver needed)";
    const DIALECT: Dialect = Dialect::Cuda;
    const COMPILER: &'static str = "ptxas";
    const UNIT: &'static str = "SM cycles";
    const RULE: &'static str = "a warp's pipes at the CUDA guide's throughputs (Nsight Compute's pipe assignment), its latency by ptxas' stall counts and scoreboards, warps per SM from the registers; / (32 x lights per kernel); Issue Cycles: the old serial sum";
    const SHOWN: &'static [&'static str] =
        &["Instruction Count", "Register Count", "Spill Bytes", "MUFU (special functions)", "Issue Cycles"];
    const ISA_EXTENSIONS: (&'static str, &'static str) = ("cu", "sass");

    fn families() -> &'static [Family] {
        &FAMILIES
    }

    fn family(f: &Family) -> super::Family {
        super::Family {
            name: f.name,
            architecture: f.architecture,
            products: f.products,
            detail: format!("compute capability {}.{}", f.compute_capability.0, f.compute_capability.1),
            default: true,
        }
    }

    fn tools() -> Result<&'static nvrtc::Tools> {
        nvrtc::tools()
    }

    fn status() -> Result<String> {
        Ok(format!("{} and nvdisasm under {}", nvrtc::tools()?.version, nvrtc::install_dir().display()))
    }

    fn vendor() -> &'static dyn super::Vendor {
        &NVIDIA
    }

    fn compile(source: &str, family: &Family, precise: bool) -> Result<Sass> {
        compile(source, family, precise)
    }

    fn driver_stats(sass: &Sass, family: &Family) -> Result<Vec<DriverStat>> {
        Ok(super::driver_stats(
            "SASS",
            SassStats::of(&sass.listing, &sass.log, sass.cubin_bytes, family)?.driver_stats(family)?,
        ))
    }

    fn rule_note(family: &Self::Family) -> Option<String> {
        let m = family.memory;
        Some(format!("{} latency {} cycles ({})", m.what, m.cycles, m.source))
    }

    fn lanes(_: &BTreeMap<String, f64>) -> Option<f64> {
        Some(32.0)
    }

    fn compilation(family: &Family, device: String, tools: &nvrtc::Tools, precise: bool) -> Compilation {
        let options = options(family, precise).join(" ");
        Compilation {
            target: format!("nvidia:{}", family.name),
            device: serde_json::json!({"name": device, "driver_name": "NVRTC", "driver_info": format!("{} ({options})", tools.version), "driver_version": tools.version}),
            compiler: serde_json::json!({"name": tools.version, "options": options, "translation": "brdfprof's SPIR-V to CUDA C++ translation"}),
            driver_note: format!(
                "NVIDIA's CUDA compiler ({}, ptxas) on the kernels' CUDA C++ translation, same maths; options: {options}",
                tools.version
            ),
            tool: ("nvrtc".to_string(), tools.version.clone()),
        }
    }

    fn isa_listing(family: &Family, label: &str, sass: &Sass, tools: &nvrtc::Tools) -> Result<String> {
        Ok(format!("// {label}: SASS for {} by {}\n{}\n{}", family.name, tools.version, sass.log.trim(), sass.listing))
    }

    fn line_compile(m: &Model, source: &str, costed: &str, family: &Family, precise: bool) -> Result<LineCompile> {
        let sass = compile_as(source, family, precise, true)?;
        let opcodes = |listing: &str| -> Result<Vec<String>> {
            Ok(sass::instructions(listing)?.into_iter().map(|i| i.opcode).collect())
        };
        Ok(LineCompile {
            lines: line_costs(&m.label(), &sass, family)?,
            costed: opcodes(&compile(costed, family, precise)?.listing)?,
            annotated: opcodes(&sass.listing)?,
        })
    }
}
