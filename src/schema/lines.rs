//! Cost per source line (`inspect --lines`) as reports hold it: per kernel its lines, costliest first, with
//! the cycles each adds to the pipes and to the schedule (the attribution: `targets::cost::lines`).

use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// One source line's instructions and cycles.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct LineCost {
    /// The file (`short`): `glsl/brdf.glsl`, or the user's file.
    pub file: String,
    pub line: u32,
    pub instructions: u32,
    /// Busy cycles per wave the line's instructions add to each pipe.
    pub pipes: BTreeMap<String, f64>,
    /// The line's cycles on the kernel's binding pipe (`KernelLines::binding_pipe`).
    pub binding: f64,
    /// Schedule cycles per wave spent issuing the line's instructions.
    pub schedule: f64,
    /// The line's text, where the file could be read.
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub text: String,
}

/// A kernel's lines, costliest first (by their cycles on the binding pipe, then their schedule cycles).
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct KernelLines {
    pub model: String,
    /// The pipe whose cycles the lines are ranked by: the kernel's busiest.
    pub binding_pipe: String,
    pub lines: Vec<LineCost>,
    /// Instructions the compiler names no line for.
    pub unattributed: u32,
    pub instructions: u32,
    /// Something the reader should know (the line-annotated compile differing from the costed one).
    #[serde(default, skip_serializing_if = "String::is_empty")]
    pub note: String,
}

impl KernelLines {
    /// The costliest `n` lines as a Markdown table, with the share of the binding pipe each takes.
    pub fn markdown(&self, n: usize, unit: &str) -> String {
        let total: f64 = self.lines.iter().map(|l| l.binding).sum();
        let mut t = crate::export::markdown::Table::new(
            [
                "file:line",
                "instructions",
                &format!("{} cycles/wave", self.binding_pipe),
                "share",
                "schedule cycles/wave",
                "source",
            ]
            .map(String::from),
        );
        for l in self.lines.iter().take(n) {
            let share = if total > 0.0 { format!("{:.0}%", 100.0 * l.binding / total) } else { "-".into() };
            t.row([
                format!("{}:{}", l.file, l.line),
                l.instructions.to_string(),
                crate::export::markdown::sig(l.binding, 4),
                share,
                crate::export::markdown::sig(l.schedule, 4),
                format!("`{}`", l.text.replace('|', "\\|").replace('`', "'")),
            ]);
        }
        format!(
            "#### {}: the costliest source lines ({unit}; ranked by their cycles on the binding pipe, {}; {} of {} instructions are the translation's own or the compiler's and name no line)\n\n{}",
            self.model,
            self.binding_pipe,
            self.unattributed,
            self.instructions,
            t.markdown()
        )
    }
}
