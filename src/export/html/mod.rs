//! A self-contained HTML page: sections, sortable tables, SVG charts (scatter, polar, lines) and PNG images as
//! data: URIs, with its CSS and script inline, so that it opens from file:// with no network. Knows nothing of
//! BRDFs: `report` decides what goes in.

use crate::export::labels::{Placer, Rect};
use anyhow::Result;
use std::fmt::Write;

/// `text` with the five characters HTML gives meaning escaped (safe in text and in quoted attributes).
pub fn esc(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            // Bidirectional controls (embeddings, overrides, isolates, marks) would reorder how a name reads
            // (U+202E shows the rest of a file name reversed): shown as their code points instead.
            '\u{200E}' | '\u{200F}' | '\u{061C}' | '\u{202A}'..='\u{202E}' | '\u{2066}'..='\u{2069}' => {
                let _ = write!(out, "[U+{:04X}]", c as u32);
            }
            c => out.push(c),
        }
    }
    out
}

/// Standard base64 (RFC 4648, padded), for data: URIs.
pub fn base64(bytes: &[u8]) -> String {
    const A: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::with_capacity(bytes.len().div_ceil(3) * 4);
    for chunk in bytes.chunks(3) {
        let b = [chunk[0], *chunk.get(1).unwrap_or(&0), *chunk.get(2).unwrap_or(&0)];
        let n = (u32::from(b[0]) << 16) | (u32::from(b[1]) << 8) | u32::from(b[2]);
        for k in 0..4 {
            if k <= chunk.len() {
                out.push(A[(n >> (18 - 6 * k) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

/// An 8-bit RGB image as a PNG data: URI.
pub fn png_data_uri(width: u32, height: u32, rgb: &[u8]) -> Result<String> {
    use image::ImageEncoder;
    anyhow::ensure!(
        rgb.len() == width as usize * height as usize * 3,
        "image of {width}x{height} needs {} bytes, got {}",
        width * height * 3,
        rgb.len()
    );
    let mut png = Vec::new();
    image::codecs::png::PngEncoder::new(&mut png).write_image(rgb, width, height, image::ExtendedColorType::Rgb8)?;
    Ok(format!("data:image/png;base64,{}", base64(&png)))
}

/// `<img>` of a data: URI, drawn `scale` times its size with square pixels.
pub fn img(uri: &str, width: u32, height: u32, scale: u32, alt: &str) -> String {
    format!(
        "<img class=\"px\" src=\"{uri}\" width=\"{}\" height=\"{}\" alt=\"{}\" title=\"{}\">",
        width * scale,
        height * scale,
        esc(alt),
        esc(alt)
    )
}

/// A heat map's axes and colour scale: the ticks of each axis as (cell index, label), its name, and the
/// viridis bar's labels at t = 0, 0.5 and 1 with its name.
pub struct HeatAxes<'a> {
    pub x: (&'a [(usize, String)], &'a str),
    pub y: (&'a [(usize, String)], &'a str),
    pub bar: ([String; 3], &'a str),
}

/// A `w` x `h` cell image (row 0 at the top, `scale` px per cell) in an SVG with its axes in values and a
/// viridis colour bar: a colour-coded picture a reader can read without its caption.
pub fn heat_svg(uri: &str, (w, h, scale): (u32, u32, u32), axes: &HeatAxes, alt: &str) -> String {
    let (iw, ih) = (f64::from(w * scale), f64::from(h * scale));
    let (l, t, b) = (46.0, 8.0, 34.0);
    let bar_x = l + iw + 14.0;
    let (sw, sh) = (bar_x + 60.0, t + ih + b);
    let cell = f64::from(scale);
    let mut s = format!(
        "<svg class=\"heatmap\" viewBox=\"0 0 {sw} {sh}\" width=\"{sw}\" height=\"{sh}\" role=\"img\"><title>{}</title><image href=\"{uri}\" x=\"{l}\" y=\"{t}\" width=\"{iw}\" height=\"{ih}\" style=\"image-rendering:pixelated\" preserveAspectRatio=\"none\"/><rect x=\"{l}\" y=\"{t}\" width=\"{iw}\" height=\"{ih}\" class=\"frame\"/>",
        esc(alt)
    );
    for (i, label) in axes.x.0 {
        let x = l + (*i as f64 + 0.5) * cell;
        let _ = write!(
            s,
            "<line x1=\"{x:.1}\" y1=\"{}\" x2=\"{x:.1}\" y2=\"{}\" stroke=\"#444\"/><text x=\"{x:.1}\" y=\"{}\" class=\"tick\" text-anchor=\"middle\">{}</text>",
            t + ih,
            t + ih + 3.0,
            t + ih + 13.0,
            esc(label)
        );
    }
    for (i, label) in axes.y.0 {
        // Row 0 of the data is drawn at the bottom.
        let y = t + ih - (*i as f64 + 0.5) * cell;
        let _ = write!(
            s,
            "<line x1=\"{}\" y1=\"{y:.1}\" x2=\"{l}\" y2=\"{y:.1}\" stroke=\"#444\"/><text x=\"{}\" y=\"{:.1}\" class=\"tick\" text-anchor=\"end\">{}</text>",
            l - 3.0,
            l - 5.0,
            y + 3.5,
            esc(label)
        );
    }
    let _ = write!(
        s,
        "<text x=\"{:.1}\" y=\"{}\" class=\"tick\" text-anchor=\"middle\">{}</text><text transform=\"translate(10 {:.1}) rotate(-90)\" class=\"tick\" text-anchor=\"middle\">{}</text>",
        l + iw / 2.0,
        t + ih + 28.0,
        esc(axes.x.1),
        t + ih / 2.0,
        esc(axes.y.1)
    );
    let stops: String = (0..=8)
        .map(|k| {
            let [r, g, b] = crate::export::raster::viridis(k as f32 / 8.0);
            format!("<stop offset=\"{}\" stop-color=\"rgb({r},{g},{b})\"/>", 1.0 - k as f64 / 8.0)
        })
        .rev()
        .collect();
    // Every bar's gradient is the same viridis, so two maps whose ids coincide still draw right.
    let id = format!("v{:x}", uri.len() ^ (w as usize) << 8 ^ (h as usize) << 16 ^ alt.len() << 24);
    let _ = write!(
        s,
        "<defs><linearGradient id=\"{id}\" x1=\"0\" y1=\"0\" x2=\"0\" y2=\"1\">{stops}</linearGradient></defs><rect x=\"{bar_x}\" y=\"{t}\" width=\"10\" height=\"{ih}\" fill=\"url(#{id})\" stroke=\"#999\"/>"
    );
    for (k, label) in axes.bar.0.iter().enumerate() {
        let y = t + ih - ih * k as f64 / 2.0;
        let _ = write!(s, "<text x=\"{}\" y=\"{:.1}\" class=\"tick\">{}</text>", bar_x + 13.0, y + 3.5, esc(label));
    }
    let _ = write!(
        s,
        "<text transform=\"translate({} {:.1}) rotate(-90)\" class=\"tick\" text-anchor=\"middle\">{}</text>",
        bar_x + 52.0,
        t + ih / 2.0,
        esc(axes.bar.1)
    );
    s + "</svg>"
}

/// Ten distinguishable colours (the same order as `chart::palette`).
pub fn colour(i: usize) -> &'static str {
    const P: [&str; 10] =
        ["#1f77b4", "#ff7f0e", "#2ca02c", "#d62728", "#9467bd", "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22", "#17becf"];
    P[i % P.len()]
}

/// Series `i`'s line: its colour and its dash pattern (SVG `stroke-dasharray`, empty for solid). The ten
/// colours solid, then dashed, then dotted: 30 series before a style repeats, so 16 overlaid models stay apart.
pub fn series_style(i: usize) -> (&'static str, &'static str) {
    const DASHES: [&str; 3] = ["", "7 3", "2 2.5"];
    (colour(i), DASHES[(i / 10) % DASHES.len()])
}

/// `stroke="..." stroke-dasharray="..."` of series `i`.
pub fn series_stroke(i: usize) -> String {
    let (c, dash) = series_style(i);
    if dash.is_empty() { format!("stroke=\"{c}\"") } else { format!("stroke=\"{c}\" stroke-dasharray=\"{dash}\"") }
}

/// A legend entry's line sample in series `i`'s style, for legends in HTML (CSS borders: solid, dashed, dotted).
pub fn series_swatch(i: usize) -> String {
    let (c, dash) = series_style(i);
    let style = match dash {
        "" => "solid",
        "7 3" => "dashed",
        _ => "dotted",
    };
    format!("<span class=\"swatch\" style=\"border-top: 3px {style} {c}\"></span>")
}

/// A folded block: `finding` (HTML), the one line a reader sees, and `body` behind it.
pub fn fold(finding: &str, body: &str) -> String {
    format!("<details class=\"fold\"><summary>{finding}</summary>{body}</details>")
}

/// A table cell: its text, and for a number the value a sort uses (and a test reads back).
#[derive(Clone, Debug)]
pub struct Cell {
    pub text: String,
    pub value: Option<f64>,
}

impl Cell {
    pub fn text(text: impl Into<String>) -> Self {
        Cell { text: text.into(), value: None }
    }

    pub fn num(value: f64, text: impl Into<String>) -> Self {
        Cell { text: text.into(), value: Some(value) }
    }
}

/// A sortable table: click a header to sort by it. Each row has a key (`data-row`) and each cell its column's
/// key (`data-col`), so that a reader of the DOM finds a figure without counting columns.
#[derive(Clone, Debug, Default)]
pub struct HtmlTable {
    pub columns: Vec<(String, String)>,
    pub rows: Vec<(String, Vec<Cell>)>,
    /// A column's long description (its header's tooltip), by key.
    pub descriptions: Vec<(String, String)>,
}

impl HtmlTable {
    /// `columns`: (key, header) pairs.
    pub fn new(columns: &[(&str, &str)]) -> Self {
        HtmlTable {
            columns: columns.iter().map(|(k, h)| (k.to_string(), h.to_string())).collect(),
            ..Default::default()
        }
    }

    /// Gives column `key` a long description, shown when the pointer rests on its short header.
    pub fn describe(&mut self, key: &str, text: impl Into<String>) {
        self.descriptions.push((key.to_string(), text.into()));
    }

    pub fn row(&mut self, key: impl Into<String>, cells: Vec<Cell>) {
        assert_eq!(cells.len(), self.columns.len(), "one cell per column");
        self.rows.push((key.into(), cells));
    }

    pub fn html(&self) -> String {
        let mut s = String::from("<table class=\"sortable\"><thead><tr>");
        for (key, header) in &self.columns {
            let title = match self.descriptions.iter().find(|(k, _)| k == key) {
                Some((_, d)) => format!("{d} (click to sort)"),
                None => "sort".into(),
            };
            let _ = write!(s, "<th data-col=\"{}\" title=\"{}\">{}</th>", esc(key), esc(&title), esc(header));
        }
        s += "</tr></thead><tbody>\n";
        for (key, cells) in &self.rows {
            let _ = write!(s, "<tr data-row=\"{}\">", esc(key));
            for ((col, _), c) in self.columns.iter().zip(cells) {
                match c.value {
                    Some(v) => {
                        let _ = write!(
                            s,
                            "<td data-col=\"{}\" data-v=\"{v:e}\" class=\"n\">{}</td>",
                            esc(col),
                            esc(&c.text)
                        );
                    }
                    None => {
                        let _ = write!(s, "<td data-col=\"{}\">{}</td>", esc(col), esc(&c.text));
                    }
                }
            }
            s += "</tr>\n";
        }
        s + "</tbody></table>\n"
    }
}

/// A chart axis: the value range and whether it is logarithmic.
#[derive(Clone, Copy, Debug)]
pub struct Axis {
    pub lo: f64,
    pub hi: f64,
    pub log: bool,
}

impl Axis {
    /// The range of `values` (finite, and positive on a log axis), padded a little; None when none fits.
    pub fn fit(values: impl Iterator<Item = f64>, log: bool) -> Option<Axis> {
        let v: Vec<f64> = values.filter(|v| v.is_finite() && (!log || *v > 0.0)).collect();
        let (lo, hi) = v.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| (a.min(x), b.max(x)));
        if v.is_empty() {
            return None;
        }
        Some(if log {
            let (l, h) = (lo.log10(), hi.log10().max(lo.log10() + 0.5));
            let pad = 0.05 * (h - l);
            Axis { lo: 10f64.powf(l - pad), hi: 10f64.powf(h + pad), log }
        } else {
            let pad = 0.05 * (hi - lo).max(hi.abs() * 0.1).max(1e-12);
            Axis { lo: lo - pad, hi: hi + pad, log }
        })
    }

    /// Where `v` falls from 0 (lo) to 1 (hi).
    pub fn frac(&self, v: f64) -> f64 {
        if self.log {
            (v.log10() - self.lo.log10()) / (self.hi.log10() - self.lo.log10())
        } else {
            (v - self.lo) / (self.hi - self.lo)
        }
    }

    /// Tick values: decades (and 2x, 5x when there are few) on a log axis, 1/2/5 steps on a linear one.
    pub fn ticks(&self) -> Vec<f64> {
        let within = |t: &f64| *t >= self.lo * (1.0 - 1e-9) && *t <= self.hi * (1.0 + 1e-9);
        if self.log {
            let (a, b) = (self.lo.log10().floor() as i32, self.hi.log10().ceil() as i32);
            let steps: &[f64] = if b - a <= 2 { &[1.0, 2.0, 5.0] } else { &[1.0] };
            return (a..=b).flat_map(|e| steps.iter().map(move |m| m * 10f64.powi(e))).filter(within).collect();
        }
        let raw = (self.hi - self.lo) / 6.0;
        let mag = 10f64.powf(raw.log10().floor());
        let step = [1.0, 2.0, 5.0, 10.0].iter().map(|m| m * mag).find(|s| *s >= raw).unwrap_or(10.0 * mag);
        let first = (self.lo / step).ceil() as i64;
        (first..).map(|k| k as f64 * step).take_while(|t| *t <= self.hi).collect()
    }
}

/// A tick label: short, in engineering-friendly form.
pub fn tick_label(v: f64) -> String {
    if v == 0.0 {
        return "0".into();
    }
    let a = v.abs();
    if !(1e-3..1e4).contains(&a) { format!("{v:.0e}") } else { format!("{}", (v * 1e6).round() / 1e6) }
}

/// One point of a scatter chart: its position, its label, the text shown on hover, and whether it is drawn
/// emphasised (e.g. on the Pareto frontier).
#[derive(Clone, Debug)]
pub struct Point {
    pub x: f64,
    pub y: f64,
    pub label: String,
    pub tip: String,
    pub emphasis: bool,
    /// Drawn at the bottom edge of a fitted axis (its value below the range, in its label): a triangle.
    pub edge: bool,
}

const M: (f64, f64, f64, f64) = (62.0, 14.0, 14.0, 44.0); // left, right, top, bottom

/// A chart's size in pixels.
#[derive(Clone, Copy, Debug)]
pub struct Size {
    pub w: f64,
    pub h: f64,
}

/// The full-width chart size.
pub const WIDE: Size = Size { w: 760.0, h: 440.0 };
/// A narrow panel beside a wide chart (sweep's fp16 specs).
pub const SIDE: Size = Size { w: 300.0, h: 440.0 };
/// A chart that fits beside others in a card.
pub const SMALL: Size = Size { w: 320.0, h: 200.0 };

#[allow(non_snake_case)] // W, H: the chart's width and height, as in the SVG
fn frame(s: &mut String, x: &Axis, y: &Axis, x_label: &str, y_label: &str, size: Size) {
    let (l, r, t, b) = M;
    let Size { w: W, h: H } = size;
    let _ = write!(s, "<rect x=\"{l}\" y=\"{t}\" width=\"{}\" height=\"{}\" class=\"frame\"/>", W - l - r, H - t - b);
    for v in x.ticks() {
        let px = l + x.frac(v) * (W - l - r);
        let _ = write!(
            s,
            "<line x1=\"{px:.1}\" y1=\"{t}\" x2=\"{px:.1}\" y2=\"{}\" class=\"grid\"/><text x=\"{px:.1}\" y=\"{}\" class=\"tick\" text-anchor=\"middle\">{}</text>",
            H - b,
            H - b + 16.0,
            tick_label(v)
        );
    }
    for v in y.ticks() {
        let py = H - b - y.frac(v) * (H - t - b);
        let _ = write!(
            s,
            "<line x1=\"{l}\" y1=\"{py:.1}\" x2=\"{}\" y2=\"{py:.1}\" class=\"grid\"/><text x=\"{}\" y=\"{:.1}\" class=\"tick\" text-anchor=\"end\">{}</text>",
            W - r,
            l - 6.0,
            py + 4.0,
            tick_label(v)
        );
    }
    let _ = write!(
        s,
        "<text x=\"{}\" y=\"{}\" text-anchor=\"middle\" class=\"axis\">{}</text>",
        (l + W - r) / 2.0,
        H - 10.0,
        esc(x_label)
    );
    let _ = write!(
        s,
        "<text transform=\"translate(16 {}) rotate(-90)\" text-anchor=\"middle\" class=\"axis\">{}</text>",
        (t + H - b) / 2.0,
        esc(y_label)
    );
}

/// Label text in the page's CSS (`.lbl`): its size and a width per character no sans-serif face exceeds on
/// average for labels (0.62 em), so that a placed box holds its text.
const LABEL_PX: f64 = 10.5;
const LABEL_CHAR_W: f64 = LABEL_PX * 0.62;

/// A scatter chart; each point shows its tip on hover (an SVG `<title>`, and the page's tooltip line). The
/// emphasised points are labelled where `labels::Placer` finds room (none overlapping another or a point) and,
/// with `frontier`, joined by a line in order of x.
#[allow(non_snake_case)] // W, H: the chart's width and height, as in the SVG
pub fn scatter_svg(
    points: &[Point],
    (x, y): (Axis, Axis),
    x_label: &str,
    y_label: &str,
    size: Size,
    frontier: bool,
) -> String {
    let (l, r, t, b) = M;
    let Size { w: W, h: H } = size;
    let mut s = format!("<svg class=\"chart\" viewBox=\"0 0 {W} {H}\" width=\"{W}\" height=\"{H}\" role=\"img\">");
    frame(&mut s, &x, &y, x_label, y_label, size);
    let at = |p: &Point| (l + x.frac(p.x) * (W - l - r), H - b - y.frac(p.y) * (H - t - b));
    let drawn: Vec<&Point> = points
        .iter()
        .filter(|p| p.x.is_finite() && p.y.is_finite() && (!x.log || p.x > 0.0) && (!y.log || p.y > 0.0))
        .collect();
    if frontier {
        let mut front: Vec<(f64, f64)> = drawn.iter().filter(|p| p.emphasis).map(|p| at(p)).collect();
        front.sort_by(|a, b| a.0.total_cmp(&b.0));
        let pts: Vec<String> = front.iter().map(|(x, y)| format!("{x:.1},{y:.1}")).collect();
        let _ = write!(s, "<polyline class=\"front\" fill=\"none\" points=\"{}\"/>", pts.join(" "));
    }
    let mut placer = Placer::new(Rect { x0: l, y0: t, x1: W - r, y1: H - b });
    for p in &drawn {
        let (px, py) = at(p);
        placer.occupy(Rect { x0: px - 5.0, y0: py - 5.0, x1: px + 5.0, y1: py + 5.0 });
        s += &point_mark(p, (px, py));
    }
    let mut labelled: Vec<&&Point> = drawn.iter().filter(|p| p.emphasis).collect();
    labelled.sort_by(|a, b| b.y.total_cmp(&a.y));
    for p in labelled {
        let w = LABEL_CHAR_W * p.label.chars().count() as f64;
        if let Some(bx) = placer.place(at(p), w, LABEL_PX * 1.3) {
            if bx.far_from(at(p)) {
                let ((x1, y1), (x2, y2)) = (at(p), bx.nearest(at(p)));
                let _ =
                    write!(s, "<line x1=\"{x1:.1}\" y1=\"{y1:.1}\" x2=\"{x2:.1}\" y2=\"{y2:.1}\" class=\"leader\"/>");
            }
            let _ = write!(
                s,
                "<text x=\"{:.1}\" y=\"{:.1}\" class=\"lbl\">{}</text>",
                bx.x0,
                bx.y1 - LABEL_PX * 0.3,
                esc(&p.label)
            );
        }
    }
    s + "</svg>"
}

/// A point's mark with its hover text: a circle, or at a fitted axis's bottom edge (`edge`) a triangle pointing
/// down off the plot (its value lies below the axis's range).
fn point_mark(p: &Point, (px, py): (f64, f64)) -> String {
    let class = if p.emphasis { "pt em" } else { "pt" };
    let tip = esc(&p.tip);
    if p.edge {
        format!(
            "<path d=\"M {:.1} {:.1} L {:.1} {:.1} L {px:.1} {:.1} Z\" class=\"{class}\" data-tip=\"{tip}\"><title>{tip}</title></path>",
            px - 6.0,
            py - 5.0,
            px + 6.0,
            py - 5.0,
            py + 6.0
        )
    } else {
        format!(
            "<circle cx=\"{px:.1}\" cy=\"{py:.1}\" r=\"5\" class=\"{class}\" data-tip=\"{tip}\"><title>{tip}</title></circle>"
        )
    }
}

/// A named curve of (x, y) points.
#[derive(Clone, Debug)]
pub struct Curve {
    pub label: String,
    pub points: Vec<(f64, f64)>,
}

/// Width of a legend column beside a chart for `labels` (10.5 px text: about 6.2 px a character).
fn legend_width(labels: &[&str]) -> f64 {
    28.0 + 6.2 * labels.iter().map(|l| l.chars().count()).max().unwrap_or(0) as f64
}

fn legend(s: &mut String, labels: &[&str], x0: f64, y0: f64) {
    for (i, label) in labels.iter().enumerate() {
        let y = y0 + 16.0 * i as f64;
        let _ = write!(
            s,
            "<line x1=\"{x0}\" y1=\"{y}\" x2=\"{}\" y2=\"{y}\" {} stroke-width=\"2.5\"/><text x=\"{}\" y=\"{}\" class=\"tick\">{}</text>",
            x0 + 18.0,
            series_stroke(i),
            x0 + 22.0,
            y + 4.0,
            esc(label)
        );
    }
}

/// Lines of `curves` on shared axes, with a legend.
#[allow(non_snake_case)] // W, H: the chart's width and height, as in the SVG
pub fn lines_svg(curves: &[Curve], x: Axis, y: Axis, x_label: &str, y_label: &str, size: Size) -> String {
    let (l, r, t, b) = M;
    let Size { w: W, h: H } = size;
    // The legend in a column of its own right of the frame, never over a curve.
    let labels: Vec<&str> = curves.iter().map(|c| c.label.as_str()).collect();
    let total = W + legend_width(&labels);
    let mut s =
        format!("<svg class=\"chart\" viewBox=\"0 0 {total} {H}\" width=\"{total}\" height=\"{H}\" role=\"img\">");
    frame(&mut s, &x, &y, x_label, y_label, size);
    for (i, c) in curves.iter().enumerate() {
        let pts: Vec<String> = c
            .points
            .iter()
            .filter(|(a, v)| a.is_finite() && v.is_finite() && (!y.log || *v > 0.0))
            .map(|(a, v)| {
                format!(
                    "{:.1},{:.1}",
                    l + x.frac(*a) * (W - l - r),
                    H - b - y.frac(*v).clamp(-0.02, 1.02) * (H - t - b)
                )
            })
            .collect();
        let _ = write!(
            s,
            "<polyline fill=\"none\" {} stroke-width=\"2\" points=\"{}\" data-tip=\"{}\"><title>{}</title></polyline>",
            series_stroke(i),
            pts.join(" "),
            esc(&c.label),
            esc(&c.label)
        );
    }
    legend(&mut s, &labels, W + 6.0, t + 8.0);
    s + "</svg>"
}

/// A polar plot of the upper half plane: each curve's points are (angle from the normal in radians, positive
/// toward +x; radius), scaled so that the largest radius of all curves reaches the rim; with `log_decades`, the
/// radius is log10(r / peak) + decades over decades (values below the range at the centre). `marks` draws a
/// labelled direction (e.g. the light).
pub fn polar_svg(title: &str, curves: &[Curve], marks: &[(f64, &str)], log_decades: Option<f64>) -> String {
    // The title has its own band above the rim, so the mark of a light at normal incidence never meets it.
    let (w, h, cx, cy, rim) = (300.0, 196.0, 150.0, 176.0, 135.0);
    let mut s = format!(
        "<svg class=\"polar\" viewBox=\"0 0 {w} {h}\" width=\"{w}\" height=\"{h}\" role=\"img\"><text x=\"6\" y=\"14\" class=\"tick\">{}</text>",
        esc(title)
    );
    for k in 1..=4 {
        let rr = rim * k as f64 / 4.0;
        let _ = write!(
            s,
            "<path d=\"M {:.1} {cy} A {rr:.1} {rr:.1} 0 0 1 {:.1} {cy}\" class=\"grid\" fill=\"none\"/>",
            cx - rr,
            cx + rr
        );
    }
    let _ = write!(s, "<line x1=\"{}\" y1=\"{cy}\" x2=\"{}\" y2=\"{cy}\" class=\"grid\"/>", cx - rim, cx + rim);
    let peak =
        curves.iter().flat_map(|c| c.points.iter().map(|p| p.1)).filter(|r| r.is_finite()).fold(0.0f64, f64::max);
    let scale = |r: f64| -> f64 {
        if !(peak > 0.0 && r.is_finite() && r > 0.0) {
            return 0.0;
        }
        match log_decades {
            Some(d) => ((r / peak).log10() + d).max(0.0) / d,
            None => r / peak,
        }
    };
    for (i, c) in curves.iter().enumerate() {
        let pts: Vec<String> = c
            .points
            .iter()
            .map(|&(a, r)| format!("{:.1},{:.1}", cx + rim * scale(r) * a.sin(), cy - rim * scale(r) * a.cos()))
            .collect();
        let _ = write!(
            s,
            "<polyline fill=\"none\" {} stroke-width=\"1.8\" points=\"{}\" data-tip=\"{}\"><title>{}</title></polyline>",
            series_stroke(i),
            pts.join(" "),
            esc(&c.label),
            esc(&c.label)
        );
    }
    for (a, label) in marks {
        let (x, y) = (cx + rim * 1.05 * a.sin(), cy - rim * 1.05 * a.cos());
        let _ = write!(
            s,
            "<line x1=\"{cx}\" y1=\"{cy}\" x2=\"{x:.1}\" y2=\"{y:.1}\" stroke=\"#000\" stroke-dasharray=\"3 2\"/><text x=\"{x:.1}\" y=\"{:.1}\" class=\"tick\">{}</text>",
            y - 2.0,
            esc(label)
        );
    }
    s + "</svg>"
}

/// A page section: its anchor, heading and HTML body.
struct Section {
    id: String,
    title: String,
    body: String,
}

/// The page: a title, a navigation bar and sections, with the page's CSS and script inline.
pub struct Page {
    title: String,
    sections: Vec<Section>,
}

const CSS: &str = include_str!("page.css");
const SCRIPT: &str = include_str!("page.js");

impl Page {
    pub fn new(title: impl Into<String>) -> Self {
        Page { title: title.into(), sections: Vec::new() }
    }

    pub fn section(&mut self, id: &str, title: &str, body: String) {
        self.sections.push(Section { id: id.into(), title: title.into(), body });
    }

    pub fn render(&self) -> String {
        let mut s = format!(
            "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><meta name=\"viewport\" content=\"width=device-width, initial-scale=1\"><title>{}</title><style>{CSS}</style></head><body>\n",
            esc(&self.title)
        );
        let _ = write!(s, "<header><h1>{}</h1><nav>", esc(&self.title));
        for sec in &self.sections {
            let _ = write!(s, "<a href=\"#{}\">{}</a> ", esc(&sec.id), esc(&sec.title));
        }
        s += "</nav></header><div id=\"tip\"></div><main>\n";
        for sec in &self.sections {
            let _ =
                write!(s, "<section id=\"{}\"><h2>{}</h2>\n{}\n</section>\n", esc(&sec.id), esc(&sec.title), sec.body);
        }
        s + "</main><script>" + SCRIPT + "</script></body></html>\n"
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn base64_matches_rfc4648_vectors() {
        for (input, want) in [
            ("", ""),
            ("f", "Zg=="),
            ("fo", "Zm8="),
            ("foo", "Zm9v"),
            ("foob", "Zm9vYg=="),
            ("fooba", "Zm9vYmE="),
            ("foobar", "Zm9vYmFy"),
        ] {
            assert_eq!(base64(input.as_bytes()), want, "{input}");
        }
    }

    #[test]
    fn escaping_covers_markup_and_quotes() {
        assert_eq!(esc("<a href=\"x\">&'</a>"), "&lt;a href=&quot;x&quot;&gt;&amp;&#39;&lt;/a&gt;");
    }

    #[test]
    fn bidirectional_controls_are_shown_not_obeyed() {
        // "evil\u{202E}fdp.brdf" would display as "evilfdp.brdf" reversed after the override.
        assert_eq!(esc("evil\u{202E}fdp.brdf"), "evil[U+202E]fdp.brdf");
        let controls = ['\u{200E}', '\u{200F}', '\u{061C}', '\u{202A}', '\u{202D}', '\u{2066}', '\u{2069}'];
        for c in controls {
            assert!(!esc(&format!("a{c}b")).contains(c), "{:04X}", c as u32);
        }
        assert_eq!(esc("héllo ✓ 光"), "héllo ✓ 光", "other characters pass");
    }

    #[test]
    fn log_axis_ticks_are_decades_within_range() {
        let a = Axis::fit([0.003, 40.0].into_iter(), true).unwrap();
        let t = a.ticks();
        assert!(t.contains(&0.01) && t.contains(&10.0), "{t:?}");
        assert!(t.iter().all(|v| *v >= a.lo && *v <= a.hi));
        assert!((a.frac(a.lo)).abs() < 1e-12 && (a.frac(a.hi) - 1.0).abs() < 1e-12);
    }

    #[test]
    fn table_rows_carry_keys_and_values() {
        let mut t = HtmlTable::new(&[("m", "model"), ("ns", "ns/eval")]);
        t.row("ggx", vec![Cell::text("ggx"), Cell::num(1.25, "1.25")]);
        let h = t.html();
        assert!(h.contains("<tr data-row=\"ggx\">") && h.contains("data-col=\"ns\" data-v=\"1.25e0\""), "{h}");
    }
}
