//! PNG charts and images. Plotters draws into an RGB buffer (DejaVu Sans embedded, so no system fonts are
//! needed); the `image` crate encodes it and `io::write_output` writes it.

use crate::export::labels::{Placer, Rect};
use anyhow::{Result, anyhow};
use plotters::prelude::*;
use plotters::style::FontStyle;
use std::path::Path;
use std::sync::Once;

pub const FONT: &str = "sans-serif";

fn register_font() {
    static ONCE: Once = Once::new();
    ONCE.call_once(|| {
        plotters::style::register_font(FONT, FontStyle::Normal, dejavu::sans::regular()).ok();
        plotters::style::register_font(FONT, FontStyle::Bold, dejavu::sans::bold()).ok();
    });
}

/// Encodes an RGB8 buffer as PNG and writes it atomically.
pub fn write_png(path: &Path, width: u32, height: u32, rgb: Vec<u8>) -> Result<()> {
    let image =
        image::RgbImage::from_raw(width, height, rgb).ok_or_else(|| anyhow!("image buffer of the wrong size"))?;
    let mut bytes = std::io::Cursor::new(Vec::new());
    image.write_to(&mut bytes, image::ImageFormat::Png)?;
    crate::io::write_output(path, bytes.get_ref())
}

/// Draws with plotters into a fresh white `width` x `height` canvas and writes it as PNG.
pub fn render(
    path: &Path,
    width: u32,
    height: u32,
    draw: impl FnOnce(&DrawingArea<BitMapBackend, plotters::coord::Shift>) -> Result<()>,
) -> Result<()> {
    let buffer = pixels(width, height, draw)?;
    write_png(path, width, height, buffer)
}

/// What `render` draws, as 8-bit RGB pixels (for a page that embeds the picture instead of writing a file).
pub fn pixels(
    width: u32,
    height: u32,
    draw: impl FnOnce(&DrawingArea<BitMapBackend, plotters::coord::Shift>) -> Result<()>,
) -> Result<Vec<u8>> {
    register_font();
    let mut buffer = vec![255u8; (width * height * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buffer, (width, height)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| anyhow!("{e}"))?;
        draw(&root)?;
        root.present().map_err(|e| anyhow!("{e}"))?;
    }
    Ok(buffer)
}

/// A distinct colour per group (Tableau 10).
pub fn palette(i: usize) -> RGBColor {
    const P: [(u8, u8, u8); 10] = [
        (31, 119, 180),
        (255, 127, 14),
        (44, 160, 44),
        (214, 39, 40),
        (148, 103, 189),
        (140, 86, 75),
        (227, 119, 194),
        (127, 127, 127),
        (188, 189, 34),
        (23, 190, 207),
    ];
    // Past the ten base colours, the same hues lighter (then darker), so that up to 30 series differ.
    let (r, g, b) = P[i % P.len()];
    let shade = |c: u8| match (i / P.len()) % 3 {
        0 => c,
        1 => c + (255 - c) / 2,
        _ => c / 2,
    };
    RGBColor(shade(r), shade(g), shade(b))
}

/// One point of the accuracy-against-cost scatter: x with its confidence interval (drawn as a horizontal
/// whisker; lo = hi = x for a deterministic cost), y, its group (colour) and label. Highlighted points carry
/// their label next to them; the others carry a number, listed with its label in the key beside the plot.
#[derive(Clone, Debug, Default)]
pub struct Point {
    pub x: f64,
    pub x_lo: f64,
    pub x_hi: f64,
    pub y: f64,
    pub label: String,
    pub group: usize,
    pub highlight: bool,
    /// Drawn at the plot's edge (an outlier below the fitted range, or a non-finite value at the top): a
    /// triangle pointing out, its value in its label.
    pub edge: bool,
}

/// What the scatter draws: the title and axis names, the frontier through `line`, the groups' legend, and the
/// cost beyond which points go to a narrow side panel (so that the main panel keeps its resolution).
pub struct Scatter<'a> {
    pub title: &'a str,
    pub x_desc: &'a str,
    pub y_desc: &'a str,
    pub line: &'a [(f64, f64)],
    pub legend: &'a [(usize, String)],
    pub split_x: Option<f64>,
}

const Y_FLOOR: f64 = 1e-8;
/// Label sizes in pixels (15 px DejaVu Sans).
const CHAR_W: i32 = 8;
const TEXT_H: i32 = 16;

/// The log y range drawn: from the data's top down to its bottom, but no further than 2.5 decades below its
/// 10th percentile, so that a few specs far below the rest (an exact dielectric at 5e-7 among errors of 0.1)
/// do not leave most of the plot empty; those are drawn at the bottom edge and marked (`pinned`).
pub fn fit_log_range(ys: &[f64]) -> (f64, f64) {
    let mut v: Vec<f64> = ys.iter().copied().filter(|y| y.is_finite()).map(|y| y.max(Y_FLOOR)).collect();
    if v.is_empty() {
        return (Y_FLOOR, 1.0);
    }
    v.sort_by(f64::total_cmp);
    let bulk = v[v.len() / 10] / 10f64.powf(2.5);
    (v[0].max(bulk) / 3.0, v[v.len() - 1] * 3.0)
}

/// Points as drawn: a y below the range at the bottom edge and a non-finite y at the top edge, each marked
/// (`edge`) and its label saying so.
fn pinned(points: &[Point], (y_lo, y_top): (f64, f64)) -> Vec<Point> {
    points
        .iter()
        .filter(|p| p.x.is_finite())
        .map(|p| {
            let (y, label, edge) = if !p.y.is_finite() {
                (y_top / 1.5, format!("{} (non-finite)", p.label), true)
            } else if p.y.max(Y_FLOOR) < y_lo {
                (y_lo * 1.25, format!("{} ({:.1e}, below)", p.label, p.y), true)
            } else {
                (p.y.max(Y_FLOOR), p.label.clone(), false)
            };
            Point { y, label, edge, ..p.clone() }
        })
        .collect()
}

/// The x range of `pts`, whiskers included, padded for labels.
fn x_range(pts: &[&Point]) -> (f64, f64) {
    let (lo, hi) = pts
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| (lo.min(p.x_lo.min(p.x)), hi.max(p.x_hi.max(p.x))));
    let pad = (hi - lo).max(1e-3) * 0.04;
    (lo - pad, hi + pad * 6.0)
}

type Area<'a> = DrawingArea<BitMapBackend<'a>, plotters::coord::Shift>;

/// One panel: axes, the frontier (main panel), whiskers and points by group, and their labels or numbers.
fn scatter_panel(
    area: &Area,
    spec: &Scatter,
    pts: &[&Point],
    numbers: &[(usize, &Point)],
    (y0, y1): (f64, f64),
    main: bool,
) -> Result<()> {
    let err = |e: &dyn std::fmt::Display| anyhow!("chart: {e}");
    let (x0, x1) = x_range(pts);
    let mut chart = ChartBuilder::on(area)
        .margin(30)
        .x_label_area_size(70)
        .y_label_area_size(if main { 110 } else { 20 })
        .build_cartesian_2d(x0..x1, (y0..y1).log_scale())
        .map_err(|e| err(&e))?;
    let plot_width = chart.plotting_area().dim_in_pixel().0 as f64;
    chart
        .configure_mesh()
        .x_desc(if main { spec.x_desc } else { "cost relative to the fastest spec" })
        .y_desc(if main { spec.y_desc } else { "" })
        // As many ticks as the panel's width holds without two labels touching (the side panel is narrow).
        .x_labels(x_tick_count(x0..x1, plot_width, if main { 10 } else { 6 }))
        .x_label_formatter(&|x| x_tick_label(*x))
        .y_label_formatter(&|y| format!("{y:.0e}"))
        .axis_desc_style((FONT, 24))
        .label_style((FONT, TICK_FONT))
        .draw()
        .map_err(|e| err(&e))?;
    if main {
        chart
            .draw_series(LineSeries::new(
                spec.line.iter().map(|&(x, y)| (x, if y.max(Y_FLOOR) < y0 { y0 * 1.25 } else { y.max(Y_FLOOR) })),
                RED.stroke_width(3),
            ))
            .map_err(|e| err(&e))?;
    }
    for (group, _) in spec.legend {
        let colour = palette(*group);
        let members: Vec<&&Point> = pts.iter().filter(|p| p.group == *group).collect();
        chart
            .draw_series(
                members.iter().map(|p| PathElement::new(vec![(p.x_lo, p.y), (p.x_hi, p.y)], colour.stroke_width(2))),
            )
            .map_err(|e| err(&e))?;
        chart
            .draw_series(members.iter().filter(|p| !p.edge).map(|p| Circle::new((p.x, p.y), 7, colour.filled())))
            .map_err(|e| err(&e))?;
        // A point at the edge: a triangle pointing off the plot (down below the range, up at the top).
        for p in members.iter().filter(|p| p.edge) {
            let (cx, cy) = chart.backend_coord(&(p.x, p.y));
            let down = p.y < (y0 * y1).sqrt();
            let (tip, base) = if down { (cy + 9, cy - 7) } else { (cy - 9, cy + 7) };
            let base_pixel = area.get_base_pixel();
            let pts = vec![(cx - 9, base), (cx + 9, base), (cx, tip)]
                .into_iter()
                .map(|(x, y)| (x - base_pixel.0, y - base_pixel.1))
                .collect::<Vec<_>>();
            area.draw(&Polygon::new(pts, colour.filled())).map_err(|e| err(&e))?;
        }
    }
    // Labels stay inside the plotting area (not over the axes' ticks); the groups' key is beside the plots.
    let (xs, ys) = chart.plotting_area().get_pixel_range();
    let inside = Rect { x0: xs.start as f64, y0: ys.start as f64, x1: xs.end as f64, y1: ys.end as f64 };
    draw_labels(area, inside, pts, numbers, |p| chart.backend_coord(&(p.x, p.y)))?;
    Ok(())
}

/// A cost axis tick's label: three decimals at most, trailing zeros dropped.
fn x_tick_label(x: f64) -> String {
    format!("{x:.3}").trim_end_matches('0').trim_end_matches('.').to_string()
}

/// Pixels between two tick labels at the least, and the labels' size.
const TICK_GAP: f64 = 12.0;
const TICK_FONT: u32 = 20;

/// The most x ticks, up to `wanted`, whose labels (at plotters' own key points for that many, `key_points`)
/// keep `TICK_GAP` apart across a plot `width` pixels wide; at least 2.
fn x_tick_count(range: std::ops::Range<f64>, width: f64, wanted: usize) -> usize {
    let apart = |n: usize| tick_boxes(range.clone(), width, n).windows(2).all(|p| p[1].0 - p[0].1 >= TICK_GAP);
    (2..=wanted.max(2)).rev().find(|&n| apart(n)).unwrap_or(2)
}

/// The (left, right) pixels of each x tick label plotters draws for a hint of `n` (its `key_points`).
fn tick_boxes(range: std::ops::Range<f64>, width: f64, n: usize) -> Vec<(f64, f64)> {
    use plotters::coord::ranged1d::Ranged;
    use plotters::coord::types::RangedCoordf64;
    let coord: RangedCoordf64 = range.clone().into();
    coord
        .key_points(n)
        .iter()
        .map(|&k| {
            let centre = (k - range.start) / (range.end - range.start) * width;
            let w = f64::from(crate::export::text::measure(&x_tick_label(k), TICK_FONT, false).0);
            (centre - w / 2.0, centre + w / 2.0)
        })
        .collect()
}

/// Where a test draws a committed picture: back into results/ under `BLESS=1` (so the committed
/// picture is what its committed JSON draws), else into `scratch`.
#[cfg(test)]
pub fn blessed_or_scratch(results_name: &str, scratch: &Path) -> std::path::PathBuf {
    match std::env::var_os("BLESS") {
        Some(_) => Path::new(env!("CARGO_MANIFEST_DIR")).join("results").join(results_name),
        None => scratch.join(results_name),
    }
}

/// Labels (highlighted points) and numbers (the rest), placed greedily from the top down by `labels::Placer`
/// within the panel, so that none overlaps another or a point; one with no free place is left out (its point
/// is still drawn, and listed in the key or the table). `coord` is a point's pixel in the chart.
fn draw_labels(
    area: &Area,
    inside: Rect,
    pts: &[&Point],
    numbers: &[(usize, &Point)],
    coord: impl Fn(&Point) -> (i32, i32),
) -> Result<()> {
    let mut placer = Placer::new(inside);
    for p in pts {
        let (x, y) = coord(p);
        let r = 8.0;
        placer.occupy(Rect { x0: x as f64 - r, y0: y as f64 - r, x1: x as f64 + r, y1: y as f64 + r });
    }
    let mut order: Vec<&&Point> = pts.iter().collect();
    order.sort_by(|a, b| b.highlight.cmp(&a.highlight).then(b.y.total_cmp(&a.y)));
    for p in order {
        let text = if p.highlight {
            p.label.clone()
        } else {
            numbers.iter().find(|(_, q)| std::ptr::eq(*q, *p)).map_or(String::new(), |(n, _)| n.to_string())
        };
        let (x, y) = coord(p);
        let width = (CHAR_W * text.chars().count() as i32) as f64;
        let Some(b) = placer.place((x as f64, y as f64), width, TEXT_H as f64) else { continue };
        let base = area.get_base_pixel();
        if b.far_from((x as f64, y as f64)) {
            let (nx, ny) = b.nearest((x as f64, y as f64));
            let leader = vec![(x - base.0, y - base.1), (nx as i32 - base.0, ny as i32 - base.1)];
            area.draw(&PathElement::new(leader, palette(p.group).mix(0.6))).map_err(|e| anyhow!("chart: {e}"))?;
        }
        let style = crate::export::text::Style {
            size: if p.highlight { 16 } else { 14 },
            bold: false,
            colour: palette(p.group),
            vertical: false,
        };
        crate::export::text::draw(area, &text, (b.x0 as i32 - base.0, b.y0 as i32 - base.1), style)?;
    }
    Ok(())
}

/// The key beside the plots, outside the data: the frontier's line and each group's colour, then each
/// numbered point's number and label in its group's colour.
fn scatter_key(area: &Area, legend: &[(usize, String)], numbers: &[(usize, &Point)]) -> Result<()> {
    let err = |e: &dyn std::fmt::Display| anyhow!("chart: {e}");
    let ink = |size: u32, colour: RGBColor| crate::export::text::Style { size, bold: false, colour, vertical: false };
    let mut y = 16;
    area.draw(&PathElement::new(vec![(10, y + 10), (40, y + 10)], RED.stroke_width(3))).map_err(|e| err(&e))?;
    crate::export::text::draw(area, "Pareto frontier", (48, y), ink(18, BLACK))?;
    for (group, name) in legend {
        y += 24;
        area.draw(&Circle::new((25, y + 10), 7, palette(*group).filled())).map_err(|e| err(&e))?;
        crate::export::text::draw(area, name, (48, y), ink(18, BLACK))?;
    }
    y += 44;
    crate::export::text::draw(area, "Numbered points", (10, y), ink(20, BLACK))?;
    let top = y + 32;
    let line = ((area.dim_in_pixel().1 as i32 - top - 20) / numbers.len().max(1) as i32).clamp(10, 22);
    for (i, (n, p)) in numbers.iter().enumerate() {
        let size = (line - 4).min(16) as u32;
        let at = (10, top + i as i32 * line);
        crate::export::text::draw(area, &format!("{n}  {}", p.label), at, ink(size, palette(p.group)))?;
    }
    Ok(())
}

/// Scatter of points on a log y axis with cost whiskers, the frontier drawn, highlighted points labelled and the
/// rest numbered with a key (so that no label overlaps another). Points whose y is not finite (a spec that
/// overflowed) are pinned to the top edge; points beyond `split_x` go to a side panel.
pub fn scatter_log_y(path: &Path, spec: &Scatter, points: &[Point]) -> Result<()> {
    let (w, h) = (2400u32, 1600u32);
    let finite: Vec<f64> =
        points.iter().filter(|p| p.x.is_finite() && p.y.is_finite()).map(|p| p.y.max(Y_FLOOR)).collect();
    if finite.is_empty() {
        return Err(anyhow!("chart {}: no point with finite coordinates", path.display()));
    }
    let ys = fit_log_range(&finite);
    let pinned = pinned(points, ys);
    let split = spec.split_x.filter(|s| pinned.iter().any(|p| p.x > *s));
    let (main_pts, side_pts): (Vec<&Point>, Vec<&Point>) = pinned.iter().partition(|p| split.is_none_or(|s| p.x <= s));
    let numbers: Vec<(usize, &Point)> =
        pinned.iter().filter(|p| !p.highlight).enumerate().map(|(i, p)| (i + 1, p)).collect();
    render(path, w, h, |root| {
        let root = root.titled(spec.title, (FONT, 34)).map_err(|e| anyhow!("chart: {e}"))?;
        let (plots, key) = root.split_horizontally((w as f64 * 0.74) as u32);
        if side_pts.is_empty() {
            scatter_panel(&plots, spec, &main_pts, &numbers, ys, true)?;
        } else {
            let (left, right) = plots.split_horizontally((w as f64 * 0.58) as u32);
            scatter_panel(&left, spec, &main_pts, &numbers, ys, true)?;
            scatter_panel(&right, spec, &side_pts, &numbers, ys, false)?;
        }
        scatter_key(&key, spec.legend, &numbers)
    })
}

/// Line chart: one series per (name, points), linear axes.
pub fn lines(
    path: &Path,
    title: &str,
    x_desc: &str,
    y_desc: &str,
    series: &[(String, Vec<(f64, f64)>)],
    y_range: (f64, f64),
) -> Result<()> {
    let (x0, x1) = series
        .iter()
        .flat_map(|(_, p)| p.iter().map(|q| q.0))
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), x| (lo.min(x), hi.max(x)));
    render(path, 1400, 900, |root| {
        let err = |e: &dyn std::fmt::Display| anyhow!("chart: {e}");
        let mut chart = ChartBuilder::on(root)
            .caption(title, (FONT, 28))
            .margin(20)
            .x_label_area_size(60)
            .y_label_area_size(80)
            .build_cartesian_2d(x0..x1, y_range.0..y_range.1)
            .map_err(|e| err(&e))?;
        chart
            .configure_mesh()
            .x_desc(x_desc)
            .y_desc(y_desc)
            .axis_desc_style((FONT, 20))
            .label_style((FONT, 16))
            .draw()
            .map_err(|e| err(&e))?;
        for (i, (name, pts)) in series.iter().enumerate() {
            let colour = palette(i);
            chart
                .draw_series(LineSeries::new(pts.iter().copied(), colour.stroke_width(3)))
                .map_err(|e| err(&e))?
                .label(name.clone())
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 30, y)], colour.stroke_width(3)));
        }
        chart
            .configure_series_labels()
            .label_font((FONT, 18))
            .background_style(WHITE.mix(0.85))
            .border_style(BLACK)
            .draw()
            .map_err(|e| err(&e))?;
        Ok(())
    })
}

/// Line charts side by side: one panel per (title, series), linear axes, a shared y range.
pub fn line_panels(
    path: &Path,
    title: &str,
    x_desc: &str,
    y_desc: &str,
    panels: &[(String, Vec<(String, Vec<(f64, f64)>)>)],
    y_range: (f64, f64),
) -> Result<()> {
    let width = 520 * panels.len() as u32;
    render(path, width, 620, |root| {
        let err = |e: &dyn std::fmt::Display| anyhow!("chart: {e}");
        let root = root.titled(title, (FONT, 26)).map_err(|e| err(&e))?;
        for (area, (name, series)) in root.split_evenly((1, panels.len())).iter().zip(panels) {
            let x1 = series.iter().flat_map(|(_, p)| p.iter().map(|q| q.0)).fold(0.0, f64::max);
            let mut chart = ChartBuilder::on(area)
                .caption(name, (FONT, 20))
                .margin(12)
                .x_label_area_size(40)
                .y_label_area_size(50)
                .build_cartesian_2d(0.0..x1, y_range.0..y_range.1)
                .map_err(|e| err(&e))?;
            chart.configure_mesh().x_desc(x_desc).y_desc(y_desc).label_style((FONT, 13)).draw().map_err(|e| err(&e))?;
            chart.draw_series(LineSeries::new([(0.0, 1.0), (x1, 1.0)], BLACK.stroke_width(1))).map_err(|e| err(&e))?;
            for (i, (label, pts)) in series.iter().enumerate() {
                let colour = palette(i);
                chart
                    .draw_series(LineSeries::new(pts.iter().copied(), colour.stroke_width(2)))
                    .map_err(|e| err(&e))?
                    .label(label.clone())
                    .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 20, y)], colour.stroke_width(2)));
            }
            chart
                .configure_series_labels()
                .position(SeriesLabelPosition::LowerRight)
                .label_font((FONT, 12))
                .background_style(WHITE.mix(0.8))
                .border_style(BLACK)
                .draw()
                .map_err(|e| err(&e))?;
        }
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Two specs five decades below the rest are drawn at the bottom edge, marked, with their value; the
    /// range keeps every other point.
    #[test]
    fn the_error_axis_fits_the_bulk_and_pins_far_outliers_to_its_edge() {
        let mut ys: Vec<f64> = (0..60).map(|k| 0.08 + 0.01 * f64::from(k % 30)).collect();
        ys.extend([5e-7, 5.2e-7]);
        let (lo, hi) = fit_log_range(&ys);
        assert!(lo > 1e-4 && lo < 0.08 / 300.0 && hi >= 0.37 * 3.0 - 1e-9, "{lo} {hi}");
        let points: Vec<Point> = ys
            .iter()
            .map(|&y| Point { x: 1.0, x_lo: 1.0, x_hi: 1.0, y, label: "p".into(), ..Point::default() })
            .collect();
        let drawn = pinned(&points, (lo, hi));
        let edge: Vec<&Point> = drawn.iter().filter(|p| p.edge).collect();
        assert_eq!(edge.len(), 2, "the two far below");
        assert!(edge.iter().all(|p| p.y > lo && p.y < 2.0 * lo && p.label.contains("e-7, below")), "{edge:?}");
        assert!(drawn.iter().filter(|p| !p.edge).all(|p| p.y >= 0.08), "the rest where they are");
        // Without outliers the range is the data's own.
        let (lo2, _) = fit_log_range(&ys[..60]);
        assert!((lo2 - 0.08 / 3.0).abs() < 1e-12, "{lo2}");
    }

    /// The fp16 side panel of the committed sweep (costs 8.3 to 13.5 over about 300 px) and the main panel:
    /// at plotters' key points for the count chosen, no two tick labels come within `TICK_GAP`.
    #[test]
    fn tick_labels_keep_apart_in_a_narrow_panel() {
        for (range, width) in [(8.1..14.3, 300.0), (0.97..2.13, 1200.0)] {
            let n = x_tick_count(range.clone(), width, 10);
            let boxes = tick_boxes(range.clone(), width, n);
            assert!(n > 2 && boxes.len() > 2, "{range:?}: {n} ticks");
            assert!(boxes.windows(2).all(|p| p[1].0 - p[0].1 >= TICK_GAP), "{range:?}: {boxes:?}");
        }
    }

    #[test]
    fn scatter_with_non_finite_points_finishes() {
        let dir = tempfile::tempdir().unwrap();
        let point = |x: f64, y: f64, label: &str, group, highlight| Point {
            x,
            x_lo: x * 0.98,
            x_hi: x * 1.02,
            y,
            label: label.into(),
            group,
            highlight,
            edge: false,
        };
        let points = vec![
            point(1.0, 0.1, "a", 0, true),
            point(2.0, f64::INFINITY, "b", 1, false),
            point(1.5, f64::NAN, "c", 1, false),
        ];
        let path = dir.path().join("s.png");
        let spec = Scatter {
            title: "t",
            x_desc: "x",
            y_desc: "y",
            line: &[(1.0, 0.1)],
            legend: &[(0, "g".into())],
            split_x: Some(1.8),
        };
        scatter_log_y(&path, &spec, &points).unwrap();
        assert!(image::open(&path).is_ok());
    }
}
