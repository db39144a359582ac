//! The reports' schemas: what `inspect` and the compile-only targets write and `check`, `compare` and the
//! pages read back (the inspect report and its rows, the cost table, cost per source line, callgrind's run,
//! the correlation with a profile), with their Markdown. Below both `inspect` and `targets`, so that the
//! code that fills a report and the code that reads it share only these types.

pub mod callgrind;
pub mod correlation;
pub mod cost;
pub mod driver;
pub mod lines;

use crate::export::markdown::{self, Table};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// Key of a row's kernel hash in `Row::notes`.
pub const HASH_NOTE: &str = "kernel-sha256";

/// Statistic sections, in report order: key prefix and title.
pub const SECTIONS: [(&str, &str); 5] = [
    ("spirv/", "SPIR-V instructions, glslang's output specialised (frozen spec constants, dead code removed)"),
    (
        "spirv-O/",
        "SPIR-V instructions after spirv-opt -O (the [[unroll]] light loop unrolled: about NUM_LIGHTS copies of the BRDF)",
    ),
    (
        "naga/",
        "naga (SPIR-V front end and validator) on the specialised float-G-buffer kernel (same BRDF; naga 30 reads no texel buffers)",
    ),
    ("driver/", "Driver statistics (VK_KHR_pipeline_executable_properties)"),
    ("callgrind/", "Executed CPU instructions (Ir) per BRDF evaluation of lavapipe's JIT code, under callgrind"),
];

/// One kernel's statistics.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct Row {
    /// The spec's name, or "baseline" for the memory-only kernel.
    pub model: String,
    /// Canonical spec (None for the baseline kernel).
    pub spec: Option<String>,
    /// Statistic key (`section/name`) -> value.
    pub stats: BTreeMap<String, f64>,
    /// Section -> text that is not a number (naga's verdict, why a section is missing).
    pub notes: BTreeMap<String, String>,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct InspectReport {
    /// Where it was measured (results::Provenance, kept as JSON so that baselines read back whatever it holds).
    pub provenance: serde_json::Value,
    /// Where the SPIR-V came from.
    pub kernels: String,
    pub lights: u32,
    /// Tool versions (spirv-opt, glslang, valgrind).
    pub tools: BTreeMap<String, String>,
    /// Statistic keys in report order.
    pub columns: Vec<String>,
    pub rows: Vec<Row>,
    /// Notes about a whole section (e.g. "not available on this device").
    pub section_notes: BTreeMap<String, String>,
    pub callgrind: Option<callgrind::CallgrindRun>,
    /// How callgrind was run (workload, valgrind version), recorded even when the run failed; empty when it
    /// was not attempted.
    #[serde(default)]
    pub callgrind_setup: BTreeMap<String, String>,
    /// Callgrind figures next to a profile's timings (`inspect --profile FILE`).
    #[serde(default)]
    pub vs_profile: Option<correlation::Correlation>,
    /// The compiler's cost model applied to the kernels (set by `targets::cost_of`: ACO's on RADV, NVIDIA's issue
    /// model on `nvidia:` targets), where the device's statistics have one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cost: Option<cost::TargetCost>,
    /// Cost per source line (`inspect --lines`), per model, where the compiler names lines.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub lines: Vec<lines::KernelLines>,
    /// The models whose loops the cost table prices at their trip count (`targets::trips`), with the
    /// compiles it extrapolates from.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub loop_trips: Vec<LoopTrips>,
}

/// A model's loops at their trip count: its loop-header passes per evaluation, and its kernel compiled with the
/// loops at fixed passes per entry (`loop-passes=`), each with its passes per evaluation and statistics.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct LoopTrips {
    pub model: String,
    pub passes: f64,
    pub fixed: Vec<FixedPasses>,
}

#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct FixedPasses {
    /// Passes per entry (`loop-passes=`).
    pub loop_passes: u32,
    /// Passes per evaluation, counted as the model's are.
    pub passes: f64,
    pub stats: BTreeMap<String, f64>,
}

/// The row note that names a file's parameters compiled in as constants (`FileModel::folded`).
pub const FOLDED_NOTE: &str = "folded";

/// Formats a statistic: whole numbers as integers, others with 4 significant digits.
pub fn format_value(v: f64) -> String {
    if v.fract() == 0.0 && v.abs() < 1e15 { format!("{}", v as i64) } else { markdown::sig(v, 4) }
}

impl InspectReport {
    pub fn row(&self, model: &str) -> Option<&Row> {
        self.rows.iter().find(|r| r.model == model)
    }

    /// One table per section (one row per kernel, one column per statistic, a statistic equal on every kernel
    /// folded into a line below it), with the section's notes.
    pub fn markdown(&self) -> String {
        let mut out = String::new();
        for (prefix, title) in SECTIONS {
            let columns: Vec<&String> = self.columns.iter().filter(|c| c.starts_with(prefix)).collect();
            out += &format!("### {title}\n\n");
            if let Some(note) = self.section_notes.get(prefix) {
                out += &format!("{note}\n\n");
            }
            let with_notes = prefix == "naga/";
            if columns.is_empty() && !with_notes {
                continue;
            }
            let (columns, constant) =
                fold_constant(&columns, |c| self.rows.iter().map(|r| r.stats.get(*c).copied()).collect());
            let mut headers = vec!["model".to_string()];
            headers.extend(columns.iter().map(|c| c[prefix.len()..].to_string()));
            if with_notes {
                headers.push("result".into());
            }
            let mut t = Table::new(headers);
            for row in &self.rows {
                let mut cells = vec![row.model.clone()];
                cells.extend(columns.iter().map(|c| row.stats.get(*c).map_or("-".into(), |v| format_value(*v))));
                if with_notes {
                    cells.push(row.notes.get("naga").cloned().unwrap_or_default());
                }
                t.row(cells);
            }
            out += &t.markdown();
            out += &constant_note(constant.iter().map(|(c, v)| (&c[prefix.len()..], *v)));
            out += "\n";
        }
        if let Some(a) = &self.cost {
            out += &a.markdown();
            out += "\n";
        }
        out += &self.lines_markdown();
        for row in &self.rows {
            if let Some(note) = row.notes.get(FOLDED_NOTE) {
                out += &format!("{}: {note}.\n\n", row.model);
            }
        }
        if let Some(c) = &self.vs_profile {
            out += &format!("### Instructions vs time per evaluation\n\n{}\n", c.markdown());
        }
        out
    }

    /// Cost per source line (`inspect --lines`): each model's costliest lines, where the report has them.
    pub fn lines_markdown(&self) -> String {
        if self.lines.is_empty() {
            return String::new();
        }
        let unit = self.cost.as_ref().map_or("cycles", |c| c.unit.as_str());
        let mut out = "### Cost per source line

Each instruction of the kernel compiled with line information, attributed to the line of the `.brdf` file or of glsl/ it came from; per line its cycles on the kernel's binding pipe (the share of what binds), and the schedule cycles spent issuing it (waits and stalls), per wave. The ten costliest lines of each model:\n\n".replace("\\n", "\n");
        for k in &self.lines {
            out += &k.markdown(10, unit);
            if !k.note.is_empty() {
                out += &format!("\n{}: {}\n", k.model, k.note);
            }
            out += "\n";
        }
        out
    }

    /// One line saying what was inspected.
    pub fn summary(&self) -> String {
        let device = self.provenance["device"]["name"].as_str().unwrap_or("?");
        format!(
            "{device}; shade kernel, {} lights; SPIR-V {}; tools: {}",
            self.lights,
            self.kernels,
            self.tools.iter().map(|(k, v)| format!("{k} = {v}")).collect::<Vec<_>>().join(", ")
        )
    }
}

/// The columns whose value differs between rows (kept), and those equal on every one of three or more rows
/// with that value (folded: a column that never changes says nothing per row). `values` gives a column's.
pub fn fold_constant<'a, C: Copy>(
    columns: &'a [C],
    values: impl Fn(&C) -> Vec<Option<f64>>,
) -> (Vec<C>, Vec<(C, f64)>) {
    let (mut kept, mut folded) = (Vec::new(), Vec::new());
    for c in columns {
        let v = values(c);
        match v.first() {
            Some(&Some(x)) if v.len() >= 3 && v.iter().all(|y| *y == Some(x)) => folded.push((*c, x)),
            _ => kept.push(*c),
        }
    }
    (kept, folded)
}

/// The line under a table that lists its folded columns, or nothing.
pub fn constant_note<'a>(folded: impl Iterator<Item = (&'a str, f64)>) -> String {
    let items: Vec<String> = folded.map(|(name, v)| format!("{name} {}", format_value(v))).collect();
    if items.is_empty() {
        String::new()
    } else {
        format!("\nThe same on every kernel (not listed per row): {}.\n", items.join(", "))
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// A report of `device` with no rows, for tests of what reads reports.
    pub fn empty_report(device: &str) -> InspectReport {
        InspectReport {
            provenance: serde_json::json!({"device": {"name": device}}),
            kernels: String::new(),
            lights: 8,
            tools: BTreeMap::new(),
            columns: vec![],
            rows: vec![],
            section_notes: BTreeMap::new(),
            callgrind: None,
            callgrind_setup: BTreeMap::new(),
            vs_profile: None,
            cost: None,
            lines: vec![],
            loop_trips: Vec::new(),
        }
    }
}
