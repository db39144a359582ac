//! Do the counts explain the timings? Joins inspect's callgrind figures (instructions per evaluation) with
//! a `brdfprof profile` JSON report (ns per evaluation) model by model, and gives Spearman's rank correlation
//! between them, gross and net of the memory-only kernel.

use super::InspectReport;
use crate::profile::ProfileReport as ProfileView;
use crate::stats;
use anyhow::{anyhow, bail, Context, Result};
use serde::{Deserialize, Serialize};
use std::path::Path;

#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct CostRow {
    pub model: String,
    pub ir_per_eval: f64,
    pub net_ir_per_eval: Option<f64>,
    pub ns_per_eval: f64,
    pub net_ns_per_eval: Option<f64>,
    /// Net Ir relative to the reference model's net Ir.
    pub net_ir_vs_reference: Option<f64>,
    /// The profile's net cost relative to its reference model, per-round median.
    pub net_vs_reference: Option<f64>,
}

#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct Correlation {
    /// The profile report read.
    pub profile: String,
    pub profile_lights: u64,
    /// The profile's reference model (ggx), which the `vs` columns divide by.
    pub reference: String,
    pub rows: Vec<CostRow>,
    /// Spearman's rho between net Ir and net ns per evaluation over the models.
    pub spearman_net: Option<f64>,
    /// Spearman's rho between gross Ir and gross ns per evaluation over every kernel, baseline included.
    pub spearman_gross: Option<f64>,
    /// Their percentile-bootstrap 95% CIs (`stats::spearman_ci`; None below 4 kernels).
    #[serde(default)]
    pub spearman_net_ci: Option<(f64, f64)>,
    #[serde(default)]
    pub spearman_gross_ci: Option<(f64, f64)>,
}

/// The bootstrap CI of `rho`'s pairs.
fn rho_ci(pairs: &[(f64, f64)]) -> Option<(f64, f64)> {
    stats::spearman_ci(&pairs.iter().map(|p| p.0).collect::<Vec<_>>(), &pairs.iter().map(|p| p.1).collect::<Vec<_>>(), 0.95)
}

/// rho and its CI as a table's text says them.
fn rho_text(rho: Option<f64>, ci: Option<(f64, f64)>) -> String {
    match (rho, ci) {
        (None, _) => "-".into(),
        (Some(r), Some((lo, hi))) => format!("{r:.2} [95% CI {lo:.2}, {hi:.2}]"),
        (Some(_), None) => "- (too few kernels for a CI)".into(),
    }
}

/// Spearman's rho, where there are at least three pairs to rank.
fn rho(pairs: &[(f64, f64)]) -> Option<f64> {
    (pairs.len() >= 3).then(|| stats::spearman(&pairs.iter().map(|p| p.0).collect::<Vec<_>>(), &pairs.iter().map(|p| p.1).collect::<Vec<_>>()))
}

/// A `brdfprof profile` report, read (before anything is measured, so that a bad file fails at once).
pub struct ProfileReport {
    pub file: String,
    pub view: ProfileView,
}

/// Reads the profile report at `path`: JSON with a `rows` array.
pub fn load_profile(path: &Path) -> Result<ProfileReport> {
    let file = path.display().to_string();
    let text = String::from_utf8(crate::io::read_bounded(path, crate::io::MAX_REPORT_BYTES).with_context(|| format!("--profile {file}"))?).map_err(|_| anyhow::anyhow!("--profile {file}: not UTF-8 text: not a brdfprof profile report"))?;
    let json: serde_json::Value = serde_json::from_str(&text).map_err(|e| anyhow!("--profile {file}: not valid JSON ({e})"))?;
    if !json["rows"].is_array() {
        bail!("--profile {file}: no `rows` array (is it a `brdfprof profile` report?)");
    }
    let view = serde_json::from_value(json).map_err(|e| anyhow!("--profile {file}: not a brdfprof profile report ({e})"))?;
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

impl Correlation {
    pub fn markdown(&self) -> String {
        let f = |v: Option<f64>| v.map_or("-".to_string(), |v| crate::export::markdown::sig(v, 3));
        let reference = &self.reference;
        let mut t = crate::export::markdown::Table::new([
            "model".to_string(),
            "Ir/eval".into(),
            "net Ir/eval".into(),
            format!("net Ir vs {reference}"),
            "ns/eval".into(),
            "net ns/eval".into(),
            format!("net ns vs {reference}"),
        ]);
        for r in &self.rows {
            t.row([
                r.model.clone(),
                f(Some(r.ir_per_eval)),
                f(r.net_ir_per_eval),
                f(r.net_ir_vs_reference),
                f(Some(r.ns_per_eval)),
                f(r.net_ns_per_eval),
                f(r.net_vs_reference),
            ]);
        }
        format!(
            "Timings from {} ({} lights). Spearman's rank correlation (CIs by percentile bootstrap over the kernels), net of the memory-only kernel (models): {}; gross (every kernel): {}.\n\n{}",
            self.profile,
            self.profile_lights,
            rho_text(self.spearman_net, self.spearman_net_ci),
            rho_text(self.spearman_gross, self.spearman_gross_ci),
            t.markdown()
        )
    }
}
