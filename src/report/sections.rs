//! The report's tables and charts drawn from the saved figures: provenance, profile cost tables, the cost
//! table across devices, the sweep's accuracy-against-cost chart and table, stability's summary and heat maps.
//! Every figure shown in a table carries its value (`data-v`) and the row and column it belongs to, so that
//! the browser test reads it back and checks it against the JSON.

use super::{Input, Loaded, file_label, utc};
use crate::accuracy::ErrorStats;
use crate::compare::CostTable;
use crate::export::html::{self, Axis, Cell, HtmlTable, Point, esc};
use crate::export::json::Provenance;
use crate::export::markdown::sig;
use crate::io::finite;
use crate::profile::{ProfileReport, Row};
use crate::stability::{SpecStability, StabilityReport};
use crate::stats::Estimate;
use crate::sweep::SweepReport;
use anyhow::Result;
use std::fmt::Write;

/// Significant digits of the figures shown.
pub const DIGITS: usize = 3;

/// "median [lo, hi]" as a cell whose value is the median.
pub fn estimate_cell(e: Option<&Estimate>) -> Cell {
    match e {
        Some(e) => {
            Cell::num(e.median, format!("{} [{}, {}]", sig(e.median, DIGITS), sig(e.lo, DIGITS), sig(e.hi, DIGITS)))
        }
        None => Cell::text("-"),
    }
}

/// A number as a cell ("-" where absent; "NaN/Inf" where the report wrote null for a figure that exists).
pub fn num_cell(x: Option<f64>) -> Cell {
    match x {
        Some(x) => Cell::num(x, crate::export::markdown::sig_compact(x, DIGITS)),
        None => Cell::text("-"),
    }
}

fn count_cell(n: usize) -> Cell {
    Cell::num(n as f64, n.to_string())
}

fn kv(items: &[(&str, String)]) -> String {
    let mut s = String::from("<dl class=\"kv\">");
    for (k, v) in items.iter().filter(|(_, v)| !v.is_empty()) {
        let _ = write!(s, "<dt>{}</dt><dd>{}</dd>", esc(k), esc(v));
    }
    s + "</dl>"
}

fn provenance_items(p: &Provenance) -> Vec<(&'static str, String)> {
    let d = &p.device;
    let cpu = p.cpu.as_ref().map_or_else(
        || p.host_cpu.clone().unwrap_or_default(),
        |c| {
            format!(
                "{} (family {}, model {}, stepping {}; {})",
                c.model_name,
                c.family,
                c.model,
                c.stepping,
                c.features.join(" ")
            )
        },
    );
    vec![
        ("device", format!("{} ({})", d.name, d.device_type)),
        ("driver", format!("{} {} ({})", d.driver_name, d.driver_version, d.driver_info)),
        ("Vulkan", d.api_version.clone()),
        (
            "Mesa / LLVM",
            format!("{} / {}", p.mesa_version.as_deref().unwrap_or("-"), p.llvm_version.as_deref().unwrap_or("-")),
        ),
        ("CPU", cpu),
        ("host threads", if p.host_threads > 0 { p.host_threads.to_string() } else { String::new() }),
        ("driver environment", p.env.iter().map(|(k, v)| format!("{k}={v}")).collect::<Vec<_>>().join(" ")),
        ("tool", p.tool.clone()),
        ("written", if p.unix_time > 0 { utc(p.unix_time) } else { String::new() }),
        (
            "command",
            p.command
                .as_ref()
                .map_or_else(|| "(not recorded by the brdfprof that wrote it)".to_string(), |c| c.join(" ")),
        ),
        ("front ends", p.front_ends.iter().map(|(m, f)| format!("{m}: {f}")).collect::<Vec<_>>().join("; ")),
    ]
}

/// Where and how each input was measured.
pub fn provenance(inputs: &[Input]) -> String {
    let mut s = String::new();
    for (i, input) in inputs.iter().enumerate() {
        let _ =
            write!(s, "<h3 data-input=\"{i}\">{} <code>{}</code></h3>", input.loaded.kind(), file_label(&input.path));
        match &input.loaded {
            Loaded::Profile(p) => s += &kv(&provenance_items(&p.provenance)),
            Loaded::Sweep(w) => s += &kv(&provenance_items(&w.profile.provenance)),
            Loaded::Stability(st) => s += &kv(&provenance_items(&st.provenance)),
            Loaded::Inspect(reports, _) => {
                for r in reports {
                    let p: Provenance = serde_json::from_value(r.provenance.clone()).unwrap_or_default();
                    let mut items = provenance_items(&p);
                    items.push((
                        "compilers",
                        r.tools.iter().map(|(k, v)| format!("{k}: {v}")).collect::<Vec<_>>().join("; "),
                    ));
                    items.push(("kernels", r.kernels.clone()));
                    s += &kv(&items);
                }
            }
            Loaded::Diff(d) => {
                let fronts = [&d.a, &d.b]
                    .iter()
                    .filter_map(|x| x.front_end.as_ref().map(|f| format!("{}: {f}", x.name)))
                    .collect::<Vec<_>>()
                    .join("; ");
                s += &kv(&[
                    ("device", d.device.clone()),
                    ("models", format!("A = {}, B = {}", d.a.canonical, d.b.canonical)),
                    ("input", d.input.clone()),
                    ("front ends", fronts),
                ]);
            }
            Loaded::DiffSet(d) => {
                let models = d.diffs.iter().map(|x| x.b.canonical.clone()).collect::<Vec<_>>().join("; ");
                s += &kv(&[
                    ("device", d.device.clone()),
                    ("reference", d.reference.canonical.clone()),
                    ("models", models),
                    ("input", d.input.clone()),
                ]);
            }
            Loaded::Costs(t) => {
                s += &kv(&[(
                    "columns",
                    t.columns.iter().map(|c| format!("{} ({})", c.name, c.source)).collect::<Vec<_>>().join("; "),
                )])
            }
        }
    }
    s
}

/// The profile columns: (key, header).
const PROFILE_COLUMNS: [(&str, &str); 7] = [
    ("model", "model"),
    ("spec", "spec"),
    ("ns", "ns/eval [95% CI]"),
    ("net", "net ns/eval [CI]"),
    ("ratio", "x reference [CI]"),
    ("net-ratio", "net x reference [CI]"),
    ("harness", "harness share [CI]"),
];

fn profile_row(r: &Row) -> Vec<Cell> {
    vec![
        Cell::text(r.model.clone()),
        Cell::text(r.spec.clone().unwrap_or_else(|| "memory-only kernel".into())),
        estimate_cell(Some(&r.ns_per_eval)),
        estimate_cell(r.net_ns_per_eval.as_ref()),
        estimate_cell(Some(&r.vs_reference)),
        estimate_cell(r.net_vs_reference.as_ref()),
        estimate_cell(r.harness_share.as_ref()),
    ]
}

/// One profile report's tables, a table per light count; rows keyed `profile<i>/<lights>/<model>`.
pub fn profile_tables(i: usize, p: &ProfileReport, path: &str) -> String {
    let w = &p.workload;
    let mut s = format!(
        "<h3>{path}</h3><p class=\"note\">{}x{} G-buffer, {} rounds, {:.0}% confidence intervals of the median over rounds; reference {}; net = minus the memory-only kernel (loads, light loop, stores).</p>",
        w.width,
        w.height,
        p.rounds,
        100.0 * p.confidence_level,
        esc(&p.reference)
    );
    for &lights in &w.lights {
        let mut t = HtmlTable::new(&PROFILE_COLUMNS);
        for r in p.rows.iter().filter(|r| r.lights == lights) {
            t.row(format!("profile{i}/{lights}/{}", r.model), profile_row(r));
        }
        let _ = write!(s, "<p class=\"note\">{lights} light(s) per pixel</p>{}", t.html());
    }
    s
}

/// The cost tables of every profile input.
pub fn profiles(inputs: &[Input]) -> String {
    let mut s = String::new();
    for (i, input) in inputs.iter().enumerate() {
        if let Loaded::Profile(p) = &input.loaded {
            s += &profile_tables(i, p, &file_label(&input.path));
        }
    }
    s
}

/// A cost column's device: its name without the unit ("navi21 cycles/eval" -> "navi21").
fn device_of(column: &str) -> &str {
    column.rsplit_once(' ').map_or(column, |(d, _)| d)
}

/// A cost table across devices, folded under its one-line finding: the table (net cost and net relative to
/// ggx per column; rows keyed `devices/<model>`, columns `c<j>` and `c<j>r`), the cost rules said once per
/// unit, and the rank correlations as a matrix.
pub fn cost_table_html(table: &CostTable) -> String {
    let mut columns: Vec<(String, String)> = vec![("model".into(), "model".into())];
    for (j, c) in table.columns.iter().enumerate() {
        columns.push((format!("c{j}"), format!("{} net", c.name)));
        columns.push((format!("c{j}r"), "x ggx".into()));
    }
    let refs: Vec<(&str, &str)> = columns.iter().map(|(k, h)| (k.as_str(), h.as_str())).collect();
    let mut t = HtmlTable::new(&refs);
    let mut spread: Vec<(f64, &str, &str)> = Vec::new();
    for m in &table.models {
        let mut cells = vec![Cell::text(m.clone())];
        for c in &table.columns {
            cells.push(num_cell(c.net.get(m).copied()));
            let r = table.relative(c, m);
            if let Some(r) = r.filter(|r| *r > 0.0 && m != crate::brdf::spec::REFERENCE_MODEL) {
                spread.push((r, m, device_of(&c.name)));
            }
            cells.push(num_cell(r));
        }
        t.row(format!("devices/{m}"), cells);
    }
    // Each rule once: the columns that share a unit's text (one vendor's families) are named together.
    let mut units: Vec<(&str, Vec<&str>)> = Vec::new();
    for c in &table.columns {
        match units.iter_mut().find(|(u, _)| *u == c.unit) {
            Some((_, names)) => names.push(device_of(&c.name)),
            None => units.push((&c.unit, vec![device_of(&c.name)])),
        }
    }
    let rules: String = units
        .iter()
        .map(|(unit, names)| format!("<li><b>{}</b>: {}</li>", esc(&names.join(", ")), esc(unit)))
        .collect();
    let sources: Vec<String> =
        table.columns.iter().map(|c| format!("{}: {}", esc(device_of(&c.name)), esc(&c.source))).collect();
    spread.sort_by(|a, b| a.0.total_cmp(&b.0));
    let range = match (spread.first(), spread.last()) {
        (Some(lo), Some(hi)) => format!(
            "; net x ggx from {} ({} on {}) to {} ({} on {})",
            sig(lo.0, DIGITS),
            esc(lo.1),
            esc(lo.2),
            sig(hi.0, DIGITS),
            esc(hi.1),
            esc(hi.2)
        ),
        _ => String::new(),
    };
    let (matrix, agreement) = rank_matrix(table);
    let models = table.models.iter().filter(|m| *m != crate::model::BASELINE_LABEL).count();
    format!(
        "<p class=\"note\"><b>{models} models on {} devices{range}.</b> {agreement}</p>{}{}{}",
        table.columns.len(),
        html::fold(
            &format!("The cost table: net cost and x ggx on each of {} devices", table.columns.len()),
            &t.html()
        ),
        html::fold(
            &format!("The cost rules, once per unit ({} rules)", units.len()),
            &format!("<ul class=\"note\">{rules}</ul><p class=\"note\">Sources: {}</p>", sources.join("; "))
        ),
        html::fold("Rank correlations between devices (Spearman rho, matrix)", &matrix)
    )
}

/// The rank correlations as a devices x devices matrix (rows keyed `rho/<device>`, each cell's `data-v` its
/// rho), a rho whose CI includes 0 or that has none greyed; and the one-line agreement finding.
fn rank_matrix(table: &CostTable) -> (String, String) {
    let pairs: Vec<&crate::compare::PairCorrelation> = table.correlations.iter().chain(&table.spirv_baseline).collect();
    let mut names: Vec<&str> = Vec::new();
    for p in &pairs {
        for n in [p.a.as_str(), p.b.as_str()] {
            if !names.contains(&n) {
                names.push(n);
            }
        }
    }
    let certain = |p: &crate::compare::PairCorrelation| p.spearman_ci.is_some_and(|(lo, hi)| lo > 0.0 || hi < 0.0);
    let rhos: Vec<f64> = pairs.iter().filter_map(|p| p.spearman_net.filter(|_| p.spearman_ci.is_some())).collect();
    let sure = pairs.iter().filter(|p| certain(p)).count();
    let agreement = match rhos.len() {
        0 => "Too few models in common to rank the devices against each other.".to_string(),
        n => format!(
            "Rank agreement between devices: median Spearman rho {:.2} over {n} pairs; {sure} of them with a 95% CI that excludes 0.",
            crate::stats::median(&rhos)
        ),
    };
    let mut s = String::from("<table class=\"matrix\"><thead><tr><th></th>");
    for n in &names {
        let _ = write!(s, "<th><span>{}</span></th>", esc(device_of(n)));
    }
    s += "</tr></thead><tbody>\n";
    for a in &names {
        let _ = write!(s, "<tr data-row=\"rho/{}\"><td>{}</td>", esc(a), esc(device_of(a)));
        for b in &names {
            let p = pairs.iter().find(|p| (p.a == *a && p.b == *b) || (p.a == *b && p.b == *a));
            match p.and_then(|p| p.spearman_net.filter(|_| p.spearman_ci.is_some()).map(|r| (p, r))) {
                Some((p, r)) => {
                    let (lo, hi) = p.spearman_ci.unwrap_or((-1.0, 1.0));
                    let _ = write!(
                        s,
                        "<td data-col=\"{}\" data-v=\"{r:e}\" class=\"n{}\" title=\"{} / {}: rho {r:.2}, 95% CI [{lo:.2}, {hi:.2}], {} models, discordant pairs {}\">{r:.2}</td>",
                        esc(b),
                        if certain(p) { "" } else { " uncertain" },
                        esc(a),
                        esc(b),
                        p.models,
                        esc(&p.discordant_cell())
                    );
                }
                None => s += "<td></td>",
            }
        }
        s += "</tr>\n";
    }
    s += "</tbody></table>";
    let _ = write!(
        s,
        "<p class=\"note\">Greyed: a rho whose 95% CI includes 0 (too few models to tell the order apart). Hover a cell for its CI, model count and discordant pairs. {}</p>",
        crate::compare::RHO_NOTE
    );
    (s, agreement)
}

/// Cost per source line (`inspect --lines`): per device and model, the costliest lines with their share of
/// the binding pipe; rows keyed `lines/<device>/<model>/<file>:<line>`.
pub fn source_lines(inputs: &[Input]) -> String {
    let mut out = String::new();
    for i in inputs {
        let Loaded::Inspect(reports, _) = &i.loaded else { continue };
        for r in reports {
            let device = r.provenance["device"]["name"].as_str().unwrap_or("?");
            let unit = r.cost.as_ref().map_or("cycles", |c| c.unit.as_str());
            for k in &r.lines {
                let total: f64 = k.lines.iter().map(|l| l.binding).sum();
                let mut t = HtmlTable::new(&[
                    ("line", "file:line"),
                    ("instructions", "instructions"),
                    ("binding", "binding pipe cycles/wave"),
                    ("share", "share"),
                    ("schedule", "schedule cycles/wave"),
                    ("source", "source"),
                ]);
                for l in k.lines.iter().take(LINES_SHOWN) {
                    let share = (total > 0.0).then(|| 100.0 * l.binding / total);
                    let at = format!("{}:{}", l.file, l.line);
                    t.row(
                        format!("lines/{device}/{}/{at}", k.model),
                        vec![
                            Cell::text(at),
                            count_cell(l.instructions as usize),
                            num_cell(Some(l.binding)),
                            num_cell(share),
                            num_cell(Some(l.schedule)),
                            Cell::text(l.text.clone()),
                        ],
                    );
                }
                out += &format!(
                    "<h3>{}: {}</h3>{}<p class=\"note\">{unit}; ranked by the cycles on the pipe that binds the kernel ({}), share in %; {} of {} instructions are the translation's own or the compiler's. {}</p>",
                    esc(device),
                    esc(&k.model),
                    t.html(),
                    esc(&k.binding_pipe),
                    k.unattributed,
                    k.instructions,
                    esc(&k.note)
                );
            }
        }
    }
    out
}

/// Lines per model in the HTML report's cost-per-line tables.
const LINES_SHOWN: usize = 10;

/// The cost table across devices: `compare` over the profile and inspect inputs (refusing kernels that
/// differ, as `brdfprof compare` does), else the inspect's own table or a compare input.
pub fn across_devices(inputs: &[Input]) -> Option<String> {
    let joinable: Vec<std::path::PathBuf> = inputs
        .iter()
        .filter(|i| matches!(i.loaded, Loaded::Profile(_) | Loaded::Inspect(..)))
        .map(|i| i.path.clone())
        .collect();
    let has_devices =
        inputs.iter().any(|i| matches!(i.loaded, Loaded::Inspect(..) | Loaded::Costs(_))) || joinable.len() > 1;
    if !has_devices {
        return None;
    }
    let own = inputs.iter().find_map(|i| match &i.loaded {
        Loaded::Inspect(_, Some(t)) | Loaded::Costs(t) => Some(t.clone()),
        _ => None,
    });
    match crate::compare::from_files(&joinable) {
        Ok(t) => Some(cost_table_html(&t)),
        Err(e) => {
            let why = format!(
                "<p class=\"err\">The profile and inspect reports given were not joined: {}</p>",
                esc(&format!("{e:#}"))
            );
            Some(why + &own.map_or_else(String::new, |t| cost_table_html(&t)))
        }
    }
}

fn err_text(e: &ErrorStats) -> String {
    match (finite(e.rms), finite(e.max)) {
        (Some(r), Some(m)) => format!("RMS {}, max {}", sig(r, DIGITS), sig(m, DIGITS)),
        _ => format!("infinite ({} NaN/Inf values)", e.nonfinite),
    }
}

/// The error axis fitted to the bulk of the specs (as the PNG's, `png::fit_log_range`): a point below `lo` sits
/// at the axis's bottom edge, marked (`edge`), its value in its label.
fn pin_below(points: Vec<(Point, bool)>, lo: f64) -> Vec<(Point, bool)> {
    points
        .into_iter()
        .map(|(mut p, half)| {
            if p.y.is_finite() && p.y > 0.0 && p.y < lo {
                p.label = format!("{} ({:.1e}, below)", p.label, p.y);
                p.tip += "\n(drawn at the axis's bottom edge: below its range)";
                p.y = lo * 1.25;
                p.edge = true;
            }
            (p, half)
        })
        .collect()
}

/// The sweep's error-against-cost chart: net ns/eval (gross where there is no net) against the RMS relative
/// error against the exact reference, both log; the Pareto frontier labelled and joined. fp16 specs (and any
/// spec costlier than every fp32 one) go to a narrow panel of their own beside it on the same error axis, so
/// that they do not squeeze the fp32 specs into one band.
pub fn sweep_chart(w: &SweepReport) -> String {
    let points: Vec<(Point, bool)> = w
        .rows
        .iter()
        .map(|r| {
            let cost = r.net_ns_per_eval.as_ref().unwrap_or(&r.ns_per_eval);
            let err = finite(r.accuracy.vs_exact.rms).unwrap_or(f64::INFINITY);
            let tip = format!(
                "{}\nspec: {}\ncost: {} [{}, {}] ns/eval{}\nerror vs exact: {}",
                r.label,
                r.canonical,
                sig(cost.median, DIGITS),
                sig(cost.lo, DIGITS),
                sig(cost.hi, DIGITS),
                if r.net_ns_per_eval.is_some() { " net" } else { "" },
                err_text(&r.accuracy.vs_exact)
            );
            let half = r.canonical.contains("precision=f16");
            (Point { x: cost.median, y: err, label: r.label.clone(), tip, emphasis: r.pareto, edge: false }, half)
        })
        .collect();
    let (lo, hi) = crate::export::png::fit_log_range(&points.iter().map(|(p, _)| p.y).collect::<Vec<_>>());
    let points = pin_below(points, lo);
    let drawable = |p: &Point| p.x.is_finite() && p.x > 0.0 && p.y.is_finite() && p.y > 0.0;
    let left_out = points.iter().filter(|(p, _)| !drawable(p)).count();
    let fp32_top = points.iter().filter(|(p, half)| !half && drawable(p)).map(|(p, _)| p.x).fold(0.0, f64::max);
    let (main, side): (Vec<Point>, Vec<Point>) = {
        let (m, s): (Vec<_>, Vec<_>) = points.into_iter().partition(|(p, half)| !half && p.x <= fp32_top);
        (m.into_iter().map(|(p, _)| p).collect(), s.into_iter().map(|(p, _)| p).collect())
    };
    let xs = |pts: &[Point]| Axis::fit(pts.iter().filter(|p| drawable(p)).map(|p| p.x), true);
    let fitted = Axis::fit(main.iter().chain(&side).filter(|p| drawable(p)).map(|p| p.y), true).map(|a| Axis {
        lo: a.lo.max(lo),
        hi: a.hi.min(hi).max(a.lo.max(lo) * 10.0),
        log: true,
    });
    let (Some(y), Some(x)) = (fitted, xs(&main).or_else(|| xs(&side))) else {
        return "<p class=\"note\">No spec has a finite, positive cost and error to draw.</p>".into();
    };
    let (x_label, y_label) = ("net ns per evaluation (log)", "RMS relative error vs exact (log)");
    let mut s = String::from("<div class=\"row\">");
    s += &html::scatter_svg(&main, (x, y), x_label, y_label, html::WIDE, true);
    let side_note = match xs(&side).filter(|_| !main.is_empty()) {
        Some(sx) => {
            s += &html::scatter_svg(&side, (sx, y), "fp16 specs: net ns/eval", y_label, html::SIDE, false);
            format!(" The {} fp16 spec(s) have their own panel (their own cost axis, the same error axis).", side.len())
        }
        None => String::new(),
    };
    s += "</div>";
    let _ = write!(
        s,
        "<p class=\"note\">Red, joined: the Pareto frontier (no spec both cheaper and more accurate), labelled where there is room; hover any point for its spec, cost and error (every spec is in the table).{side_note}{}</p>",
        if left_out > 0 {
            format!(" {left_out} spec(s) with an infinite, zero or NaN figure are not drawn.")
        } else {
            String::new()
        }
    );
    s
}

const SWEEP_COLUMNS: [(&str, &str); 10] = [
    ("rank", "rank"),
    ("label", "spec"),
    ("ns", "ns/eval [CI]"),
    ("net", "net ns/eval [CI]"),
    ("fastest", "x fastest [CI]"),
    ("rms", "RMS err vs exact"),
    ("max", "max err vs exact"),
    ("numerical", "RMS err vs f64 formula"),
    ("albedo", "albedo err"),
    ("pareto", "Pareto"),
];

/// One sweep: the chart and the table; rows keyed `sweep<i>/<label>`.
pub fn sweep_html(i: usize, w: &SweepReport, path: &str) -> String {
    let mut t = HtmlTable::new(&SWEEP_COLUMNS);
    for r in &w.rows {
        let a = &r.accuracy;
        t.row(
            format!("sweep{i}/{}", r.label),
            vec![
                Cell::num(r.rank as f64, format!("{}{}", r.rank, if r.tied { " (tied)" } else { "" })),
                Cell::text(r.label.clone()),
                estimate_cell(Some(&r.ns_per_eval)),
                estimate_cell(r.net_ns_per_eval.as_ref()),
                estimate_cell(Some(&r.cost_vs_fastest)),
                num_cell(finite(a.vs_exact.rms)),
                num_cell(finite(a.vs_exact.max)),
                num_cell(a.numerical.as_ref().and_then(|n| finite(n.rms))),
                num_cell(finite(a.albedo_vs_exact)),
                Cell::text(if r.pareto { "yes" } else { "" }),
            ],
        );
    }
    let against = if w.against.is_empty() { String::new() } else { format!(" Errors against {}.", esc(&w.against)) };
    format!(
        "<h3>{path}</h3><p class=\"note\">{} specs on {}; fastest {}.{against}</p>{}{}",
        w.rows.len(),
        esc(&w.sample_set),
        esc(&w.fastest),
        sweep_chart(w),
        html::fold(&format!("Every spec's cost and accuracy ({} rows)", w.rows.len()), &t.html())
    )
}

pub fn sweeps(inputs: &[Input]) -> String {
    let mut s = String::new();
    for (i, input) in inputs.iter().enumerate() {
        if let Loaded::Sweep(w) = &input.loaded {
            s += &sweep_html(i, w, &file_label(&input.path));
        }
    }
    s
}

const STABILITY_COLUMNS: [(&str, &str); 12] = [
    ("spec", "spec"),
    ("nan", "NaN"),
    ("inf", "Inf"),
    ("negative", "negative"),
    ("cases", "cases out of tolerance"),
    ("grid", "grid points out of tolerance"),
    ("worst", "worst deviation (tolerances)"),
    ("jumps", "discontinuities"),
    ("model-jumps", "the formula's own steps"),
    ("reciprocity", "reciprocity"),
    ("max-e", "max albedo (F = 1)"),
    ("verdict", "verdict"),
];

fn stability_row(s: &SpecStability) -> Vec<Cell> {
    vec![
        Cell::text(s.label().to_string()),
        count_cell(s.nan),
        count_cell(s.inf),
        count_cell(s.negative),
        Cell::num(
            s.cases_out_of_tolerance.len() as f64,
            crate::stability::cases_cell(s.cases_out_of_tolerance.len(), s.cases_run, s.checked()),
        ),
        if s.checked() { count_cell(s.grid_out_of_tolerance) } else { Cell::text("-".to_string()) },
        if s.checked() { num_cell(finite(s.worst.deviation)) } else { Cell::text("-".to_string()) },
        if s.jumps_checked {
            count_cell(s.discontinuities)
        } else {
            Cell::text(crate::stability::jumps_cell(s.discontinuities, false))
        },
        count_cell(s.model_jumps),
        num_cell(s.reciprocity),
        num_cell(s.energy.as_ref().and_then(|e| e.max_e)),
        Cell::text(if s.fails() {
            "FAIL"
        } else if s.energy.as_ref().is_some_and(|e| e.gains_energy) {
            "gains energy"
        } else {
            "ok"
        }),
    ]
}

/// The bad values of a spec over (roughness, NoV) as a heat map image: white none, viridis by log count.
fn heat_map(s: &SpecStability, triples: &[[u32; 3]]) -> Result<String> {
    use crate::stability::grid::{COSINES, ROUGHNESS};
    let (w, h) = (COSINES.len() as u32, ROUGHNESS.len() as u32);
    let max = triples.iter().map(|t| t[2]).max().unwrap_or(1).max(1) as f32;
    let mut rgb = vec![255u8; (w * h * 3) as usize];
    for &[r, v, n] in triples.iter().filter(|t| (t[0] as usize) < ROUGHNESS.len() && (t[1] as usize) < COSINES.len()) {
        // Roughness up the image (row 0 at the bottom), NoV to the right.
        let k = (((h - 1 - r) * w + v) * 3) as usize;
        let c = crate::export::raster::viridis((1.0 + n as f32).ln() / (1.0 + max).ln());
        rgb[k..k + 3].copy_from_slice(&c);
    }
    // Counts read from a saved report: summed wide, so a crafted one cannot wrap the caption's total.
    let total: u64 = triples.iter().map(|t| u64::from(t[2])).sum();
    let uri = html::png_data_uri(w, h, &rgb)?;
    let caption = format!(
        "{}: {total} bad values (NaN, Inf, negative) in {} cells; NoV {}..{} right, roughness {}..{} up; most in a cell {max}",
        s.label(),
        triples.len(),
        COSINES[0],
        COSINES[COSINES.len() - 1],
        ROUGHNESS[0],
        ROUGHNESS[ROUGHNESS.len() - 1]
    );
    let ticks = |grid: &[f64], at: &[f64]| -> Vec<(usize, String)> {
        at.iter().filter_map(|v| grid.iter().position(|g| (g - v).abs() < 1e-6).map(|i| (i, v.to_string()))).collect()
    };
    let roughness: Vec<f64> = ROUGHNESS.iter().map(|&r| f64::from(r)).collect();
    let (x, y) = (ticks(&COSINES, &[0.0, 0.1, 0.5, 0.9, 1.0]), ticks(&roughness, &[0.0, 0.1, 0.5, 1.0]));
    // The colour is ln(1 + n) / ln(1 + most): its middle is n = sqrt(1 + most) - 1.
    let middle = ((1.0 + max as f64).sqrt() - 1.0).round();
    let axes = html::HeatAxes {
        x: (&x, "NoV"),
        y: (&y, "roughness"),
        bar: (["0".into(), format!("{middle}"), format!("{max}")], "bad values per cell (log)"),
    };
    Ok(format!(
        "<figure>{}<figcaption>{}</figcaption></figure>",
        html::heat_svg(&uri, (w, h, 6), &axes, &caption),
        esc(s.label())
    ))
}

/// What a failing result is: NaN before Inf before negative (the text `Failure::result` writes).
fn result_class(result: &str) -> &'static str {
    if result.contains("NaN") {
        "NaN"
    } else if result.contains("inf") {
        "Inf"
    } else {
        "negative"
    }
}

/// Causes shown before the fold.
const CAUSES_SHOWN: usize = 10;

/// A cause of failure: the hard case (or the grid), what it gives, the input guards that remove it.
type Cause = (String, &'static str, String);

/// Each failing spec's causes (guard variants left out), with the specs that fail so, most specs first.
fn causes_of(st: &StabilityReport) -> Vec<(Cause, Vec<&str>)> {
    let mut causes: Vec<(Cause, Vec<&str>)> = Vec::new();
    for spec in st.specs.iter().filter(|x| x.fails() && !crate::stability::is_guard_variant(&x.spec)) {
        let f = &spec.failures;
        let mut keys: Vec<Cause> = f
            .cases
            .iter()
            .map(|c| (c.at.clone(), result_class(&c.result), crate::stability::failures::removed_text(c)))
            .collect();
        if f.grid_points > 0 {
            let all: Vec<String> = f
                .grid_removed_by
                .iter()
                .filter(|g| g.removes == f.grid_points && g.guard != crate::stability::failures::ALL_GUARDS)
                .map(|g| format!("`{}`", g.guard))
                .collect();
            let class = f.grid_examples.first().map_or("bad value", |e| result_class(&e.result));
            let removed = if all.is_empty() {
                "no input guard alone removes every point".to_string()
            } else {
                format!("removed by {}", all.join(", "))
            };
            keys.push(("the grid (NoV x roughness)".to_string(), class, removed));
        }
        keys.dedup();
        for key in keys {
            match causes.iter_mut().find(|(k, _)| *k == key) {
                Some((_, specs)) => specs.push(spec.label()),
                None => causes.push((key, vec![spec.label()])),
            }
        }
    }
    causes.sort_by(|a, b| b.1.len().cmp(&a.1.len()));
    causes
}

/// The causes' table (rows keyed `cause<i>/<k>` from `from`), each row's specs all on hover.
fn causes_table(i: usize, rows: &[(Cause, Vec<&str>)], from: usize) -> String {
    let mut t = HtmlTable::new(&[
        ("case", "where"),
        ("result", "gives"),
        ("removed", "input guards"),
        ("specs", "specs"),
        ("which", "which (hover for all)"),
    ]);
    for (k, ((case, class, removed), specs)) in rows.iter().enumerate() {
        let few: Vec<&str> = specs.iter().take(4).copied().collect();
        let more = if specs.len() > few.len() { format!(" +{} more", specs.len() - few.len()) } else { String::new() };
        t.row(
            format!("cause{i}/{}", from + k),
            vec![
                Cell::text(case.clone()),
                Cell::text(class.to_string()),
                Cell::text(removed.replace('`', "")),
                count_cell(specs.len()),
                Cell::text(format!("{}{more}", few.join(", "))),
            ],
        );
    }
    let mut h = t.html();
    for (k, (_, specs)) in rows.iter().enumerate() {
        let row = format!("<tr data-row=\"cause{i}/{}\">", from + k);
        let tip = format!("<tr data-row=\"cause{i}/{}\" data-tip=\"{}\">", from + k, esc(&specs.join("\n")));
        h = h.replacen(&row, &tip, 1);
    }
    h
}

/// The failing specs grouped by cause (`causes_of`): the first `CAUSES_SHOWN` in a table, the rest folded;
/// and how many causes there are.
fn failure_causes(i: usize, st: &StabilityReport) -> (String, usize) {
    let causes = causes_of(st);
    if causes.is_empty() {
        return (String::new(), 0);
    }
    let (first, rest) = causes.split_at(causes.len().min(CAUSES_SHOWN));
    let mut s = format!(
        "<h3>The failures by cause</h3><p class=\"note\">Each hard case (or the grid) that gives NaN, Inf or a negative value, with the input guards (as a caller could apply them) that remove it, and the specs that fail there; a spec failing several cases is under each.</p>{}",
        causes_table(i, first, 0)
    );
    if !rest.is_empty() {
        s += &html::fold(&format!("{} more cause(s)", rest.len()), &causes_table(i, rest, first.len()));
    }
    (s, causes.len())
}

/// One stability report: its finding, the failures by cause, then folded the summary table (rows keyed
/// `stability<i>/<spec>`), a heat map per spec with bad values, and where each spec fails.
pub fn stability_html(i: usize, st: &StabilityReport, path: &str) -> Result<String> {
    let mut t = HtmlTable::new(&STABILITY_COLUMNS);
    for s in &st.specs {
        t.row(format!("stability{i}/{}", s.spec), stability_row(s));
    }
    let failing = st.specs.iter().filter(|s| s.fails()).count();
    let mut maps = String::new();
    let mut drawn = 0;
    for s in &st.specs {
        if let Some(cells) = s.bad_cell_triples.as_ref().filter(|c| !c.is_empty()) {
            maps += &heat_map(s, cells)?;
            drawn += 1;
        }
    }
    let (causes, n_causes) = failure_causes(i, st);
    let maps = if maps.is_empty() {
        "<p class=\"note\">No spec gives a bad value on the grid.</p>".to_string()
    } else {
        html::fold(
            &format!("Where the bad values are: {drawn} heat map(s) of NoV x roughness (all azimuths and NoL)"),
            &format!("<div class=\"heat\">{maps}</div>"),
        )
    };
    let out_of_tolerance = st.specs.iter().filter(|s| s.checked() && s.grid_out_of_tolerance > 0).count();
    let located = located_failures(st) + &out_of_tolerance_html(st) + &bounds_html(st);
    let verdict = if failing == 0 {
        "none fails".to_string()
    } else {
        format!("{failing} fail (NaN, Inf or negative on valid inputs), from {n_causes} cause(s)")
    };
    Ok(format!(
        "<h3>{path}</h3><p class=\"note\"><b>{} specs: {verdict}; {out_of_tolerance} out of tolerance on the grid.</b> {} hard cases; {} grid points; deviation in units of the tolerance.</p>{causes}{}{maps}{located}",
        st.specs.len(),
        st.cases.len(),
        st.grid_points,
        html::fold(&format!("Every spec's figures ({} rows)", st.specs.len()), &t.html()),
    ))
}

/// Where each spec checked against a twin or reference is out of tolerance: its worst value's inputs and each
/// hard case out of tolerance with its inputs, as the Markdown's "Out of tolerance: where".
fn out_of_tolerance_html(st: &StabilityReport) -> String {
    let mut items = String::new();
    for s in st.specs.iter().filter(|s| s.checked()) {
        let cases: Vec<&crate::stability::CaseResult> =
            s.cases_out_of_tolerance.iter().filter(|c| !c.inputs.is_empty()).collect();
        if cases.is_empty() && s.grid_out_of_tolerance == 0 {
            continue;
        }
        let each: String = cases
            .iter()
            .map(|c| format!("<li>{} at {} ({:.2e} x tolerance)</li>", esc(&c.case), esc(&c.inputs), c.deviation))
            .collect();
        items += &format!(
            "<li><b>{}</b>: {} hard cases and {} grid points out of tolerance; the worst ({:.2e} x tolerance) at {}<ul>{each}</ul></li>",
            esc(s.label()),
            cases.len(),
            s.grid_out_of_tolerance,
            s.worst.deviation,
            esc(&s.worst.input)
        );
    }
    if items.is_empty() {
        return items;
    }
    format!("<details><summary>Out of tolerance: where</summary><ul class=\"failures\">{items}</ul></details>")
}

/// The cases at each declared domain's bounds with what the precision loses there (`BoundCase`).
fn bounds_html(st: &StabilityReport) -> String {
    let mut t = HtmlTable::new(&[
        ("spec", "spec"),
        ("case", "case"),
        ("inputs", "inputs"),
        ("loss", "loss against the exact value"),
        ("verdict", "verdict"),
    ]);
    let mut any = false;
    for s in &st.specs {
        for (k, b) in s.at_domain_bounds.iter().enumerate() {
            any = true;
            t.row(
                format!("bounds/{}/{k}", s.spec),
                vec![
                    Cell::text(s.label().to_string()),
                    Cell::text(b.case.clone()),
                    Cell::text(b.inputs.clone()),
                    b.loss.map_or(Cell::text("-"), |l| Cell::num(l, crate::stability::loss_text(l))),
                    Cell::text(if b.ok { "within" } else { "out of tolerance" }),
                ],
            );
        }
    }
    if !any {
        return String::new();
    }
    html::fold(
        "At the domain's bounds: what the precision loses at each declared domain's ends",
        &format!(
            "<p class=\"note\">Each declared domain's own ends, against the formula's exact value (no floor), with what the kernel's precision loses there, said even within tolerance.</p>{}",
            t.html()
        ),
    )
}

/// Each failing spec's failing inputs and the input guards that remove them.
fn located_failures(st: &StabilityReport) -> String {
    let mut located = String::new();
    for s in st.specs.iter().filter(|s| s.fails()) {
        let f = &s.failures;
        if f.is_empty() {
            continue;
        }
        let items: String =
            f.lines().iter().map(|(depth, line)| format!("<li class=\"depth{depth}\">{}</li>", esc(line))).collect();
        located += &format!("<li><b>{}</b><ul>{items}</ul></li>", esc(s.label()));
    }
    if !located.is_empty() {
        located = html::fold(
            "Where the failing specs fail: each case's inputs and result",
            &format!(
                "<p class=\"note\">Each failing hard case with its inputs, the grid's failing points, and the input guards (roughness floor, cosine floor, safe half vector, lit mask, F0 clamp, as a caller could apply them) that remove each.</p><ul class=\"failures\">{located}</ul>"
            ),
        );
    }
    located
}

pub fn stability(inputs: &[Input]) -> Result<String> {
    let mut s = String::new();
    for (i, input) in inputs.iter().enumerate() {
        if let Loaded::Stability(st) = &input.loaded {
            s += &stability_html(i, st, &file_label(&input.path))?;
        }
    }
    Ok(s)
}
