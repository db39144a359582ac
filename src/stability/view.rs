//! The stability report (`StabilityReport`) as read back by `brdfprof report` and `--html`. Values that are
//! NaN or Inf are written as JSON null and read as None.

use crate::export::json::Provenance;
use serde::Deserialize;

#[derive(Clone, Debug, Deserialize)]
pub struct CaseView {
    pub name: String,
}

/// `CaseResult` as read back.
#[derive(Clone, Debug, Deserialize)]
pub struct CaseResultView {
    pub case: String,
    pub deviation: Option<f64>,
}

/// `Worst` as read back.
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(default)]
pub struct WorstView {
    pub deviation: Option<f64>,
    pub input: String,
}

/// `energy::Energy` as read back: E[roughness][NoV] over `energy::ROUGHNESS` x `energy::NOV`.
#[derive(Clone, Debug, Deserialize)]
pub struct EnergyView {
    pub e: Vec<Vec<Option<f32>>>,
    pub max_e: Option<f64>,
    pub gains_energy: bool,
    pub hemispherical_at_r1: Option<f64>,
}

/// `SpecStability` as read back; `bad_cells` as the report writes them: [roughness index, NoV index, count]
/// over `grid::ROUGHNESS` x `grid::COSINES`.
#[derive(Clone, Debug, Deserialize)]
pub struct SpecView {
    /// `Model::label` (reports written before labels: empty, read as `spec`).
    #[serde(default)]
    pub label: String,
    pub spec: String,
    pub precision: String,
    #[serde(default)]
    pub has_twin: bool,
    /// What it was checked against (None: nothing; reports written before it: read from `has_twin`).
    #[serde(default)]
    pub expected_from: Option<String>,
    /// Whether jumps were looked for (reports written before it counted them always).
    #[serde(default)]
    pub jumps_checked: Option<bool>,
    #[serde(default)]
    pub failures: Option<crate::stability::failures::FailuresView>,
    pub nan: usize,
    pub inf: usize,
    pub negative: usize,
    #[serde(default)]
    pub invalid_input_poisoned: usize,
    pub cases_run: usize,
    pub cases_out_of_tolerance: Vec<CaseResultView>,
    pub grid_out_of_tolerance: usize,
    #[serde(default)]
    pub worst: WorstView,
    #[serde(default)]
    pub discontinuities: usize,
    #[serde(default)]
    pub model_jumps: usize,
    pub reciprocity: Option<f64>,
    pub bad_cells: Option<Vec<[u32; 3]>>,
    pub energy: Option<EnergyView>,
}

impl SpecView {
    /// What to call it: its label, or its spec in a report written before labels.
    pub fn label(&self) -> &str {
        if self.label.is_empty() { &self.spec } else { &self.label }
    }

    /// Whether its values were checked against expected ones (a twin or a reference).
    pub fn checked(&self) -> bool {
        self.has_twin || self.expected_from.is_some()
    }

    /// NaN, Inf or a negative value on a valid input (as `SpecStability::fails`).
    pub fn fails(&self) -> bool {
        self.nan + self.inf + self.negative > 0
    }
}

/// `StabilityReport` as read back.
#[derive(Clone, Debug, Deserialize)]
pub struct StabilityView {
    pub provenance: Provenance,
    pub specs: Vec<SpecView>,
    pub grid_points: usize,
    pub cases: Vec<CaseView>,
}
