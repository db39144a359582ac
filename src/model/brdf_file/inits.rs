//! Global initialisers that read a parameter (`float k2 = k * k;`, or an HLSL `static float k2 = k * k;`,
//! which the translation writes so). GLSL runs a global's initialiser once, at the start of `main`, before the
//! kernel sets the parameters bound to an input (in `specular_brdf_unit`, or per CSV row): such an initialiser
//! would read them unset. The composition runs each initialiser that reads a bound parameter again after the
//! bindings (`FileModel`'s `BRDF_FILE_BIND`), in declaration order; one of constants stays as it is.

use super::*;
use std::collections::{BTreeSet, HashMap, HashSet};

/// A global variable's initialiser, as an assignment in the renamed shader's names.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Initialiser {
    /// The global, as the shader names it.
    pub name: String,
    /// The parameters it reads, directly or through other globals and functions.
    pub reads: BTreeSet<String>,
    /// `brdf_f_k2 = brdf_f_k * brdf_f_k;`
    pub assignment: String,
}

/// What a global-scope item of the shader names: a variable's initialiser or a function's body (token ranges).
enum Named {
    Initialiser(String, std::ops::Range<usize>),
    Function(String, std::ops::Range<usize>),
}

/// The non-`const` global variables' initialisers of the shader (`tokens` of `file.shader`), in declaration
/// order, with the parameters each reads.
pub(super) fn initialisers(file: &BrdfFile, tokens: &[Token]) -> Result<Vec<Initialiser>> {
    let params: HashSet<&str> = file.params.iter().map(|p| p.name.as_str()).collect();
    let members = struct_members(tokens);
    let mut items = Vec::new();
    let mut i = 0;
    while i < tokens.len() {
        let (end, body) = item_end(&file.path, &file.shader, tokens, i)?;
        named_by(tokens, i, end, body, &mut items);
        i = end;
    }
    // The renamed names (parameters and globals) a token is, where the renaming renames it.
    let renamed = |k: usize| {
        tokens[k].kind == Kind::Ident
            && file.renamed.lookup.contains(&tokens[k].text)
            && !(k > 0 && tokens[k - 1].is("."))
            && !members.contains(&k)
    };
    let mentions = |r: &std::ops::Range<usize>| -> BTreeSet<String> {
        r.clone().filter(|&k| renamed(k)).map(|k| tokens[k].text.clone()).collect()
    };
    let direct: Vec<(&str, BTreeSet<String>)> = items
        .iter()
        .map(|n| match n {
            Named::Initialiser(g, r) | Named::Function(g, r) => (g.as_str(), mentions(r)),
        })
        .collect();
    let reads = transitive_reads(&direct, &params);
    let rename = |k: usize| if renamed(k) { file.glsl_name(&tokens[k].text) } else { tokens[k].text.clone() };
    Ok(items
        .iter()
        .filter_map(|n| match n {
            Named::Initialiser(g, r) => Some(Initialiser {
                name: g.clone(),
                reads: reads.get(g.as_str()).cloned().unwrap_or_default(),
                assignment: format!("{} = {};", file.glsl_name(g), spaced(tokens, r.clone(), rename)),
            }),
            Named::Function(..) => None,
        })
        .collect())
}

/// The parameters each name reads through what it mentions (`direct`), to a fixed point.
fn transitive_reads<'a>(
    direct: &[(&'a str, BTreeSet<String>)],
    params: &HashSet<&str>,
) -> HashMap<&'a str, BTreeSet<String>> {
    let mut reads: HashMap<&str, BTreeSet<String>> =
        direct.iter().map(|(g, m)| (*g, m.iter().filter(|n| params.contains(n.as_str())).cloned().collect())).collect();
    loop {
        let mut changed = false;
        for (g, m) in direct {
            let through: BTreeSet<String> = m.iter().filter_map(|n| reads.get(n.as_str())).flatten().cloned().collect();
            let own = reads.get_mut(g).expect("every item has its entry");
            let before = own.len();
            own.extend(through);
            changed |= own.len() != before;
        }
        if !changed {
            return reads;
        }
    }
}

/// `tokens[range]` as text, a space where the source had one (or a line break, or a comment) between two.
fn spaced(tokens: &[Token], range: std::ops::Range<usize>, text: impl Fn(usize) -> String) -> String {
    let mut out = String::new();
    for k in range.clone() {
        if k > range.start && (tokens[k].line != tokens[k - 1].line || tokens[k].start > tokens[k - 1].end) {
            out.push(' ');
        }
        out += &text(k);
    }
    out
}

/// What the global-scope item `tokens[start..end]` names (`body`: its braces, as indices of `tokens`): a function definition's body,
/// or each declarator's initialiser of a variable declaration without `const` (`float a = x, b[2] = y;`).
fn named_by(tokens: &[Token], start: usize, end: usize, body: Option<(usize, usize)>, out: &mut Vec<Named>) {
    let item = &tokens[start..end];
    if item.iter().any(|t| t.text == "struct" || t.text == "precision") {
        return;
    }
    if let Some((open, close)) = body {
        if let Some(p) = item.iter().position(|t| t.is("(")).filter(|&p| p > 0 && item[p - 1].kind == Kind::Ident) {
            out.push(Named::Function(item[p - 1].text.clone(), open..close.min(tokens.len())));
        }
        return;
    }
    let mut p = 0;
    while p < item.len() && (QUALIFIERS.contains(&item[p].text.as_str()) || item[p].text == "layout") {
        if item[p].text == "const" {
            return; // a constant's initialiser is a constant expression
        }
        p = if item[p].text == "layout" && item.get(p + 1).is_some_and(|t| t.is("(")) {
            matching(item, p + 1) + 1
        } else {
            p + 1
        };
    }
    p += 1; // the type
    while p < item.len() {
        while p < item.len() && item[p].is("[") {
            p = matching(item, p) + 1;
        }
        let Some(name) = item.get(p).filter(|t| t.kind == Kind::Ident) else { return };
        p += 1;
        while p < item.len() && item[p].is("[") {
            p = matching(item, p) + 1;
        }
        let stop = top_level_end(item, p);
        if item.get(p).is_some_and(|t| t.is("=")) {
            out.push(Named::Initialiser(name.text.clone(), start + p + 1..start + stop));
        }
        p = stop + 1;
    }
}

/// The index of the top-level `,` or `;` at or after `from` (the item's end without one).
fn top_level_end(item: &[Token], from: usize) -> usize {
    let mut nest = 0i32;
    for (k, t) in item.iter().enumerate().skip(from) {
        if t.is("(") || t.is("[") || t.is("{") {
            nest += 1;
        } else if t.is(")") || t.is("]") || t.is("}") {
            nest -= 1;
        } else if nest == 0 && (t.is(",") || t.is(";")) {
            return k;
        }
    }
    item.len()
}
