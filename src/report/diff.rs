//! The report's section for `brdfprof diff` results: per channel max/RMS (rows keyed `diff<i>/<channel>`), the
//! worst rows with their inputs (`diff<i>/worst<k>`), the histogram (`diff<i>/bin<k>`) and, with a device, the
//! lit-sphere and lobe picture of B against A (`diff::picture`).

use super::sections::num_cell;
use super::{Input, Loaded, file_label};
use crate::diff::{DiffReport, DiffSet, WorstRow};
use crate::export::html::{Cell, HtmlTable, esc, img, png_data_uri};
use crate::export::markdown::sig;
use crate::gpu::Gpu;
use crate::io::finite;
use crate::model::Model;
use anyhow::Result;
use std::fmt::Write;

const CHANNEL_COLUMNS: [(&str, &str); 6] = [
    ("channel", "channel"),
    ("max_rel", "max rel"),
    ("rms_rel", "RMS rel"),
    ("max_abs", "max |B - A|"),
    ("rms_abs", "RMS |B - A|"),
    ("mismatched", "finite on one side"),
];

const WORST_COLUMNS: [(&str, &str); 9] = [
    ("index", "row"),
    ("line", "CSV line"),
    ("nov", "NoV"),
    ("nol", "NoL"),
    ("roughness", "roughness"),
    ("f0", "F0"),
    ("channel", "channel"),
    ("a_b", "A / B"),
    ("rel", "rel"),
];

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// An f32 of the report as the page shows it: the f64 its JSON text reads as (None where it wrote null), so
/// that the page shows the JSON's numbers, not the f32's binary expansion.
fn as_written(x: f32) -> Option<f64> {
    serde_json::to_string(&x).ok().and_then(|text| serde_json::from_str(&text).ok())
}

fn worst_row(w: &WorstRow) -> Vec<Cell> {
    let value = |x: Option<f64>| x.map_or("NaN/Inf".into(), |x| sig(x, 4));
    let c = ["r", "g", "b"].iter().position(|c| *c == w.channel).unwrap_or(0);
    let s = &w.sample;
    let v3 = |v: [f32; 3]| v.map(|x| as_written(x).unwrap_or(f64::NAN));
    vec![
        Cell::num(w.index as f64, w.index.to_string()),
        w.line.map_or(Cell::text("-"), |l| Cell::num(l as f64, l.to_string())),
        num_cell(Some(dot(v3(s.n), v3(s.v)))),
        num_cell(Some(dot(v3(s.n), v3(s.l)))),
        num_cell(as_written(s.roughness)),
        Cell::text(v3(s.f0).map(|x| sig(x, 3)).join(", ")),
        Cell::text(w.channel.clone()),
        Cell::text(format!("{} / {}", value(as_written(w.a[c])), value(as_written(w.b[c])))),
        num_cell(finite(w.rel)),
    ]
}

/// The histogram as a table: one row per bin, its lower edge and count.
fn histogram(i: usize, d: &DiffReport) -> String {
    let mut t = HtmlTable::new(&[("from", "rel from"), ("to", "to"), ("rows", "rows")]);
    let h = &d.histogram;
    for (k, (&edge, &count)) in h.edges.iter().zip(&h.counts).enumerate() {
        let to = h.edges.get(k + 1).map_or(Cell::text("inf"), |&e| Cell::num(e, sig(e, 3)));
        t.row(
            format!("diff{i}/bin{k}"),
            vec![Cell::num(edge, sig(edge, 3)), to, Cell::num(count as f64, count.to_string())],
        );
    }
    format!("<p>{} rows identical in value; {} finite on one side only.</p>{}", h.identical, h.nonfinite, t.html())
}

/// The picture of B against A drawn on `gpu` (a PNG data: URI), or why not.
fn picture(d: &DiffReport, gpu: Option<&Gpu>) -> Result<String> {
    let Some(gpu) = gpu else {
        return Ok("<p class=\"note\">Picture not drawn: the report was built without a device (--no-gpu).</p>".into());
    };
    // A model file gone or changed since the diff ran: the rest of the diff is still the saved result.
    let models = Model::parse(&d.a.canonical).and_then(|a| Ok((a, Model::parse(&d.b.canonical)?)));
    let (a, b) = match models {
        Ok(ab) => ab,
        Err(e) => {
            crate::messages::warning(format!(
                "report: the picture of {} against {}: not drawn: {e:#}",
                d.b.name, d.a.name
            ));
            return Ok(format!(
                "<p class=\"err\">Picture not drawn: a model cannot be read now ({}); the tables above are the saved diff's.</p>",
                esc(&format!("{e:#}"))
            ));
        }
    };
    let (w, h, px) = crate::diff::picture::pixels(gpu, &a, &b)?;
    let alt = format!("B = {} against A = {}: lit spheres, relative difference and lobes", d.b.name, d.a.name);
    Ok(format!(
        "<figure>{}<figcaption>{}</figcaption></figure>",
        img(&png_data_uri(w, h, &px)?, w, h, 1, &alt),
        esc(&alt)
    ))
}

fn diff_html(i: usize, d: &DiffReport, path: &str, gpu: Option<&Gpu>) -> Result<String> {
    let mut s = String::new();
    let verdict = match (d.tolerance, d.within_tolerance) {
        (Some(t), true) => format!("within --tolerance {t}"),
        (Some(t), false) => format!("beyond --tolerance {t}"),
        (None, _) => "no tolerance given".into(),
    };
    let _ = write!(
        s,
        "<h3>B = <code>{}</code> against A = <code>{}</code> ({path})</h3><p>{} rows: {}; on {}; {}; {verdict}. A: <code>{}</code>; B: <code>{}</code>.</p>",
        esc(&d.b.name),
        esc(&d.a.name),
        d.rows,
        esc(&d.input),
        esc(&d.device),
        esc(&d.relative_to),
        esc(&d.a.canonical),
        esc(&d.b.canonical)
    );
    let mut t = HtmlTable::new(&CHANNEL_COLUMNS);
    for c in &d.difference.channels {
        t.row(
            format!("diff{i}/{}", c.channel),
            vec![
                Cell::text(c.channel.clone()),
                num_cell(finite(c.max_rel)),
                num_cell(finite(c.rms_rel)),
                num_cell(finite(c.max_abs)),
                num_cell(finite(c.rms_abs)),
                Cell::num(c.mismatched_nonfinite as f64, c.mismatched_nonfinite.to_string()),
            ],
        );
    }
    s += &t.html();
    let mut w = HtmlTable::new(&WORST_COLUMNS);
    for (k, row) in d.worst.iter().enumerate() {
        w.row(format!("diff{i}/worst{k}"), worst_row(row));
    }
    let sg = &d.signed;
    let _ = write!(
        s,
        "<p>Signed, B against A: best-fit scale <span data-key=\"diff{i}/best_fit_scale\">{}</span>; B/A median {}, 5th to 95th percentile {} to {}; B brighter on {:.1}% of values, darker on {:.1}%.</p>",
        sg.best_fit_scale.map_or("-".into(), |x| sig(x, 4)),
        sg.ratio_at(50.0).map_or("-".into(), |x| sig(x, 3)),
        sg.ratio_at(5.0).map_or("-".into(), |x| sig(x, 3)),
        sg.ratio_at(95.0).map_or("-".into(), |x| sig(x, 3)),
        100.0 * sg.brighter,
        100.0 * sg.darker
    );
    let _ = write!(
        s,
        "<h4>Rows where they differ most</h4>{}<h4>Rows by their largest relative difference</h4>{}",
        w.html(),
        histogram(i, d)
    );
    Ok(s + &picture(d, gpu)?)
}

const SET_COLUMNS: [(&str, &str); 6] = [
    ("model", "model"),
    ("max_rel", "max rel"),
    ("scale", "best-fit scale"),
    ("rms_rel", "RMS rel (worst channel)"),
    ("one_side", "finite on one side"),
    ("verdict", "verdict"),
];

/// `diff --reference`: one table of every model against the reference (rows keyed `diffset<i>/<model>`),
/// then each model's own section.
fn diff_set_html(i: usize, d: &DiffSet, path: &str, gpu: Option<&Gpu>) -> Result<String> {
    let mut t = HtmlTable::new(&SET_COLUMNS);
    for x in &d.diffs {
        let rms = x
            .difference
            .channels
            .iter()
            .filter_map(|c| finite(c.rms_rel))
            .fold(None, |m: Option<f64>, r| Some(m.map_or(r, |m| m.max(r))));
        // Counts read from a saved report: summed so that a crafted one cannot wrap.
        let one_side = x.difference.channels.iter().fold(0usize, |n, c| n.saturating_add(c.mismatched_nonfinite));
        let verdict = match d.tolerance {
            Some(t) if x.within_tolerance => format!("within {t}"),
            Some(t) => format!("beyond {t}"),
            None => "-".into(),
        };
        t.row(
            format!("diffset{i}/{}", x.b.name),
            vec![
                Cell::text(x.b.name.clone()),
                num_cell(finite(x.difference.max_rel)),
                num_cell(x.signed.best_fit_scale),
                num_cell(rms),
                Cell::num(one_side as f64, one_side.to_string()),
                Cell::text(verdict),
            ],
        );
    }
    let mut s = format!(
        "<h3>{} models against <code>{}</code> ({path})</h3><p>{} rows: {}; on {}.</p>{}",
        d.diffs.len(),
        esc(&d.reference.name),
        d.rows,
        esc(&d.input),
        esc(&d.device),
        t.html()
    );
    for (k, x) in d.diffs.iter().enumerate() {
        s += &diff_html(i * 1000 + k, x, path, gpu)?;
    }
    Ok(s)
}

/// Every diff input's section.
pub fn diffs(inputs: &[Input], gpu: Option<&Gpu>) -> Result<String> {
    let mut s = String::new();
    for (i, input) in inputs.iter().enumerate() {
        match &input.loaded {
            Loaded::Diff(d) => s += &diff_html(i, d, &file_label(&input.path), gpu)?,
            Loaded::DiffSet(d) => s += &diff_set_html(i, d, &file_label(&input.path), gpu)?,
            _ => {}
        }
    }
    Ok(s)
}
