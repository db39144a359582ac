//! Which statistics can regress, and by how much before they do.

use anyhow::{Result, anyhow, bail};

/// Significance level of the timing test.
pub const ALPHA: f64 = 0.05;
/// Fewest per-round ratios on each side for a timing verdict.
pub const MIN_TIMING_ROUNDS: usize = 9;
pub const DEFAULT_COUNT_THRESHOLD: f64 = 0.01;
pub const DEFAULT_TIMING_THRESHOLD: f64 = 0.05;
/// A compile-only target's modelled cycles per evaluation (`COST_KEYS`): the figure its reports headline.
pub const DEFAULT_COST_THRESHOLD: f64 = 0.02;
/// Statistic groups (the part of a key before '/').
pub const GROUPS: [&str; 7] = ["cost", "spirv", "spirv-O", "naga", "driver", "callgrind", "timing"];
/// The cost group's keys: a compile-only target's modelled cycles per evaluation under its one rule, gross and net
/// of the memory-only kernel (`schema::cost::CostRow`), compared as the other statistics are.
pub const COST_KEYS: [&str; 2] = ["cost/cycles-per-eval", "cost/net-cycles-per-eval"];
/// The timing statistic of each model.
pub const TIMING_KEY: &str = "timing/cost-ratio";
/// Driver statistics that cost more when they grow (the aliases); other driver statistics are reported only.
const GATED_DRIVER_KEYS: [&str; 11] = [
    "driver/registers",
    "driver/scalar-registers",
    "driver/instructions",
    "driver/code-bytes",
    "driver/spills",
    "driver/fills",
    "driver/scratch-bytes",
    "driver/branches",
    "driver/latency",
    "driver/inverse-throughput",
    "driver/issue-cycles",
];

/// The group of a statistic key.
pub fn group_of(key: &str) -> &str {
    key.split('/').next().unwrap_or(key)
}

/// True for statistics whose growth is a cost (and so can regress).
pub fn is_gated(key: &str) -> bool {
    match group_of(key) {
        "driver" => GATED_DRIVER_KEYS.contains(&key),
        _ => !key.ends_with("/functions"),
    }
}

/// Per-statistic regression thresholds from `--threshold KEY=FRACTION` (KEY: a statistic key such as
/// spirv/total, or a group such as callgrind).
#[derive(Clone, Debug, Default)]
pub struct Thresholds {
    entries: Vec<(String, f64)>,
}

impl Thresholds {
    pub fn parse(items: &[String]) -> Result<Self> {
        let mut entries = Vec::new();
        for item in items {
            let (key, value) = item
                .split_once('=')
                .ok_or_else(|| anyhow!("--threshold `{item}`: expected STAT=FRACTION, e.g. spirv/total=0.02"))?;
            let (key, value) = (key.trim(), value.trim());
            if !GROUPS.contains(&group_of(key)) {
                bail!(
                    "--threshold `{item}`: unknown statistic `{key}`: give a group ({}) or a key such as spirv/total",
                    GROUPS.join(", ")
                );
            }
            let fraction: f64 = value
                .parse()
                .map_err(|_| anyhow!("--threshold `{item}`: `{value}` is not a number (a fraction: 0.01 is 1%)"))?;
            if !(fraction.is_finite() && fraction >= 0.0) {
                bail!("--threshold `{item}`: the fraction must be finite and not negative");
            }
            entries.push((key.to_string(), fraction));
        }
        Ok(Thresholds { entries })
    }

    /// The threshold of `key`: its own, else its group's, else the default.
    pub fn get(&self, key: &str) -> f64 {
        let find = |k: &str| self.entries.iter().rev().find(|(e, _)| e == k).map(|(_, v)| *v);
        find(key).or_else(|| find(group_of(key))).unwrap_or(match group_of(key) {
            "timing" => DEFAULT_TIMING_THRESHOLD,
            "cost" => DEFAULT_COST_THRESHOLD,
            _ => DEFAULT_COUNT_THRESHOLD,
        })
    }
}
