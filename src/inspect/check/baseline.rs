//! The baseline file: every count, the timing ratios and the environment they were measured in.

use crate::inspect::timing::TimingRun;
use crate::inspect::InspectReport;
use crate::model::Model;
use anyhow::{anyhow, bail, Context, Result};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::Path;

/// The `format` field of a baseline file.
pub const FORMAT: &str = "brdfprof-check-baseline/1";

/// A saved run: every count, the timing ratios and the environment they were measured in.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Baseline {
    pub format: String,
    pub inspect: InspectReport,
    pub timing: Option<TimingRun>,
    /// Group -> what its figures depend on (key -> value); compared before the group's figures are.
    pub environment: BTreeMap<String, BTreeMap<String, String>>,
}

/// Reads and checks a baseline file; every error names the file and what is wrong with it.
pub fn load(path: &Path) -> Result<Baseline> {
    let name = path.display();
    let text = std::fs::read_to_string(path).with_context(|| format!("baseline {name}: cannot read it"))?;
    let value: serde_json::Value = serde_json::from_str(&text).map_err(|e| anyhow!("baseline {name}: corrupt, not valid JSON ({e})"))?;
    match value.get("format").and_then(|f| f.as_str()) {
        Some(FORMAT) => {}
        Some(other) => bail!("baseline {name}: format `{other}`, this brdfprof reads `{FORMAT}`; save a new one with --save-baseline"),
        None => bail!("baseline {name}: not a brdfprof check baseline (no `format` field; expected `{FORMAT}`)"),
    }
    let baseline: Baseline = serde_json::from_value(value).map_err(|e| anyhow!("baseline {name}: corrupt ({e})"))?;
    validate(&baseline).map_err(|e| anyhow!("baseline {name}: corrupt ({e})"))?;
    Ok(baseline)
}

/// What serde cannot check: models that parse, finite statistics, timing ratios for known models.
fn validate(b: &Baseline) -> Result<()> {
    if b.inspect.rows.is_empty() {
        bail!("no rows");
    }
    for row in &b.inspect.rows {
        if let Some(s) = &row.spec {
            Model::parse(s).map_err(|e| anyhow!("row `{}`: spec `{s}`: {e}", row.model))?;
        }
        if let Some((k, v)) = row.stats.iter().find(|(_, v)| !v.is_finite()) {
            bail!("row `{}`: statistic {k} is {v}", row.model);
        }
    }
    if let Some(t) = &b.timing {
        for (model, ratios) in &t.ratios {
            if ratios.is_empty() || ratios.iter().any(|r| !r.is_finite() || *r <= 0.0) {
                bail!("timing ratios of `{model}` are empty or not positive numbers");
            }
        }
    }
    Ok(())
}

