//! C preprocessor `#include` for HLSL, resolved by brdfprof before glslang reads the shader: glslang's HLSL
//! front end ignores `#pragma once` (a header included twice is then a redefinition) and knows no virtual paths
//! (UE's `/Engine/Private/...`). The result is one text, line for line with the files it came from
//! (`Expanded::origin`), which glslang then preprocesses as it would the files themselves:
//! - Directives are read outside comments only, as a C preprocessor reads them (an `#include` in a `/* */`
//!   comment is no inclusion, and an `#if` there opens nothing).
//! - `#include "NAME"` is looked for beside the including file, then in each `--include-dir` in order;
//!   `#include <NAME>` in the include directories alone; a NAME under a mapped virtual prefix (`--include-map
//!   /Engine=DIR`) under DIR alone (`Includes::find`, which WGSL's quoted imports share).
//! - `#line` is dropped, as in a GLSL shader (`Expanded::dropped`): brdfprof maps every line to its file.
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
use anyhow::{Result, anyhow, bail};
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
    /// Lines brdfprof wrote itself (parameters, an entry's glue, the stub): line index -> what each stands for
    /// (`parameter \`Roughness\``), which messages name instead of a column in text the user never wrote.
    pub generated: HashMap<usize, String>,
    /// The `#line` directives dropped: (file index, 1-based line, the directive as written).
    pub dropped: Vec<(usize, usize, String)>,
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

    /// Appends a line brdfprof wrote, standing for the model file's line `line`, saying what it is.
    pub fn push_generated(&mut self, text: impl Into<String>, line: usize, what: impl Into<String>) {
        self.generated.insert(self.lines.len(), what.into());
        self.push(text, 0, line);
    }

    /// The whole text, one line per line.
    pub fn text(&self) -> String {
        self.lines.iter().map(|l| format!("{l}\n")).collect()
    }

    /// The file and 1-based line of the text's 0-based line `index`.
    pub fn origin(&self, index: usize) -> Option<(&str, usize)> {
        self.origins.get(index).map(|&(f, l)| (self.files[f].as_str(), l))
    }

    /// Appends the model's section `lines` (numbered as in its file `path`), each `#include` resolved from the
    /// file's directory and `includes`. The file itself is one of the files (an `#include` of it after its
    /// `#pragma once` is empty, as a compiler's would be).
    pub fn include_section(&mut self, path: &Path, lines: &[(usize, String)], includes: &Includes) -> Result<()> {
        let code = code_lines(lines);
        let once = code.iter().any(|c| directive(&c.text).is_some_and(|(d, r)| d == "pragma" && r.trim() == "once"));
        let model = Source { dir: super::dir_of(path), code, lines: lines.to_vec(), once, guard: None };
        let key = std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf());
        let mut x = Expander {
            includes,
            sources: vec![model],
            by_path: HashMap::from([(key, 0)]),
            wrapped: HashSet::new(),
            stack: vec![0],
            done: HashSet::new(),
            undefined: HashSet::new(),
            out: std::mem::take(self),
        };
        let result = x.expand(0, 0);
        *self = x.out;
        result
    }
}

/// A file read for inclusion.
struct Source {
    dir: PathBuf,
    lines: Vec<(usize, String)>,
    /// Each line's code outside comments (`code_lines`), where directives are read.
    code: Vec<Code>,
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
    /// `#pragma once` files written inside a guard of brdfprof's: needed only where an `#if` surrounds the
    /// inclusion (brdfprof itself leaves out one included again outside every `#if`), so that a long chain of
    /// headers never nests glslang's `#ifdef`s past its limit.
    wrapped: HashSet<usize>,
    out: Expanded,
}

/// The directive of a `#` line and the text after it (`#  include "a"` -> (`include`, ` "a"`)).
pub fn directive(line: &str) -> Option<(&str, &str)> {
    let rest = line.trim_start().strip_prefix('#')?.trim_start();
    let end = rest.find(|c: char| !(c.is_ascii_alphanumeric() || c == '_')).unwrap_or(rest.len());
    Some((&rest[..end], &rest[end..]))
}

impl Expander<'_> {
    /// Appends source `idx`'s lines; `outer` is the `#if` depth around its inclusion. Directives are read from
    /// each line's code outside comments; where a directive line brdfprof replaces opens a `/*` comment, a `/*`
    /// line after it (after an included file's lines) lets the comment go on as in the file.
    fn expand(&mut self, idx: usize, outer: usize) -> Result<()> {
        let (lines, code) = (self.sources[idx].lines.clone(), self.sources[idx].code.clone());
        let mut depth = 0usize;
        for ((n, text), code) in lines.iter().zip(&code) {
            match directive(&code.text) {
                Some(("include", rest)) => {
                    self.include(idx, *n, text, rest, outer + depth)?;
                    if code.opens_comment {
                        self.out.push("/*", idx, *n);
                    }
                }
                Some(("pragma", rest)) if rest.trim() == "once" => self.replace(idx, *n, code),
                Some(("line", _)) => {
                    self.out.dropped.push((idx, *n, text.trim().to_string()));
                    self.replace(idx, *n, code);
                }
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

    /// A directive line brdfprof consumes, as an empty line (or `/*` where the line opens a comment).
    fn replace(&mut self, idx: usize, n: usize, code: &Code) {
        self.out.push(if code.opens_comment { "/*" } else { "" }, idx, n);
    }

    /// One `#include` line of source `from`, at the `#if` depth `depth`.
    fn include(&mut self, from: usize, n: usize, text: &str, rest: &str, depth: usize) -> Result<()> {
        let column = text.find(['"', '<']).map_or(1, |c| c + 1);
        let Some((name, quoted)) = include_name(rest) else {
            return Ok(self.error_line(
                from,
                n,
                column,
                format!(
                    "`{}`: brdfprof resolves #include itself and reads only \"NAME\" or <NAME>, not a macro",
                    text.trim()
                ),
            ));
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
        let once = self.sources[idx].once && (depth > 0 || self.wrapped.contains(&idx));
        if once {
            self.wrapped.insert(idx);
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

    /// Where `name` is found (`Includes::find`: beside source `from` for a quoted name), with how messages
    /// name it.
    fn resolve(&self, from: usize, name: &str, quoted: bool) -> Option<(PathBuf, String)> {
        let p = self.includes.find(name, quoted.then(|| self.sources[from].dir.as_path()))?;
        Some((p.clone(), p.display().to_string()))
    }

    fn not_found(&self, from: usize, name: &str, quoted: bool) -> String {
        let hint = if self.includes.mapped(name).is_some() {
            String::new()
        } else if name.starts_with('/') {
            format!(
                "; a virtual path needs --include-map {}=DIR",
                name.split('/').take(2).collect::<Vec<_>>().join("/")
            )
        } else {
            "; add the directory with --include-dir DIR".to_string()
        };
        format!(
            "cannot find include `{name}`{}{hint}",
            self.includes.searched(name, quoted.then(|| self.sources[from].dir.as_path()))
        )
    }

    /// The message of a cycle that reaches source `idx` again through `#include "name"`.
    fn cycle(&self, idx: usize, name: &str) -> String {
        let from = self.stack.iter().position(|&s| s == idx).unwrap_or(0);
        let chain: Vec<&str> = self.stack[from..].iter().map(|&s| self.shown(s)).collect();
        format!(
            "include cycle: {} includes `{name}` again ({}), which has neither `#pragma once` nor an include guard",
            chain.last().copied().unwrap_or("?"),
            chain.iter().chain([&self.shown(idx)]).copied().collect::<Vec<_>>().join(" -> ")
        )
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
        let text = String::from_utf8(bytes).map_err(|e| {
            fail(anyhow!("{} is not UTF-8 text (byte {})", path.display(), e.utf8_error().valid_up_to()))
        })?;
        let lines: Vec<(usize, String)> = split_lines(text.strip_prefix('\u{feff}').unwrap_or(&text))
            .into_iter()
            .enumerate()
            .map(|(i, l)| (i + 1, l))
            .collect();
        if let Some((n, l)) = lines.iter().find(|(_, l)| l.contains('\0')) {
            let column = l[..l.find('\0').unwrap_or(0)].chars().count() + 1;
            bail!("{}:{n}:{column}: a NUL byte (U+0000), where glslang would end the text; remove it", path.display());
        }
        let code = code_lines(&lines);
        let once = code.iter().any(|c| directive(&c.text).is_some_and(|(d, r)| d == "pragma" && r.trim() == "once"));
        let guard = guard_macro(&code);
        self.sources.push(Source { dir: super::dir_of(path), lines, code, once, guard });
        self.out.files.push(shown);
        self.by_path.insert(key, self.sources.len() - 1);
        Ok(self.sources.len() - 1)
    }
}

/// A file's lines, each ending at `\r\n`, `\n` or a lone `\r` (old Mac line ends), as a compiler counts them.
pub fn split_lines(text: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut rest = text;
    while let Some(i) = rest.find(['\r', '\n']) {
        out.push(rest[..i].to_string());
        let skip = if rest[i..].starts_with("\r\n") { 2 } else { 1 };
        rest = &rest[i + skip..];
    }
    out.push(rest.to_string());
    out
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

/// A line's code: its text outside comments (each character of a `/* */` comment a space, so that columns
/// stay those of the line; a `//` comment cut off), and whether it ends inside a `/*` comment.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Code {
    pub text: String,
    pub opens_comment: bool,
}

/// Each line's code (`//` and `/* */` comments, which may span lines, outside string literals).
pub fn code_lines(lines: &[(usize, String)]) -> Vec<Code> {
    let mut in_block = false;
    lines
        .iter()
        .map(|(_, l)| {
            let (b, mut text, mut i) = (l.as_bytes(), String::new(), 0);
            let blank = |text: &mut String, from: usize, to: usize| text.extend(l[from..to].chars().map(|_| ' '));
            while i < b.len() {
                if in_block {
                    let close = l[i..].find("*/").map(|e| i + e + 2);
                    blank(&mut text, i, close.unwrap_or(b.len()));
                    (i, in_block) = (close.unwrap_or(b.len()), close.is_none());
                } else if l[i..].starts_with("//") {
                    break;
                } else if l[i..].starts_with("/*") {
                    blank(&mut text, i, i + 2);
                    (i, in_block) = (i + 2, true);
                } else if b[i] == b'"' {
                    let end = l[i + 1..].find('"').map_or(b.len(), |e| i + e + 2);
                    text += &l[i..end];
                    i = end;
                } else {
                    let c = l[i..].chars().next().unwrap_or(' ');
                    text.push(c);
                    i += c.len_utf8();
                }
            }
            Code { text, opens_comment: in_block }
        })
        .collect()
}

/// The macro of a classic include guard around the whole file (`code`: its lines' code): its first code is
/// `#ifndef X` (or `#if !defined(X)`), then `#define X`, the `#endif` that closes it is its last code, and
/// no `#else` or `#elif` of its own gives a second inclusion something.
pub fn guard_macro(code: &[Code]) -> Option<String> {
    let code: Vec<&str> = code.iter().map(|c| c.text.trim()).filter(|l| !l.is_empty()).collect();
    let (first, second, last) = (code.first()?, code.get(1)?, code.last()?);
    let name = match directive(first)? {
        ("ifndef", r) => r.trim().to_string(),
        ("if", r) => {
            r.trim().strip_prefix("!defined")?.trim().trim_start_matches('(').trim_end_matches(')').trim().to_string()
        }
        _ => return None,
    };
    let defines =
        directive(second).is_some_and(|(d, r)| d == "define" && r.split_whitespace().next() == Some(name.as_str()));
    if !defines || directive(last).map(|(d, _)| d) != Some("endif") {
        return None;
    }
    let mut depth = 0i32;
    for (k, l) in code.iter().enumerate() {
        match directive(l).map(|(d, _)| d) {
            Some("if" | "ifdef" | "ifndef") => depth += 1,
            Some("endif") => depth -= 1,
            Some("else" | "elif") if depth == 1 => return None,
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
        x.include_section(&dir.join("m.hlsl"), &lines(text), includes).unwrap();
        x
    }

    #[test]
    fn include_guards_are_recognised_only_around_the_whole_file() {
        let guard = |text: &str| guard_macro(&code_lines(&lines(text)));
        assert_eq!(
            guard("// licence\n/* more\n */\n#ifndef A_H\n#define A_H\nfloat a;\n#endif // A_H\n"),
            Some("A_H".into())
        );
        assert_eq!(guard("#if !defined(B)\n#define B 1\n#endif\n"), Some("B".into()));
        assert_eq!(guard("#ifndef A\n#define A\n#endif\nfloat b;\n"), None, "code after the guard");
        assert_eq!(guard("#ifndef A\n#define A\n#endif\n#ifndef C\n#endif\n"), None, "two blocks");
        assert_eq!(guard("#ifndef A\n#define B\n#endif\n"), None);
        assert_eq!(
            guard("#ifndef A\n#define A\nfloat a;\n#else\nfloat b;\n#endif\n"),
            None,
            "a second inclusion is not empty"
        );
        assert_eq!(
            guard("#ifndef A\n#define A\n#if Q\n#else\n#endif\n#endif\n"),
            Some("A".into()),
            "an #else of an inner #if"
        );
        assert_eq!(
            guard("/*\n#endif */\n#ifndef A\n#define A\n/* #else */\n#endif\n"),
            Some("A".into()),
            "directives in comments are none"
        );
    }

    #[test]
    fn pragma_once_guards_and_virtual_paths() {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        std::fs::create_dir_all(d.join("engine/Private")).unwrap();
        std::fs::write(d.join("engine/Private/Common.ush"), "#pragma once\nstatic const float PI = 3.14;\n").unwrap();
        std::fs::write(
            d.join("brdf.ush"),
            "#pragma once\n#include \"/Engine/Private/Common.ush\"\nfloat D() { return PI; }\n",
        )
        .unwrap();
        let inc = Includes { dirs: vec![], maps: vec![("/Engine".into(), d.join("engine"))], overrides: vec![] };
        let x = expand(d, "#include \"brdf.ush\"\n#include \"brdf.ush\"\nfloat3 BRDF();\n", &inc);
        let text = x.text();
        assert_eq!(text.matches("float D()").count(), 1, "{text}");
        assert_eq!(text.matches("PI = 3.14").count(), 1, "{text}");
        assert!(!text.contains("#ifndef") && x.notes.is_empty(), "outside every #if, no guard to nest: {text}");
        let at = x.lines.iter().position(|l| l.contains("PI = 3.14")).unwrap();
        assert_eq!(x.origin(at), Some((d.join("engine/Private/Common.ush").display().to_string().as_str(), 2)));
        assert_eq!(x.origin(x.lines.len() - 1), Some((d.join("m.hlsl").display().to_string().as_str(), 3)));
    }

    #[test]
    fn directives_are_read_outside_comments_only_and_line_directives_are_dropped() {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        std::fs::write(d.join("a.ush"), "#pragma once\nfloat a;\n").unwrap();
        std::fs::write(d.join("old.ush"), "/* old */\nfloat old;\n").unwrap();
        let x = expand(
            d,
            "/*\n#include \"a.ush\"\n#include \"old.ush\"\n#if 0\n*/\n#include \"a.ush\" /* the header\n of a */\n#line 90\nfloat b;\n",
            &Includes::default(),
        );
        let text = x.text();
        assert_eq!(text.matches("float a;").count(), 1, "{text}");
        assert!(!text.contains("float old;") && !text.contains("#line") && x.notes.is_empty(), "{text}");
        let after = x.lines.iter().rposition(|l| l == "/*").unwrap();
        assert!(after > x.lines.iter().position(|l| l == "float a;").unwrap(), "after the included lines");
        assert_eq!(
            (x.lines[after].as_str(), x.lines[after + 1].as_str()),
            ("/*", " of a */"),
            "the comment the #include line opens goes on"
        );
        assert_eq!(x.dropped, [(0, 8, "#line 90".to_string())]);
        assert_eq!(
            code_lines(&lines("x = \"//\"; // c\n/* a */ #include \"b\"")),
            [
                Code { text: "x = \"//\"; ".into(), opens_comment: false },
                Code { text: "        #include \"b\"".into(), opens_comment: false }
            ]
        );
    }

    #[test]
    fn conditional_inclusions_stay_for_the_preprocessor_and_cycles_and_missing_files_are_error_lines() {
        let dir = tempfile::tempdir().unwrap();
        let d = dir.path();
        std::fs::write(d.join("a.ush"), "#pragma once\nfloat a;\n").unwrap();
        std::fs::write(d.join("loop1.ush"), "float l1;\n#include \"loop2.ush\"\n").unwrap();
        std::fs::write(d.join("loop2.ush"), "float l2;\n  #include \"loop1.ush\"\n").unwrap();
        let x = expand(
            d,
            "#if Q\n#include \"a.ush\"\n#endif\n#include \"a.ush\"\n#if 0\n#include \"gone.ush\"\n#endif\n#include \"loop1.ush\"\n",
            &Includes::default(),
        );
        assert_eq!(
            x.lines.iter().filter(|l| l.as_str() == "float a;").count(),
            2,
            "inside an #if it is expanded again, guarded"
        );
        let notes: Vec<&(usize, String)> = {
            let mut k: Vec<_> = x.notes.iter().collect();
            k.sort();
            k.into_iter().map(|(_, n)| n).collect()
        };
        assert!(notes[0].1.starts_with("cannot find include `gone.ush` (searched: "), "{notes:?}");
        assert_eq!(notes[0].0, 10);
        assert!(
            notes[1].1.starts_with("include cycle: ") && notes[1].1.contains("loop1.ush -> ") && notes[1].0 == 12,
            "{notes:?}"
        );
        let at = *x.notes.keys().max().unwrap();
        assert_eq!(x.origin(at).map(|(f, l)| (f.ends_with("loop2.ush"), l)), Some((true, 2)));
    }
}
