//! A `brdfprof diff --json` report as read back (by `brdfprof report`): the same fields as `DiffReport`, with
//! every figure that may be infinite (written as JSON null) optional.

use serde::Deserialize;

#[derive(Clone, Debug, Deserialize)]
pub struct SideView {
    pub name: String,
    pub canonical: String,
    #[serde(default)]
    pub front_end: Option<String>,
}

#[derive(Clone, Debug, Deserialize)]
pub struct ChannelView {
    pub channel: String,
    pub max_abs: Option<f64>,
    pub rms_abs: Option<f64>,
    pub max_rel: Option<f64>,
    pub rms_rel: Option<f64>,
    pub mismatched_nonfinite: usize,
}

#[derive(Clone, Debug, Deserialize)]
pub struct DifferenceView {
    pub channels: Vec<ChannelView>,
    pub max_rel: Option<f64>,
}

#[derive(Clone, Debug, Deserialize)]
pub struct SampleView {
    pub n: [f64; 3],
    pub v: [f64; 3],
    pub l: [f64; 3],
    pub roughness: f64,
    pub f0: [f64; 3],
}

#[derive(Clone, Debug, Deserialize)]
pub struct WorstView {
    pub index: usize,
    pub line: Option<usize>,
    pub sample: SampleView,
    pub a: [Option<f64>; 3],
    pub b: [Option<f64>; 3],
    pub channel: String,
    pub rel: Option<f64>,
}

#[derive(Clone, Debug, Deserialize)]
pub struct HistogramView {
    pub edges: Vec<f64>,
    pub counts: Vec<usize>,
    pub identical: usize,
    pub nonfinite: usize,
}

#[derive(Clone, Debug, Deserialize)]
pub struct DiffView {
    pub a: SideView,
    pub b: SideView,
    pub device: String,
    pub input: String,
    pub rows: usize,
    pub relative_to: String,
    pub difference: DifferenceView,
    pub worst: Vec<WorstView>,
    pub histogram: HistogramView,
    pub tolerance: Option<f64>,
    pub within_tolerance: bool,
}

/// `DiffSet` (`diff --reference`) as read back.
#[derive(Clone, Debug, Deserialize)]
pub struct DiffSetView {
    pub reference: SideView,
    pub device: String,
    pub input: String,
    pub rows: usize,
    pub tolerance: Option<f64>,
    pub within_tolerance: bool,
    pub diffs: Vec<DiffView>,
}
