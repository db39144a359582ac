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

/// A cost table across devices: net cost and net relative to ggx per column; rows keyed `devices/<model>`,
/// columns `c<j>` (net) and `c<j>r` (relative); the rank correlations after it.
pub fn cost_table_html(table: &CostTable) -> String {
    let mut columns: Vec<(String, String)> = vec![("model".into(), "model".into())];
    for (j, c) in table.columns.iter().enumerate() {
        columns.push((format!("c{j}"), format!("{} net", c.name)));
        columns.push((format!("c{j}r"), "x ggx".into()));
    }
    let refs: Vec<(&str, &str)> = columns.iter().map(|(k, h)| (k.as_str(), h.as_str())).collect();
    let mut t = HtmlTable::new(&refs);
    for m in &table.models {
        let mut cells = vec![Cell::text(m.clone())];
        for c in &table.columns {
            cells.push(num_cell(c.net.get(m).copied()));
            cells.push(num_cell(table.relative(c, m)));
        }
        t.row(format!("devices/{m}"), cells);
    }
    let mut corr = HtmlTable::new(&[
        ("a", "device A"),
        ("b", "device B"),
        ("models", "models"),
        ("rho", "Spearman rho (net)"),
        ("ci", "95% CI"),
        ("discordant", "discordant pairs"),
    ]);
    let ci = |p: &crate::compare::PairCorrelation| {
        Cell::text(p.spearman_ci.map_or("-".into(), |(lo, hi)| format!("[{lo:.2}, {hi:.2}]")))
    };
    for (k, p) in table.correlations.iter().chain(&table.spirv_baseline).enumerate() {
        // A rho without its CI (too few models) is not shown.
        corr.row(
            format!("rho/{k}"),
            vec![
                Cell::text(p.a.clone()),
                Cell::text(p.b.clone()),
                count_cell(p.models),
                num_cell(p.spearman_net.filter(|_| p.spearman_ci.is_some())),
                ci(p),
                Cell::text(p.discordant_cell()),
            ],
        );
    }
    let units: Vec<String> = table
        .columns
        .iter()
        .map(|c| format!("<b>{}</b>: {} ({})", esc(&c.name), esc(&c.unit), esc(&c.source)))
        .collect();
    format!(
        "{}<p class=\"note\">{}</p><h3>Rank correlations</h3>{}<p class=\"note\">{}</p>",
        t.html(),
        units.join("<br>"),
        corr.html(),
        crate::compare::RHO_NOTE
    )
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
            (Point { x: cost.median, y: err, label: r.label.clone(), tip, emphasis: r.pareto }, half)
        })
        .collect();
    let drawable = |p: &Point| p.x.is_finite() && p.x > 0.0 && p.y.is_finite() && p.y > 0.0;
    let left_out = points.iter().filter(|(p, _)| !drawable(p)).count();
    let fp32_top = points.iter().filter(|(p, half)| !half && drawable(p)).map(|(p, _)| p.x).fold(0.0, f64::max);
    let (main, side): (Vec<Point>, Vec<Point>) = {
        let (m, s): (Vec<_>, Vec<_>) = points.into_iter().partition(|(p, half)| !half && p.x <= fp32_top);
        (m.into_iter().map(|(p, _)| p).collect(), s.into_iter().map(|(p, _)| p).collect())
    };
    let xs = |pts: &[Point]| Axis::fit(pts.iter().filter(|p| drawable(p)).map(|p| p.x), true);
    let (Some(y), Some(x)) = (
        Axis::fit(main.iter().chain(&side).filter(|p| drawable(p)).map(|p| p.y), true),
        xs(&main).or_else(|| xs(&side)),
    ) else {
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
        t.html()
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

/// One stability report: the summary table (rows keyed `stability<i>/<spec>`) and a heat map per spec with
/// bad values.
pub fn stability_html(i: usize, st: &StabilityReport, path: &str) -> Result<String> {
    let mut t = HtmlTable::new(&STABILITY_COLUMNS);
    for s in &st.specs {
        t.row(format!("stability{i}/{}", s.spec), stability_row(s));
    }
    let failing = st.specs.iter().filter(|s| s.fails()).count();
    let mut maps = String::new();
    for s in &st.specs {
        if let Some(cells) = s.bad_cell_triples.as_ref().filter(|c| !c.is_empty()) {
            maps += &heat_map(s, cells)?;
        }
    }
    let located = located_failures(st) + &out_of_tolerance_html(st) + &bounds_html(st);
    let maps = if maps.is_empty() {
        "<p class=\"note\">No spec gives a bad value on the grid.</p>".to_string()
    } else {
        format!(
            "<h3>Where the bad values are (grid of NoV x roughness, all azimuths and NoL)</h3><div class=\"heat\">{maps}</div>"
        )
    };
    Ok(format!(
        "<h3>{path}</h3><p class=\"note\">{} specs, {failing} failing (NaN, Inf or negative on valid inputs); {} hard cases; {} grid points. Deviation in units of the tolerance.</p>{}{maps}{located}",
        st.specs.len(),
        st.cases.len(),
        st.grid_points,
        t.html()
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
    format!(
        "<h3>At the domain's bounds</h3><p class=\"note\">Each declared domain's own ends, against the formula's exact value (no floor), with what the kernel's precision loses there, said even within tolerance.</p>{}",
        t.html()
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
        located = format!(
            "<h3>Where the failing specs fail</h3><p class=\"note\">Each failing hard case with its inputs, the grid's failing points, and the input guards (roughness floor, cosine floor, safe half vector, lit mask, F0 clamp, as a caller could apply them) that remove each.</p><ul class=\"failures\">{located}</ul>"
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
