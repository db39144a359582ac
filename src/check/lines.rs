//! The source lines behind a regression: a model's per-line cost (`inspect --lines`, kept in baselines on the
//! targets that name lines) before and after, matched line by line, and the lines whose cost rose most.

use crate::schema::lines::{KernelLines, LineCost};

/// One source line's cost before and after, on the new kernel's binding pipe (cycles per wave).
#[derive(Clone, Debug, PartialEq)]
pub struct LineChange {
    pub file: String,
    /// The line in this run's file (the baseline's where the line is gone).
    pub line: u32,
    pub text: String,
    pub before: f64,
    pub after: f64,
    /// This line's rise as a share of the kernel's rises on that pipe (0 where it fell).
    pub share: f64,
}

impl LineChange {
    pub fn rise(&self) -> f64 {
        self.after - self.before
    }
}

/// A file name as lines are matched by it: `./shaders/x` and `shaders/x` are one file.
fn same_path(file: &str) -> String {
    let parts: Vec<&str> = file.split('/').filter(|p| *p != "." && !p.is_empty()).collect();
    let joined = parts.join("/");
    if file.starts_with('/') { format!("/{joined}") } else { joined }
}

/// A line's cycles on `pipe`.
fn cycles(l: &LineCost, pipe: &str) -> f64 {
    l.pipes.get(pipe).copied().unwrap_or(0.0)
}

/// Every line of `model` in both runs, matched by file and text (the k-th occurrence of a text with the k-th:
/// an edit above a line moves its number, not its text), with the cycles each had on the new kernel's binding
/// pipe; sorted by rise, largest first. None where either run has no lines for the model.
pub fn changes(old: &[KernelLines], new: &[KernelLines], model: &str) -> Option<Vec<LineChange>> {
    let (old, new) = (old.iter().find(|k| k.model == model)?, new.iter().find(|k| k.model == model)?);
    let pipe = new.binding_pipe.as_str();
    let ordered = |k: &KernelLines| {
        let mut lines: Vec<LineCost> = k.lines.clone();
        lines.sort_by(|a, b| a.file.cmp(&b.file).then(a.line.cmp(&b.line)));
        lines
    };
    let mut unmatched: Vec<Option<LineCost>> = ordered(old).into_iter().map(Some).collect();
    let mut out = Vec::new();
    for n in ordered(new) {
        let key =
            |l: &LineCost| (same_path(&l.file), if l.text.is_empty() { l.line.to_string() } else { l.text.clone() });
        let found = unmatched.iter_mut().find(|o| o.as_ref().is_some_and(|o| key(o) == key(&n))).and_then(Option::take);
        out.push(LineChange {
            file: n.file.clone(),
            line: n.line,
            text: n.text.clone(),
            before: found.as_ref().map_or(0.0, |o| cycles(o, pipe)),
            after: cycles(&n, pipe),
            share: 0.0,
        });
    }
    for o in unmatched.into_iter().flatten() {
        out.push(LineChange {
            file: o.file.clone(),
            line: o.line,
            text: o.text.clone(),
            before: cycles(&o, pipe),
            after: 0.0,
            share: 0.0,
        });
    }
    let risen: f64 = out.iter().map(|c| c.rise().max(0.0)).sum();
    for c in &mut out {
        c.share = if risen > 0.0 { c.rise().max(0.0) / risen } else { 0.0 };
    }
    out.sort_by(|a, b| b.rise().total_cmp(&a.rise()).then(a.file.cmp(&b.file)).then(a.line.cmp(&b.line)));
    Some(out)
}

/// The lines of `changes` whose cost rose, at most `n`.
pub fn risen(changes: &[LineChange], n: usize) -> Vec<&LineChange> {
    changes.iter().filter(|c| c.rise() > 0.0).take(n).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::BTreeMap;

    fn line(line: u32, text: &str, cycles: f64) -> LineCost {
        LineCost {
            file: "m.brdf".into(),
            line,
            instructions: 1,
            pipes: BTreeMap::from([("FMA".to_string(), cycles)]),
            binding: cycles,
            schedule: 0.0,
            text: text.into(),
            harness: false,
        }
    }

    fn kernel(lines: Vec<LineCost>) -> KernelLines {
        KernelLines {
            model: "m".into(),
            binding_pipe: "FMA".into(),
            lines,
            unattributed: 0,
            instructions: 0,
            note: String::new(),
        }
    }

    #[test]
    fn lines_are_matched_by_text_so_an_inserted_line_alone_is_blamed() {
        let old = kernel(vec![line(3, "a = b;", 2.0), line(4, "c = d;", 1.0), line(5, "a = b;", 3.0)]);
        // A line inserted at 4 moves the rest down; the second `a = b;` got cheaper.
        let new = kernel(vec![
            line(3, "a = b;", 2.0),
            line(4, "x = pow(x, y);", 8.0),
            line(5, "c = d;", 1.0),
            line(6, "a = b;", 1.0),
        ]);
        let c = changes(&[old], &[new], "m").unwrap();
        assert_eq!((c[0].line, c[0].before, c[0].after, c[0].share), (4, 0.0, 8.0, 1.0));
        let moved = c.iter().find(|c| c.line == 5).unwrap();
        assert_eq!((moved.before, moved.after), (1.0, 1.0), "matched by its text, not its number");
        let cheaper = c.iter().find(|c| c.line == 6).unwrap();
        assert_eq!((cheaper.before, cheaper.after), (3.0, 1.0), "the k-th occurrence with the k-th");
        assert_eq!(risen(&c, 5).len(), 1);
        assert!(changes(&[], &[kernel(vec![])], "m").is_none(), "no lines in the baseline: nothing to say");
    }

    /// `./shaders/x` in this run and `shaders/x` in the baseline are one file: no line reads as new cost.
    #[test]
    fn a_path_written_with_dot_slash_is_the_same_file() {
        let old = kernel(vec![LineCost { file: "shaders/m.brdf".into(), ..line(3, "a = b;", 2.0) }]);
        let new = kernel(vec![LineCost { file: "./shaders//m.brdf".into(), ..line(3, "a = b;", 2.0) }]);
        let c = changes(&[old], &[new], "m").unwrap();
        assert_eq!(c.len(), 1);
        assert_eq!((c[0].before, c[0].after), (2.0, 2.0));
        assert_eq!(same_path("/abs/./x.brdf"), "/abs/x.brdf");
    }
}
