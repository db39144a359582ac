//! A correlation of inspect's callgrind figures with a profile's timings, model by model (`inspect --profile`).

use serde::{Deserialize, Serialize};

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

/// rho and its CI as a table's text says them.
fn rho_text(rho: Option<f64>, ci: Option<(f64, f64)>) -> String {
    match (rho, ci) {
        (None, _) => "-".into(),
        (Some(r), Some((lo, hi))) => format!("{r:.2} [95% CI {lo:.2}, {hi:.2}]"),
        (Some(_), None) => "- (too few kernels for a CI)".into(),
    }
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
