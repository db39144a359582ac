//! glslang's preprocessor on the shader section, line for line with the file.

use super::*;
use anyhow::{Result, anyhow, bail};
use std::path::Path;

/// glslang's preprocessor on the shader's lines under `defines`, numbered as in the file: the result is line
/// for line with `source` (glslang keeps a blank line for each directive and a macro's continuation lines).
/// Without directives and defines the source is returned as it is (no glslang run, and the text keeps its
/// spacing). A preprocessor error (`#error`, an unterminated `#if`) names the file's line.
pub(super) fn preprocess(
    path: &Path,
    source: &[(usize, String)],
    defines: &[(String, String)],
) -> Result<Vec<(usize, String)>> {
    let directive = |l: &str| l.trim_start().starts_with('#');
    if defines.is_empty() && !source.iter().any(|(_, l)| directive(l)) {
        return Ok(source.to_vec());
    }
    let first = source.first().map_or(1, |l| l.0);
    let mut text = format!("#version 450\n#line {first}\n");
    for (_, l) in source {
        text += l;
        text.push('\n');
    }
    let flags: Vec<String> =
        defines.iter().map(|(n, v)| if v.is_empty() { n.clone() } else { format!("{n}={v}") }).collect();
    let out = match crate::shaders::glslang_preprocess(
        &text,
        &flags,
        &format!("{} (glslang's preprocessor)", path.display()),
    )? {
        Ok(out) => out,
        Err(log) => bail!("{}", preprocessor_errors(path, source, &log)),
    };
    number_preprocessed(path, source, &out)
}

/// glslang's preprocessor log as `FILE:LINE: message` lines. glslang says "missing #endif" at the end of the
/// source, and also after an `#error` stopped it: the message goes to the `#if` left open
/// (`unterminated_if`), or away when every `#if` is closed.
pub(super) fn preprocessor_errors(path: &Path, source: &[(usize, String)], log: &str) -> String {
    let open_if = unterminated_if(source);
    let mut located: Vec<String> = Vec::new();
    for (_, n, message) in log.lines().filter_map(|l| l.trim().strip_prefix("ERROR: ")).filter_map(split_location) {
        let message = message.trim_end();
        let message = message.strip_prefix("'' : ").unwrap_or(message);
        if message.contains("missing #endif") {
            if let Some((line, text)) = &open_if {
                located.push(at(path, *line, format!("preprocessor: `{}` has no #endif", text.trim())));
            }
            continue;
        }
        located.push(at(path, n, format!("preprocessor: {message}")));
    }
    located.dedup();
    if located.is_empty() {
        format!("{}: glslang's preprocessor failed:\n{}", path.display(), log.trim_end())
    } else {
        located.join("\n")
    }
}

/// The outermost `#if`/`#ifdef`/`#ifndef` of `source` that no `#endif` closes, with its line.
fn unterminated_if(source: &[(usize, String)]) -> Option<(usize, String)> {
    let mut open: Vec<&(usize, String)> = Vec::new();
    for line in source.iter().filter(|(_, l)| l.trim_start().starts_with('#')) {
        match directive_of(line.1.trim_start()) {
            "if" | "ifdef" | "ifndef" => open.push(line),
            "endif" => {
                open.pop();
            }
            _ => {}
        }
    }
    open.first().map(|l| (l.0, l.1.clone()))
}

/// The preprocessed text's lines given the file lines glslang's `#line` directives number them with.
pub(super) fn number_preprocessed(path: &Path, source: &[(usize, String)], out: &str) -> Result<Vec<(usize, String)>> {
    number_lines(path, source, out.lines().skip_while(|l| l.trim().is_empty()).skip(1), 0)
}

/// Preprocessed `out` lines (after any header), one per line of `source` from line `next` on, renumbered
/// where a `#line` directive says: `source`'s lines with their preprocessed text.
pub(super) fn number_lines<'a>(
    path: &Path,
    source: &[(usize, String)],
    out: impl Iterator<Item = &'a str>,
    mut next: usize,
) -> Result<Vec<(usize, String)>> {
    let mut shader: Vec<(usize, String)> = source.iter().map(|(n, _)| (*n, String::new())).collect();
    let first = source.first().map_or(1, |l| l.0);
    for line in out {
        if let Some(n) = line.trim().strip_prefix("#line ") {
            next = n
                .split_whitespace()
                .next()
                .and_then(|d| d.parse().ok())
                .ok_or_else(|| anyhow!("{}: glslang's preprocessor wrote `{line}`", path.display()))?;
            continue;
        }
        let slot = next.checked_sub(first).and_then(|k| shader.get_mut(k));
        match slot {
            Some(slot) => slot.1 = line.to_string(),
            None if line.trim().is_empty() => {}
            None => bail!(
                "{}: glslang's preprocessor wrote line {next} beyond the shader section: `{line}`",
                path.display()
            ),
        }
        next += 1;
    }
    Ok(shader)
}
