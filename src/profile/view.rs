//! The profile report (`ProfileReport`) as read back by `brdfprof report` and `--html`: the fields a reader
//! shows, typed. Figures that can be NaN or Inf (written as JSON null) are Options.

use crate::export::json::Provenance;
use crate::stats::Estimate;
use serde::Deserialize;
use std::collections::BTreeMap;

#[derive(Clone, Debug, Deserialize)]
pub struct WorkloadView {
    pub width: u32,
    pub height: u32,
    pub lights: Vec<u32>,
    #[serde(default)]
    pub bytes_per_pixel: u64,
}

/// `profile::Row` as read back.
#[derive(Clone, Debug, Deserialize)]
pub struct RowView {
    pub model: String,
    pub spec: Option<String>,
    pub lights: u32,
    pub ns_per_eval: Estimate,
    pub vs_reference: Option<Estimate>,
    pub net_ns_per_eval: Option<Estimate>,
    pub net_vs_reference: Option<Estimate>,
    pub harness_share: Option<Estimate>,
}

/// `ProfileReport` as read back.
#[derive(Clone, Debug, Deserialize)]
pub struct ProfileView {
    pub provenance: Provenance,
    pub reference: String,
    pub workload: WorkloadView,
    pub rounds: usize,
    pub confidence_level: f64,
    pub rows: Vec<RowView>,
    #[serde(default)]
    pub kernel_sha256: BTreeMap<String, String>,
}

impl ProfileView {
    /// The rows of models (not the memory-only kernel), in report order.
    pub fn model_rows(&self) -> impl Iterator<Item = &RowView> {
        self.rows.iter().filter(|r| r.spec.is_some())
    }
}
