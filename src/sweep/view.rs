//! The sweep report (`SweepReport`) as read back by `brdfprof report` and `--html`. Errors that are NaN or
//! Inf (a spec that returns NaN somewhere) are written as JSON null and read as None.

use crate::profile::view::ProfileView;
use crate::stats::Estimate;
use serde::Deserialize;

/// `accuracy::ErrorStats` as read back: None where the error is infinite (NaN or Inf values).
#[derive(Clone, Debug, Deserialize)]
pub struct ErrorView {
    pub max: Option<f64>,
    pub rms: Option<f64>,
    #[serde(default)]
    pub nonfinite: usize,
    #[serde(default)]
    pub values: usize,
}

/// `accuracy::Accuracy` as read back.
#[derive(Clone, Debug, Deserialize)]
pub struct AccuracyView {
    pub numerical: Option<ErrorView>,
    pub vs_exact: ErrorView,
    pub formula_vs_exact: Option<ErrorView>,
    pub albedo_vs_exact: Option<f64>,
    pub reference: Option<String>,
}

/// `SweepRow` as read back.
#[derive(Clone, Debug, Deserialize)]
pub struct SweepRowView {
    pub spec: String,
    pub canonical: String,
    pub label: String,
    pub ns_per_eval: Estimate,
    pub net_ns_per_eval: Option<Estimate>,
    pub cost_vs_fastest: Estimate,
    pub rank: usize,
    pub tied: bool,
    pub accuracy: AccuracyView,
    pub pareto: bool,
}

/// `SweepReport` as read back.
#[derive(Clone, Debug, Deserialize)]
pub struct SweepView {
    pub fastest: String,
    pub rows: Vec<SweepRowView>,
    pub sample_set: String,
    /// What "vs exact" is against (absent before the sweep took a reference for every model).
    #[serde(default)]
    pub against: Option<String>,
    pub profile: ProfileView,
}
