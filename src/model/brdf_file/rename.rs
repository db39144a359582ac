//! Renaming the shader's globals and parameters with the file's prefix, and mapping glslang's messages about
//! the composed source back to the file's lines and names.

use super::*;
use std::collections::HashSet;

impl BrdfFile {
    /// The prefix of every renamed name: `brdf_f_`, or `brdf_f1_`, `brdf_f2_`, ... when some identifier-like word
    /// of the shader (comments included) already starts with `brdf_f`, so that no renamed name can equal a name
    /// left alone; without its final `_` when such a word or a parameter starts with `_`, so that no `__` (which
    /// GLSL reserves) appears.
    pub(super) fn choose_prefix(&self) -> String {
        let runs: Vec<&str> = self.shader.iter().flat_map(|(_, l)| identifier_runs(l)).collect();
        let underscore =
            runs.iter().copied().chain(self.params.iter().map(|p| p.name.as_str())).any(|s| s.starts_with('_'));
        let base = (0..)
            .map(|k| if k == 0 { "brdf_f".to_string() } else { format!("brdf_f{k}") })
            .find(|base| !runs.iter().any(|r| r.starts_with(base.as_str())))
            .expect("some prefix is free");
        if underscore { base } else { base + "_" }
    }

    /// The name `original` (a parameter, `BRDF`, any global of the shader) has in the renamed shader.
    pub fn glsl_name(&self, original: &str) -> String {
        format!("{}{original}", self.prefix)
    }

    /// The preprocessed shader with every occurrence of each parameter and global name renamed (`glsl_name`),
    /// except after a `.` and in struct member declarations, and with `uniform` dropped from globals. Lines
    /// stay one for one.
    pub fn renamed_shader(&self) -> &RenamedShader {
        &self.renamed
    }

    pub(super) fn rename(&self, tokens: &[Token], scan: &Scan) -> RenamedShader {
        let prefix = self.prefix.clone();
        // A set beside the list: a file of 100,000 functions renames in linear time.
        let mut seen: HashSet<&str> = HashSet::new();
        let mut renamed: Vec<String> = Vec::new();
        for name in self.params.iter().map(|p| &p.name).chain(scan.globals.iter().map(|g| &g.name)) {
            if seen.insert(name.as_str()) {
                renamed.push(name.clone());
            }
        }
        let names = seen;
        let members = struct_members(tokens);
        let mut edits: Vec<(usize, usize, usize, String)> = Vec::new();
        for (i, t) in tokens.iter().enumerate() {
            let after_dot = i > 0 && tokens[i - 1].is(".");
            if t.kind == Kind::Ident && names.contains(t.text.as_str()) && !after_dot && !members.contains(&i) {
                edits.push((t.line, t.start, t.end, format!("{prefix}{}", t.text)));
            }
        }
        for &u in &scan.uniform_tokens {
            edits.push((tokens[u].line, tokens[u].start, tokens[u].end, String::new()));
        }
        let mut lines = self.shader.clone();
        edits.sort_by(|a, b| (b.0, b.1).cmp(&(a.0, a.1)));
        for (line, start, end, text) in edits {
            lines[line].1.replace_range(start..end, &text);
        }
        let lookup = renamed.iter().cloned().collect();
        RenamedShader { lines, prefix, renamed, lookup, initialisers: Vec::new() }
    }

    /// `const TYPE NAME = DEFAULT;` for each parameter, under its GLSL name: the simplest composition.
    pub fn default_constants(&self) -> String {
        self.params
            .iter()
            .map(|p| format!("const {} {} = {};\n", p.glsl_type(), self.glsl_name(&p.name), p.default_glsl()))
            .collect()
    }

    /// The name the composed source's `#line` directive gives the file: its path, the characters glslang cannot
    /// take in a directive's string (non-ASCII, `"`, control characters) percent-encoded (`io::directive_name`;
    /// per-line cost reads it back with `io::from_directive_name`).
    pub(crate) fn directive_name(&self) -> String {
        let shown = match self.language {
            _ if !self.translated() => self.path.display().to_string(),
            Language::Glsl => format!("{} (its GLSL and includes as GLSL)", self.path.display()),
            other => format!("{} (its {} as GLSL)", self.path.display(), other.name()),
        };
        crate::io::directive_name(&shown)
    }

    /// The function that calls a declared entry as BRDF Explorer's `BRDF(L, V, N, X, Y)` is called, and its
    /// text, to put after the renamed shader: `#line` at the declaration (so glslang's messages about an
    /// argument name the `entry` line), then one call whose arguments are the declaration's expressions with
    /// the file's names renamed. The name (the prefix, then a digit) is one no renamed name can take.
    pub fn entry_glue(&self, entry: &Entry) -> (String, String) {
        let name = format!("{}0entry", self.prefix);
        if let Some(glue) = &entry.glue {
            let text = format!(
                "#line {} \"{}\"\nvec3 {name}(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y) {{ return {}(L, V, N, X, Y); }}\n",
                entry.line,
                self.directive_name(),
                self.glsl_name(glue)
            );
            return (name, text);
        }
        let mut locals = String::new();
        let mut result = None;
        let mut args = Vec::new();
        for (k, a) in entry.args.iter().enumerate() {
            if a.starts_with('@') {
                let local = format!("{}0arg{k}", self.prefix);
                let ty = entry.param_types.get(k).map_or("vec3", String::as_str);
                // Numbers and vectors start at zero (an accumulator's value is then the function's own sum);
                // any other type is declared as it is.
                let zero = ty.starts_with("float") || ["vec2", "vec3", "vec4"].contains(&ty);
                locals += &if zero { format!("{ty} {local} = {ty}(0.0); ") } else { format!("{ty} {local}; ") };
                if a == super::globals::OUT_ARG {
                    result = Some(local.clone());
                }
                args.push(local);
            } else {
                args.push(self.renamed_argument(a));
            }
        }
        let call = format!("{}({})", self.glsl_name(&entry.name), args.join(", "));
        let body = match result {
            Some(out) => format!("{locals}{call}; return {out};"),
            None => format!("{locals}return {call};"),
        };
        let text = format!(
            "#line {} \"{}\"\nvec3 {name}(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y) {{ {body} }}\n",
            entry.line,
            self.directive_name()
        );
        (name, text)
    }

    /// An entry's argument with the file's parameters and globals renamed as the shader's are (`rename`: an
    /// identifier, not after a `.`), except the entry's own arguments `L V N X Y`. An argument the tokenizer
    /// refuses stays as written, for glslang to report at the entry's line.
    fn renamed_argument(&self, arg: &str) -> String {
        let Ok(tokens) = tokenize(&self.path, &[(0, arg.to_string())]) else { return arg.to_string() };
        let mut out = arg.to_string();
        for (i, t) in tokens.iter().enumerate().rev() {
            let after_dot = i > 0 && tokens[i - 1].is(".");
            if t.kind == Kind::Ident
                && !after_dot
                && !["L", "V", "N", "X", "Y"].contains(&t.text.as_str())
                && self.renamed.lookup.contains(&t.text)
            {
                out.replace_range(t.start..t.end, &self.glsl_name(&t.text));
            }
        }
        out
    }

    /// `#line N "FILE"`, to put just before the renamed shader lines (it needs
    /// `GL_GOOGLE_cpp_style_line_directive`, or `GL_GOOGLE_include_directive`, which implies it): glslang then
    /// reports the file's own name and lines.
    pub fn line_directive(&self) -> String {
        format!("#line {} \"{}\"", self.shader.first().map_or(1, |l| l.0), self.directive_name())
    }

    /// glslang's log about a composed source, as messages about this file: `FILE:LINE: 'token' : message`,
    /// with the original names. A message names a file line when glslang located it in this file (the
    /// `line_directive` mechanism) or when `line_of` maps its composed line to one (the line-map mechanism,
    /// without directives: then `line_of` must answer None for lines of any other source). Other located
    /// messages (about the host's code) are kept as glslang wrote them, and messages located nowhere (counts,
    /// "compilation terminated", link errors that follow a failed compile) are dropped.
    pub fn remap_log(&self, renamed: &RenamedShader, log: &str, line_of: impl Fn(usize) -> Option<usize>) -> String {
        // A translated shader's lines are its GLSL's, named so.
        let shown = if self.translated() { self.directive_name() } else { self.path.display().to_string() };
        let ours = [self.path.display().to_string(), self.directive_name()];
        let mut out = String::new();
        for line in log.lines().map(str::trim) {
            let Some((severity, rest)) = line
                .split_once(": ")
                .filter(|(s, _)| ["ERROR", "WARNING", "NOTE", "UNIMPLEMENTED", "INTERNAL ERROR"].contains(s))
            else {
                continue;
            };
            let Some((source, n, message)) = split_location(rest) else {
                continue;
            };
            if message.starts_with("'' : compilation terminated") {
                continue;
            }
            let mut message = renamed.original_names(message.trim_end());
            let file_line = if ours.iter().any(|o| o == source) { Some(n) } else { line_of(n) };
            if let Some(fl) = file_line {
                message = self.non_ascii(fl, &message).unwrap_or(message);
            }
            let kind = if severity == "ERROR" { String::new() } else { format!("{}: ", severity.to_lowercase()) };
            match file_line {
                Some(fl) => out += &format!("{shown}:{fl}: {kind}{message}\n"),
                None => out += &format!("{severity}: {source}:{n}: {message}\n"),
            }
        }
        out
    }
}

impl BrdfFile {
    /// A message quoting a byte glslang could not read (it reads bytes, and a non-ASCII character's first byte
    /// comes back as U+FFFD) with the character the file has on that line, its code point and column, and why:
    /// GLSL's tokens are ASCII (non-ASCII text belongs in comments).
    fn non_ascii(&self, line: usize, message: &str) -> Option<String> {
        if !message.contains('\u{FFFD}') {
            return None;
        }
        let text = &self.source.iter().find(|(n, _)| *n == line)?.1;
        let (i, c) = text.char_indices().find(|(_, c)| !c.is_ascii())?;
        let column = text[..i].chars().count() + 1;
        Some(format!(
            "{} (column {column}: `{c}`, U+{:04X}; GLSL identifiers and tokens are ASCII letters, digits and _ only, non-ASCII text belongs in comments)",
            message.replace('\u{FFFD}', &c.to_string()),
            u32::from(c)
        ))
    }

    /// glslang's log when none of its messages is located in the file (errors of the link stage, such as
    /// recursion, which GLSL forbids): its messages and their continuation lines with the file's own names,
    /// without glslang's banner lines (the source's name, "SPIR-V is not generated ...").
    pub fn unlocated_log(&self, renamed: &RenamedShader, log: &str) -> String {
        let mut out = String::new();
        for line in log.lines().filter(|l| !l.trim().is_empty()) {
            let continuation = line.starts_with([' ', '\t']);
            if !continuation && (!line.contains(": ") || line.starts_with("SPIR-V is not generated")) {
                continue;
            }
            out += &renamed.original_names(line.trim_end());
            out.push('\n');
        }
        if log.contains("Recursion detected") {
            out += "(GLSL forbids recursion: a function of the file calls itself, directly or through others)\n";
        }
        out
    }
}

/// `SOURCE:LINE: message` -> (SOURCE, LINE, message), at the first `:digits: ` (a source may contain `:`).
pub(super) fn split_location(rest: &str) -> Option<(&str, usize, &str)> {
    let b = rest.as_bytes();
    for (i, _) in rest.match_indices(':') {
        let digits = b[i + 1..].iter().take_while(|c| c.is_ascii_digit()).count();
        let after = i + 1 + digits;
        if digits > 0 && b.get(after) == Some(&b':') {
            let n = rest[i + 1..after].parse().ok()?;
            return Some((&rest[..i], n, rest[after + 1..].trim_start()));
        }
    }
    None
}

impl RenamedShader {
    /// `text` with every renamed identifier shown by its original name.
    pub fn original_names(&self, text: &str) -> String {
        let mut out = String::with_capacity(text.len());
        let mut rest = text;
        while let Some(start) = rest.find(|c: char| c == '_' || c.is_ascii_alphanumeric()) {
            let len =
                rest[start..].find(|c: char| !(c == '_' || c.is_ascii_alphanumeric())).unwrap_or(rest.len() - start);
            let word = &rest[start..start + len];
            out += &rest[..start];
            match word.strip_prefix(self.prefix.as_str()).filter(|w| self.lookup.contains(*w)) {
                Some(original) => out += original,
                None => out += word,
            }
            rest = &rest[start + len..];
        }
        out + rest
    }

    /// The renamed lines joined, one per line.
    pub fn text(&self) -> String {
        self.lines.iter().map(|(_, l)| format!("{l}\n")).collect()
    }
}
