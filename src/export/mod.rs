//! Every output format in one place: Markdown tables (markdown), saved JSON reports (json), self-contained
//! HTML pages (html), PNG charts (png), the label placement charts share (labels) and the pixel helpers pictures share (raster), text drawn into PNGs (text), SARIF for code scanning
//! (sarif), GitHub's workflow commands and step summary (github), benchmark-dashboard JSON (bench). What a command measured
//! stays with the command; only how it is written out lives here.

pub mod bench;
pub mod github;
pub mod heat_table;
pub mod html;
pub mod json;
pub mod labels;
pub mod markdown;
pub mod png;
pub mod raster;
pub mod sarif;
pub mod text;

/// The file-name form of a device name: its first words, lower case ("llvmpipe (LLVM 15.0.6, 256 bits)" ->
/// "llvmpipe").
pub fn name_slug(name: &str) -> String {
    let first = name.split(['(', ',']).next().unwrap_or("device").trim().to_lowercase();
    let slug: String = first.chars().map(|c| if c.is_ascii_alphanumeric() { c } else { '-' }).collect();
    let slug = slug.trim_matches('-').to_string();
    if slug.is_empty() { "device".into() } else { slug }
}

pub use crate::messages::{escape_line, safe_text};
