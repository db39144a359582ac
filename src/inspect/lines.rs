//! Cost per source line (`inspect --lines`): every machine instruction a compiler emitted, attributed to the
//! line of the user's `.brdf` file (or of glsl/) it came from, and summed per line by the figures of the cost
//! rule (`inspect::schedule`): the cycles each instruction keeps its pipe busy, and the cycles the compiler's
//! schedule spends issuing it (its stall and the waits before it). A line's share of the pipe that binds is what
//! removing it would save in throughput; its schedule cycles, what it adds to one wave's latency.

use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

/// One instruction with where it came from and what it costs (per wave, in the target's unit).
#[derive(Clone, Debug, PartialEq)]
pub struct Attributed {
    /// The source file and line, None where the compiler names none (its own prologue, the harness).
    pub source: Option<(String, u32)>,
    /// The pipe it occupies and for how many cycles (None: the issue slot alone).
    pub pipe: Option<(String, f64)>,
    /// Cycles of the compiler's schedule from its issue to the next instruction's.
    pub schedule: f64,
}

/// One source line's instructions and cycles.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct LineCost {
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
}

/// Sums `instructions` per source line; `binding_pipe` is the kernel's busiest pipe (`schedule::Schedule`).
pub fn per_line(model: &str, instructions: &[Attributed], binding_pipe: &str) -> KernelLines {
    let mut by_line: BTreeMap<(String, u32), LineCost> = BTreeMap::new();
    let mut unattributed = 0;
    for i in instructions {
        let Some((file, line)) = &i.source else {
            unattributed += 1;
            continue;
        };
        let entry = by_line.entry((file.clone(), *line)).or_insert_with(|| LineCost { file: file.clone(), line: *line, instructions: 0, pipes: BTreeMap::new(), binding: 0.0, schedule: 0.0, text: String::new() });
        entry.instructions += 1;
        entry.schedule += i.schedule;
        if let Some((pipe, cycles)) = &i.pipe {
            *entry.pipes.entry(pipe.clone()).or_default() += cycles;
            if pipe == binding_pipe {
                entry.binding += cycles;
            }
        }
    }
    let mut lines: Vec<LineCost> = by_line.into_values().collect();
    lines.sort_by(|a, b| b.binding.total_cmp(&a.binding).then(b.schedule.total_cmp(&a.schedule)).then(a.file.cmp(&b.file)).then(a.line.cmp(&b.line)));
    for l in &mut lines {
        l.text = source_text(&l.file, l.line);
    }
    KernelLines { model: model.into(), binding_pipe: binding_pipe.into(), lines, unattributed, instructions: instructions.len() as u32 }
}

/// Line `line` of `file` trimmed, or empty where it cannot be read.
fn source_text(file: &str, line: u32) -> String {
    let path = std::path::Path::new(file);
    let embedded = || file.rsplit_once("glsl/").and_then(|(_, rel)| crate::shaders::embedded_glsl(rel)).map(str::to_string);
    let text = crate::io::read_bounded(path, 64 << 20).ok().map(|b| String::from_utf8_lossy(&b).into_owned()).or_else(embedded);
    text.and_then(|t| t.lines().nth(line.saturating_sub(1) as usize).map(|l| l.trim().to_string())).unwrap_or_default()
}

impl KernelLines {
    /// The costliest `n` lines as a Markdown table, with the share of the binding pipe each takes.
    pub fn markdown(&self, n: usize, unit: &str) -> String {
        let total: f64 = self.lines.iter().map(|l| l.binding).sum();
        let mut t = crate::results::Table::new(["file:line", "instructions", &format!("{} cycles/wave", self.binding_pipe), "share", "schedule cycles/wave", "source"].map(String::from));
        for l in self.lines.iter().take(n) {
            let share = if total > 0.0 { format!("{:.0}%", 100.0 * l.binding / total) } else { "-".into() };
            t.row([format!("{}:{}", short(&l.file), l.line), l.instructions.to_string(), crate::results::sig(l.binding, 4), share, crate::results::sig(l.schedule, 4), format!("`{}`", l.text.replace('|', "\\|").replace('`', "'"))]);
        }
        format!(
            "#### {}: the costliest source lines ({unit}; ranked by their cycles on the binding pipe, {}; {} of {} instructions name no line)\n\n{}",
            self.model,
            self.binding_pipe,
            self.unattributed,
            self.instructions,
            t.markdown()
        )
    }
}

/// A file name as tables show it: glsl/'s by their name, a user's file as given.
fn short(file: &str) -> String {
    file.rsplit_once("/glsl/").map_or(file.to_string(), |(_, rest)| format!("glsl/{rest}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(file: &str, line: u32, pipe: &str, busy: f64, schedule: f64) -> Attributed {
        Attributed { source: Some((file.into(), line)), pipe: Some((pipe.into(), busy)), schedule }
    }

    #[test]
    fn lines_sum_their_instructions_and_rank_by_the_binding_pipe() {
        let is = [at("a.brdf", 3, "FMA", 1.0, 2.0), at("a.brdf", 5, "MUFU", 8.0, 20.0), at("a.brdf", 3, "FMA", 1.0, 1.0), at("a.brdf", 4, "FMA", 1.5, 0.0), Attributed { source: None, pipe: None, schedule: 1.0 }];
        let k = per_line("ggx", &is, "FMA");
        assert_eq!(k.lines.iter().map(|l| l.line).collect::<Vec<_>>(), [3, 4, 5]);
        assert_eq!((k.lines[0].instructions, k.lines[0].binding, k.lines[0].schedule), (2, 2.0, 3.0));
        assert_eq!((k.unattributed, k.instructions), (1, 5));
        assert_eq!(k.lines[2].pipes["MUFU"], 8.0);
        assert!(k.markdown(2, "SM cycles").contains("| a.brdf:3 | 2"));
    }
}
