//! One HTML report from saved results (`brdfprof report`, and `--html` on the measuring commands): provenance,
//! cost tables with their confidence intervals, the cost table across devices with rank correlations, the
//! sweep's accuracy-against-cost chart, per-model lobes, lit spheres and directional albedo, and stability
//! heat maps. Reports are read back as the very types their commands write (`ProfileReport`, `SweepReport`,
//! `StabilityReport`, `InspectReport`, `DiffReport`), so a field cannot be written one way and read another.
//! Lobes, spheres and albedo are evaluated at report time by the GPU kernels on the device given
//! (docs/report.md says why).

pub mod diff;
pub mod sections;
pub mod shapes;
pub mod summary;

use crate::compare::CostTable;
use crate::export::html::{self, Page};
use crate::gpu::Gpu;
use crate::profile::ProfileReport;
use crate::schema::InspectReport;
use crate::stability::StabilityReport;
use crate::sweep::SweepReport;
use anyhow::{Result, anyhow, bail};
use serde::Deserialize;
use serde::de::{DeserializeOwned, IgnoredAny};
use std::path::{Path, PathBuf};

/// What a results file holds.
pub enum Loaded {
    Profile(Box<ProfileReport>),
    Sweep(Box<SweepReport>),
    Stability(Box<StabilityReport>),
    /// One inspect report per device, and with several devices the inspect's own cost table.
    Inspect(Vec<InspectReport>, Option<CostTable>),
    /// A `brdfprof compare` table.
    Costs(CostTable),
    /// A `brdfprof diff` result.
    Diff(Box<crate::diff::DiffReport>),
    /// A `brdfprof diff --reference` result: every model against one reference.
    DiffSet(Box<crate::diff::DiffSet>),
}

impl Loaded {
    pub fn kind(&self) -> &'static str {
        match self {
            Loaded::Profile(_) => "profile",
            Loaded::Sweep(_) => "sweep",
            Loaded::Stability(_) => "stability",
            Loaded::Inspect(..) => "inspect",
            Loaded::Costs(_) => "compare",
            Loaded::Diff(_) => "diff",
            Loaded::DiffSet(_) => "diff-set",
        }
    }
}

/// One results file, read.
pub struct Input {
    pub path: PathBuf,
    pub loaded: Loaded,
}

/// The keys that tell the report kinds apart (each kind's writer puts them there).
#[derive(Deserialize)]
struct Probe {
    fastest: Option<IgnoredAny>,
    workload: Option<IgnoredAny>,
    grid_points: Option<IgnoredAny>,
    kernels: Option<IgnoredAny>,
    reports: Option<IgnoredAny>,
    correlations: Option<IgnoredAny>,
    kind: Option<String>,
}

/// The largest results file read (`io::MAX_REPORT_BYTES`).
pub const MAX_INPUT_BYTES: u64 = crate::io::MAX_REPORT_BYTES;

fn parse<T: DeserializeOwned>(path: &Path, text: &str, kind: &str) -> Result<T> {
    let de = &mut serde_json::Deserializer::from_str(text);
    serde_path_to_error::deserialize(de).map_err(|e| {
        anyhow!("{}: not a brdfprof {kind} report: at JSON path `{}`: {}", path.display(), e.path(), e.inner())
    })
}

/// Reads a profile, sweep, stability, inspect (one device or several) or compare JSON report.
pub fn load(path: &Path) -> Result<Input> {
    // A regular file within the bound (`report /dev/zero` read without end before).
    let bytes = crate::io::read_bounded(path, MAX_INPUT_BYTES)?;
    let text = String::from_utf8(bytes).map_err(|e| {
        anyhow!(
            "{}: not UTF-8 text at byte {}: not a brdfprof JSON report",
            path.display(),
            e.utf8_error().valid_up_to()
        )
    })?;
    from_json(path, &text)
}

/// A report just measured, read back through its JSON as a saved one would be (`--html`): what the page
/// shows is what the JSON says.
pub fn from_report(label: &Path, report: &impl serde::Serialize) -> Result<Input> {
    from_json(label, &serde_json::to_string(report)?)
}

/// Reads a report's JSON text; `path` names it in errors.
pub fn from_json(path: &Path, text: &str) -> Result<Input> {
    let text = text.to_string();
    let probe: Probe = serde_json::from_str(&text)
        .map_err(|e| anyhow!("{}: not a JSON object: line {}, column {}: {e}", path.display(), e.line(), e.column()))?;
    use crate::export::json::Kind;
    // A report that names its kind is read as that kind; older ones, without `kind`, by their keys.
    let named = match probe.kind.as_deref() {
        None | Some("diff") | Some(crate::diff::SET_KIND) => None,
        Some(k) => Some(Kind::parse(k).ok_or_else(|| {
            anyhow!(
                "{}: at JSON path `kind`: `{k}` is not a kind of brdfprof report ({})",
                path.display(),
                Kind::ALL.map(Kind::name).join(", ")
            )
        })?),
    };
    let loaded = if let Some(kind) = named {
        match kind {
            Kind::Profile => Loaded::Profile(parse(path, &text, "profile")?),
            Kind::Sweep => Loaded::Sweep(parse(path, &text, "sweep")?),
            Kind::Stability => Loaded::Stability(parse(path, &text, "stability")?),
            Kind::Inspect => Loaded::Inspect(vec![parse(path, &text, "inspect")?], None),
            Kind::InspectDevices => {
                let m: crate::inspect::devices::MultiReport = parse(path, &text, "inspect (several devices)")?;
                Loaded::Inspect(m.reports, Some(m.costs))
            }
            Kind::Compare => Loaded::Costs(parse(path, &text, "compare")?),
            Kind::SceneProfile | Kind::SweepCost | Kind::SweepFrontiers | Kind::Baseline => bail!(
                "{}: a `{}` report, which the HTML report does not draw (its tables are in the Markdown written beside it); give profile, sweep, stability, inspect, compare or diff reports",
                path.display(),
                kind.name()
            ),
        }
    } else if probe.fastest.is_some() {
        Loaded::Sweep(parse(path, &text, "sweep")?)
    } else if probe.workload.is_some() {
        Loaded::Profile(parse(path, &text, "profile")?)
    } else if probe.grid_points.is_some() {
        Loaded::Stability(parse(path, &text, "stability")?)
    } else if probe.reports.is_some() {
        let m: crate::inspect::devices::MultiReport = parse(path, &text, "inspect (several devices)")?;
        Loaded::Inspect(m.reports, Some(m.costs))
    } else if probe.kernels.is_some() {
        Loaded::Inspect(vec![parse(path, &text, "inspect")?], None)
    } else if probe.correlations.is_some() {
        Loaded::Costs(parse(path, &text, "compare")?)
    } else if probe.kind.as_deref() == Some("diff") {
        Loaded::Diff(parse(path, &text, "diff")?)
    } else if probe.kind.as_deref() == Some(crate::diff::SET_KIND) {
        Loaded::DiffSet(parse(path, &text, "diff --reference")?)
    } else {
        bail!(
            "{}: not a brdfprof profile, sweep, stability, inspect, compare or diff JSON report (none of the keys `fastest`, `workload`, `grid_points`, `reports`, `kernels`, `correlations`, nor `\"kind\": \"diff\"` at its top level)",
            path.display()
        );
    };
    Ok(Input { path: path.to_path_buf(), loaded })
}

/// The report page of `inputs`; with `gpu`, each model's lobes, spheres and albedo evaluated on it.
pub fn build(inputs: &[Input], gpu: Option<&Gpu>) -> Result<String> {
    let mut page = Page::new("brdfprof report");
    if let Some(body) = summary::summary(inputs) {
        page.section("summary", "Summary", body);
    }
    let costs = sections::profiles(inputs);
    if !costs.is_empty() {
        page.section("costs", "Cost per evaluation", costs);
    }
    if let Some(body) = sections::across_devices(inputs) {
        page.section("devices", "Across devices", body);
    }
    let lines = sections::source_lines(inputs);
    if !lines.is_empty() {
        page.section("lines", "Cost per source line", lines);
    }
    let sweeps = sections::sweeps(inputs);
    if !sweeps.is_empty() {
        page.section("sweep", "Accuracy against cost", sweeps);
    }
    let models = shapes::models_of(inputs);
    if !models.is_empty() {
        let body = match gpu {
            Some(gpu) => shapes::section(gpu, &models)?,
            None => "<p class=\"note\">Not drawn: the report was built without a device (--no-gpu).</p>".to_string(),
        };
        page.section("models", "Lobes, lit spheres and directional albedo", body);
    }
    let stability = sections::stability(inputs)?;
    if !stability.is_empty() {
        page.section("stability", "Stability", stability);
    }
    let diffs = diff::diffs(inputs, gpu)?;
    if !diffs.is_empty() {
        page.section("diff", "Models side by side (brdfprof diff)", diffs);
    }
    // Where each figure comes from, folded: it filled the first screen when it came first.
    page.section(
        "provenance",
        "Provenance",
        format!(
            "<details><summary>Device, driver, CPU, tools and command of each report ({})</summary>{}</details>",
            inputs.len(),
            sections::provenance(inputs)
        ),
    );
    Ok(page.render())
}

/// Builds the page of `inputs` and writes it to `out` (atomically); returns its size in bytes.
pub fn write(inputs: &[Input], out: &Path, gpu: Option<&Gpu>) -> Result<usize> {
    if inputs.is_empty() {
        bail!("report needs at least one RESULTS.json (a profile, sweep, stability, inspect, compare or diff report)");
    }
    let page = build(inputs, gpu)?;
    crate::io::write_output(out, page.as_bytes())?;
    Ok(page.len())
}

/// "YYYY-MM-DD HH:MM UTC" of a Unix time (days to a civil date: the proleptic Gregorian calendar).
pub fn utc(unix: u64) -> String {
    let (days, secs) = ((unix / 86_400) as i64, unix % 86_400);
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let day = doy - (153 * mp + 2) / 5 + 1;
    let month = if mp < 10 { mp + 3 } else { mp - 9 };
    let year = yoe + era * 400 + i64::from(month <= 2);
    format!("{year:04}-{month:02}-{day:02} {:02}:{:02} UTC", secs / 3600, secs % 3600 / 60)
}

/// A file's name for headings.
pub fn file_label(path: &Path) -> String {
    html::esc(&path.display().to_string())
}

#[cfg(test)]
mod tests {
    use super::utc;

    #[test]
    fn utc_dates_match_known_instants() {
        assert_eq!(utc(0), "1970-01-01 00:00 UTC");
        assert_eq!(utc(951_782_400), "2000-02-29 00:00 UTC");
        assert_eq!(utc(1_796_163_856), "2026-12-01 22:24 UTC");
    }
}
