//! Pixel helpers every raster picture shares (`render`'s scene pictures, `diff`'s picture, the report page's
//! embedded images): tone mapping to 8-bit sRGB, the viridis heat-map colours and their bar, labels and blits
//! onto a plotters canvas, and the polar lobe panels.

use super::markdown::sig;
use super::png::{self, FONT};
use crate::kernels::{LOBE_VIEW_DEG, LobePanel};
use anyhow::{Result, anyhow};
use plotters::prelude::*;

/// ACES filmic tone curve, Narkowicz 2015 fit: x (2.51 x + 0.03) / (x (2.43 x + 0.59) + 0.14), clamped to [0, 1].
pub fn aces(x: f32) -> f32 {
    let x = x.max(0.0);
    (x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14)).clamp(0.0, 1.0)
}

/// The sRGB OETF (IEC 61966-2-1): linear [0, 1] to display-encoded.
pub fn linear_to_srgb(c: f32) -> f32 {
    if c <= 0.0031308 { 12.92 * c } else { 1.055 * c.powf(1.0 / 2.4) - 0.055 }
}

/// Radiance to 8-bit sRGB: exposure, ACES per channel, sRGB encoding.
pub fn tone_map(rgb: [f32; 3], exposure: f32) -> [u8; 3] {
    rgb.map(|c| (linear_to_srgb(aces(c * exposure)) * 255.0).round() as u8)
}

/// Draws an RGB picture (w x h, row-major) at (x0, y0) of a plotters area.
pub fn blit(
    root: &DrawingArea<BitMapBackend, plotters::coord::Shift>,
    x0: i32,
    y0: i32,
    w: u32,
    px: &[[u8; 3]],
) -> Result<()> {
    for (i, c) in px.iter().enumerate() {
        let (x, y) = ((i as u32 % w) as i32, (i as u32 / w) as i32);
        root.draw_pixel((x0 + x, y0 + y), &RGBColor(c[0], c[1], c[2])).map_err(|e| anyhow!("{e}"))?;
    }
    Ok(())
}

pub fn label(
    root: &DrawingArea<BitMapBackend, plotters::coord::Shift>,
    text: &str,
    x: i32,
    y: i32,
    size: i32,
    colour: RGBColor,
) -> Result<()> {
    let size = size.max(1) as u32;
    let style = crate::export::text::Style { size, bold: false, colour, vertical: false };
    // Placed as plotters places text at (x, y), its baseline half a size below y: the pictures' layouts (and
    // the tests that read a picture below its title) keep their positions.
    let top = y + size as i32 / 2 - crate::export::text::ascent(size, false);
    crate::export::text::draw(root, text, (x, top), style)
}

/// Viridis colour map (matplotlib's, 9 control points, linear in between) for t in [0, 1].
pub fn viridis(t: f32) -> [u8; 3] {
    const P: [[f32; 3]; 9] = [
        [68.0, 1.0, 84.0],
        [71.0, 44.0, 122.0],
        [59.0, 81.0, 139.0],
        [44.0, 113.0, 142.0],
        [33.0, 144.0, 141.0],
        [39.0, 173.0, 129.0],
        [92.0, 200.0, 99.0],
        [170.0, 220.0, 50.0],
        [253.0, 231.0, 37.0],
    ];
    let x = t.clamp(0.0, 1.0) * 8.0;
    let i = (x as usize).min(7);
    let f = x - i as f32;
    [0, 1, 2].map(|c| (P[i][c] * (1.0 - f) + P[i + 1][c] * f).round() as u8)
}

/// Where `v` falls on a log scale from `floor` (0) to `top` (1); 0 below the floor.
pub fn log_position(v: f32, floor: f32, top: f32) -> f32 {
    if v < floor {
        return 0.0;
    }
    if top <= floor {
        return 1.0;
    }
    ((v / floor).ln() / (top / floor).ln()).clamp(0.0, 1.0)
}

/// A vertical viridis bar on a log scale from `floor` (bottom) to `top`, labelled at `top`, at each decade
/// between (where the labels keep apart) and, at the bottom, "< floor" for values under it.
pub fn log_colour_bar(
    root: &DrawingArea<BitMapBackend, plotters::coord::Shift>,
    (x0, y0, h): (i32, i32, i32),
    floor: f32,
    top: f32,
) -> Result<()> {
    for y in 0..h {
        let c = viridis(1.0 - y as f32 / (h - 1) as f32);
        root.draw(&Rectangle::new([(x0, y0 + y), (x0 + 14, y0 + y + 1)], RGBColor(c[0], c[1], c[2]).filled()))
            .map_err(|e| anyhow!("{e}"))?;
    }
    let at = |v: f32| y0 + ((1.0 - log_position(v, floor, top)) * (h - 1) as f32).round() as i32;
    let mut marks: Vec<(i32, String)> =
        vec![(y0, sig(f64::from(top), 2)), (y0 + h - 12, format!("<{}", sig(f64::from(floor), 2)))];
    let mut decade = 10f32.powf(floor.log10().ceil());
    while decade < top {
        let y = at(decade) - 6;
        if marks.iter().all(|(m, _)| (m - y).abs() >= 16) {
            marks.push((y, sig(f64::from(decade), 1)));
        }
        decade *= 10.0;
    }
    for (y, text) in marks {
        label(root, &text, x0 + 18, y, 12, BLACK)?;
    }
    Ok(())
}

/// One lobe panel's size in pixels (`draw_lobes` adds a 40-pixel title).
pub const LOBE_PANEL: (u32, u32) = (420, 300);

/// Draws `kernels::lobe_curves` (one curve per label) into `root`: a title, then the panels side by side.
pub fn draw_lobes(
    root: &DrawingArea<BitMapBackend, plotters::coord::Shift>,
    labels: &[String],
    panels: &[LobePanel],
) -> Result<()> {
    let theta_v = LOBE_VIEW_DEG.to_radians();
    let err = |e: &dyn std::fmt::Display| anyhow!("lobes: {e}");
    let root = root
        .titled("f_s NoL in the plane of incidence (view at 45 deg, F0 = 1); each panel scaled to its peak", (FONT, 18))
        .map_err(|e| err(&e))?;
    for (area, (r, curves)) in root.split_evenly((1, panels.len())).iter().zip(panels) {
        let peak = curves.iter().flatten().map(|p| p.1).fold(0.0f64, f64::max).max(1e-30);
        let mut chart = ChartBuilder::on(area)
            .caption(format!("r = {r} (peak {})", sig(peak, 3)), (FONT, 16))
            .margin(10)
            .build_cartesian_2d(-1.15f64..1.15, -0.05f64..1.15)
            .map_err(|e| err(&e))?;
        for rr in [0.25, 0.5, 0.75, 1.0] {
            let arc = (0..=180).map(|i| {
                let t = (i as f64 - 90.0).to_radians();
                (rr * t.sin(), rr * t.cos())
            });
            chart.draw_series(LineSeries::new(arc, RGBColor(215, 215, 215).stroke_width(1))).map_err(|e| err(&e))?;
        }
        let view = [(0.0, 0.0), (-theta_v.sin() * 1.1, theta_v.cos() * 1.1)];
        chart.draw_series(LineSeries::new(view, BLACK.stroke_width(2))).map_err(|e| err(&e))?;
        chart
            .draw_series(std::iter::once(Text::new(
                "V",
                (-theta_v.sin() * 1.12, theta_v.cos() * 1.12 + 0.05),
                (FONT, 14),
            )))
            .map_err(|e| err(&e))?;
        for (i, (label, c)) in labels.iter().zip(curves).enumerate() {
            let colour = png::palette(i);
            let pts = c.iter().map(|(t, y)| {
                let rr = y / peak;
                (rr * t.sin(), rr * t.cos())
            });
            chart
                .draw_series(LineSeries::new(pts, colour.stroke_width(2)))
                .map_err(|e| err(&e))?
                .label(label.clone())
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 18, y)], colour.stroke_width(2)));
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::UpperLeft)
            .label_font((FONT, 12))
            .background_style(WHITE.mix(0.8))
            .border_style(BLACK)
            .draw()
            .map_err(|e| err(&e))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::log_position;

    #[test]
    fn the_log_scale_spreads_decades_evenly_and_zeroes_below_its_floor() {
        let (floor, top) = (1e-3f32, 1.0f32);
        assert_eq!(log_position(1e-4, floor, top), 0.0);
        assert!((log_position(1e-3, floor, top)).abs() < 1e-6);
        assert!((log_position(1e-2, floor, top) - 1.0 / 3.0).abs() < 1e-5);
        assert!((log_position(1e-1, floor, top) - 2.0 / 3.0).abs() < 1e-5);
        assert_eq!(log_position(5.0, floor, top), 1.0);
        assert_eq!(log_position(0.5, 1.0, 1.0), 0.0, "below a floor that is the top");
    }
}
