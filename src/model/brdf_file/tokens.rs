//! GLSL tokens of the shader, each with its line and columns.

use super::*;
use anyhow::{Result, bail};
use std::path::Path;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Kind {
    Ident,
    Number,
    Punct,
}

/// A token of the shader: its text and where it lies (index into the shader's lines, byte range in the line).
#[derive(Clone, Debug)]
pub(super) struct Token {
    pub(super) kind: Kind,
    pub(super) text: String,
    pub(super) line: usize,
    pub(super) start: usize,
    pub(super) end: usize,
}

impl Token {
    pub(super) fn is(&self, punct: &str) -> bool {
        self.kind == Kind::Punct && self.text == punct
    }
}

/// Tokens of `lines` without comments. GLSL has no strings; anything not an identifier or a number is a
/// one-character punctuation token (multi-character operators do not matter to what reads the tokens).
pub(super) fn tokenize(path: &Path, lines: &[(usize, String)]) -> Result<Vec<Token>> {
    tokenize_as(path, lines, false)
}

/// WGSL's tokens (`tokenize`), whose block comments nest (`/* a /* b */ c */` is one comment).
pub(super) fn tokenize_wgsl(path: &Path, lines: &[(usize, String)]) -> Result<Vec<Token>> {
    tokenize_as(path, lines, true)
}

fn tokenize_as(path: &Path, lines: &[(usize, String)], nested: bool) -> Result<Vec<Token>> {
    let mut tokens = Vec::new();
    let mut comment_from: Option<usize> = None;
    let mut depth = 0usize;
    for (li, (n, text)) in lines.iter().enumerate() {
        let b = text.as_bytes();
        let mut i = 0;
        while i < b.len() {
            if comment_from.is_some() {
                if b[i..].starts_with(b"*/") {
                    depth -= 1;
                    if depth == 0 {
                        comment_from = None;
                    }
                    i += 2;
                } else if nested && b[i..].starts_with(b"/*") {
                    depth += 1;
                    i += 2;
                } else {
                    i += 1;
                }
                continue;
            }
            let c = b[i];
            if c.is_ascii_whitespace() {
                i += 1;
                continue;
            }
            if b[i..].starts_with(b"//") {
                break;
            }
            if b[i..].starts_with(b"/*") {
                comment_from = Some(*n);
                depth = 1;
                i += 2;
                continue;
            }
            let start = i;
            let kind = if c == b'_' || c.is_ascii_alphabetic() {
                while i < b.len() && (b[i] == b'_' || b[i].is_ascii_alphanumeric()) {
                    i += 1;
                }
                Kind::Ident
            } else if c.is_ascii_digit() || (c == b'.' && b.get(i + 1).is_some_and(u8::is_ascii_digit)) {
                i = number_end(b, i);
                Kind::Number
            } else {
                i += text[i..].chars().next().map_or(1, char::len_utf8);
                Kind::Punct
            };
            tokens.push(Token { kind, text: text[start..i].to_string(), line: li, start, end: i });
        }
    }
    if let Some(n) = comment_from {
        bail!(at(path, n, "`/*` comment is never closed"));
    }
    Ok(tokens)
}

/// The end of the number starting at `i`: digits, letters (exponents, hex digits, suffixes), `.`, and a sign
/// right after a decimal exponent (or a hex float's binary one, WGSL's `0x1.8p-1`).
pub(super) fn number_end(b: &[u8], mut i: usize) -> usize {
    let hex = b[i..].starts_with(b"0x") || b[i..].starts_with(b"0X");
    i += 1;
    while i < b.len() {
        let exponent = if hex { matches!(b[i - 1], b'p' | b'P') } else { matches!(b[i - 1], b'e' | b'E') };
        let sign_of_exponent = (b[i] == b'+' || b[i] == b'-') && exponent;
        if b[i].is_ascii_alphanumeric() || b[i] == b'.' || b[i] == b'_' || sign_of_exponent {
            i += 1;
        } else {
            break;
        }
    }
    i
}

/// Identifier-like runs of `text` (comments included): what the prefix must not start.
pub(super) fn identifier_runs(text: &str) -> impl Iterator<Item = &str> {
    text.split(|c: char| !(c == '_' || c.is_ascii_alphanumeric()))
        .filter(|s| s.chars().next().is_some_and(|c| !c.is_ascii_digit()))
}

/// Index of the token closing the bracket opened at `open` (or the end, when it is never closed).
pub(super) fn matching(tokens: &[Token], open: usize) -> usize {
    let (o, c) = match tokens[open].text.as_str() {
        "(" => ("(", ")"),
        "[" => ("[", "]"),
        _ => ("{", "}"),
    };
    let mut depth = 0;
    for (j, t) in tokens.iter().enumerate().skip(open) {
        if t.is(o) {
            depth += 1;
        } else if t.is(c) {
            depth -= 1;
            if depth == 0 {
                return j;
            }
        }
    }
    tokens.len()
}
