//! The shader's loops and their trip counts, where the source bounds them.

use super::*;

/// lavapipe (Mesa 22.3's llvmpipe) ends every loop after this many iterations, silently: a longer loop's
/// result is wrong there (a `while (true)` returns, a loop of 10^9 steps stops after 65535). Measured with a
/// counting loop (`tests/kernels/brdf_files.rs`).
pub const LAVAPIPE_LOOP_LIMIT: u64 = 65535;

/// The shader's `for`, `while` and `do` loops (a do-while's `while` is its own), each with its trip count
/// where `trip_count` can read it.
pub(super) fn loops(lines: &[(usize, String)], tokens: &[Token]) -> Vec<Loop> {
    let mut out = Vec::new();
    let mut do_whiles = HashSet::new();
    for (i, t) in tokens.iter().enumerate() {
        if t.kind != Kind::Ident || do_whiles.contains(&i) {
            continue;
        }
        let keyword = match t.text.as_str() {
            "for" => "for",
            "while" => "while",
            "do" => "do",
            _ => continue,
        };
        if keyword == "do" {
            // The `while` that ends it: after its braced body, or after the statement's `;`.
            let end = match tokens.get(i + 1) {
                Some(b) if b.is("{") => matching(tokens, i + 1),
                _ => (i + 1..tokens.len()).find(|&j| tokens[j].is(";")).unwrap_or(tokens.len()),
            };
            do_whiles.insert(end + 1);
        }
        let trip_count = if keyword == "for" { trip_count(&tokens[i + 1..]) } else { None };
        out.push(Loop { file: None, line: lines[t.line].0, keyword, trip_count });
    }
    out
}

/// WGSL's loops (`for`, `while`, `loop`), each with its trip count where `trip_count` can read it and the
/// function it is in (the last `fn NAME` before it at the top level).
pub(super) fn wgsl_loops(lines: &[(usize, String)], tokens: &[Token]) -> Vec<(Loop, Option<String>)> {
    let mut out = Vec::new();
    let (mut function, mut depth) = (None, 0usize);
    for (i, t) in tokens.iter().enumerate() {
        match t.text.as_str() {
            "{" if t.kind == Kind::Punct => depth += 1,
            "}" if t.kind == Kind::Punct => depth = depth.saturating_sub(1),
            "fn" if depth == 0 && t.kind == Kind::Ident => {
                function = tokens.get(i + 1).filter(|n| n.kind == Kind::Ident).map(|n| n.text.clone())
            }
            "for" | "while" | "loop" if t.kind == Kind::Ident => {
                let keyword = match t.text.as_str() {
                    "for" => "for",
                    "while" => "while",
                    _ => "loop",
                };
                let trip_count = if keyword == "for" { trip_count(&tokens[i + 1..]) } else { None };
                out.push((Loop { file: None, line: lines[t.line].0, keyword, trip_count }, function.clone()));
            }
            _ => {}
        }
    }
    out
}

/// A literal of the loop header (an optional `-`, then a number: `10`, `0x10`, `5u`, `0.5f`, `1e5`, WGSL's
/// `7i`) at `tokens[*at]`, advancing past it.
pub(super) fn literal(tokens: &[Token], at: &mut usize) -> Option<f64> {
    let negative = tokens.get(*at).is_some_and(|t| t.is("-"));
    if negative {
        *at += 1;
    }
    let t = tokens.get(*at).filter(|t| t.kind == Kind::Number)?;
    *at += 1;
    let x = match t.text.strip_prefix("0x").or_else(|| t.text.strip_prefix("0X")) {
        // A hex digit `f` is no suffix.
        Some(h) => u64::from_str_radix(h.trim_end_matches(['u', 'U', 'i']), 16).ok()? as f64,
        None => t
            .text
            .trim_end_matches("lf")
            .trim_end_matches("LF")
            .trim_end_matches(['u', 'U', 'f', 'F', 'h', 'i'])
            .parse::<f64>()
            .ok()?,
    };
    Some(if negative { -x } else { x })
}

/// The iterations of `( [const] [TYPE] I = A ; I OP B ; STEP )` (WGSL's `(var I[: TYPE] = A; ...)` too;
/// `tokens` start at the `(`), OP one of
/// `<`, `<=`, `>`, `>=`, `!=`, STEP `I++`, `++I`, `I--`, `--I`, `I += D`, `I -= D`, with A, B, D literals;
/// None for any other header, or a loop that never ends.
pub(super) fn trip_count(tokens: &[Token]) -> Option<u64> {
    let is = |j: usize, text: &str| tokens.get(j).is_some_and(|t| t.text == text);
    if !is(0, "(") {
        return None;
    }
    // Init: the variable is the identifier before `=`, or before WGSL's `: TYPE` (`var i: i32 = 0`).
    let eq = (1..tokens.len().min(7)).find(|&j| is(j, "="))?;
    let typed = eq >= 3 && is(eq - 2, ":");
    let var = tokens.get(if typed { eq - 3 } else { eq - 1 }).filter(|t| t.kind == Kind::Ident)?.text.clone();
    let mut at = eq + 1;
    let start = literal(tokens, &mut at)?;
    if !is(at, ";") || !is(at + 1, &var) {
        return None;
    }
    at += 2;
    let mut op = tokens.get(at)?.text.clone();
    at += 1;
    if is(at, "=") {
        op.push('=');
        at += 1;
    }
    let end = literal(tokens, &mut at)?;
    if !is(at, ";") {
        return None;
    }
    at += 1;
    let step = match (
        tokens.get(at).map(|t| t.text.as_str()),
        tokens.get(at + 1).map(|t| t.text.as_str()),
        tokens.get(at + 2).map(|t| t.text.as_str()),
    ) {
        (Some(v), Some("+"), Some("+")) | (Some("+"), Some("+"), Some(v)) if v == var => 1.0,
        (Some(v), Some("-"), Some("-")) | (Some("-"), Some("-"), Some(v)) if v == var => -1.0,
        (Some(v), Some(sign @ ("+" | "-")), Some("=")) if v == var => {
            let mut j = at + 3;
            let d = literal(tokens, &mut j)?;
            if sign == "+" { d } else { -d }
        }
        _ => return None,
    };
    iterations(start, &op, end, step)
}

/// How many times `i = start; i OP end; i += step` runs; None when it never ends.
pub(super) fn iterations(start: f64, op: &str, end: f64, step: f64) -> Option<u64> {
    let holds = |i: f64| match op {
        "<" => i < end,
        "<=" => i <= end,
        ">" => i > end,
        ">=" => i >= end,
        _ => i != end,
    };
    let span = (end - start) / step;
    let n = if !holds(start) {
        0.0
    } else if op == "!=" {
        // Runs until it lands on the end exactly, or forever.
        if span > 0.0 && span.fract() == 0.0 { span } else { return None }
    } else if (op.starts_with('<')) != (step > 0.0) {
        return None; // the step moves away from the end
    } else if op.ends_with('=') {
        span.floor() + 1.0
    } else {
        span.ceil()
    };
    (n.is_finite() && n >= 0.0 && n <= u64::MAX as f64).then_some(n as u64)
}
