//! Do the counts explain the timings? Joins inspect's callgrind figures (instructions per evaluation) with
//! a `brdfprof profile` JSON report (ns per evaluation) model by model, and gives Spearman's rank correlation
//! between them, gross and net of the memory-only kernel.

use crate::profile::ProfileReport as ProfileView;
use crate::schema::InspectReport;
use crate::schema::correlation::{Correlation, CostRow};
use crate::stats;
use anyhow::{Context, Result, anyhow, bail};
use std::path::Path;

/// The bootstrap CI of `rho`'s pairs.
fn rho_ci(pairs: &[(f64, f64)]) -> Option<(f64, f64)> {
    stats::spearman_ci(
        &pairs.iter().map(|p| p.0).collect::<Vec<_>>(),
        &pairs.iter().map(|p| p.1).collect::<Vec<_>>(),
        0.95,
    )
}

/// Spearman's rho, where there are at least three pairs to rank.
fn rho(pairs: &[(f64, f64)]) -> Option<f64> {
    (pairs.len() >= 3).then(|| {
        stats::spearman(&pairs.iter().map(|p| p.0).collect::<Vec<_>>(), &pairs.iter().map(|p| p.1).collect::<Vec<_>>())
    })
}

/// A `brdfprof profile` report, read (before anything is measured, so that a bad file fails at once).
pub struct ProfileReport {
    pub file: String,
    pub view: ProfileView,
}

/// Reads the profile report at `path`: JSON with a `rows` array.
pub fn load_profile(path: &Path) -> Result<ProfileReport> {
    let file = path.display().to_string();
    let text = String::from_utf8(
        crate::io::read_bounded(path, crate::io::MAX_REPORT_BYTES).with_context(|| format!("--profile {file}"))?,
    )
    .map_err(|_| anyhow::anyhow!("--profile {file}: not UTF-8 text: not a brdfprof profile report"))?;
    let json: serde_json::Value =
        serde_json::from_str(&text).map_err(|e| anyhow!("--profile {file}: not valid JSON ({e})"))?;
    if !json["rows"].is_array() {
        bail!("--profile {file}: no `rows` array (is it a `brdfprof profile` report?)");
    }
    let view =
        serde_json::from_value(json).map_err(|e| anyhow!("--profile {file}: not a brdfprof profile report ({e})"))?;
    Ok(ProfileReport { file, view })
}

/// Joins `report`'s callgrind figures with the profile report at `path`.
pub fn correlate(report: &InspectReport, path: &Path) -> Result<Correlation> {
    correlate_with(report, &load_profile(path)?)
}

/// Joins `report`'s callgrind figures with a profile report already read.
pub fn correlate_with(report: &InspectReport, profile: &ProfileReport) -> Result<Correlation> {
    let (file, profile) = (profile.file.clone(), &profile.view);
    let mut out = Vec::new();
    for row in &report.rows {
        let Some(ir) = row.stats.get("callgrind/ir-per-eval") else { continue };
        let model = row.model.as_str();
        // A profile of several light counts: the rows at the count inspect measured.
        let Some(p) = profile.rows.iter().find(|r| r.lights == report.lights && r.model == model) else { continue };
        out.push(CostRow {
            model: row.model.clone(),
            ir_per_eval: *ir,
            net_ir_per_eval: row.stats.get("callgrind/net-ir-per-eval").copied(),
            ns_per_eval: p.ns_per_eval.median,
            net_ns_per_eval: p.net_ns_per_eval.as_ref().map(|e| e.median),
            net_ir_vs_reference: None,
            net_vs_reference: p.net_vs_reference.as_ref().map(|e| e.median),
        });
    }
    let reference = profile.reference.clone();
    if let Some(reference_ir) = out.iter().find(|r| r.model == reference).and_then(|r| r.net_ir_per_eval) {
        for r in &mut out {
            r.net_ir_vs_reference = r.net_ir_per_eval.map(|n| n / reference_ir);
        }
    }
    if out.is_empty() {
        bail!("--profile {file}: no model of this report has both a callgrind figure and a profile row");
    }
    let net: Vec<(f64, f64)> = out.iter().filter_map(|r| Some((r.net_ir_per_eval?, r.net_ns_per_eval?))).collect();
    let gross: Vec<(f64, f64)> = out.iter().map(|r| (r.ir_per_eval, r.ns_per_eval)).collect();
    Ok(Correlation {
        profile: file,
        // The profile's light counts (a list since `--lights 1,8,64`; a number in older reports); the rows used are
        // those at the inspected count.
        profile_lights: u64::from(report.lights),
        reference,
        spearman_net: rho(&net),
        spearman_gross: rho(&gross),
        spearman_net_ci: rho_ci(&net),
        spearman_gross_ci: rho_ci(&gross),
        rows: out,
    })
}
