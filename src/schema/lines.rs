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
    /// The line is the harness's (the profiling kernel's loads, light loop, accumulation and store), not the
    /// model's (`KernelLines::mark_harness`).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub harness: bool,
}

/// The file of the term library, whose lines are a built-in model's.
pub const TERM_LIBRARY: &str = "glsl/brdf.glsl";

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
    /// Marks the harness's lines: glsl/'s other than the term library's, and for a model of the user's files
    /// (`user_model`) every line of glsl/ (the term library's helpers there serve the harness).
    pub fn mark_harness(&mut self, user_model: bool) {
        for l in &mut self.lines {
            l.harness = l.file.starts_with("glsl/") && (user_model || l.file != TERM_LIBRARY);
        }
    }

    /// The costliest `n` lines of the model as a Markdown table, with the share of the binding pipe each takes,
    /// and the harness's lines after it, apart.
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
        for l in self.lines.iter().filter(|l| !l.harness).take(n) {
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
        let harness: Vec<&LineCost> = self.lines.iter().filter(|l| l.harness).collect();
        let apart = if harness.is_empty() {
            String::new()
        } else {
            let cycles: f64 = harness.iter().map(|l| l.binding).sum();
            let share = if total > 0.0 { format!("{:.0}%", 100.0 * cycles / total) } else { "-".into() };
            let top: Vec<String> = harness
                .iter()
                .take(3)
                .map(|l| format!("{}:{} {}", l.file, l.line, crate::export::markdown::sig(l.binding, 3)))
                .collect();
            format!(
                "\nThe harness's own lines (the profiling kernel's loads, light loop, accumulation and store, not the model's; ranked apart): {} lines, {} instructions, {} {} cycles/wave ({share}); costliest {}.\n",
                harness.len(),
                harness.iter().map(|l| l.instructions).sum::<u32>(),
                crate::export::markdown::sig(cycles, 4),
                self.binding_pipe,
                top.join(", ")
            )
        };
        format!(
            "#### {}: the costliest source lines of the model ({unit}; ranked by their cycles on the binding pipe, {}; {} of {} instructions are the translation's own or the compiler's and name no line)\n\n{}{apart}",
            self.model,
            self.binding_pipe,
            self.unattributed,
            self.instructions,
            t.markdown()
        )
    }
}
