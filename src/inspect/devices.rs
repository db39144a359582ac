//! `inspect` over several devices: Vulkan devices of this machine (each opened in turn) and compile-only
//! targets (`targets`), one report each, then one cost table across them with every pair's rank correlation
//! and, with `--profile`, a profile's measured costs beside them.

use crate::compare::{self, CostTable};
use crate::gpu::Gpu;
use crate::inspect::InspectOptions;
use crate::inspect::correlate::{self, ProfileReport};
use crate::schema::InspectReport;
use crate::shaders::Shaders;
use crate::targets::{self, Target};
use anyhow::{Result, anyhow};
use serde::Serialize;
use std::path::Path;

/// What one `--device` stands for.
pub enum Planned {
    /// A Vulkan device of this machine (None: the default one).
    Local(Option<String>),
    Target(Target),
}

/// The devices in the order given (a target named twice is measured once); the default device alone when
/// none is given.
pub fn plan(devices: &[String]) -> Result<Vec<Planned>> {
    if devices.is_empty() {
        return Ok(vec![Planned::Local(None)]);
    }
    let mut out: Vec<Planned> = Vec::new();
    for d in devices {
        match targets::parse(d).map_err(|e| anyhow!("--device {d}: {e:#}"))? {
            Some(ts) => {
                for t in ts {
                    if !out.iter().any(|p| matches!(p, Planned::Target(x) if *x == t)) {
                        out.push(Planned::Target(t));
                    }
                }
            }
            None => out.push(Planned::Local(Some(d.clone()))),
        }
    }
    Ok(out)
}

/// How to run the plan.
pub struct Run<'a> {
    pub options: &'a InspectOptions,
    pub shaders: &'a Shaders,
    pub validate: bool,
    pub isa_dir: Option<&'a Path>,
    pub precise: bool,
    /// Cost per source line on the targets that name lines (`targets::Request::lines`).
    pub lines: bool,
}

/// Opens a local device (None: the default) and runs `work` on it; the CLI's (progress, validation check).
pub type OpenLocal<'a> = dyn Fn(Option<&str>, &mut dyn FnMut(&Gpu) -> Result<()>) -> Result<()> + 'a;

/// The JSON of `inspect` over several devices, and what `report` reads back (`format` is not read).
#[derive(Clone, Debug, Serialize, serde::Deserialize)]
pub struct MultiReport {
    #[serde(skip_deserializing)]
    pub format: &'static str,
    pub reports: Vec<InspectReport>,
    pub costs: CostTable,
    /// Why a `--profile` report is not in the cost table, if it is not.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub profile_note: Option<String>,
}

/// What `inspect` produced: one report per device, the markdown of them all, and with several devices the
/// combined JSON.
pub struct Inspected {
    pub reports: Vec<InspectReport>,
    pub multi: Option<MultiReport>,
    pub markdown: String,
}

impl Inspected {
    /// Each model's headline figure per device or target, as benchmark-dashboard entries named
    /// `inspect/<target or device>/<model>`: a compile-only target's modelled cycles per evaluation (its cost
    /// rule), a device's callgrind instructions per evaluation where measured.
    pub fn bench_entries(&self) -> Vec<crate::export::bench::Entry> {
        use crate::export::bench::Entry;
        let mut out = Vec::new();
        for report in &self.reports {
            let device = report.provenance["device"]["name"].as_str().unwrap_or("device");
            match &report.cost {
                Some(cost) => {
                    let on = cost.target.clone().unwrap_or_else(|| crate::export::name_slug(device));
                    out.extend(cost.rows.iter().filter(|r| r.model != crate::model::BASELINE_LABEL).map(|r| Entry {
                        name: format!("inspect/{on}/{}", r.model),
                        unit: format!("{}/eval", cost.unit),
                        value: r.cycles_per_eval,
                        range: None,
                        interval: None,
                        extra: format!("modelled, not measured: {} ({})", cost.model, cost.compiler),
                    }));
                }
                None => {
                    out.extend(report.rows.iter().filter(|r| r.model != crate::model::BASELINE_LABEL).filter_map(|r| {
                        Some(Entry {
                            name: format!("inspect/{}/{}", crate::export::name_slug(device), r.model),
                            unit: "instructions/eval (callgrind)".into(),
                            value: *r.stats.get("callgrind/ir-per-eval")?,
                            range: None,
                            interval: None,
                            extra: format!(
                                "CPU instructions per evaluation of lavapipe's JIT code under callgrind, on {device}"
                            ),
                        })
                    }))
                }
            }
        }
        out
    }

    /// The outputs' default file stem: `inspect-<device>` for one device, `inspect-devices` for several.
    pub fn stem(&self) -> String {
        match &self.multi {
            None => format!("inspect-{}", slug(&self.reports[0])),
            Some(_) => "inspect-devices".to_string(),
        }
    }

    /// The JSON written: the one device's report, or the combined report of several.
    pub fn json_value(&self) -> Result<serde_json::Value> {
        let (kind, mut value) = match &self.multi {
            None => (crate::export::json::Kind::Inspect, serde_json::to_value(&self.reports[0])?),
            Some(m) => (crate::export::json::Kind::InspectDevices, serde_json::to_value(m)?),
        };
        if let Some(map) = value.as_object_mut() {
            map.insert("kind".into(), kind.name().into());
        }
        Ok(value)
    }
}

/// The compile-only targets' runs: the default Vulkan device opened first for the targets whose costs are of
/// a translation that must run before it is believed.
fn target_reports(plan: &[Planned], run: &Run, open: &OpenLocal) -> Result<Vec<InspectReport>> {
    let targets: Vec<Target> =
        plan.iter().filter_map(|p| if let Planned::Target(t) = p { Some(*t) } else { None }).collect();
    if targets.is_empty() {
        return Ok(Vec::new());
    }
    let compile = |verify_on: Option<&Gpu>| -> Result<Vec<InspectReport>> {
        let request = targets::Request {
            models: &run.options.models,
            lights: run.options.lights,
            shaders: run.shaders,
            validate: run.validate,
            isa_dir: run.isa_dir,
            precise: run.precise,
            verify_on,
            lines: run.lines,
        };
        let runs = targets::compile_all(&targets, &request)?;
        for r in &runs {
            if let Some(n) = &r.note {
                crate::messages::note(n);
            }
            if !r.isa_files.is_empty() {
                crate::messages::progress(format!("inspect: {}: {} ISA files", r.target.name(), r.isa_files.len()));
            }
        }
        Ok(runs.into_iter().map(|r| r.report).collect())
    };
    if !targets.iter().any(|t| t.vendor.needs_verification()) {
        return compile(None);
    }
    let mut reports = Vec::new();
    open(None, &mut |gpu| {
        reports = compile(Some(gpu))?;
        Ok(())
    })?;
    Ok(reports)
}

/// Runs every planned device, in order.
/// The reference (ggx) is added first when the models lack it, as `profile` adds it, so that every device's
/// "net vs ggx" column has its denominator.
pub fn inspect(plan: &[Planned], run: &Run, open: &OpenLocal, profile: Option<&ProfileReport>) -> Result<Inspected> {
    let options = InspectOptions { models: crate::model::with_reference(&run.options.models), ..run.options.clone() };
    let run = &Run { options: &options, ..*run };
    let mut compiled = target_reports(plan, run, open)?.into_iter();
    let mut reports = Vec::new();
    for p in plan {
        match p {
            Planned::Local(device) => {
                let mut report = None;
                open(device.as_deref(), &mut |gpu| {
                    report = Some(crate::inspect::run(gpu, run.shaders, run.options)?);
                    Ok(())
                })?;
                reports.push(report.expect("the device ran"));
            }
            Planned::Target(_) => reports.push(compiled.next().expect("one report per target")),
        }
    }
    if let Some(p) = profile {
        for r in reports.iter_mut().filter(|r| r.callgrind.is_some()) {
            r.vs_profile = Some(correlate::correlate_with(r, p)?);
        }
    }
    if reports.len() == 1 {
        let r = &reports[0];
        let markdown = format!("# brdfprof inspect\n\n{}\n\n{}", r.summary(), r.markdown());
        return Ok(Inspected { reports, multi: None, markdown });
    }
    let (costs, profile_note) = cost_table(&reports, profile)?;
    let markdown = multi_markdown(&reports, &costs, profile_note.as_deref());
    let multi = MultiReport { format: "brdfprof-inspect-devices/1", reports: reports.clone(), costs, profile_note };
    Ok(Inspected { reports, multi: Some(multi), markdown })
}

/// The cost table of several reports, with a profile's columns first where its kernels are the same.
fn cost_table(reports: &[InspectReport], profile: Option<&ProfileReport>) -> Result<(CostTable, Option<String>)> {
    let mut columns: Vec<compare::CostColumn> = Vec::new();
    let mut profile_note = None;
    if let Some(p) = profile {
        let cols = compare::profile_columns(&p.view, &format!("{}: ", p.file));
        let mut all = cols.clone();
        all.extend(reports.iter().flat_map(|r| compare::inspect_columns(r, "")));
        match compare::check_kernels(&all) {
            Ok(()) => columns.extend(cols),
            Err(e) => profile_note = Some(format!("--profile {} is not in the cost table: {e:#}", p.file)),
        }
    }
    for r in reports {
        columns.extend(compare::inspect_columns(r, ""));
    }
    Ok((compare::build(columns).with_spirv_baseline(&compare::spirv_counts(reports)), profile_note))
}

/// Each device's section (a compile-only target's cost table alone: its SPIR-V and naga counts are every
/// device's), then the table across devices.
fn multi_markdown(reports: &[InspectReport], costs: &CostTable, profile_note: Option<&str>) -> String {
    let mut text = String::from("# brdfprof inspect\n\n");
    for r in reports {
        text += &format!("## {}\n\n{}\n\n", r.provenance["device"]["name"].as_str().unwrap_or("?"), r.summary());
        match (&r.cost, targets::of_report(r)) {
            (Some(c), Some(_)) => {
                text += &c.markdown();
                text += "\n";
                if let Some(n) = r.section_notes.get("driver/") {
                    text += &format!("{n}\n\n");
                }
                text += &r.lines_markdown();
            }
            _ => text += &r.markdown(),
        }
    }
    text += &costs.markdown();
    if let Some(n) = profile_note {
        text += &format!("{n}\n");
    }
    text
}

/// A file-name form of a report's device: `radv-navi21`, `nvidia-sm_89`, `llvmpipe`.
pub fn slug(report: &InspectReport) -> String {
    if let Some(t) = targets::of_report(report) {
        return t.slug();
    }
    crate::export::name_slug(report.provenance["device"]["name"].as_str().unwrap_or("device"))
}
