//! Text drawn into the PNG pictures with ab_glyph, each glyph placed at the pen position plus its own left
//! side bearing, advanced and kerned in fractional pixels. Plotters 0.3.7's ab_glyph text draws each glyph's
//! bitmap at the whole-pixel pen position without the glyph's bearing (its `style/font/ab_glyph.rs`), so
//! letters with different bearings drift apart ("la vapipe", "na vi21"); the pictures whose words a reader
//! reads (the heat table, chart labels and keys) draw through here instead.

use ab_glyph::{Font, FontRef, PxScale, ScaleFont, point};
use anyhow::{Result, anyhow};
use plotters::coord::Shift;
use plotters::prelude::*;

/// The embedded DejaVu Sans, parsed once per weight (layouts measure many texts).
fn face(bold: bool) -> &'static FontRef<'static> {
    static REGULAR: std::sync::OnceLock<FontRef<'static>> = std::sync::OnceLock::new();
    static BOLD: std::sync::OnceLock<FontRef<'static>> = std::sync::OnceLock::new();
    let (cell, bytes) = if bold { (&BOLD, dejavu::sans::bold()) } else { (&REGULAR, dejavu::sans::regular()) };
    cell.get_or_init(|| FontRef::try_from_slice(bytes).expect("the embedded DejaVu Sans parses"))
}

/// The width and height in pixels of `text` at `size` px (the font's ascent to descent), as `draw` lays it.
pub fn measure(text: &str, size: u32, bold: bool) -> (i32, i32) {
    let font = face(bold);
    let s = font.as_scaled(PxScale::from(size as f32));
    let mut width = 0.0f32;
    let mut prev = None;
    for c in text.chars() {
        let id = font.glyph_id(c);
        if let Some(p) = prev {
            width += s.kern(p, id);
        }
        width += s.h_advance(id);
        prev = Some(id);
    }
    (width.ceil() as i32, (s.ascent() - s.descent()).ceil() as i32)
}

/// The font's ascent at `size` px: from a text box's top to its baseline.
pub fn ascent(size: u32, bold: bool) -> i32 {
    face(bold).as_scaled(PxScale::from(size as f32)).ascent().round() as i32
}

/// How a text is drawn.
#[derive(Clone, Copy)]
pub struct Style {
    pub size: u32,
    pub bold: bool,
    pub colour: RGBColor,
    /// Read bottom to top (turned a quarter anticlockwise).
    pub vertical: bool,
}

/// Draws `text` with its box's top-left corner at `at` (horizontal), or, vertical, its box's bottom-left.
pub fn draw<DB: DrawingBackend>(area: &DrawingArea<DB, Shift>, text: &str, at: (i32, i32), style: Style) -> Result<()> {
    let font = face(style.bold);
    let scale = PxScale::from(style.size as f32);
    let s = font.as_scaled(scale);
    let mut pen = 0.0f32;
    let mut prev = None;
    let mut failed = None;
    for c in text.chars() {
        let id = font.glyph_id(c);
        if let Some(p) = prev {
            pen += s.kern(p, id);
        }
        if let Some(outline) = font.outline_glyph(id.with_scale_and_position(scale, point(pen, s.ascent()))) {
            let b = outline.px_bounds();
            outline.draw(|x, y, coverage| {
                // (along, down) in the text's own frame, from its box's top-left.
                let (along, down) = (b.min.x as i32 + x as i32, b.min.y as i32 + y as i32);
                let px = if style.vertical { (at.0 + down, at.1 - along) } else { (at.0 + along, at.1 + down) };
                if coverage > 0.0 && failed.is_none() {
                    if let Err(e) = area.draw_pixel(px, &style.colour.mix(f64::from(coverage.min(1.0)))) {
                        failed = Some(e.to_string());
                    }
                }
            });
        }
        pen += s.h_advance(id);
        prev = Some(id);
    }
    failed.map_or(Ok(()), |e| Err(anyhow!("text {text:?}: {e}")))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The gaps between letters' ink: with each glyph's bearing kept, "lavapipe"'s widest gap between two
    /// neighbouring letters is no more than twice its narrowest.
    #[test]
    fn letters_are_evenly_spaced() {
        let (w, h) = measure("lavapipe", 40, false);
        let mut rgb = vec![255u8; (w * h * 3) as usize];
        {
            let root = BitMapBackend::with_buffer(&mut rgb, (w as u32, h as u32)).into_drawing_area();
            draw(&root, "lavapipe", (0, 0), Style { size: 40, bold: false, colour: BLACK, vertical: false }).unwrap();
            root.present().unwrap();
        }
        let inked: Vec<bool> = (0..w).map(|x| (0..h).any(|y| rgb[((y * w + x) * 3) as usize] < 128)).collect();
        // Runs of blank columns between inked ones.
        let mut gaps = Vec::new();
        let mut run = 0;
        let mut seen = false;
        for &ink in &inked {
            if ink {
                if seen && run > 0 {
                    gaps.push(run);
                }
                seen = true;
                run = 0;
            } else {
                run += 1;
            }
        }
        assert!(gaps.len() >= 5, "letters apart: {gaps:?}");
        let (lo, hi) = (*gaps.iter().min().unwrap(), *gaps.iter().max().unwrap());
        assert!(hi <= 2 * lo.max(2), "uneven letter gaps {gaps:?}");
    }

    #[test]
    fn a_vertical_text_fills_a_box_of_its_width_turned() {
        let (w, h) = measure("navi21", 30, false);
        assert!(w > 3 * h / 2 && h > 20, "{w} x {h}");
    }
}
