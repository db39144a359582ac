//! No function in src/ or a crate's src/ over 70 lines, counted from the line of its `fn` to the
//! line of its closing brace. A brace-aware scan: strings, raw strings, chars and comments are blanked first
//! so a `{` inside them does not count.

use crate::common;
use crate::layering::rust_files;

const MAX_LINES: usize = 70;

/// Files not held to the limit yet, with why. The lead owns these; remove an entry when its file is split.
const NOT_YET: &[(&str, &str)] = &[];

fn is_ident(c: char) -> bool {
    c.is_alphanumeric() || c == '_'
}

/// Index just past a raw string starting at `i` (`r"`, `r#"`, ...), or None when `i` starts none.
fn raw_string_end(s: &[char], i: usize) -> Option<usize> {
    if s[i] != 'r'
        || (i > 0 && is_ident(s[i - 1]) && s[i - 1] != 'b')
        || (i > 1 && s[i - 1] == 'b' && is_ident(s[i - 2]))
    {
        return None;
    }
    let hashes = s[i + 1..].iter().take_while(|c| **c == '#').count();
    if s.get(i + 1 + hashes) != Some(&'"') {
        return None;
    }
    let mut j = i + 2 + hashes;
    while j < s.len() {
        if s[j] == '"'
            && s[j + 1..].iter().take(hashes).filter(|c| **c == '#').count() == hashes
            && j + hashes < s.len()
        {
            return Some(j + 1 + hashes);
        }
        j += 1;
    }
    Some(s.len())
}

/// Index just past the literal or comment starting at `i`, or None when code starts there.
fn skip_non_code(s: &[char], i: usize) -> Option<usize> {
    let next = s.get(i + 1).copied();
    match s[i] {
        '/' if next == Some('/') => Some(s[i..].iter().position(|c| *c == '\n').map_or(s.len(), |p| i + p)),
        '/' if next == Some('*') => {
            let (mut depth, mut j) = (1, i + 2);
            while j < s.len() && depth > 0 {
                if s[j] == '/' && s.get(j + 1) == Some(&'*') {
                    depth += 1;
                    j += 1;
                } else if s[j] == '*' && s.get(j + 1) == Some(&'/') {
                    depth -= 1;
                    j += 1;
                }
                j += 1;
            }
            Some(j)
        }
        '"' => {
            let mut j = i + 1;
            while j < s.len() && s[j] != '"' {
                j += if s[j] == '\\' { 2 } else { 1 };
            }
            Some(j + 1)
        }
        // a char literal ('x', '\n', '\u{..}'), not a lifetime ('a)
        '\'' if next == Some('\\') => Some(i + 3 + s[i + 3..].iter().position(|c| *c == '\'').unwrap_or(0) + 1),
        '\'' if s.get(i + 2) == Some(&'\'') => Some(i + 3),
        'r' => raw_string_end(s, i),
        _ => None,
    }
}

/// `text` with every comment and literal blanked to spaces, newlines kept (so line numbers hold).
fn code_only(text: &str) -> Vec<char> {
    let s: Vec<char> = text.chars().collect();
    let mut out = Vec::with_capacity(s.len());
    let mut i = 0;
    while i < s.len() {
        match skip_non_code(&s, i) {
            Some(end) => {
                let end = end.min(s.len());
                out.extend(s[i..end].iter().map(|c| if *c == '\n' { '\n' } else { ' ' }));
                i = end;
            }
            None => {
                out.push(s[i]);
                i += 1;
            }
        }
    }
    out
}

/// The first `{` or `;` from `j` outside brackets (`[f32; 3]` in a signature is no end), or None.
fn body_or_end(code: &[char], j: usize) -> Option<usize> {
    let mut depth = 0i32;
    for (k, c) in code.iter().enumerate().skip(j) {
        match c {
            '(' | '[' => depth += 1,
            ')' | ']' => depth -= 1,
            '{' | ';' if depth == 0 => return Some(k),
            _ => {}
        }
    }
    None
}

/// (name, line of `fn`, lines from `fn` to its closing brace) of every function with a body in `text`.
fn functions(text: &str) -> Vec<(String, usize, usize)> {
    let code = code_only(text);
    let line_at = |i: usize| 1 + code[..i].iter().filter(|c| **c == '\n').count();
    let mut out = Vec::new();
    let mut i = 0;
    while i + 2 < code.len() {
        let keyword =
            code[i] == 'f' && code[i + 1] == 'n' && (i == 0 || !is_ident(code[i - 1])) && !is_ident(code[i + 2]);
        if !keyword {
            i += 1;
            continue;
        }
        let mut j = i + 2;
        while j < code.len() && code[j].is_whitespace() {
            j += 1;
        }
        let name: String = code[j..].iter().take_while(|c| is_ident(**c)).collect();
        // `fn(` is a function-pointer type, not an item
        if name.is_empty() {
            i += 2;
            continue;
        }
        let Some(open) = body_or_end(&code, j) else { break };
        if code[open] == ';' {
            i = open;
            continue;
        }
        let mut depth = 0;
        let mut close = open;
        for (k, c) in code.iter().enumerate().skip(open) {
            depth += match c {
                '{' => 1,
                '}' => -1,
                _ => 0,
            };
            if depth == 0 {
                close = k;
                break;
            }
        }
        let first = line_at(i);
        out.push((name, first, line_at(close) - first + 1));
        i += 2;
    }
    out
}

#[test]
fn the_scanner_counts_what_it_should() {
    let text = "fn a() {\n    let s = \"}\";\n    let c = '}';\n    // }\n    /* } */\n    let r = r#\"}\"#;\n    fn inner<'x>(v: &'x str) -> &'x str { v }\n}\ntrait T { fn decl(&self); fn def(&self) {\n} }\nfn p(f: fn(u8) -> u8, v: [u8; 2]) -> [u8; 2] {\n    let e = '\\''; v }\n";
    let got = functions(text);
    let want = [("a", 1, 8), ("inner", 7, 1), ("def", 9, 2), ("p", 11, 2)];
    let got: Vec<(&str, usize, usize)> = got.iter().map(|(n, l, c)| (n.as_str(), *l, *c)).collect();
    assert_eq!(got, want);
}

#[test]
fn no_function_in_src_over_70_lines() {
    let mut files = Vec::new();
    for dir in common::source_dirs() {
        rust_files(&dir, &mut files);
    }
    files.sort();
    let mut bad = Vec::new();
    let mut checked = 0;
    for f in &files {
        let rel = f.strip_prefix(common::repo_root()).unwrap().to_string_lossy().to_string();
        if NOT_YET.iter().any(|(p, _)| *p == rel) {
            continue;
        }
        for (name, line, len) in functions(&std::fs::read_to_string(f).unwrap()) {
            checked += 1;
            if len > MAX_LINES {
                bad.push(format!("{rel}:{line}: fn {name} is {len} lines (at most {MAX_LINES})"));
            }
        }
    }
    assert!(checked > 500, "only {checked} functions found in src/: the scanner is broken");
    assert!(bad.is_empty(), "functions over {MAX_LINES} lines:\n{}", bad.join("\n"));
}
