//! Trend data for benchmark dashboards: github-action-benchmark's `customSmallerIsBetter` list, one entry per
//! figure (`name`, `unit`, `value`, and `range` where the figure has an interval), which the action plots per
//! commit and alerts on.

use serde::Serialize;
use std::path::Path;

/// One figure of the list.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Entry {
    /// `<command>/<device or target>/<model>`: the action keys its series by name.
    pub name: String,
    pub unit: String,
    pub value: f64,
    /// `± H`, H the larger distance from the value to its interval's ends, where there is an interval.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub range: Option<String>,
    /// What the figure is, in words (the interval and its coverage, the cost rule).
    #[serde(skip_serializing_if = "String::is_empty")]
    pub extra: String,
}

impl Entry {
    /// `range` of a value with the interval [lo, hi].
    pub fn range_of(value: f64, lo: f64, hi: f64) -> Option<String> {
        let half = (hi - value).max(value - lo);
        half.is_finite().then(|| format!("± {}", super::markdown::sig(half, 3)))
    }
}

/// Writes the list (atomically); a figure that is not finite is left out, as the action cannot plot it.
pub fn write(path: &Path, entries: &[Entry]) -> anyhow::Result<()> {
    let finite: Vec<&Entry> = entries.iter().filter(|e| e.value.is_finite()).collect();
    crate::io::write_output(path, format!("{}\n", serde_json::to_string_pretty(&finite)?).as_bytes())
}
