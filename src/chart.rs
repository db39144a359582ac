//! PNG charts and images. Plotters draws into an RGB buffer (DejaVu Sans embedded, so no system fonts are
//! needed); the `image` crate encodes it and `io::write_atomic` writes it.

use anyhow::{anyhow, Result};
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
    let image = image::RgbImage::from_raw(width, height, rgb).ok_or_else(|| anyhow!("image buffer of the wrong size"))?;
    let mut bytes = std::io::Cursor::new(Vec::new());
    image.write_to(&mut bytes, image::ImageFormat::Png)?;
    crate::io::write_atomic(path, bytes.get_ref())
}

/// Draws with plotters into a fresh white `width` x `height` canvas and writes it as PNG.
pub fn render(path: &Path, width: u32, height: u32, draw: impl FnOnce(&DrawingArea<BitMapBackend, plotters::coord::Shift>) -> Result<()>) -> Result<()> {
    register_font();
    let mut buffer = vec![255u8; (width * height * 3) as usize];
    {
        let root = BitMapBackend::with_buffer(&mut buffer, (width, height)).into_drawing_area();
        root.fill(&WHITE).map_err(|e| anyhow!("{e}"))?;
        draw(&root)?;
        root.present().map_err(|e| anyhow!("{e}"))?;
    }
    write_png(path, width, height, buffer)
}

/// A distinct colour per group (Tableau 10).
pub fn palette(i: usize) -> RGBColor {
    const P: [(u8, u8, u8); 10] = [
        (31, 119, 180), (255, 127, 14), (44, 160, 44), (214, 39, 40), (148, 103, 189),
        (140, 86, 75), (227, 119, 194), (127, 127, 127), (188, 189, 34), (23, 190, 207),
    ];
    let (r, g, b) = P[i % P.len()];
    RGBColor(r, g, b)
}

/// One labelled point of a scatter chart.
pub struct Point {
    pub x: f64,
    pub y: f64,
    pub label: String,
    pub group: usize,
}

/// Scatter of labelled points on a log y axis, with a polyline (the Pareto frontier) drawn through `line`.
/// Points whose y is not finite (a spec that overflowed) are pinned to the top edge and labelled so. Points
/// far to the right of the rest (`split_x`: beyond it) go to a narrow side panel, so that the main panel keeps
/// its resolution; labels are placed greedily where they overlap no other label.
#[allow(clippy::too_many_arguments)]
pub fn scatter_log_y(path: &Path, title: &str, x_desc: &str, y_desc: &str, points: &[Point], line: &[(f64, f64)], legend: &[(usize, String)], split_x: Option<f64>) -> Result<()> {
    let (w, h) = (2400u32, 1600u32);
    let y_floor = 1e-8;
    let finite: Vec<&Point> = points.iter().filter(|p| p.x.is_finite() && p.y.is_finite()).collect();
    if finite.is_empty() {
        return Err(anyhow!("chart {}: no point with finite coordinates", path.display()));
    }
    let ys = finite.iter().map(|p| p.y.max(y_floor));
    let (y0, y1) = (ys.clone().fold(f64::INFINITY, f64::min) / 3.0, ys.fold(f64::NEG_INFINITY, f64::max) * 3.0);
    let pinned: Vec<Point> = points
        .iter()
        .filter(|p| p.x.is_finite())
        .map(|p| {
            let (y, label) = if p.y.is_finite() { (p.y.max(y_floor), p.label.clone()) } else { (y1 / 1.5, format!("{} (non-finite)", p.label)) };
            Point { x: p.x, y, label, group: p.group }
        })
        .collect();
    let split = split_x.filter(|s| pinned.iter().any(|p| p.x > *s));
    let (main_pts, side_pts): (Vec<&Point>, Vec<&Point>) = pinned.iter().partition(|p| split.is_none_or(|s| p.x <= s));
    let x_range = |pts: &[&Point]| {
        let (lo, hi) = pts.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), p| (lo.min(p.x), hi.max(p.x)));
        let pad = (hi - lo).max(1e-3) * 0.04;
        (lo - pad, hi + pad * 6.0)
    };
    render(path, w, h, |root| {
        let err = |e: &dyn std::fmt::Display| anyhow!("chart: {e}");
        let root = root.titled(title, (FONT, 34)).map_err(|e| err(&e))?;
        let areas: Vec<_> = if side_pts.is_empty() { vec![root.clone()] } else {
            let (left, right) = root.split_horizontally((w as f64 * 0.8) as u32);
            vec![left, right]
        };
        let mut placed: Vec<(i32, i32, i32, i32)> = Vec::new();
        for (k, area) in areas.iter().enumerate() {
            let pts = if k == 0 { &main_pts } else { &side_pts };
            let (x0, x1) = x_range(pts);
            let mut chart = ChartBuilder::on(area)
                .margin(30)
                .x_label_area_size(70)
                .y_label_area_size(if k == 0 { 110 } else { 20 })
                .build_cartesian_2d(x0..x1, (y0..y1).log_scale())
                .map_err(|e| err(&e))?;
            chart
                .configure_mesh()
                .x_desc(if k == 0 { x_desc } else { "" })
                .y_desc(if k == 0 { y_desc } else { "" })
                .y_label_formatter(&|y| format!("{y:.0e}"))
                .axis_desc_style((FONT, 24))
                .label_style((FONT, 20))
                .draw()
                .map_err(|e| err(&e))?;
            if k == 0 {
                chart
                    .draw_series(LineSeries::new(line.iter().map(|&(x, y)| (x, y.max(y_floor))), RED.stroke_width(3)))
                    .map_err(|e| err(&e))?
                    .label("Pareto frontier")
                    .legend(|(x, y)| PathElement::new(vec![(x, y), (x + 30, y)], RED.stroke_width(3)));
            }
            for (group, name) in legend {
                let colour = palette(*group);
                let series = chart
                    .draw_series(pts.iter().filter(|p| p.group == *group).map(|p| Circle::new((p.x, p.y), 7, colour.filled())))
                    .map_err(|e| err(&e))?;
                if k == 0 {
                    series.label(name.clone()).legend(move |(x, y)| Circle::new((x + 15, y), 7, colour.filled()));
                }
            }
            // Greedy labels: the first candidate offset whose box overlaps no placed label (and no point).
            let (char_w, text_h) = (8, 16);
            let mut order: Vec<&&Point> = pts.iter().collect();
            order.sort_by(|a, b| b.y.total_cmp(&a.y));
            for p in order {
                let (px, py) = chart.backend_coord(&(p.x, p.y));
                let width = char_w * p.label.chars().count() as i32;
                let candidates = [(10, -8), (10, 10), (10, -26), (10, 28), (-10 - width, -8), (-10 - width, 10), (10, -44), (10, 46), (-10 - width, -26), (-10 - width, 28)];
                let free = |(dx, dy): (i32, i32)| {
                    let bx = (px + dx, py + dy - text_h / 2, px + dx + width, py + dy + text_h / 2);
                    !placed.iter().any(|b| bx.0 < b.2 && b.0 < bx.2 && bx.1 < b.3 && b.1 < bx.3)
                };
                let (dx, dy) = candidates.iter().copied().find(|c| free(*c)).unwrap_or(candidates[0]);
                placed.push((px + dx, py + dy - text_h / 2, px + dx + width, py + dy + text_h / 2));
                area.draw(&Text::new(p.label.clone(), (px + dx - area.get_base_pixel().0, py + dy - text_h / 2 - area.get_base_pixel().1), (FONT, 15).into_font().color(&palette(p.group).mix(0.95))))
                    .map_err(|e| err(&e))?;
            }
            if k == 0 {
                chart
                    .configure_series_labels()
                    .position(SeriesLabelPosition::UpperRight)
                    .label_font((FONT, 22))
                    .background_style(WHITE.mix(0.85))
                    .border_style(BLACK)
                    .draw()
                    .map_err(|e| err(&e))?;
            }
        }
        Ok(())
    })
}

/// Line chart: one series per (name, points), linear axes.
pub fn lines(path: &Path, title: &str, x_desc: &str, y_desc: &str, series: &[(String, Vec<(f64, f64)>)], y_range: (f64, f64)) -> Result<()> {
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
        chart.configure_mesh().x_desc(x_desc).y_desc(y_desc).axis_desc_style((FONT, 20)).label_style((FONT, 16)).draw().map_err(|e| err(&e))?;
        for (i, (name, pts)) in series.iter().enumerate() {
            let colour = palette(i);
            chart
                .draw_series(LineSeries::new(pts.iter().copied(), colour.stroke_width(3)))
                .map_err(|e| err(&e))?
                .label(name.clone())
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 30, y)], colour.stroke_width(3)));
        }
        chart.configure_series_labels().label_font((FONT, 18)).background_style(WHITE.mix(0.85)).border_style(BLACK).draw().map_err(|e| err(&e))?;
        Ok(())
    })
}

/// Line charts side by side: one panel per (title, series), linear axes, a shared y range.
pub fn line_panels(path: &Path, title: &str, x_desc: &str, y_desc: &str, panels: &[(String, Vec<(String, Vec<(f64, f64)>)>)], y_range: (f64, f64)) -> Result<()> {
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
            chart.configure_series_labels().position(SeriesLabelPosition::LowerRight).label_font((FONT, 12)).background_style(WHITE.mix(0.8)).border_style(BLACK).draw().map_err(|e| err(&e))?;
        }
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scatter_with_non_finite_points_finishes() {
        let dir = tempfile::tempdir().unwrap();
        let points = vec![
            Point { x: 1.0, y: 0.1, label: "a".into(), group: 0 },
            Point { x: 2.0, y: f64::INFINITY, label: "b".into(), group: 1 },
            Point { x: 1.5, y: f64::NAN, label: "c".into(), group: 1 },
        ];
        let path = dir.path().join("s.png");
        scatter_log_y(&path, "t", "x", "y", &points, &[(1.0, 0.1)], &[(0, "g".into())], Some(1.8)).unwrap();
        assert!(image::open(&path).is_ok());
    }
}
