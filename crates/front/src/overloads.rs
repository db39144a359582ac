//! DXC's overloads on minimum-precision types, as DXC resolves them with 16-bit types off (its default, without
//! `-enable-16bit-types`): `min16float`, `min10float` and `half` are 32-bit floats there, yet distinct types for
//! overloading, so engines define `min16float Sq(min16float x)` beside `float Sq(float x)` (O3DE's Math.azsli,
//! Unity's `TEMPLATE_*_FLT_HALF` macros). Both of brdfprof's HLSL front ends read those types as `float`, where
//! the pair is one function defined twice. On the preprocessed text (macros expanded), every definition whose
//! signature collides with another's once the types are 32-bit is found; the minimum-precision one is dropped
//! (its text blanked, line numbers kept), so every call takes the 32-bit overload, as DXC's calls with 32-bit
//! arguments do.

/// The 16-bit type names and the 32-bit ones they read as (vectors and matrices by suffix).
const NARROW: [(&str, &str); 6] = [
    ("min16float", "float"),
    ("min10float", "float"),
    ("half", "float"),
    ("min16int", "int"),
    ("min12int", "int"),
    ("min16uint", "uint"),
];

/// Parameter modifiers that are not part of a parameter's type for overloading.
const MODIFIERS: [&str; 10] =
    ["in", "out", "inout", "const", "uniform", "precise", "linear", "nointerpolation", "centroid", "sample"];

/// `ty` with a 16-bit base type read as its 32-bit one (`min16float3` -> `float3`), and whether it was one.
fn widened(ty: &str) -> (String, bool) {
    for (narrow, wide) in NARROW {
        if let Some(rest) = ty.strip_prefix(narrow) {
            if rest.is_empty() || rest.chars().next().is_some_and(|c| c.is_ascii_digit()) {
                return (format!("{wide}{rest}"), true);
            }
        }
    }
    (ty.to_string(), false)
}

/// One function definition at the top level of the text.
#[derive(Debug)]
struct Definition {
    name: String,
    /// The parameters' types, widened.
    key: Vec<String>,
    narrow: bool,
    /// Byte span in the text, from the start of its declaration to its closing brace.
    start: usize,
    end: usize,
}

/// The text with comments, strings and preprocessor lines replaced by spaces (same byte positions), so that a
/// scan for braces and names sees code only.
fn code_only(text: &str) -> Vec<u8> {
    let b = text.as_bytes();
    let mut out = b.to_vec();
    let mut i = 0;
    let mut line_start = true;
    while i < b.len() {
        let blank_to = |out: &mut Vec<u8>, from: usize, to: usize| {
            for k in from..to.min(out.len()) {
                if out[k] != b'\n' {
                    out[k] = b' ';
                }
            }
        };
        if line_start && b[i] == b'#' {
            let end = text[i..].find('\n').map_or(b.len(), |e| i + e);
            blank_to(&mut out, i, end);
            i = end;
            continue;
        }
        if b[i] == b'/' && b.get(i + 1) == Some(&b'/') {
            let end = text[i..].find('\n').map_or(b.len(), |e| i + e);
            blank_to(&mut out, i, end);
            i = end;
        } else if b[i] == b'/' && b.get(i + 1) == Some(&b'*') {
            let end = text[i + 2..].find("*/").map_or(b.len(), |e| i + 2 + e + 2);
            blank_to(&mut out, i, end);
            i = end;
        } else if b[i] == b'"' {
            let mut k = i + 1;
            while k < b.len() && b[k] != b'"' && b[k] != b'\n' {
                k += if b[k] == b'\\' { 2 } else { 1 };
            }
            blank_to(&mut out, i, k + 1);
            i = k + 1;
        } else {
            if b[i] == b'\n' {
                line_start = true;
            } else if !b[i].is_ascii_whitespace() {
                line_start = false;
            }
            i += 1;
        }
    }
    out
}

fn ident(c: u8) -> bool {
    c == b'_' || c.is_ascii_alphanumeric()
}

/// The identifiers of a parameter's text, in order.
fn words(text: &str) -> Vec<&str> {
    text.split(|c: char| !(c == '_' || c.is_ascii_alphanumeric())).filter(|w| !w.is_empty()).collect()
}

/// A parameter's type for overloading: its words without modifiers, semantic, default value or name, widened.
fn parameter_type(param: &str) -> Option<(String, bool)> {
    let param = param.split(':').next().unwrap_or(param);
    let param = param.split('=').next().unwrap_or(param);
    let param = param.split('[').next().unwrap_or(param);
    let mut w: Vec<&str> = words(param).into_iter().filter(|w| !MODIFIERS.contains(w)).collect();
    if w.len() < 2 {
        return (w.len() == 1).then(|| widened(w[0]));
    }
    w.pop();
    let parts: Vec<(String, bool)> = w.iter().map(|t| widened(t)).collect();
    Some((parts.iter().map(|p| p.0.as_str()).collect::<Vec<_>>().join(" "), parts.iter().any(|p| p.1)))
}

/// Every function definition at brace depth 0 of `code` (`code_only`'s output).
fn definitions(code: &[u8]) -> Vec<Definition> {
    let mut out = Vec::new();
    let (mut depth, mut item_start) = (0usize, 0usize);
    let mut i = 0;
    while i < code.len() {
        match code[i] {
            b'{' => depth += 1,
            b'}' => {
                depth = depth.saturating_sub(1);
                if depth == 0 {
                    item_start = i + 1;
                }
            }
            b';' if depth == 0 => item_start = i + 1,
            b'(' if depth == 0 => {
                if let Some(d) = definition_at(code, item_start, i) {
                    i = d.end;
                    item_start = d.end;
                    out.push(d);
                    continue;
                }
            }
            _ => {}
        }
        i += 1;
    }
    out
}

/// The definition whose parameter list opens at `open` (a `(` at depth 0), if a body follows it.
fn definition_at(code: &[u8], item_start: usize, open: usize) -> Option<Definition> {
    let mut n = open;
    while n > item_start && code[n - 1].is_ascii_whitespace() {
        n -= 1;
    }
    let name_end = n;
    while n > item_start && ident(code[n - 1]) {
        n -= 1;
    }
    let name = std::str::from_utf8(&code[n..name_end]).ok()?.to_string();
    if name.is_empty() || name.as_bytes()[0].is_ascii_digit() {
        return None;
    }
    // The matching `)`, then an optional `: SEMANTIC`, then the body's `{`.
    let close = closing(code, open, b'(', b')')?;
    let mut k = close + 1;
    while k < code.len() && code[k] != b'{' && code[k] != b';' && code[k] != b'(' {
        k += 1;
    }
    if code.get(k) != Some(&b'{') {
        return None;
    }
    let end = closing(code, k, b'{', b'}').map_or(code.len(), |e| e + 1);
    let (key, narrow_params) = parameter_key(std::str::from_utf8(&code[open + 1..close]).ok()?);
    let narrow = narrow_params || words(std::str::from_utf8(&code[item_start..n]).ok()?).iter().any(|w| widened(w).1);
    let start = (item_start..n).find(|&s| !code[s].is_ascii_whitespace()).unwrap_or(n);
    Some(Definition { name, key, narrow, start, end })
}

/// The index of the `close` that matches the `open` at `at`.
fn closing(code: &[u8], at: usize, open: u8, close: u8) -> Option<usize> {
    let mut depth = 0;
    for (k, &c) in code.iter().enumerate().skip(at) {
        if c == open {
            depth += 1;
        } else if c == close {
            depth -= 1;
            if depth == 0 {
                return Some(k);
            }
        }
    }
    None
}

/// A parameter list's types for overloading (`parameter_type` of each, split at top-level commas), and
/// whether any was a 16-bit type.
fn parameter_key(params: &str) -> (Vec<String>, bool) {
    let (mut key, mut narrow) = (Vec::new(), false);
    let (mut paren, mut from) = (0i32, 0);
    let bytes = params.as_bytes();
    for j in 0..=bytes.len() {
        let at_end = j == bytes.len();
        if !at_end {
            match bytes[j] {
                b'(' | b'<' => paren += 1,
                b')' | b'>' => paren -= 1,
                _ => {}
            }
        }
        if at_end || (bytes[j] == b',' && paren == 0) {
            if let Some((ty, was)) = parameter_type(&params[from..j]) {
                key.push(ty);
                narrow |= was;
            }
            from = j + 1;
        }
    }
    (key, narrow)
}

/// A definition dropped: its byte offset in the text (for its line) and what the note says of it.
pub struct Dropped {
    pub offset: usize,
    pub note: String,
}

/// `text` (preprocessed HLSL) with each minimum-precision definition that collides with another once 32-bit
/// blanked (spaces, newlines kept), and what was dropped; None where nothing collides.
pub fn drop_narrow_collisions(text: &str) -> Option<(String, Vec<Dropped>)> {
    let code = code_only(text);
    let defs = definitions(&code);
    let mut drop: Vec<&Definition> = Vec::new();
    let mut seen: Vec<(&str, &[String])> = Vec::new();
    for d in &defs {
        if seen.contains(&(d.name.as_str(), d.key.as_slice())) {
            continue;
        }
        seen.push((d.name.as_str(), d.key.as_slice()));
        let same: Vec<&Definition> = defs.iter().filter(|o| o.name == d.name && o.key == d.key).collect();
        // The 32-bit definition stays (the first where every one is narrow); the others go.
        let keep = same.iter().position(|o| !o.narrow).unwrap_or(0);
        drop.extend(same.iter().enumerate().filter(|(k, _)| *k != keep).map(|(_, o)| *o));
    }
    if drop.is_empty() {
        return None;
    }
    let mut out = text.as_bytes().to_vec();
    let mut dropped = Vec::new();
    for d in &drop {
        for b in &mut out[d.start..d.end] {
            if *b != b'\n' {
                *b = b' ';
            }
        }
        dropped.push(Dropped {
            offset: d.start,
            note: format!(
                "`{}({})` is defined again once minimum-precision types are 32-bit (DXC's default, without -enable-16bit-types, where they are distinct types only for overloading): this definition is dropped, and calls take the 32-bit one",
                d.name,
                d.key.join(", ")
            ),
        });
    }
    Some((String::from_utf8(out).ok()?, dropped))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_min16float_overload_beside_its_float_twin_is_dropped() {
        let text = "float Sq(float x) { return x * x; }\n// min16float Sq(min16float x) in a comment\nmin16float Sq(min16float x)\n{\n    return x * x;\n}\nfloat3 BRDF(float3 L, float3 V, float3 N, float3 X, float3 Y) { return Sq(dot(N, L)); }\n";
        let (out, dropped) = drop_narrow_collisions(text).expect("a collision");
        assert_eq!(dropped.len(), 1);
        assert_eq!(out.lines().count(), text.lines().count(), "line numbers kept");
        assert!(out.contains("float Sq(float x) { return x * x; }") && out.contains("BRDF"));
        assert!(!out.lines().nth(2).unwrap().contains("Sq"), "{out}");
        assert_eq!(text[..dropped[0].offset].lines().count(), 2, "named at its own line");
        // Distinct after widening: nothing dropped.
        assert!(
            drop_narrow_collisions("float f(float x) { return x; }\nfloat f(float2 x) { return x.x; }\n").is_none()
        );
        assert!(drop_narrow_collisions("half3 g(in half3 a : COLOR, uniform min16int b) { return a; }\nfloat3 g(float3 a, int b) { return a; }\n").is_some());
    }
}
