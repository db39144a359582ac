//! Trend data for benchmark dashboards: github-action-benchmark's `customSmallerIsBetter` list, one entry per
//! figure (`name`, `unit`, `value`, and `range` where the figure has an interval), which the action plots per
//! commit and alerts on; or Bencher's Metric Format (`--bench-format bmf`), an object keyed by benchmark name,
//! each a measure (the unit) with its `value` and, where there is an interval, `lower_value` and `upper_value`.

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
    /// The interval [lo, hi] where there is one (BMF's lower and upper values).
    #[serde(skip)]
    pub interval: Option<(f64, f64)>,
}

/// The formats `--bench-format` offers.
pub const FORMATS: [&str; 2] = ["github", "bmf"];

impl Entry {
    /// `range` of a value with the interval [lo, hi].
    pub fn range_of(value: f64, lo: f64, hi: f64) -> Option<String> {
        let half = (hi - value).max(value - lo);
        half.is_finite().then(|| format!("± {}", super::markdown::sig(half, 3)))
    }
}

/// Writes the list (atomically) in `format` (`FORMATS`); a figure that is not finite is left out, as no
/// dashboard can plot it.
pub fn write(path: &Path, entries: &[Entry], format: &str) -> anyhow::Result<()> {
    let finite: Vec<&Entry> = entries.iter().filter(|e| e.value.is_finite()).collect();
    let value = if format == "bmf" { bmf(&finite) } else { serde_json::to_value(&finite)? };
    crate::io::write_output(path, format!("{}\n", serde_json::to_string_pretty(&value)?).as_bytes())
}

/// Bencher's Metric Format: `{ NAME: { MEASURE: { "value", "lower_value", "upper_value" } } }`, the measure
/// named by the unit (`ns/eval` as `ns-eval`).
fn bmf(entries: &[&Entry]) -> serde_json::Value {
    let mut out = serde_json::Map::new();
    for e in entries {
        let measure: String =
            e.unit.chars().map(|c| if c.is_ascii_alphanumeric() { c.to_ascii_lowercase() } else { '-' }).collect();
        let mut m = serde_json::json!({ "value": e.value });
        if let Some((lo, hi)) = e.interval.filter(|(lo, hi)| lo.is_finite() && hi.is_finite()) {
            m["lower_value"] = lo.into();
            m["upper_value"] = hi.into();
        }
        out.insert(e.name.clone(), serde_json::json!({ measure: m }));
    }
    serde_json::Value::Object(out)
}
