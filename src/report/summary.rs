//! The report's first screen: one row per model however many reports mention it, one column per figure the
//! reports give (cost against the reference per device and target, accuracy against a reference, stability's
//! verdict). Rows are keyed `summary/<label>`; each figure's cell carries its value as every table's does.

use super::sections::{estimate_cell, num_cell};
use super::{Input, Loaded};
use crate::export::html::{self, Cell, HtmlTable, esc};
use crate::io::finite;
use crate::model::Model;
use crate::stability::SpecStability;
use std::collections::BTreeMap;

/// The mark of a modelled (compile-only) column's header.
const MODELLED: &str = "(m)";

/// Rows on the first screen (the rest folded below them) and figure columns (the sections below hold every
/// figure).
const MAX_ROWS: usize = 14;
const MAX_COLUMNS: usize = 10;

/// The stability column's header.
const STABILITY: &str = "stability";

/// What a model is, whatever form a report wrote it in: its canonical spec where it parses (a `.brdf`
/// file's where the file is still there), else the text as written.
pub fn model_key(spec: &str) -> String {
    Model::parse(spec).map(|m| m.canonical()).unwrap_or_else(|_| spec.to_string())
}

struct Column {
    /// The header: a few words (the device or report and what the figure is).
    short: String,
    /// What the figure is in full: the header's tooltip and the table's footnote.
    title: String,
    cells: BTreeMap<String, Cell>,
}

/// Why a model is in the summary: what puts it on the first screen (`Summary::order`).
#[derive(Clone, Copy, Default)]
struct Why {
    /// A file of the user's own (`.brdf`, shader).
    own_file: bool,
    /// Profiled, inspected or diffed: the models a run was asked about.
    named: bool,
    failing: bool,
    pareto: bool,
}

#[derive(Default)]
struct Summary {
    /// (key, label) in order of first mention.
    models: Vec<(String, String)>,
    why: BTreeMap<String, Why>,
    columns: Vec<Column>,
}

impl Summary {
    fn model(&mut self, spec: &str, label: &str) -> String {
        let key = model_key(spec);
        if !self.models.iter().any(|(k, _)| *k == key) {
            self.models.push((key.clone(), label.to_string()));
            let own_file = Model::parse(spec).is_ok_and(|m| m.file().is_some());
            self.why.insert(key.clone(), Why { own_file, ..Why::default() });
        }
        key
    }

    fn mark(&mut self, key: &str, f: impl Fn(&mut Why)) {
        if let Some(w) = self.why.get_mut(key) {
            f(w);
        }
    }

    /// Model indices, those that matter first: the user's own files, the models a run named, then failing
    /// and Pareto-optimal ones taken in turn (so that neither crowds the other off the first screen), then
    /// the rest; each group in order of first mention.
    fn order(&self) -> Vec<usize> {
        let why = |i: usize| self.why.get(&self.models[i].0).copied().unwrap_or_default();
        let all: Vec<usize> = (0..self.models.len()).collect();
        let mut out: Vec<usize> = all.iter().copied().filter(|&i| why(i).own_file).collect();
        out.extend(all.iter().copied().filter(|&i| !why(i).own_file && why(i).named));
        let rest: Vec<usize> = all.iter().copied().filter(|i| !out.contains(i)).collect();
        let failing: Vec<usize> = rest.iter().copied().filter(|&i| why(i).failing).collect();
        let pareto: Vec<usize> = rest.iter().copied().filter(|&i| why(i).pareto && !why(i).failing).collect();
        for k in 0..failing.len().max(pareto.len()) {
            out.extend(failing.get(k).into_iter().chain(pareto.get(k)));
        }
        let left: Vec<usize> = rest.into_iter().filter(|i| !out.contains(i)).collect();
        out.extend(left);
        out
    }

    /// A second column of one short name (one device in two reports) is numbered: `tahiti x ggx (m) #2`.
    fn column(&mut self, short: String, title: String, cells: Vec<(String, Cell)>) {
        if !cells.is_empty() {
            let same =
                self.columns.iter().filter(|c| c.short == short || c.short.starts_with(&format!("{short} #"))).count();
            let short = if same > 0 { format!("{short} #{}", same + 1) } else { short };
            self.columns.push(Column { short, title, cells: cells.into_iter().collect() });
        }
    }
}

fn stability_cell(s: &SpecStability) -> Cell {
    if s.fails() {
        let counts: Vec<String> = [(s.nan, "NaN"), (s.inf, "Inf"), (s.negative, "neg.")]
            .iter()
            .filter(|(n, _)| *n > 0)
            .map(|(n, what)| format!("{n} {what}"))
            .collect();
        Cell::num((s.nan + s.inf + s.negative) as f64, format!("FAIL ({})", counts.join(", ")))
    } else {
        Cell::num(0.0, "ok")
    }
}

/// A profile's column: each model's cost against the reference at the first light count.
fn profile_column(s: &mut Summary, p: &crate::profile::ProfileReport) {
    let lights = p.rows.first().map(|r| r.lights);
    let mut cells = Vec::new();
    for r in p.rows.iter().filter(|r| Some(r.lights) == lights && r.spec.is_some()) {
        let key = s.model(r.spec.as_deref().unwrap(), &r.model);
        s.mark(&key, |w| w.named = true);
        cells.push((key, estimate_cell(r.net_vs_reference.as_ref().or(Some(&r.vs_reference)))));
    }
    let net = if p.rows.iter().any(|r| r.net_vs_reference.is_some()) { "net cost" } else { "cost" };
    let device = &p.provenance.device.name;
    s.column(
        format!("{} {net} x {}", crate::export::name_slug(device), p.reference),
        format!("{net} vs {} ({device}, {} lights), measured", p.reference, lights.unwrap_or(0)),
        cells,
    );
}

/// One column per vendor among the inspected compile-only targets: each model's modelled net cost against
/// the reference, the median over that vendor's targets with their range (every target's figure is in
/// "Across devices").
fn inspect_columns(s: &mut Summary, reports: &[crate::schema::InspectReport]) {
    // vendor -> (family names, model key -> ratio per target)
    let mut groups: Vec<(&'static str, Vec<String>, BTreeMap<String, Vec<f64>>)> = Vec::new();
    for r in reports {
        let Some(cost) = r.cost.clone().or_else(|| crate::targets::cost_of(r)) else { continue };
        let vendor = cost.target.as_deref().and_then(crate::targets::vendor_name).unwrap_or("other");
        let specs: BTreeMap<&str, &str> =
            r.rows.iter().filter_map(|x| x.spec.as_deref().map(|sp| (x.model.as_str(), sp))).collect();
        let reference = cost
            .rows
            .iter()
            .find(|c| c.model == crate::brdf::spec::REFERENCE_MODEL)
            .and_then(|c| c.net_cycles_per_eval);
        let at = match groups.iter().position(|g| g.0 == vendor) {
            Some(k) => k,
            None => {
                groups.push((vendor, Vec::new(), BTreeMap::new()));
                groups.len() - 1
            }
        };
        let family = crate::targets::column_name(&cost).split_whitespace().next().unwrap_or("?").to_string();
        groups[at].1.push(family);
        for c in &cost.rows {
            let (Some(spec), Some(net), Some(base)) = (specs.get(c.model.as_str()), c.net_cycles_per_eval, reference)
            else {
                continue;
            };
            let key = s.model(spec, &c.model);
            s.mark(&key, |w| w.named = true);
            groups[at].2.entry(key).or_default().push(net / base);
        }
    }
    let reference = crate::brdf::spec::REFERENCE_MODEL;
    for (vendor, families, ratios) in groups {
        let cells = ratios.into_iter().map(|(key, v)| (key, range_cell(&v))).collect();
        s.column(
            format!("{vendor} x {reference} {MODELLED}"),
            format!(
                "modelled net cost vs {reference} on {} {vendor} target(s) ({}): the median, and (lowest-highest) where there are several",
                families.len(),
                families.join(", ")
            ),
            cells,
        );
    }
}

/// The median of `v` with its range: "1.92 (1.50-2.31)"; one value alone.
fn range_cell(v: &[f64]) -> Cell {
    let mut v: Vec<f64> = v.iter().copied().filter(|x| x.is_finite()).collect();
    if v.is_empty() {
        return Cell::text("-");
    }
    v.sort_by(f64::total_cmp);
    let n = v.len();
    let median = crate::stats::median(&v);
    let f = |x: f64| crate::export::markdown::sig_compact(x, 3);
    if n == 1 || v[0] == v[n - 1] {
        Cell::num(median, f(median))
    } else {
        Cell::num(median, format!("{} ({}\u{2013}{})", f(median), f(v[0]), f(v[n - 1])))
    }
}

/// A diff's two columns: the unsigned max relative difference, and the signed figure that says how the model
/// is wrong (its best-fit scale against the reference, and the shares of values brighter and darker).
fn diff_columns(s: &mut Summary, against: &str, diffs: Vec<(String, &crate::diff::DiffReport)>) {
    let max = diffs.iter().map(|(k, d)| (k.clone(), num_cell(finite(d.difference.max_rel)))).collect();
    s.column(format!("max diff. vs {against}"), format!("max relative difference vs {against}"), max);
    let signed = diffs
        .iter()
        .map(|(k, d)| {
            let g = &d.signed;
            let cell = match g.best_fit_scale {
                Some(scale) => Cell::num(
                    scale,
                    format!(
                        "x{} ({:.0}% brighter, {:.0}% darker)",
                        crate::export::markdown::sig_compact(scale, 3),
                        100.0 * g.brighter,
                        100.0 * g.darker
                    ),
                ),
                None => Cell::text("-"),
            };
            (k.clone(), cell)
        })
        .collect();
    s.column(
        format!("signed vs {against}"),
        format!(
            "best-fit scale against {against} (1: right on average; above 1 brighter), and the shares of values brighter and darker"
        ),
        signed,
    );
}

/// Gathers the rows and columns: models from every report but stability first, then the specs stability
/// failed (guard variants left out); a stability column fills in for the models it checked.
fn gather(inputs: &[Input]) -> Summary {
    let mut s = Summary::default();
    for input in inputs {
        match &input.loaded {
            Loaded::Profile(p) => profile_column(&mut s, p),
            Loaded::Inspect(reports, _) => inspect_columns(&mut s, reports),
            Loaded::Sweep(w) => {
                let mut cells = Vec::new();
                for r in w.rows.iter().filter(|r| r.pareto) {
                    let key = s.model(&r.canonical, &r.label);
                    s.mark(&key, |w| w.pareto = true);
                    cells.push((key, num_cell(finite(r.accuracy.vs_exact.rms))));
                }
                s.column("RMS err. (sweep)".into(), "RMS relative error vs exact (sweep)".into(), cells);
            }
            Loaded::Diff(d) => {
                let a = s.model(&d.a.canonical, &d.a.name);
                let key = s.model(&d.b.canonical, &d.b.name);
                for k in [&a, &key] {
                    s.mark(k, |w| w.named = true);
                }
                diff_columns(&mut s, &d.a.name, vec![(key, &**d)]);
            }
            Loaded::DiffSet(d) => {
                let mut cells = Vec::new();
                for x in &d.diffs {
                    let key = s.model(&x.b.canonical, &x.b.name);
                    s.mark(&key, |w| w.named = true);
                    cells.push((key, x));
                }
                diff_columns(&mut s, &d.reference.name, cells);
            }
            Loaded::Stability(_) | Loaded::Costs(_) => {}
        }
    }
    for input in inputs {
        if let Loaded::Stability(st) = &input.loaded {
            for spec in st.specs.iter().filter(|x| x.fails() && !crate::stability::is_guard_variant(&x.spec)) {
                let key = s.model(&spec.spec, spec.label());
                s.mark(&key, |w| w.failing = true);
            }
            let known: Vec<String> = s.models.iter().map(|(k, _)| k.clone()).collect();
            let cells = st
                .specs
                .iter()
                .filter(|x| !crate::stability::is_guard_variant(&x.spec))
                .map(|x| (model_key(&x.spec), stability_cell(x)))
                .filter(|(k, _)| known.contains(k))
                .collect();
            let failing = st.specs.iter().filter(|x| x.fails()).count();
            s.column(
                STABILITY.into(),
                format!("stability: NaN, Inf or negative values ({failing} of {} specs fail)", st.specs.len()),
                cells,
            );
        }
    }
    // Stability's verdict first: the one column a reader must not lose when the others do not fit.
    s.columns.sort_by_key(|c| c.short != STABILITY);
    s
}

/// Each model's label, numbered `label #k` where models of different specs share it.
fn numbered_labels(models: &[(String, String)]) -> Vec<String> {
    models
        .iter()
        .enumerate()
        .map(|(i, (_, label))| {
            let same: Vec<usize> = (0..models.len()).filter(|&j| models[j].1 == *label).collect();
            if same.len() < 2 {
                label.clone()
            } else {
                format!("{label} #{}", same.iter().position(|&j| j == i).unwrap_or(0) + 1)
            }
        })
        .collect()
}

/// The fold's line: how many more models, how many of them fail and how many are on the frontier.
fn folded_finding(s: &Summary, folded: &[usize]) -> String {
    let count = |f: fn(&Why) -> bool| folded.iter().filter(|&&i| s.why.get(&s.models[i].0).is_some_and(f)).count();
    let (failing, pareto) = (count(|w| w.failing), count(|w| w.pareto));
    let mut what = Vec::new();
    if failing > 0 {
        what.push(format!("{failing} failing stability"));
    }
    if pareto > 0 {
        what.push(format!("{pareto} on the sweep's Pareto frontier"));
    }
    let what = if what.is_empty() { String::new() } else { format!(": {}", what.join(", ")) };
    format!("{} more model(s){what}", folded.len())
}

/// The summary section's body, or None when no report names a model.
pub fn summary(inputs: &[Input]) -> Option<String> {
    let s = gather(inputs);
    if s.models.is_empty() {
        return None;
    }
    let keys: Vec<String> = (0..s.columns.len().min(MAX_COLUMNS)).map(|i| format!("c{i}")).collect();
    let mut header: Vec<(&str, &str)> = vec![("model", "model")];
    header.extend(keys.iter().map(String::as_str).zip(s.columns.iter().map(|c| c.short.as_str())));
    let table = || {
        let mut t = HtmlTable::new(&header);
        for (key, c) in keys.iter().zip(&s.columns) {
            t.describe(key, c.title.clone());
        }
        t
    };
    let footnotes: Vec<String> = s
        .columns
        .iter()
        .take(MAX_COLUMNS)
        .map(|c| format!("<li><b>{}</b>: {}</li>", esc(&c.short), esc(&c.title)))
        .collect();
    // Two different models under one label (from different reports) are told apart by a number, and said so.
    let shown = numbered_labels(&s.models);
    let shared: Vec<&str> =
        s.models.iter().zip(&shown).filter(|((_, l), shown)| l != *shown).map(|(_, shown)| shown.as_str()).collect();
    let order = s.order();
    let (first, folded) = order.split_at(order.len().min(MAX_ROWS));
    let rows = |indices: &[usize]| {
        let mut t = table();
        for &i in indices {
            let (key, label) = (&s.models[i].0, &shown[i]);
            let mut cells = vec![Cell::text(label.clone())];
            cells.extend(
                s.columns
                    .iter()
                    .take(MAX_COLUMNS)
                    .map(|c| c.cells.get(key).cloned().unwrap_or_else(|| Cell::text("-"))),
            );
            t.row(format!("summary/{label}"), cells);
        }
        t.html()
    };
    let mut more =
        if folded.is_empty() { String::new() } else { html::fold(&folded_finding(&s, folded), &rows(folded)) };
    if s.columns.len() > MAX_COLUMNS {
        more +=
            &format!("<p class=\"note\">{} more column(s) in the sections below.</p>", s.columns.len() - MAX_COLUMNS);
    }
    if !shared.is_empty() {
        more += &format!(
            "<p class=\"note\">Different models (canonical specs) carry one label in the reports given; numbered here: {}. Their specs are in provenance.</p>",
            esc(&shared.join(", "))
        );
    }
    Some(format!(
        "<p class=\"note\">One row per model: the user's own files, the models a run named, then failing and Pareto-optimal ones; costs are ratios to the reference ({MODELLED}: modelled, <a href=\"#devices\">rules</a>).</p>{}{more}<details class=\"columns\"><summary>The columns</summary><p class=\"note\">A cost is a ratio to the reference model, with its confidence interval where measured; {MODELLED} marks a modelled compile-only cost, one column per vendor (the median over its targets and their range); accuracy is against the reference each report names; stability: NaN, Inf or negative values on valid inputs. Where each figure comes from: <a href=\"#provenance\">provenance</a>, at the end.</p><ul class=\"note\">{}</ul></details>",
        rows(first),
        footnotes.join("")
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn two_models_under_one_label_are_numbered_and_others_keep_theirs() {
        let models: Vec<(String, String)> =
            [("a", "mine"), ("b", "ggx"), ("c", "mine")].iter().map(|(k, l)| (k.to_string(), l.to_string())).collect();
        assert_eq!(numbered_labels(&models), ["mine #1", "ggx", "mine #2"]);
    }
}
