//! A compile-only target's cost table as reports hold it: for every kernel a few of its compiler's statistics,
//! its modelled cycles per BRDF evaluation, and the same net of the memory-only kernel. Each vendor fills it
//! from its own statistics and model (`targets::cost`); `inspect`, `compare` and `sweep --cost-device` read
//! only this.

use crate::export::markdown::{Table, sig};
use serde::{Deserialize, Serialize};

/// One kernel's figures.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct CostRow {
    pub model: String,
    /// The statistics of `TargetCost::columns` by name.
    pub stats: std::collections::BTreeMap<String, f64>,
    /// Modelled cycles per evaluation (one invocation x one light).
    pub cycles_per_eval: f64,
    /// The same minus the memory-only kernel's (None for that kernel).
    pub net_cycles_per_eval: Option<f64>,
    /// The term (pipe, or latency over resident waves) that binds the kernel, where the vendor's rule is a
    /// bound over terms.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub bound: Option<String>,
    /// Per evaluation, each term's difference from the memory-only kernel's (the net's breakdown; the net
    /// itself is the difference of the bounds, never above it).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub net_terms: Vec<(String, f64)>,
    /// The rule's terms per wave (`targets::cost::schedule`: each pipe's busy cycles, then latency / resident waves),
    /// where the vendor's rule has them.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub terms: Vec<(String, f64)>,
}

#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct TargetCost {
    /// The report's device name.
    pub device: String,
    /// `radv:navi21`, `nvidia:sm_89`, ... (None: a real device that reports such statistics).
    pub target: Option<String>,
    /// The family's short name (navi21, sm_89) and architecture.
    pub family: Option<String>,
    pub architecture: Option<String>,
    /// What the compiler is, with the options that matter to the figures.
    pub compiler: String,
    /// How cycles/eval is computed, one line.
    pub model: String,
    /// What a cycle is ("SIMD cycles", "SM cycles").
    pub unit: String,
    pub lights_per_kernel: u32,
    /// Statistic names of `CostRow::stats` (as the compiler names them).
    pub columns: Vec<String>,
    pub rows: Vec<CostRow>,
    /// Models the target could not compile (fp16 arithmetic without shaderFloat16), each with why: named in
    /// the table so that no column drops a model silently.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub absent: Vec<(String, String)>,
    /// Models whose kernel failed for this target (its translation check, its compile), with the reason: the
    /// other models and targets go on, and the command exits 1.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub failed: Vec<(String, String)>,
    /// How the vendor's rule fares against published measurements (`targets::cost::measured::line`), one line.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub checked: Option<String>,
}

/// What a net cost at or below zero reads as in a ratio column: the memory-only kernel's bound sets it, not
/// the BRDF (`NEGATIVE_NET` says why), so it is no ratio at all.
pub const HARNESS_BOUND: &str = "harness-bound";

/// A "net vs REFERENCE" cell: the ratio of the nets, "harness-bound" where this kernel's net is not above 0.
pub fn ratio_cell(net: Option<f64>, reference: Option<f64>) -> String {
    match (net, reference) {
        (Some(v), Some(_)) if v <= 0.0 => HARNESS_BOUND.into(),
        (Some(v), Some(g)) if g > 0.0 => format!("{:.2}", v / g),
        _ => "-".into(),
    }
}

/// The note beside a net cost at or below zero.
pub const NEGATIVE_NET: &str = "net cost not above zero (harness-bound): the kernel's bound is not above the memory-only kernel's (a constant BRDF, or the BRDF's work hidden under a pipe both kernels bind on, such as Mali's load/store); its net figure measures that, and the breakdown by term says what the BRDF's code adds";

impl TargetCost {
    /// The reference model's cycles taken apart (its terms per wave, the binding one named), where the rule
    /// has terms.
    fn terms_note(&self) -> String {
        let Some(r) =
            self.row(crate::brdf::spec::REFERENCE_MODEL).or_else(|| self.rows.first()).filter(|r| !r.terms.is_empty())
        else {
            return String::new();
        };
        let (bind, _) =
            r.terms.iter().fold(("", f64::NEG_INFINITY), |b, (n, v)| if *v > b.1 { (n.as_str(), *v) } else { b });
        let parts: Vec<String> = r
            .terms
            .iter()
            .map(|(n, v)| if n == bind { format!("**{n} {}**", sig(*v, 4)) } else { format!("{n} {}", sig(*v, 4)) })
            .collect();
        let added: Vec<String> = r.net_terms.iter().map(|(n, v)| format!("{n} {}", sig(*v, 4))).collect();
        let breakdown = if added.is_empty() {
            String::new()
        } else {
            format!(
                " Per evaluation, each term's difference from the memory-only kernel's: {}; the net is the difference of the bounds, never above it.",
                added.join(", ")
            )
        };
        format!(
            "\n{}'s cycles per wave taken apart ({}): {}; the largest binds.{breakdown}\n",
            r.model,
            self.unit,
            parts.join(", ")
        )
    }

    /// "navi21 (RDNA 2)" or the device name.
    pub fn label(&self) -> String {
        match (&self.family, &self.architecture) {
            (Some(f), Some(a)) => format!("{f} ({a})"),
            _ => self.device.clone(),
        }
    }

    /// The column name in cross-device tables: "navi21 cycles/eval" (`targets::column_name` names a family two
    /// vendors share by its target).
    pub fn column_name(&self) -> String {
        format!("{} cycles/eval", self.family.clone().unwrap_or_else(|| self.device.clone()))
    }

    pub fn row(&self, model: &str) -> Option<&CostRow> {
        self.rows.iter().find(|r| r.model == model)
    }

    /// A statistic of a row by its column name.
    pub fn stat(&self, row: &CostRow, name: &str) -> Option<f64> {
        row.stats.get(name).copied()
    }

    pub fn markdown(&self) -> String {
        let all: Vec<&String> = self.columns.iter().collect();
        let (columns, constant) =
            super::fold_constant(&all, |c| self.rows.iter().map(|r| r.stats.get(*c).copied()).collect());
        let mut headers: Vec<String> = vec!["model".into()];
        headers.extend(columns.iter().map(|c| c.to_string()));
        let unguarded = self.row(crate::brdf::spec::UNGUARDED_REFERENCE_MODEL).and_then(|r| r.net_cycles_per_eval);
        headers.extend(["cycles/eval".into(), "net cycles/eval".into(), "net vs ggx".into()]);
        if unguarded.is_some() {
            headers.push(format!("net vs {}", crate::brdf::spec::UNGUARDED_REFERENCE_MODEL));
        }
        let bound = self.rows.iter().any(|r| r.bound.is_some());
        if bound {
            headers.push("bound by".into());
        }
        let mut t = Table::new(headers);
        let reference = self.row(crate::brdf::spec::REFERENCE_MODEL).and_then(|r| r.net_cycles_per_eval);
        for r in &self.rows {
            let mut cells = vec![r.model.clone()];
            cells.extend(columns.iter().map(|c| r.stats.get(*c).map_or("-".into(), |v| super::format_value(*v))));
            cells.push(sig(r.cycles_per_eval, 4));
            cells.push(r.net_cycles_per_eval.map_or("-".into(), |v| sig(v, 4)));
            cells.push(ratio_cell(r.net_cycles_per_eval, reference));
            if unguarded.is_some() {
                cells.push(ratio_cell(r.net_cycles_per_eval, unguarded));
            }
            if bound {
                cells.push(r.bound.clone().unwrap_or_else(|| "-".into()));
            }
            t.row(cells);
        }
        let mut out = format!(
            "### {} statistics, {} ({} lights per kernel; {}; {})\n\n{}",
            self.compiler,
            self.label(),
            self.lights_per_kernel,
            self.model,
            self.unit,
            t.markdown()
        );
        out += &super::constant_note(constant.iter().map(|(c, v)| (c.as_str(), *v)));
        if let Some(checked) = &self.checked {
            out += &format!("\n{checked}\n");
        }
        out += &self.terms_note();
        for (model, why) in &self.absent {
            out += &format!("\n{model}: not compiled for this target ({why}), so no figure.\n");
        }
        for (model, why) in &self.failed {
            out += &format!("\n**{model}: failed, so no figure**: {why}\n");
        }
        for r in self.rows.iter().filter(|r| r.net_cycles_per_eval.is_some_and(|v| v <= 0.0)) {
            out += &format!("\n{}: {}\n", r.model, NEGATIVE_NET);
        }
        out
    }
}
