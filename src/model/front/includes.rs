//! C preprocessor `#include` for HLSL, resolved by brdfprof before glslang reads the shader: glslang's HLSL
//! front end ignores `#pragma once` (a header included twice is then a redefinition) and knows no virtual paths
//! (UE's `/Engine/Private/...`). The result is one text, line for line with the files it came from
//! (`Expanded::origin`), which glslang then preprocesses as it would the files themselves:
//! - `#include "NAME"` is looked for beside the including file, then in each `--include-dir` in order;
//!   `#include <NAME>` in the include directories alone; a NAME under a mapped virtual prefix (`--include-map
//!   /Engine=DIR`) under DIR alone.
//! - The `#include` line becomes an empty line and the file's lines follow. A file with `#pragma once` is wrapped
//!   in a guard of its own (`#ifndef BRDFPROF_ONCE_k` ... `#endif`), so that whichever of its inclusions the
//!   preprocessor reaches first is the one that counts, whatever `#if`s surround them.
//! - An inclusion known to be empty is left out: a `#pragma once` or include-guarded file included again after
//!   an inclusion outside every `#if`, or from inside itself.
//! - A name found nowhere, or a file that includes itself again without `#pragma once` or a guard, becomes an
//!   `#error` line at the `#include` (`Expanded::notes` holds the message): glslang's preprocessor reports it
//!   only where the line is live, as a C preprocessor does (an `#include` in an `#if 0` branch may name a file
//!   that does not exist).

use super::Includes;
use anyhow::{anyhow, bail, Result};
use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};

/// Files may nest this deep (gcc's limit), and the expanded text may be this long.
const MAX_DEPTH: usize = 200;
const MAX_LINES: usize = 4_000_000;

/// The text glslang reads, each line with its origin.
#[derive(Clone, Debug, Default)]
pub struct Expanded {
    /// Files as messages name them; [0] is the model's own file.
    pub files: Vec<String>,
    pub lines: Vec<String>,
    /// (file index, 1-based line) of each line.
    pub origins: Vec<(usize, usize)>,
    /// The `#error` lines brdfprof wrote (a missing include, a cycle): line index -> (1-based column, message).
    pub notes: HashMap<usize, (usize, String)>,
}

impl Expanded {
    /// An empty text whose file 0 is the model's.
    pub fn new(model: &Path) -> Self {
        Expanded { files: vec![model.display().to_string()], ..Default::default() }
    }

    pub fn push(&mut self, text: impl Into<String>, file: usize, line: usize) {
        self.lines.push(text.into());
        self.origins.push((file, line));
    }

    /// The whole text, one line per line.
    pub fn text(&self) -> String {
        self.lines.iter().map(|l| format!("{l}\n")).collect()
    }

    /// The file and 1-based line of the text's 0-based line `index`.
    pub fn origin(&self, index: usize) -> Option<(&str, usize)> {
        self.origins.get(index).map(|&(f, l)| (self.files[f].as_str(), l))
    }

    /// Appends the model's section `lines` (numbered as in its file), each `#include` resolved from `dir` (the
    /// model file's directory) and `includes`.
    pub fn include_section(&mut self, dir: &Path, lines: &[(usize, String)], includes: &Includes) -> Result<()> {
        let model = Source { dir: dir.to_path_buf(), lines: lines.to_vec(), once: false, guard: None };
        let mut x = Expander { includes, sources: vec![model], by_path: HashMap::new(), stack: vec![0], done: HashSet::new(), undefined: HashSet::new(), out: std::mem::take(self) };
        let result = x.expand(0, 0);
        *self = x.out;
        result
    }
}

/// A file read for inclusion.
struct Source {
    dir: PathBuf,
    lines: Vec<(usize, String)>,
    once: bool,
    /// The macro of a classic include guard around the whole file (`#ifndef X` / `#define X` ... `#endif`).
    guard: Option<String>,
}

struct Expander<'a> {
    includes: &'a Includes,
    sources: Vec<Source>,
    by_path: HashMap<PathBuf, usize>,
    /// The files being expanded, outermost first.
    stack: Vec<usize>,
    /// Files expanded outside every `#if`: a guarded one included again is empty.
    done: HashSet<usize>,
    /// Macros some `#undef` names (a guard among them no longer proves a file empty).
    undefined: HashSet<String>,
    out: Expanded,
}

/// The directive of a `#` line and the text after it (`#  include "a"` -> (`include`, ` "a"`)).
pub fn directive(line: &str) -> Option<(&str, &str)> {
    let rest = line.trim_start().strip_prefix('#')?.trim_start();
    let end = rest.find(|c: char| !(c.is_ascii_alphanumeric() || c == '_')).unwrap_or(rest.len());
    Some((&rest[..end], &rest[end..]))
}

impl Expander<'_> {
    /// Appends source `idx`'s lines; `outer` is the `#if` depth around its inclusion.
    fn expand(&mut self, idx: usize, outer: usize) -> Result<()> {
        let lines = self.sources[idx].lines.clone();
        let mut depth = 0usize;
        for (n, text) in &lines {
            match directive(text) {
                Some(("include", rest)) => self.include(idx, *n, text, rest, outer + depth)?,
                Some(("pragma", rest)) if rest.trim() == "once" => self.out.push("", idx, *n),
                Some((d, rest)) => {
                    match d {
                        "if" | "ifdef" | "ifndef" => depth += 1,
                        "endif" => depth = depth.saturating_sub(1),
                        "undef" => drop(self.undefined.insert(rest.trim().to_string())),
                        _ => {}
                    }
                    self.out.push(text.as_str(), idx, *n);
                }
                None => self.out.push(text.as_str(), idx, *n),
            }
            if self.out.lines.len() > MAX_LINES {
                bail!("{}:{n}: the shader's includes expand to more than {MAX_LINES} lines", self.out.files[idx]);
            }
        }
        Ok(())
    }

    /// One `#include` line of source `from`, at the `#if` depth `depth`.
    fn include(&mut self, from: usize, n: usize, text: &str, rest: &str, depth: usize) -> Result<()> {
        let column = text.find(['"', '<']).map_or(1, |c| c + 1);
        let Some((name, quoted)) = include_name(rest) else {
            return Ok(self.error_line(from, n, column, format!("`{}`: brdfprof resolves #include itself and reads only \"NAME\" or <NAME>, not a macro", text.trim())));
        };
        let Some((path, shown)) = self.resolve(from, name, quoted) else {
            let message = self.not_found(from, name, quoted);
            return Ok(self.error_line(from, n, column, message));
        };
        let idx = self.load(&path, shown, (from, n, column))?;
        let source = &self.sources[idx];
        let empty_again = source.once || source.guard.as_ref().is_some_and(|g| !self.undefined.contains(g));
        if self.stack.contains(&idx) && !empty_again {
            let message = self.cycle(idx, name);
            return Ok(self.error_line(from, n, column, message));
        }
        if empty_again && (self.stack.contains(&idx) || self.done.contains(&idx)) {
            self.out.push("", from, n);
            return Ok(());
        }
        if self.stack.len() >= MAX_DEPTH {
            return Ok(self.error_line(from, n, column, format!("#include nested deeper than {MAX_DEPTH} files")));
        }
        self.out.push("", from, n);
        let once = self.sources[idx].once;
        if once {
            self.out.push(format!("#ifndef BRDFPROF_ONCE_{idx}"), from, n);
            self.out.push(format!("#define BRDFPROF_ONCE_{idx}"), from, n);
        }
        self.stack.push(idx);
        self.expand(idx, depth)?;
        self.stack.pop();
        if once {
            self.out.push("#endif", from, n);
        }
        if depth == 0 {
            self.done.insert(idx);
        }
        Ok(())
    }

    /// An `#error` line at source `from`'s line `n` that glslang reports (where live) as `message`.
    fn error_line(&mut self, from: usize, n: usize, column: usize, message: String) {
        self.out.notes.insert(self.out.lines.len(), (column, message));
        self.out.push("#error brdfprof_include", from, n);
    }

    /// Where `name` is found: under its mapped virtual prefix alone; else beside source `from` (a quoted name),
    /// then in each include directory.
    fn resolve(&self, from: usize, name: &str, quoted: bool) -> Option<(PathBuf, String)> {
        if let Some(((_, dir), rest)) = self.includes.mapped(name) {
            let p = dir.join(rest);
            return p.is_file().then(|| (p.clone(), p.display().to_string()));
        }
        let beside = quoted.then(|| self.sources[from].dir.join(name));
        beside.into_iter().chain(self.includes.dirs.iter().map(|d| d.join(name))).find(|p| p.is_file()).map(|p| (p.clone(), p.display().to_string()))
    }

    fn not_found(&self, from: usize, name: &str, quoted: bool) -> String {
        if let Some(((v, dir), rest)) = self.includes.mapped(name) {
            return format!("cannot find include `{name}`: --include-map {v}={} maps it to {}, which does not exist", dir.display(), dir.join(rest).display());
        }
        let shown = |d: &Path| if d.as_os_str().is_empty() { ".".to_string() } else { d.display().to_string() };
        let mut searched: Vec<String> = quoted.then(|| shown(&self.sources[from].dir)).into_iter().collect();
        searched.extend(self.includes.dirs.iter().map(|d| d.display().to_string()));
        let hint = if name.starts_with('/') { format!("; a virtual path needs --include-map {}=DIR", name.split('/').take(2).collect::<Vec<_>>().join("/")) } else { "; add the directory with --include-dir DIR".to_string() };
        format!("cannot find include `{name}` (searched: {}){hint}", if searched.is_empty() { "no directory".to_string() } else { searched.join(", ") })
    }

    /// The message of a cycle that reaches source `idx` again through `#include "name"`.
    fn cycle(&self, idx: usize, name: &str) -> String {
        let from = self.stack.iter().position(|&s| s == idx).unwrap_or(0);
        let chain: Vec<&str> = self.stack[from..].iter().map(|&s| self.shown(s)).collect();
        format!("include cycle: {} includes `{name}` again ({}), which has neither `#pragma once` nor an include guard", chain.last().copied().unwrap_or("?"), chain.iter().chain([&self.shown(idx)]).copied().collect::<Vec<_>>().join(" -> "))
    }

    fn shown(&self, idx: usize) -> &str {
        // Source k was the (k)th file named in `out.files` (the model's is 0).
        &self.out.files[idx]
    }

    /// Source index of the file at `path`, read once (by its canonical path: two names of one file are one
    /// file, as `#pragma once` means it). `at`: the including line, for a read error.
    fn load(&mut self, path: &Path, shown: String, at: (usize, usize, usize)) -> Result<usize> {
        let key = std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf());
        if let Some(&idx) = self.by_path.get(&key) {
            return Ok(idx);
        }
        let fail = |e: anyhow::Error| anyhow!("{}:{}:{}: {e:#}", self.out.files[at.0], at.1, at.2);
        let bytes = crate::io::read_input(path).map_err(fail)?;
        let text = String::from_utf8(bytes).map_err(|e| fail(anyhow!("{} is not UTF-8 text (byte {})", path.display(), e.utf8_error().valid_up_to())))?;
        let lines: Vec<(usize, String)> = text.strip_prefix('\u{feff}').unwrap_or(&text).split('\n').map(|l| l.strip_suffix('\r').unwrap_or(l).to_string()).enumerate().map(|(i, l)| (i + 1, l)).collect();
        let once = lines.iter().any(|(_, l)| directive(l).is_some_and(|(d, r)| d == "pragma" && r.trim() == "once"));
        let guard = guard_macro(&lines);
        let dir = path.parent().map_or_else(PathBuf::new, Path::to_path_buf);
        self.sources.push(Source { dir, lines, once, guard });
        self.out.files.push(shown);
        self.by_path.insert(key, self.sources.len() - 1);
        Ok(self.sources.len() - 1)
    }
}

/// `"NAME"` (quoted: true) or `<NAME>` after `#include`.
fn include_name(rest: &str) -> Option<(&str, bool)> {
    let rest = rest.trim();
    let (close, quoted) = match rest.chars().next()? {
        '"' => ('"', true),
        '<' => ('>', false),
        _ => return None,
    };
    let name = rest[1..].split(close).next()?;
    (rest[1..].len() > name.len() && !name.is_empty()).then_some((name, quoted))
}

/// The lines without comments (`//` and `/* */`, which may span lines).
fn code_lines(lines: &[(usize, String)]) -> Vec<String> {
    let mut out = Vec::with_capacity(lines.len());
    let mut in_block = false;
    for (_, l) in lines {
        let mut code = String::new();
        let mut rest = l.as_str();
        loop {
            if in_block {
                match rest.find("*/") {
                    Some(e) => {
                        rest = &rest[e + 2..];
                        in_block = false;
                    }
                    None => break,
                }
            }
            let (line_c, block_c) = (rest.find("//"), rest.find("/*"));
            match (line_c, block_c) {
                (Some(a), b) if b.is_none_or(|b| a < b) => {
                    code += &rest[..a];
                    break;
                }
                (_, Some(b)) => {
                    code += &rest[..b];
                    rest = &rest[b + 2..];
                    in_block = true;
                }
                _ => {
                    code += rest;
                    break;
                }
            }
        }
        out.push(code);
    }
    out
}

/// The macro of a classic include guard around the whole file: its first code is `#ifndef X` (or
/// `#if !defined(X)`), then `#define X`, and the `#endif` that closes it is its last code.
pub fn guard_macro(lines: &[(usize, String)]) -> Option<String> {
    let code: Vec<String> = code_lines(lines).into_iter().map(|l| l.trim().to_string()).filter(|l| !l.is_empty()).collect();
    let (first, second, last) = (code.first()?, code.get(1)?, code.last()?);
    let name = match directive(first)? {
        ("ifndef", r) => r.trim().to_string(),
        ("if", r) => r.trim().strip_prefix("!defined")?.trim().trim_start_matches('(').trim_end_matches(')').trim().to_string(),
        _ => return None,
    };
    let defines = directive(second).is_some_and(|(d, r)| d == "define" && r.split_whitespace().next() == Some(name.as_str()));
    if !defines || directive(last).map(|(d, _)| d) != Some("endif") {
        return None;
    }
    let mut depth = 0i32;
    for (k, l) in code.iter().enumerate() {
        match directive(l).map(|(d, _)| d) {
            Some("if" | "ifdef" | "ifndef") => depth += 1,
            Some("endif") => depth -= 1,
            _ => {}
        }
        if depth == 0 && k + 1 < code.len() {
            return None;
        }
    }
    Some(name)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lines(text: &str) -> Vec<(usize, String)> {
        text.lines().enumerate().map(|(i, l)| (i + 1, l.to_string())).collect()
    }

    fn expand(dir: &Path, text: &str, includes: &Includes) -> Expanded {
        let mut x = Expanded::new(&dir.join("m.hlsl"));
        x.include_section(dir, &lines(text), includes).unwrap();
        x
    }

    #[test]
    fn include_guards_are_recognised_only_around_the_whole_file() {
        assert_eq!(guard_macro(&lines("// licence\n/* more\n */\n#ifndef A_H\n#define A_H\nfloat a;\n#endif // A_H\n")), Some("A_H".into()));
        assert_eq!(guard_macro(&lines("#if !defined(B)\n#define B 1\n#endif\n")), Some("B".into()));
        assert_eq!(guard_macro(&lines("#ifndef A\n#define A\n#endif\nfloat b;\n")), None, "code after the guard");
        assert_eq!(guard_macro(&lines("#ifndef A\n#define A\n#endif\n#ifndef C\n#endif\n")), None, "two blocks");
        assert_eq!(guard_macro(&lines("#ifndef A\n#define B\n#endif\n")), None);
    }

    #[test]
    fn pragma_once_guards_and_virtual_paths() {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        std::fs::create_dir_all(d.join("engine/Private")).unwrap();
        std::fs::write(d.join("engine/Private/Common.ush"), "#pragma once\nstatic const float PI = 3.14;\n").unwrap();
        std::fs::write(d.join("brdf.ush"), "#pragma once\n#include \"/Engine/Private/Common.ush\"\nfloat D() { return PI; }\n").unwrap();
        let inc = Includes { dirs: vec![], maps: vec![("/Engine".into(), d.join("engine"))] };
        let x = expand(d, "#include \"brdf.ush\"\n#include \"brdf.ush\"\nfloat3 BRDF();\n", &inc);
        let text = x.text();
        assert_eq!(text.matches("float D()").count(), 1, "{text}");
        assert_eq!(text.matches("PI = 3.14").count(), 1, "{text}");
        assert!(text.contains("#ifndef BRDFPROF_ONCE_1") && x.notes.is_empty(), "{text}");
        let at = x.lines.iter().position(|l| l.contains("PI = 3.14")).unwrap();
        assert_eq!(x.origin(at), Some((d.join("engine/Private/Common.ush").display().to_string().as_str(), 2)));
        assert_eq!(x.origin(x.lines.len() - 1), Some((d.join("m.hlsl").display().to_string().as_str(), 3)));
    }

    #[test]
    fn conditional_inclusions_stay_for_the_preprocessor_and_cycles_and_missing_files_are_error_lines() {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        std::fs::write(d.join("a.ush"), "#pragma once\nfloat a;\n").unwrap();
        std::fs::write(d.join("loop1.ush"), "float l1;\n#include \"loop2.ush\"\n").unwrap();
        std::fs::write(d.join("loop2.ush"), "float l2;\n  #include \"loop1.ush\"\n").unwrap();
        let x = expand(d, "#if Q\n#include \"a.ush\"\n#endif\n#include \"a.ush\"\n#if 0\n#include \"gone.ush\"\n#endif\n#include \"loop1.ush\"\n", &Includes::default());
        assert_eq!(x.lines.iter().filter(|l| l.as_str() == "float a;").count(), 2, "inside an #if it is expanded again, guarded");
        let notes: Vec<&(usize, String)> = { let mut k: Vec<_> = x.notes.iter().collect(); k.sort(); k.into_iter().map(|(_, n)| n).collect() };
        assert!(notes[0].1.starts_with("cannot find include `gone.ush` (searched: "), "{notes:?}");
        assert_eq!(notes[0].0, 10);
        assert!(notes[1].1.starts_with("include cycle: ") && notes[1].1.contains("loop1.ush -> ") && notes[1].0 == 12, "{notes:?}");
        let at = *x.notes.keys().max().unwrap();
        assert_eq!(x.origin(at).map(|(f, l)| (f.ends_with("loop2.ush"), l)), Some((true, 2)));
    }
}
