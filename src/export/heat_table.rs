//! A table of ratios drawn as a picture: rows (models) x columns (devices) grouped under headers (vendors),
//! each cell its ratio printed on a diverging colour (blue cheaper than 1, white 1, red costlier; log2 scale
//! clamped at 0.5x and 2x), a colour bar in values beside it. README's headline picture: one vendor's
//! columns side by side, which columns are measured and which modelled in the group's header.
//! Every text's box is measured with the font it is drawn in and laid out on a grid, and `layout` returns
//! them, so a test checks that none overlaps another.

use crate::export::labels::Rect;
use crate::export::png::render;
use anyhow::{Result, anyhow};
use plotters::prelude::*;
use std::path::Path;

/// What the picture shows.
pub struct HeatTable {
    pub title: String,
    /// (group header, the columns' names under it).
    pub groups: Vec<(String, Vec<String>)>,
    pub rows: Vec<String>,
    /// Per row, per column in group order: the ratio, or None where there is none (`-`).
    pub cells: Vec<Vec<Option<f64>>>,
    /// What a ratio is, under the colour bar.
    pub scale_name: String,
}

/// Pixel sizes: picture drawn at twice a screen's density, so it stays sharp when GitHub scales it to its
/// README width (about 880 px).
const CELL_W: i32 = 84;
const CELL_H: i32 = 38;
const NAME_W: i32 = 190;
const GROUP_H: i32 = 40;
const TITLE_H: i32 = 50;
const BAR_W: i32 = 200;
const MARGIN: i32 = 16;
/// The colour bar's height: 2x at the top to 0.5x at the bottom.
const BAR_H: i32 = 240;
const CELL_FONT: u32 = 24;
/// The height of the triangles beyond the bar's ends that say it is clamped.
const CLAMP_H: i32 = 10;
const HEAD_FONT: u32 = 20;

/// Colour of a ratio: log2 clamped to [-1, 1], white at 0.
pub fn colour(ratio: f64) -> RGBColor {
    let t = ratio.log2().clamp(-1.0, 1.0);
    let (to, k) = if t < 0.0 { ((33, 102, 172), -t) } else { ((178, 24, 43), t) };
    let mix = |c: u8| (255.0 + (f64::from(c) - 255.0) * k).round() as u8;
    RGBColor(mix(to.0), mix(to.1), mix(to.2))
}

/// The text colour that reads best on `fill`: white or black, whichever has the higher contrast ratio (WCAG 2's
/// relative luminance of the sRGB colour).
pub fn text_colour(fill: RGBColor) -> RGBColor {
    let linear = |c: u8| {
        let c = f64::from(c) / 255.0;
        if c <= 0.04045 { c / 12.92 } else { ((c + 0.055) / 1.055).powf(2.4) }
    };
    let l = 0.2126 * linear(fill.0) + 0.7152 * linear(fill.1) + 0.0722 * linear(fill.2);
    if 1.05 / (l + 0.05) > (l + 0.05) / 0.05 { WHITE } else { BLACK }
}

/// A text to draw: its box (top-left, size), anchor point, size, rotation, and the colour it is drawn in.
#[derive(Clone, Debug)]
pub struct Placed {
    pub text: String,
    pub at: (i32, i32),
    pub size: u32,
    pub vertical: bool,
    pub bold: bool,
    pub rect: Rect,
    pub colour: RGBColor,
}

fn group_of(table: &HeatTable) -> Vec<(usize, usize)> {
    let mut start = 0;
    table
        .groups
        .iter()
        .map(|(_, c)| {
            let r = (start, c.len());
            start += c.len();
            r
        })
        .collect()
}

/// Where everything goes: the picture's size, the cells' top, each group's left edge, the colour bar's left
/// edge, and every text.
pub struct Layout {
    pub size: (u32, u32),
    pub grid_top: i32,
    pub group_left: Vec<i32>,
    /// Each group's cell width.
    pub cell_w: Vec<i32>,
    /// Where the groups' rules run under their headers.
    pub rule_y: i32,
    pub bar_x: i32,
    pub texts: Vec<Placed>,
}

/// Pixels between two groups of columns.
const GAP: i32 = 8;

/// A group header's words as lines no wider than `width` (a word wider than that on a line of its own).
fn wrap(name: &str, width: i32, measure: &dyn Fn(&str, u32, bool) -> (i32, i32)) -> Vec<String> {
    let mut lines: Vec<String> = Vec::new();
    for word in name.split_whitespace() {
        match lines.last_mut() {
            Some(line) if measure(&format!("{line} {word}"), HEAD_FONT, true).0 <= width => {
                line.push(' ');
                line.push_str(word);
            }
            _ => lines.push(word.to_string()),
        }
    }
    lines
}

/// The columns' geometry: each group's cell width and wrapped header, the header band's line and total
/// heights, each group's left edge and the right edge of the last.
struct Columns {
    cell_w: Vec<i32>,
    headers: Vec<Vec<String>>,
    line_h: i32,
    group_h: i32,
    group_left: Vec<i32>,
    right: i32,
}

fn columns(table: &HeatTable, measure: &dyn Fn(&str, u32, bool) -> (i32, i32)) -> Columns {
    // The row names' column is as wide as the longest name (a sweep spec can be long).
    let names = table.rows.iter().map(|r| measure(r, CELL_FONT, false).0 + 16).max().unwrap_or(0);
    let x0 = MARGIN + NAME_W.max(names);
    // A group's cells are wide enough for the longest word of its header; the header wraps at its width.
    let cell_w: Vec<i32> = table
        .groups
        .iter()
        .map(|(name, cols)| {
            let word = name.split_whitespace().map(|w| measure(w, HEAD_FONT, true).0).max().unwrap_or(0);
            CELL_W.max((word + 8 + cols.len() as i32 - 1) / cols.len().max(1) as i32)
        })
        .collect();
    let headers: Vec<Vec<String>> = table
        .groups
        .iter()
        .zip(&cell_w)
        .map(|((name, cols), w)| wrap(name, cols.len() as i32 * w - 4, measure))
        .collect();
    let line_h = measure("Ag", HEAD_FONT, true).1.max(1) + 2;
    let group_h = headers.iter().map(Vec::len).max().unwrap_or(1) as i32 * line_h + GROUP_H - line_h;
    let mut group_left = Vec::new();
    let mut x = x0;
    for ((_, cols), w) in table.groups.iter().zip(&cell_w) {
        group_left.push(x);
        x += cols.len() as i32 * w + GAP;
    }
    Columns { cell_w, headers, line_h, group_h, group_left, right: x - GAP }
}

/// The layout of `table`; `measure` gives a text's width and height at a size (bold or not).
pub fn layout(table: &HeatTable, measure: &dyn Fn(&str, u32, bool) -> (i32, i32)) -> Layout {
    let Columns { cell_w, headers, line_h, group_h, group_left, right } = columns(table, measure);
    let col_x = |g: usize, k: usize| group_left[g] + k as i32 * cell_w[g];
    let header_h =
        table.groups.iter().flat_map(|g| &g.1).map(|c| measure(c, HEAD_FONT, false).0).max().unwrap_or(0) + 16;
    let grid_top = TITLE_H + group_h + header_h;
    let width = right + BAR_W + MARGIN;
    let height = grid_top + (table.rows.len() as i32 * CELL_H).max(BAR_H + 12) + MARGIN;
    let mut out = Vec::new();
    let mut put_in = |text: String, at: (i32, i32), size: u32, vertical: bool, bold: bool, centre: bool, colour| {
        let (w, h) = measure(&text, size, bold);
        let (w, h) = if vertical { (h, w) } else { (w, h) };
        let left = if centre { at.0 - w / 2 } else { at.0 };
        let top = if vertical { at.1 - h } else { at.1 - h / 2 };
        let rect = Rect { x0: left as f64, y0: top as f64, x1: (left + w) as f64, y1: (top + h) as f64 };
        out.push(Placed { text, at, size, vertical, bold, rect, colour });
    };
    put_in(table.title.clone(), (MARGIN, TITLE_H / 2), 26, false, true, false, BLACK);
    for (g, ((_, cols), lines)) in table.groups.iter().zip(&headers).enumerate() {
        let centre = (col_x(g, 0) + col_x(g, cols.len())) / 2;
        // The header's last line sits on the group's rule.
        let first = TITLE_H + group_h - GROUP_H / 2 - (lines.len() as i32 - 1) * line_h;
        for (l, line) in lines.iter().enumerate() {
            put_in(line.clone(), (centre, first + l as i32 * line_h), HEAD_FONT, false, true, true, BLACK);
        }
        for (k, c) in cols.iter().enumerate() {
            put_in(c.clone(), (col_x(g, k) + cell_w[g] / 2, grid_top - 8), HEAD_FONT, true, false, true, BLACK);
        }
    }
    for (i, row) in table.rows.iter().enumerate() {
        let y = grid_top + i as i32 * CELL_H + CELL_H / 2;
        put_in(row.clone(), (MARGIN, y), CELL_FONT, false, false, false, BLACK);
        let mut j = 0;
        for (g, (_, n)) in group_of(table).iter().enumerate() {
            for k in 0..*n {
                let ratio = table.cells[i].get(j + k).copied().flatten();
                let text = ratio.map_or("-".into(), |r| format!("{r:.2}"));
                let ink = ratio.map_or(BLACK, |r| text_colour(colour(r)));
                put_in(text, (col_x(g, k) + cell_w[g] / 2, y), CELL_FONT, false, false, true, ink);
            }
            j += n;
        }
    }
    let bar_x = width - BAR_W - MARGIN + 40;
    // The bar runs from 2x at its top to 0.5x at its bottom, log2-even: a label every quarter. Its ends are the
    // clamp (a triangle beyond each end, as a colour bar extended past its range draws it): 3.8x reads as 2x.
    for (k, v) in [">= 2", "1.41", "1", "0.71", "<= 0.5"].iter().enumerate() {
        put_in(v.to_string(), (bar_x + 34, grid_top + k as i32 * BAR_H / 4), HEAD_FONT, false, false, false, BLACK);
    }
    put_in(table.scale_name.clone(), (bar_x + 130, grid_top + BAR_H), HEAD_FONT, true, false, true, BLACK);
    let rule_y = TITLE_H + group_h - 4;
    Layout { size: (width as u32, height as u32), grid_top, group_left, cell_w, rule_y, bar_x, texts: out }
}

/// Draws the table to `path` as PNG.
pub fn draw(path: &Path, table: &HeatTable) -> Result<()> {
    let Layout { size, grid_top, group_left, cell_w, rule_y, bar_x, texts } =
        layout(table, &crate::export::text::measure);
    let e = |e: DrawingAreaErrorKind<_>| anyhow!("{}: {e}", path.display());
    render(path, size.0, size.1, |root| {
        for (((start, n), left), cell_w) in group_of(table).into_iter().zip(group_left).zip(cell_w) {
            root.draw(&PathElement::new(
                vec![(left, rule_y), (left + n as i32 * cell_w, rule_y)],
                BLACK.stroke_width(2),
            ))
            .map_err(e)?;
            // A light grey behind the cells draws the grid lines between them (a ratio of 1 is white).
            let bottom = grid_top + table.rows.len() as i32 * CELL_H;
            root.draw(&Rectangle::new(
                [(left - 2, grid_top - 2), (left + n as i32 * cell_w, bottom)],
                RGBColor(214, 214, 214).filled(),
            ))
            .map_err(e)?;
            for i in 0..table.rows.len() {
                for k in 0..n {
                    let x = left + k as i32 * cell_w;
                    let y = grid_top + i as i32 * CELL_H;
                    let fill = table.cells[i].get(start + k).copied().flatten().map_or(RGBColor(238, 238, 238), colour);
                    root.draw(&Rectangle::new([(x, y), (x + cell_w - 2, y + CELL_H - 2)], fill.filled())).map_err(e)?;
                }
            }
        }
        for p in 0..BAR_H {
            let ratio = 2f64.powf(1.0 - 2.0 * p as f64 / BAR_H as f64);
            root.draw(&Rectangle::new([(bar_x, grid_top + p), (bar_x + 24, grid_top + p + 1)], colour(ratio).filled()))
                .map_err(e)?;
        }
        let (top, bottom) = (grid_top, grid_top + BAR_H);
        for (tip, base, ratio) in [(top - CLAMP_H, top, 2.0), (bottom + CLAMP_H, bottom, 0.5)] {
            let points = vec![(bar_x, base), (bar_x + 24, base), (bar_x + 12, tip)];
            root.draw(&Polygon::new(points, colour(ratio).filled())).map_err(e)?;
        }
        for t in &texts {
            let at = (t.rect.x0 as i32, if t.vertical { t.rect.y1 } else { t.rect.y0 } as i32);
            let style =
                crate::export::text::Style { size: t.size, bold: t.bold, colour: t.colour, vertical: t.vertical };
            crate::export::text::draw(root, &t.text, at, style)?;
        }
        Ok(())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn no_text_of_a_wide_table_overlaps_another_and_the_colours_diverge_at_one() {
        let groups: Vec<(String, Vec<String>)> = [
            ("lavapipe: measured, counted", 2),
            ("AMD (ACO): modelled", 7),
            ("NVIDIA (ptxas): modelled", 5),
            ("Intel (IGC): modelled", 5),
        ]
        .iter()
        .map(|(g, n)| (g.to_string(), (0..*n).map(|k| format!("polaris1{k} cycles/eval")).collect()))
        .collect();
        let rows: Vec<String> = ["ggx", "blinn", "cook-torrance", "burley"].iter().map(|s| s.to_string()).collect();
        let cells = rows.iter().map(|_| (0..19).map(|k| (k != 3).then_some(0.5 + k as f64 / 10.0)).collect()).collect();
        let table =
            HeatTable { title: "net cost relative to ggx".into(), groups, rows, cells, scale_name: "x ggx".into() };
        let dir = tempfile::tempdir().unwrap();
        draw(&dir.path().join("t.png"), &table).unwrap();
        let measure = |t: &str, s: u32, _: bool| ((t.chars().count() as u32 * s * 6 / 10) as i32, s as i32);
        let Layout { size: (w, h), texts, .. } = layout(&table, &measure);
        for (i, a) in texts.iter().enumerate() {
            assert!(a.rect.x0 >= 0.0 && a.rect.x1 <= w as f64 && a.rect.y0 >= 0.0 && a.rect.y1 <= h as f64, "{a:?}");
            for b in &texts[..i] {
                assert!(!a.rect.overlaps(&b.rect), "{} over {}", a.text, b.text);
            }
        }
        assert_eq!(colour(1.0), RGBColor(255, 255, 255));
        // Dark cells carry white text, light ones black; the bar's ends say they clamp.
        assert_eq!(
            (text_colour(colour(3.83)), text_colour(colour(1.1)), text_colour(colour(0.5))),
            (WHITE, BLACK, WHITE)
        );
        let cell = |t: &str| texts.iter().find(|p| p.text == t).unwrap_or_else(|| panic!("no {t}")).colour;
        assert_eq!((cell("1.90"), cell("1.00")), (WHITE, BLACK));
        assert!(texts.iter().any(|p| p.text == ">= 2") && texts.iter().any(|p| p.text == "<= 0.5"));
        let (cheap, dear) = (colour(0.5), colour(2.0));
        assert!(cheap.2 > cheap.0 && dear.0 > dear.2, "blue below 1, red above");
    }
}
