//! The one `Vendor` of the targets that compile the kernels' C translation instead of SPIR-V (`nvidia`: NVRTC
//! and ptxas on CUDA C++; `intel`: IGC through ocloc on OpenCL C). Every such target runs the same way: each
//! kernel's translation checked against its Vulkan kernel first, compiled for every family, its compiler's
//! listing read into driver statistics, costed by the schedule rule (`cost::schedule`), and where asked its
//! cost per source line. What differs is a `Translator`: the vendor's table of families (with the rates its
//! parser charges), its compiler and its listing parser.

use super::cost::{
    self,
    schedule::{self, Schedule},
};
use super::{Family, RawKernel, Request, Run, Target, Vendor};
use crate::gpu::{DriverStat, Gpu};
use crate::kernel_stats::{compiled_report, kernels_of, static_row};
use crate::model::Model;
use crate::schema::cost::TargetCost;
use crate::schema::{InspectReport, Row};
use crate::translate::Dialect;
use anyhow::{Result, anyhow};
use std::collections::BTreeMap;
use std::marker::PhantomData;
use std::path::Path;

/// What one translating vendor supplies.
pub trait Translator: Sync + 'static {
    /// A row of the vendor's family table.
    type Family: Sync + 'static;
    /// One kernel compiled: what the listing parser reads.
    type Binary: Send;
    /// The compiler, found once.
    type Tools: Sync + 'static;

    /// The `--device` prefix, without the colon.
    const PREFIX: &'static str;
    /// The GPU vendor ("NVIDIA"), as device names and messages give it.
    const NAME: &'static str;
    /// One line: the vendor and its compiler, how brdfprof runs it.
    const TITLE: &'static str;
    /// The C dialect the compiler takes.
    const DIALECT: Dialect;
    /// The cost table's compiler, its unit, and how the vendor's figures meet the rule (after `schedule::RULE`).
    const COMPILER: &'static str;
    const UNIT: &'static str;
    const RULE: &'static str;
    /// The statistics the cost table shows beside cycles/eval (and the rule's figures).
    const SHOWN: &'static [&'static str];
    /// The `--isa` files' extensions: the translation's and the listing's.
    const ISA_EXTENSIONS: (&'static str, &'static str);

    /// The family table.
    fn families() -> &'static [Self::Family];
    /// A family as `devices --targets` shows it.
    fn family(f: &Self::Family) -> Family;
    fn tools() -> Result<&'static Self::Tools>;
    /// The compiler's name, version and where it was found.
    fn status() -> Result<String>;
    /// The vendor's `Vendor`, for the runs' targets.
    fn vendor() -> &'static dyn Vendor;
    /// Compiles a translation for a family (through the cache).
    fn compile(source: &str, family: &Self::Family, precise: bool) -> Result<Self::Binary>;
    /// Why a family cannot compile a kernel, where the error says it lacks what the kernel needs (the kernel is
    /// left out of that family's report); None: the error stops the run.
    fn unsupported(_error: &anyhow::Error) -> Option<String> {
        None
    }
    /// The listing parser: a compiled kernel's statistics as driver statistics, its pipes at the family's rates.
    fn driver_stats(binary: &Self::Binary, family: &Self::Family) -> Result<Vec<DriverStat>>;
    /// The lanes of one wave (what the rule's per-wave figures divide by), from a row's statistics.
    fn lanes(stats: &BTreeMap<String, f64>) -> Option<f64>;
    /// What the family's rule takes that other families' does not (NVIDIA: its memory latency and its source),
    /// appended to the cost table's rule line.
    fn rule_note(_family: &Self::Family) -> Option<String> {
        None
    }
    /// What a family's report says of the compiler, the device (named `device`) and the options.
    fn compilation(family: &Self::Family, device: String, tools: &Self::Tools, precise: bool) -> Compilation;
    /// The `--isa` listing of a compiled kernel.
    fn isa_listing(family: &Self::Family, label: &str, binary: &Self::Binary, tools: &Self::Tools) -> Result<String>;
    /// A model's line-annotated `source` compiled for `family`, its line costs, and the instruction sequences
    /// of that compile and of the costed one (`costed`, the checked translation).
    fn line_compile(
        model: &Model,
        source: &str,
        costed: &str,
        family: &Self::Family,
        precise: bool,
    ) -> Result<LineCompile>;
}

/// A translating vendor's compile-only targets.
pub struct Translated<C>(PhantomData<fn() -> C>);

impl<C> Translated<C> {
    pub const fn new() -> Self {
        Translated(PhantomData)
    }
}

/// The device name of a family's reports.
pub fn device_name<C: Translator>(family: &C::Family) -> String {
    let f = C::family(family);
    format!("{} {} ({}), compile-only", C::NAME, f.name, f.architecture)
}

impl<C: Translator> Translated<C> {
    /// Every kernel (the models' and the memory-only one) compiled for each family, as `inspect` reports (one
    /// per family, in order), after each translation agreed with its Vulkan kernel.
    fn inspect(&self, families: &[&C::Family], req: &Request) -> Result<Vec<InspectReport>> {
        let tools = C::tools()?;
        let gpu =
            req.verify_on.ok_or_else(|| anyhow!("{}: no Vulkan device to check the translation against", C::PREFIX))?;
        let checked = checked_translations(req, gpu, C::DIALECT)?;
        let statics = kernels_of(req.models)
            .into_iter()
            .map(|m| static_row(req.shaders, m, req.lights))
            .collect::<Result<Vec<_>>>()?;
        let mut reports = self.compile_checked(families, statics, &checked, tools, req)?;
        add_lines(&mut reports, families, req, &checked, C::DIALECT, |m, source, costed, family| {
            C::line_compile(m, source, costed, family, req.precise)
        })?;
        Ok(reports)
    }

    /// Every checked translation compiled for each family, its statistics added to its row (`statics`, in the
    /// same order), as one report per family.
    fn compile_checked(
        &self,
        families: &[&C::Family],
        statics: Vec<Row>,
        checked: &[Checked],
        tools: &C::Tools,
        req: &Request,
    ) -> Result<Vec<InspectReport>> {
        let jobs: Vec<(usize, usize)> =
            (0..families.len()).flat_map(|f| (0..checked.len()).map(move |k| (f, k))).collect();
        // Compiles are independent (NVRTC's API is thread-safe; ocloc is a process): one job per core.
        use rayon::prelude::*;
        let (sources, precise): (Vec<&str>, bool) = (checked.iter().map(|c| c.source.as_str()).collect(), req.precise);
        // A model whose translation failed its check is not compiled.
        let compiled: Vec<Option<Result<C::Binary>>> = jobs
            .par_iter()
            .map(|&(f, k)| checked[k].failed.is_none().then(|| C::compile(sources[k], families[f], precise)))
            .collect();
        // A family without what a kernel needs leaves it out with the reason; a model's failure is its row's;
        // the memory-only kernel's stops the family, which has no net figure without it.
        let mut reports = Vec::new();
        for (f, family) in families.iter().enumerate() {
            let mut rows = statics.clone();
            let (mut left_out, mut failed) = (Vec::new(), Vec::new());
            for (k, row) in rows.iter_mut().enumerate() {
                let binary = match &compiled[f * checked.len() + k] {
                    Some(Ok(b)) => b,
                    Some(Err(e)) => {
                        match C::unsupported(e) {
                            Some(why) => left_out.push((row.model.clone(), why)),
                            None if row.model == crate::model::BASELINE_LABEL => return Err(anyhow!("{e:#}")),
                            None => failed.push((row.model.clone(), format!("{e:#}"))),
                        }
                        continue;
                    }
                    None => {
                        failed.push((row.model.clone(), checked[k].failed.clone().unwrap_or_default()));
                        continue;
                    }
                };
                row.stats.extend(crate::schema::driver::stats(&C::driver_stats(binary, family)?));
                row.notes.insert("translation".into(), checked[k].agreement.clone());
                if let Some(dir) = req.isa_dir {
                    write_isa::<C>(dir, family, &row.model, &checked[k].source, binary, tools)?;
                }
            }
            rows.retain(|r| !left_out.iter().chain(&failed).any(|(m, _)| *m == r.model));
            let compilation = C::compilation(family, device_name::<C>(family), tools, req.precise);
            let mut report = translated_report(self, compilation, rows, req);
            if let Some(cost) = &mut report.cost {
                cost.absent = left_out.clone();
                cost.failed = failed;
            }
            if !left_out.is_empty() {
                let note = format!(
                    "not compiled for {}:{}: {}",
                    C::PREFIX,
                    C::family(family).name,
                    left_out.iter().map(|(m, why)| format!("{m} ({why})")).collect::<Vec<_>>().join("; ")
                );
                crate::messages::warning(&note);
                report.section_notes.insert("driver/".into(), note);
            }
            reports.push(report);
        }
        Ok(reports)
    }

    fn runs(reports: Vec<InspectReport>, families: &[usize]) -> Vec<Run> {
        reports
            .into_iter()
            .zip(families)
            .map(|(report, &family)| Run {
                target: Target { vendor: C::vendor(), family },
                report,
                isa_files: Vec::new(),
                note: None,
            })
            .collect()
    }

    fn chosen(families: &[usize]) -> Vec<&'static C::Family> {
        families.iter().map(|&k| &C::families()[k]).collect()
    }
}

/// Writes a kernel's translation and its compiler's listing to DIR/<prefix>-<family>/<kernel>.<extension>.
fn write_isa<C: Translator>(
    dir: &Path,
    family: &C::Family,
    label: &str,
    source: &str,
    binary: &C::Binary,
    tools: &C::Tools,
) -> Result<()> {
    let dir = dir.join(format!("{}-{}", C::PREFIX, C::family(family).name));
    std::fs::create_dir_all(&dir).map_err(|e| anyhow!("--isa: cannot create {}: {e}", dir.display()))?;
    let stem = super::file_slug(label);
    let (translation, listing) = C::ISA_EXTENSIONS;
    crate::io::write_output(&dir.join(format!("{stem}.{translation}")), source.as_bytes())?;
    crate::io::write_output(
        &dir.join(format!("{stem}.{listing}")),
        C::isa_listing(family, label, binary, tools)?.as_bytes(),
    )
}

impl<C: Translator> Vendor for Translated<C> {
    fn prefix(&self) -> &'static str {
        C::PREFIX
    }

    fn name(&self) -> &'static str {
        C::NAME
    }

    fn title(&self) -> &'static str {
        C::TITLE
    }

    fn families(&self) -> Vec<Family> {
        C::families().iter().map(C::family).collect()
    }

    fn status(&self) -> Result<String> {
        C::status()
    }

    fn needs_verification(&self) -> bool {
        true
    }

    fn compile(&self, families: &[usize], request: &Request) -> Result<Vec<Run>> {
        Ok(Self::runs(self.inspect(&Self::chosen(families), request)?, families))
    }

    fn compile_raw(&self, families: &[usize], kernels: &[RawKernel], request: &Request) -> Result<Vec<Run>> {
        let (rows, checked) = raw_translations(self, kernels, C::DIALECT)?;
        Ok(Self::runs(self.compile_checked(&Self::chosen(families), rows, &checked, C::tools()?, request)?, families))
    }

    fn cost(&self, report: &InspectReport) -> Option<TargetCost> {
        let row = &C::families()[self.family_of(report)?];
        let family = C::family(row);
        let header = TargetCost {
            device: device_name::<C>(row),
            target: Some(format!("{}:{}", C::PREFIX, family.name)),
            family: Some(family.name.to_string()),
            architecture: Some(family.architecture.to_string()),
            compiler: C::COMPILER.into(),
            model: match C::rule_note(row) {
                Some(note) => format!("{}; {}; {note}", schedule::RULE, C::RULE),
                None => format!("{}; {}", schedule::RULE, C::RULE),
            },
            unit: C::UNIT.into(),
            lights_per_kernel: 0,
            columns: C::SHOWN.iter().map(|s| s.to_string()).collect(),
            rows: Vec::new(),
            absent: Vec::new(),
            failed: Vec::new(),
            checked: None,
        };
        cost::schedule_table(report, header, |stats| Some((Schedule::of(stats)?, C::lanes(stats)?)))
    }

    fn family_of(&self, report: &InspectReport) -> Option<usize> {
        let target = report.provenance["target"].as_str()?.strip_prefix(C::PREFIX)?.strip_prefix(':')?;
        C::families().iter().position(|f| C::family(f).name == target)
    }

    fn fingerprint(&self, report: &InspectReport) -> BTreeMap<String, String> {
        // The compiler's output depends on the device, the compiler's version and options, and the translation.
        let p = &report.provenance;
        [
            ("device".to_string(), p["device"]["name"].as_str().unwrap_or("?").to_string()),
            ("compiler".to_string(), p["compiler"]["name"].as_str().unwrap_or("?").to_string()),
            ("options".to_string(), p["compiler"]["options"].as_str().unwrap_or("?").to_string()),
        ]
        .into()
    }
}

/// One kernel's translation in a dialect, checked against its Vulkan kernel, ready for every family.
pub struct Checked {
    pub source: String,
    /// The row note: the device checked on and the worst difference.
    pub agreement: String,
    /// Why the translation is not compiled: its check failed (a model's kernel only).
    pub failed: Option<String>,
}

/// Every kernel of `req` (the models' and the memory-only one) translated into `dialect`, after the
/// translation (its body is the same text in every dialect) agreed with the Vulkan kernel on `gpu`; a model
/// whose translation does not is `failed` with the reason (the memory-only kernel's stops the run).
fn checked_translations(req: &Request, gpu: &Gpu, dialect: Dialect) -> Result<Vec<Checked>> {
    let check = |m: Option<&Model>| -> Result<Checked> {
        let agreements = crate::translate::verify::check_cached(gpu, m, req.lights, req.shaders)?;
        let source = crate::translate::prepare::shade_kernel(m, req.lights, req.shaders)?.source(dialect);
        let agreement = agreements
            .iter()
            .map(|a| format!("{}{}", a.summary(), a.note().map_or_else(String::new, |n| format!(": {n}"))))
            .collect::<Vec<_>>()
            .join("; ");
        Ok(Checked {
            source,
            agreement: format!(
                "translation checked on the host against {} and the translation's f64 evaluation: {agreement}",
                gpu.info.name
            ),
            failed: None,
        })
    };
    kernels_of(req.models)
        .into_iter()
        .map(|m| match (check(m), m) {
            (Err(e), Some(model)) => {
                crate::messages::warning(&format!("{}: not costed on this vendor's targets: {e:#}", model.label()));
                Ok(Checked { source: String::new(), agreement: String::new(), failed: Some(format!("{e:#}")) })
            }
            (result, _) => result,
        })
        .collect()
}

/// What a translating vendor says about a family's compilation, for its reports.
pub struct Compilation {
    /// `nvidia:sm_89`, `intel:gen12lp`.
    pub target: String,
    /// The report's `provenance.device` and `provenance.compiler`.
    pub device: serde_json::Value,
    pub compiler: serde_json::Value,
    /// The `driver/` section's note: which compiler, on what, with which options.
    pub driver_note: String,
    /// The compiler in the report's tool list: (name, version).
    pub tool: (String, String),
}

/// The inspect report of a target that compiles the kernels' C translation: provenance, notes (callgrind does
/// not apply: nothing executes), the rows and the vendor's cost table.
fn translated_report(vendor: &dyn Vendor, c: Compilation, rows: Vec<Row>, req: &Request) -> InspectReport {
    let provenance = serde_json::json!({
        "tool": format!("brdfprof {}", env!("CARGO_PKG_VERSION")),
        "device": c.device,
        "target": c.target,
        "compiler": c.compiler,
        "host_cpu": crate::host_cpu::HostCpu::detect().describe(),
    });
    let mut notes = std::collections::BTreeMap::new();
    notes.insert("driver/".into(), c.driver_note);
    notes.insert("callgrind/".into(), format!("not applicable: {} compiles only, nothing executes", c.target));
    let mut report = compiled_report(rows, provenance, req.lights, req.shaders, [c.tool].into(), notes);
    report.cost = vendor.cost(&report);
    report
}

/// The rows (label, the agreement as the note) and the `dialect` sources of raw kernels, for a vendor that
/// compiles their translations.
fn raw_translations(vendor: &dyn Vendor, kernels: &[RawKernel], dialect: Dialect) -> Result<(Vec<Row>, Vec<Checked>)> {
    let mut rows = Vec::new();
    let mut checked = Vec::new();
    for k in kernels {
        let t = k.translation.as_ref().ok_or_else(|| {
            anyhow!("{}: {} compiles the kernel's translation, and none was checked", k.label, vendor.prefix())
        })?;
        rows.push(Row {
            model: k.label.clone(),
            spec: Some(k.model.canonical()),
            stats: BTreeMap::new(),
            notes: [("translation".to_string(), t.agreement.clone())].into(),
        });
        checked.push(Checked { source: t.translation.source(dialect), agreement: t.agreement.clone(), failed: None });
    }
    Ok((rows, checked))
}

/// Each family's report given its models' cost per source line when `req.lines`. The line-annotated translation
/// is not executed; its lines are reported for the checked, costed code only where the two compiles give the
/// same instruction sequence, else a note says they differ. `lines` compiles a model's line-annotated `dialect`
/// source (with its checked translation, `checked`, in the order of `kernels_of`) for a family and returns its
/// lines with both compiles' instruction sequences (the costed one's first).
fn add_lines<F>(
    reports: &mut [InspectReport],
    families: &[&F],
    req: &Request,
    checked: &[Checked],
    dialect: Dialect,
    mut lines: impl FnMut(&Model, &str, &str, &F) -> Result<LineCompile>,
) -> Result<()> {
    if !req.lines {
        return Ok(());
    }
    for (report, family) in reports.iter_mut().zip(families) {
        let mut per_model = Vec::new();
        // A fixed-pass twin's cost is the model's, whose lines these are.
        let costed = req.models.iter().zip(checked).filter(|(m, c)| c.failed.is_none() && !super::trips::is_twin(m));
        for (m, checked) in costed {
            let source = crate::translate::prepare::shade_kernel_with_lines(Some(m), req.lights, req.shaders)?
                .source_with_lines(dialect);
            let LineCompile { mut lines, costed, annotated } = lines(m, &source, &checked.source, family)?;
            if costed != annotated {
                lines.note = format!(
                    "the line-annotated compile is not the costed code ({} instructions against {}, not in the same sequence): its lines describe that compile",
                    annotated.len(),
                    costed.len()
                );
            }
            lines.mark_harness(matches!(m, Model::File(_)));
            if let Model::File(f) = m {
                // An HLSL or WGSL shader's lines are those of the GLSL its front end wrote: their text is the file
                // model's, not on disk; where the front end's line information names the user's file and line
                // (HLSL through glslang), the cost moves there.
                for l in lines.lines.iter_mut().filter(|l| l.text.is_empty()) {
                    l.text = f.file.front_end_line(&l.file, l.line).unwrap_or_default().to_string();
                }
                super::cost::lines::moved(&mut lines, |l| {
                    let (file, line, text) = f.file.front_end_origin(&l.file, l.line)?;
                    Some((file.clone(), *line as u32, text.clone()))
                });
            }
            per_model.push(lines);
        }
        report.lines = per_model;
    }
    Ok(())
}

/// A model's line costs and the instruction sequences (one entry per instruction: its opcode and what the
/// vendor's listing says of its width and type) of the costed compile and of the line-annotated one.
pub struct LineCompile {
    pub lines: crate::schema::lines::KernelLines,
    pub costed: Vec<String>,
    pub annotated: Vec<String>,
}

/// The line an instruction is charged to: the innermost of `chain` (its location, then the call sites it was
/// inlined at) that is a source's, not the translation's own (`TRANSLATION_FILE`: its prelude helpers and
/// entry); None where every one is the translation's.
pub fn user_source(chain: &[(String, u32)]) -> Option<(String, u32)> {
    chain.iter().find(|(file, line)| !file.ends_with(crate::translate::TRANSLATION_FILE) && *line > 0).cloned()
}
