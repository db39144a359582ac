//! Markdown: aligned tables and the number formatting every report's text and picture labels share.

use crate::stats::Estimate;
use std::collections::BTreeMap;

/// A Markdown table.
#[derive(Clone, Debug, Default)]
pub struct Table {
    pub headers: Vec<String>,
    pub rows: Vec<Vec<String>>,
}

impl Table {
    pub fn new<S: Into<String>>(headers: impl IntoIterator<Item = S>) -> Self {
        Table { headers: headers.into_iter().map(Into::into).collect(), rows: Vec::new() }
    }

    pub fn row<S: Into<String>>(&mut self, cells: impl IntoIterator<Item = S>) {
        self.rows.push(cells.into_iter().map(Into::into).collect());
    }

    pub fn markdown(&self) -> String {
        let widths: Vec<usize> = (0..self.headers.len())
            .map(|c| {
                self.rows
                    .iter()
                    .map(|r| r[c].chars().count())
                    .chain([self.headers[c].chars().count(), 3])
                    .max()
                    .unwrap()
            })
            .collect();
        let line = |cells: &[String]| {
            let padded: Vec<String> = cells.iter().zip(&widths).map(|(c, w)| format!("{c:<w$}")).collect();
            format!("| {} |\n", padded.join(" | "))
        };
        let rule: Vec<String> = widths.iter().map(|w| "-".repeat(*w)).collect();
        let mut out = line(&self.headers);
        out += &line(&rule);
        for r in &self.rows {
            out += &line(r);
        }
        out
    }
}

/// `x` with `digits` significant digits.
pub fn sig(x: f64, digits: usize) -> String {
    if x == 0.0 || !x.is_finite() {
        return format!("{x}");
    }
    let magnitude = x.abs().log10().floor() as i32;
    let decimals = (digits as i32 - 1 - magnitude).max(0) as usize;
    format!("{x:.decimals$}")
}

/// `sig`, in scientific form below 1e-3 and from 1e6 on (`5.17e-7`), so that a figure stays a few characters
/// wide in a table cell.
pub fn sig_compact(x: f64, digits: usize) -> String {
    if x != 0.0 && x.is_finite() && !(1e-3..1e6).contains(&x.abs()) {
        return format!("{x:.prec$e}", prec = digits.saturating_sub(1));
    }
    sig(x, digits)
}

/// "median [lo, hi]".
pub fn estimate(e: &Estimate, digits: usize) -> String {
    format!("{} [{}, {}]", sig(e.median, digits), sig(e.lo, digits), sig(e.hi, digits))
}

/// A report's `front_ends` as a paragraph to append to its summary (empty when it has none).
pub fn front_ends_line(front_ends: &BTreeMap<String, String>) -> String {
    if front_ends.is_empty() {
        return String::new();
    }
    let items: Vec<String> = front_ends.iter().map(|(path, front)| format!("`{path}`: {front}")).collect();
    format!("\n\nFront ends: {}.", items.join("; "))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn significant_digits() {
        assert_eq!(sig(1234.5, 3), "1234");
        assert_eq!(sig(1.2345, 3), "1.23");
        assert_eq!(sig(0.0012345, 3), "0.00123");
        assert_eq!(sig_compact(5.17e-7, 3), "5.17e-7");
        assert_eq!(sig_compact(0.0012345, 3), "0.00123");
        assert_eq!(sig_compact(2.5e7, 2), "2.5e7");
        assert_eq!(sig_compact(0.0, 3), "0");
    }

    #[test]
    fn table_is_aligned_markdown() {
        let mut t = Table::new(["a", "long header"]);
        t.row(["1", "2"]);
        assert_eq!(t.markdown(), "| a   | long header |\n| --- | ----------- |\n| 1   | 2           |\n");
    }
}
