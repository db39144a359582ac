//! Cost per source line (`inspect --lines`): every machine instruction a compiler emitted, attributed to the
//! line of the user's `.brdf` file (or of glsl/) it came from, and summed per line by the figures of the cost
//! rule (`schedule`): the cycles each instruction keeps its pipe busy, and the cycles the compiler's
//! schedule spends issuing it (its stall and the waits before it). A line's share of the pipe that binds is what
//! removing it would save in throughput; its schedule cycles, what it adds to one wave's latency.

use crate::schema::lines::{KernelLines, LineCost};
use std::collections::BTreeMap;

/// One instruction with where it came from and what it costs (per wave, in the target's unit).
#[derive(Clone, Debug, PartialEq)]
pub struct Attributed {
    /// The source file and line, None where the compiler names none (its own prologue, the harness).
    pub source: Option<(String, u32)>,
    /// The pipes it occupies and for how many cycles each (none: the issue slot alone).
    pub pipes: Vec<(String, f64)>,
    /// Cycles of the compiler's schedule spent on it: the wait before it and its own stall.
    pub schedule: f64,
    /// Its issue cycles where the rule has an issue term (NVIDIA: 32 / 128 SM cycles per warp instruction).
    pub issue: f64,
}
/// The term name of an issue-slot bound among the pipes (NVIDIA's).
pub const ISSUE: &str = "issue";

/// Sums `instructions` per source line; `binding_pipe` is the kernel's busiest pipe (`schedule::Schedule`).
/// The lines' order: cycles on the binding pipe, then schedule cycles, then file and line.
pub fn costliest_first(a: &LineCost, b: &LineCost) -> std::cmp::Ordering {
    b.binding
        .total_cmp(&a.binding)
        .then(b.schedule.total_cmp(&a.schedule))
        .then(a.file.cmp(&b.file))
        .then(a.line.cmp(&b.line))
}

/// `lines` with each line `to` names moved to the line it gives (file, line, text), lines that land on one
/// merged (instructions and cycles summed), in `costliest_first` order.
pub fn moved(lines: &mut crate::schema::lines::KernelLines, to: impl Fn(&LineCost) -> Option<(String, u32, String)>) {
    let mut out: Vec<LineCost> = Vec::new();
    for mut l in std::mem::take(&mut lines.lines) {
        if let Some((file, line, text)) = to(&l) {
            (l.file, l.line, l.text) = (file, line, text);
        }
        match out.iter_mut().find(|o| o.file == l.file && o.line == l.line) {
            Some(o) => {
                o.instructions += l.instructions;
                o.binding += l.binding;
                o.schedule += l.schedule;
                for (pipe, cycles) in l.pipes {
                    *o.pipes.entry(pipe).or_default() += cycles;
                }
            }
            None => out.push(l),
        }
    }
    out.sort_by(costliest_first);
    lines.lines = out;
}

pub fn per_line(model: &str, instructions: &[Attributed], binding_pipe: &str) -> KernelLines {
    let mut by_line: BTreeMap<(String, u32), LineCost> = BTreeMap::new();
    let mut unattributed = 0;
    for i in instructions {
        let Some((file, line)) = &i.source else {
            unattributed += 1;
            continue;
        };
        let entry = by_line.entry((file.clone(), *line)).or_insert_with(|| LineCost {
            file: file.clone(),
            line: *line,
            instructions: 0,
            pipes: BTreeMap::new(),
            binding: 0.0,
            schedule: 0.0,
            text: String::new(),
            harness: false,
        });
        entry.instructions += 1;
        entry.schedule += i.schedule;
        if i.issue > 0.0 {
            *entry.pipes.entry(ISSUE.to_string()).or_default() += i.issue;
        }
        for (pipe, cycles) in &i.pipes {
            *entry.pipes.entry(pipe.clone()).or_default() += cycles;
        }
        entry.binding = entry.pipes.get(binding_pipe).copied().unwrap_or(0.0);
    }
    let mut lines: Vec<LineCost> = by_line.into_values().collect();
    lines.sort_by(costliest_first);
    for l in &mut lines {
        // A user's file is named in the compiled code as its `#line` directive gave it (`io::directive_name`).
        l.file = crate::io::from_directive_name(&l.file);
        l.text = source_text(&l.file, l.line);
        l.file = short(&l.file);
    }
    KernelLines {
        model: model.into(),
        binding_pipe: binding_pipe.into(),
        lines,
        unattributed,
        instructions: instructions.len() as u32,
        note: String::new(),
    }
}

/// Line `line` of `file` trimmed (lines ended as a compiler counts them, a lone `\r` included), or empty where
/// it cannot be read.
fn source_text(file: &str, line: u32) -> String {
    let path = std::path::Path::new(file);
    let embedded =
        || file.rsplit_once("glsl/").and_then(|(_, rel)| crate::shaders::embedded_glsl(rel)).map(str::to_string);
    let text = crate::io::read_bounded(path, 64 << 20)
        .ok()
        .map(|b| String::from_utf8_lossy(&b).into_owned())
        .or_else(embedded);
    let nth = |t: String| {
        crate::model::front::includes::split_lines(&t)
            .get(line.saturating_sub(1) as usize)
            .map(|l| l.trim().to_string())
    };
    text.and_then(nth).unwrap_or_default()
}
/// A file name as reports give it: glsl/'s (compiled from a temporary copy) by their name in the tree, a user's
/// file relative to the working directory where it lies below it.
fn short(file: &str) -> String {
    if let Some((_, rest)) = file.rsplit_once("/glsl/") {
        return format!("glsl/{rest}");
    }
    let cwd = std::env::current_dir().map(|d| format!("{}/", d.display())).unwrap_or_default();
    file.strip_prefix(&cwd).filter(|_| !cwd.is_empty()).unwrap_or(file).to_string()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(file: &str, line: u32, pipe: &str, busy: f64, schedule: f64) -> Attributed {
        Attributed { source: Some((file.into(), line)), pipes: vec![(pipe.into(), busy)], schedule, issue: 0.25 }
    }

    #[test]
    fn lines_sum_their_instructions_and_rank_by_the_binding_pipe() {
        let is = [
            at("a.brdf", 3, "FMA", 1.0, 2.0),
            at("a.brdf", 5, "MUFU", 8.0, 20.0),
            at("a.brdf", 3, "FMA", 1.0, 1.0),
            at("a.brdf", 4, "FMA", 1.5, 0.0),
            Attributed { source: None, pipes: vec![], schedule: 1.0, issue: 0.25 },
        ];
        let k = per_line("ggx", &is, "FMA");
        assert_eq!(k.lines.iter().map(|l| l.line).collect::<Vec<_>>(), [3, 4, 5]);
        assert_eq!((k.lines[0].instructions, k.lines[0].binding, k.lines[0].schedule), (2, 2.0, 3.0));
        assert_eq!((k.unattributed, k.instructions), (1, 5));
        assert_eq!(k.lines[2].pipes["MUFU"], 8.0);
        let md = k.markdown(2, "SM cycles");
        let first = md.lines().find(|l| l.contains("a.brdf:")).unwrap_or_default();
        assert!(first.contains("a.brdf:3") && !md.contains("a.brdf:5"), "{md}");
        // Ranked by the issue slots where they bind: line 3's two instructions first.
        let k = per_line("ggx", &is, ISSUE);
        assert_eq!((k.lines[0].line, k.lines[0].binding), (3, 0.5));
    }
}
