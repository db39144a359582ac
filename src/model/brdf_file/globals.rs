//! What the shader declares at global scope, and the checks on it (`BRDF`'s signature, no `layout`, no
//! global named like a parameter).

use super::*;
use anyhow::{Result, bail};
use std::collections::HashSet;
use std::path::Path;

/// The shader section must exist and define `BRDF`; its globals must not take a parameter's name; a `uniform`
/// qualifier on a global is dropped (renamed_shader) with a warning.
pub(super) fn check_shader(file: &mut BrdfFile, begin: usize, tokens: &[Token], scan: &Scan) -> Result<()> {
    // A stage interface's `layout(location = N)` is dropped with its `in`/`out` (`Scan::interface`); any other
    // layout would be the kernel's.
    let dropped = |i: usize| scan.uniform_tokens.contains(&i);
    if let Some((_, t)) =
        tokens.iter().enumerate().find(|(i, t)| t.kind == Kind::Ident && t.text == "layout" && !dropped(*i))
    {
        bail!(at(
            &file.path,
            file.shader[t.line].0,
            "`layout(...)` is not supported in a .brdf shader: the kernel the file is composed into sets its own layout (work-group size, bindings); declare values in the parameters section"
        ));
    }
    if !file.translated() {
        file.loops = loops(&file.shader, tokens);
    }
    let params: std::collections::HashMap<&str, usize> =
        file.params.iter().map(|p| (p.name.as_str(), p.line)).collect();
    for g in &scan.globals {
        if let Some(line) = params.get(g.name.as_str()) {
            bail!(at(
                &file.path,
                g.line,
                format!("`{}` is both a parameter (line {line}) and a global of the shader", g.name)
            ));
        }
    }
    for &(line, ref name) in &scan.uniforms {
        file.warnings.push(at(&file.path, line, format!("`uniform` dropped from `{name}`: Vulkan GLSL has no uniforms outside blocks, so it is a private global nothing sets (declare it as a parameter instead)")));
    }
    for (line, qualifier, name) in &scan.interface {
        file.warnings.push(at(&file.path, *line, format!("`{qualifier}` dropped from `{name}`: a fragment or vertex stage's interface, not the BRDF's inputs (brdfprof calls the BRDF function with N, V, L and its parameters), so it is a private global here")));
    }
    for (name, _, line) in &file.binds {
        if !params.contains_key(name.as_str()) {
            bail!(at(&file.path, *line, format!("`bind {name}=...`: the file has no parameter `{name}`")));
        }
    }
    let lines = Lines { path: &file.path, origin: None };
    let brdf = check_brdf(&lines, begin, &scan.globals, &GLSL_SIGNATURE);
    file.defines_brdf = brdf.is_ok();
    if file.entries.is_empty() {
        return brdf;
    }
    for e in &mut file.entries {
        e.param_types = match &e.glue {
            Some(glue) => check_glue(&lines, e, glue, &scan.globals)?,
            None => check_entry(&lines, e, &scan.globals, &GLSL_SIGNATURE)?,
        };
    }
    Ok(())
}

/// The function an HLSL or WGSL front end wrote for entry `e` (its arguments already checked in the shader's
/// own language) must be in its GLSL: `vec3 glue(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y)`.
fn check_glue(lines: &Lines, e: &Entry, glue: &str, globals: &[Global]) -> Result<Vec<String>> {
    let view = Entry {
        name: glue.to_string(),
        args: ["L", "V", "N", "X", "Y"].map(String::from).to_vec(),
        param_types: Vec::new(),
        returns: e.returns,
        line: e.line,
        glue: None,
    };
    check_entry(lines, &view, globals, &GLSL_SIGNATURE)
        .map_err(|err| anyhow::anyhow!("{err:#} (the front end's call of `{}`)", e.name))
}

/// Where the scanned lines are: the model file's own lines (GLSL), or lines of an expanded text whose
/// `origin` gives each one's file and line (an HLSL shader with its includes).
pub(super) struct Lines<'a> {
    pub(super) path: &'a Path,
    pub(super) origin: Option<&'a dyn Fn(usize) -> (String, usize)>,
}

impl Lines<'_> {
    /// `FILE:LINE: message` for scanned line `line`.
    pub(super) fn at(&self, line: usize, message: impl Display) -> String {
        match self.origin {
            Some(o) => {
                let (f, l) = o(line);
                format!("{f}:{l}: {message}")
            }
            None => at(self.path, line, message),
        }
    }

    /// Scanned line `line` cited in a message: `line 12` in the model file, else `FILE:LINE`.
    pub(super) fn cite(&self, line: usize) -> String {
        match self.origin {
            Some(o) => {
                let (f, l) = o(line);
                format!("{f}:{l}")
            }
            None => format!("line {line}"),
        }
    }
}

/// An entry argument brdfprof fills in itself: `@out` takes the value, `@scratch` a value discarded.
pub(super) const OUT_ARG: &str = "@out";
pub(super) const SCRATCH_ARG: &str = "@scratch";

/// A declared entry must be a function defined at global scope with one parameter per argument, returning
/// vec3 (`sig`'s spellings of it), or writing its value to the one `@out` argument (an `out`/`inout vec3`; its
/// return value is then discarded). `@scratch` fills an `out`/`inout` parameter whose value is discarded.
/// Returns each parameter's type.
pub(super) fn check_entry(lines: &Lines, entry: &Entry, globals: &[Global], sig: &Signature) -> Result<Vec<String>> {
    let vec3 = sig.vec3[0];
    let defined = globals.iter().find_map(|g| match &g.kind {
        GlobalKind::Function { defined: true, returns, params } if g.name == entry.name => {
            Some((lines.cite(g.line), returns, params))
        }
        _ => None,
    });
    let fail = |m: String| Err(anyhow::anyhow!(at(lines.path, entry.line, m)));
    let Some((line, returns, params)) = defined else {
        return fail(format!(
            "entry `{}`: the shader defines no function `{}` at global scope",
            entry.name, entry.name
        ));
    };
    if params.len() != entry.args.len() {
        return fail(format!(
            "entry `{}` takes {} arguments ({line}) and the declaration gives {}",
            entry.name,
            params.len(),
            entry.args.len()
        ));
    }
    let outs = check_special_args(lines.path, entry, sig.language)?;
    if outs == 0 && !sig.vec3.contains(&returns.as_str()) {
        return fail(format!(
            "entry `{}` returns `{returns}` ({line}); an entry returns {vec3} (f_s, or f_s N.L with `returns f_nol`), or writes it to an `{OUT_ARG}` argument",
            entry.name
        ));
    }
    let types: Vec<String> = params
        .iter()
        .map(|p| p.iter().find(|t| !QUALIFIERS.contains(&t.as_str())).cloned().unwrap_or_default())
        .collect();
    for (k, (arg, p)) in entry.args.iter().zip(params).enumerate() {
        let writable = p.iter().any(|t| t == "out" || t == "inout");
        if arg.starts_with('@') && !writable {
            return fail(format!(
                "entry `{}`: argument {} is `{arg}` but parameter {} ({line}) is not `out` or `inout`",
                entry.name,
                k + 1,
                k + 1
            ));
        }
        if arg == OUT_ARG && !sig.vec3.contains(&types[k].as_str()) {
            return fail(format!(
                "entry `{}`: the `{OUT_ARG}` parameter {} ({line}) is `{}`; the value is a {vec3}",
                entry.name,
                k + 1,
                types[k]
            ));
        }
    }
    Ok(types)
}

/// An entry's arguments of brdfprof's own: only `@out` and `@scratch`, at most one `@out` (the count returned).
pub(super) fn check_special_args(path: &Path, entry: &Entry, language: &str) -> Result<usize> {
    let fail = |m: String| Err(anyhow::anyhow!(at(path, entry.line, m)));
    if let Some(a) = entry.args.iter().find(|a| a.starts_with('@') && ![OUT_ARG, SCRATCH_ARG].contains(&a.as_str())) {
        return fail(format!(
            "entry `{}`: `{a}`: an argument is a {language} expression, `{OUT_ARG}` (the argument the function writes its value to) or `{SCRATCH_ARG}` (one whose value is discarded)",
            entry.name
        ));
    }
    let outs = entry.args.iter().filter(|a| *a == OUT_ARG).count();
    if outs > 1 {
        return fail(format!("entry `{}`: `{OUT_ARG}` is given {outs} times; the value is one argument", entry.name));
    }
    Ok(outs)
}

/// BRDF Explorer's entry in a C-like shader language: its name, how it spells a 3-vector of floats, and the
/// signature.
pub(super) struct Signature {
    pub(super) language: &'static str,
    pub(super) vec3: &'static [&'static str],
    pub(super) text: &'static str,
}

pub(super) const GLSL_SIGNATURE: Signature =
    Signature { language: "GLSL", vec3: &["vec3"], text: "vec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y)" };
/// HLSL's, `half3` included (32-bit: glslang's and DXC's default).
pub(super) const HLSL_SIGNATURE: Signature = Signature {
    language: "HLSL",
    vec3: &["float3", "half3"],
    text: "float3 BRDF(float3 L, float3 V, float3 N, float3 X, float3 Y)",
};

/// `BRDF` must be defined at global scope with BRDF Explorer's signature (`sig`).
pub(super) fn check_brdf(lines: &Lines, begin: usize, globals: &[Global], sig: &Signature) -> Result<()> {
    let brdfs: Vec<&Global> = globals.iter().filter(|g| g.name == "BRDF").collect();
    let is_vec3 = |t: &String| sig.vec3.contains(&t.as_str());
    let fits = |g: &Global| match &g.kind {
        GlobalKind::Function { defined, returns, params } => {
            *defined && is_vec3(returns) && params.len() == 5 && params.iter().all(|p| p.iter().any(is_vec3))
        }
        _ => false,
    };
    let signature = sig.text;
    if brdfs.iter().any(|g| fits(g)) {
        return Ok(());
    }
    let defined = |g: &&&Global| matches!(g.kind, GlobalKind::Function { defined: true, .. });
    match (brdfs.iter().find(defined), brdfs.first()) {
        (Some(g), _) => bail!(lines.at(g.line, format!("`BRDF` must be defined as `{signature}`"))),
        (None, Some(g)) => {
            bail!(lines.at(g.line, format!("`BRDF` is declared but not defined (BRDF Explorer calls `{signature}`)")))
        }
        (None, None) => bail!(at(
            lines.path,
            begin,
            format!("the shader defines no function `BRDF` at global scope (BRDF Explorer calls `{signature}`)")
        )),
    }
}

#[derive(Clone, Debug, PartialEq)]
pub(super) enum GlobalKind {
    /// A function definition (`defined`) or prototype: the token before its name, and each parameter's tokens.
    Function {
        defined: bool,
        returns: String,
        params: Vec<Vec<String>>,
    },
    Variable,
    Struct,
}

#[derive(Clone, Debug, PartialEq)]
pub(super) struct Global {
    pub(super) name: String,
    /// File line.
    pub(super) line: usize,
    pub(super) kind: GlobalKind,
}

/// What the shader declares at global scope, and the `uniform` qualifiers to drop (token index).
pub(super) struct Scan {
    pub(super) globals: Vec<Global>,
    /// (file line, variable) of each dropped `uniform`.
    pub(super) uniforms: Vec<(usize, String)>,
    /// (file line, the qualifier as written, variable) of each dropped stage interface qualifier.
    pub(super) interface: Vec<(usize, String, String)>,
    pub(super) uniform_tokens: Vec<usize>,
}

/// Qualifiers that may precede a global's type.
pub(super) const QUALIFIERS: &[&str] = &[
    "const",
    "uniform",
    "in",
    "out",
    "inout",
    "buffer",
    "shared",
    "highp",
    "mediump",
    "lowp",
    "precise",
    "invariant",
    "flat",
    "smooth",
    "noperspective",
    "centroid",
    "sample",
    "patch",
    "coherent",
    "volatile",
    "restrict",
    "readonly",
    "writeonly",
];

pub(super) fn scan_globals(path: &Path, lines: &[(usize, String)], tokens: &[Token]) -> Result<Scan> {
    let mut scan =
        Scan { globals: Vec::new(), uniforms: Vec::new(), interface: Vec::new(), uniform_tokens: Vec::new() };
    let mut i = 0;
    while i < tokens.len() {
        let (end, body) = item_end(path, lines, tokens, i)?;
        let item = &tokens[i..end];
        declare(&mut scan, lines, item, i, body.map(|(o, c)| (o - i, c - i)));
        i = end;
    }
    Ok(scan)
}

/// The end (exclusive) of the global-scope item starting at `start` (a declaration up to its `;`, or a
/// function definition up to its body's `}`), and the body's braces (function or struct), if any.
pub(super) fn item_end(
    path: &Path,
    lines: &[(usize, String)],
    tokens: &[Token],
    start: usize,
) -> Result<(usize, Option<(usize, usize)>)> {
    let mut nest = 0;
    let mut body = None;
    let mut j = start;
    while j < tokens.len() {
        let t = &tokens[j];
        if t.is("(") || t.is("[") {
            nest += 1;
        } else if t.is(")") || t.is("]") {
            nest -= 1;
        } else if t.is("{") && nest == 0 {
            let close = matching(tokens, j);
            let header = &tokens[start..j];
            // A function's body: after its `)`, or after an HLSL return semantic (`) : SV_Target {`).
            let semantic =
                j >= start + 3 && tokens[j - 1].kind == Kind::Ident && tokens[j - 2].is(":") && tokens[j - 3].is(")");
            if j > start && (tokens[j - 1].is(")") || semantic) {
                return Ok(((close + 1).min(tokens.len()), Some((j, close))));
            } else if header.iter().any(|t| t.text == "struct") {
                body = Some((j, close));
                j = close;
            } else if header.last().is_some_and(|t| t.kind == Kind::Ident)
                && header.iter().any(|t| ["uniform", "buffer", "in", "out"].contains(&t.text.as_str()))
            {
                bail!(at(
                    path,
                    lines[t.line].0,
                    "interface blocks are not supported in a .brdf shader: declare values in the parameters section"
                ));
            } else {
                nest += 1; // an initializer list
            }
        } else if t.is("{") {
            nest += 1;
        } else if t.is("}") {
            if nest == 0 {
                return Ok((j + 1, body)); // a stray `}`: glslang will say so
            }
            nest -= 1;
        } else if t.is(";") && nest == 0 {
            return Ok((j + 1, body));
        }
        j += 1;
    }
    Ok((tokens.len(), body))
}

/// Records what one global-scope item declares. `first` is its first token's index; `body` its braces,
/// relative to the item.
pub(super) fn declare(
    scan: &mut Scan,
    lines: &[(usize, String)],
    item: &[Token],
    first: usize,
    body: Option<(usize, usize)>,
) {
    let line_of = |t: &Token| lines[t.line].0;
    let mut push =
        |t: &Token, kind: GlobalKind| scan.globals.push(Global { name: t.text.clone(), line: line_of(t), kind });
    if item.first().is_some_and(|t| t.text == "precision") {
        return;
    }
    if let Some(s) = item.iter().position(|t| t.text == "struct") {
        if let (Some(name), Some((_, close))) = (item.get(s + 1).filter(|t| t.kind == Kind::Ident), body) {
            push(name, GlobalKind::Struct);
            for (k, t) in item.iter().enumerate().skip(close + 1) {
                if t.kind == Kind::Ident && (item[k - 1].is("}") || item[k - 1].is(",")) {
                    push(t, GlobalKind::Variable);
                }
            }
        }
        return;
    }
    let header_end = body.map_or(item.len(), |(open, _)| open);
    let header = &item[..header_end];
    if let Some(k) = header.iter().position(|t| t.is("(")) {
        let typed = k >= 2 && (header[k - 2].kind == Kind::Ident || header[k - 2].is("]"));
        if typed && header[k - 1].kind == Kind::Ident && !header[..k].iter().any(|t| t.is("=")) {
            let close = matching(header, k).min(header.len());
            let params = split_params(&header[k + 1..close]);
            push(
                &header[k - 1],
                GlobalKind::Function { defined: body.is_some(), returns: header[k - 2].text.clone(), params },
            );
            return;
        }
    }
    declare_variables(scan, lines, header, first);
}

/// Records the variables an item's `header` declares (and its uniforms, by token index from `first`):
/// `[qualifiers] TYPE [[..]] NAME [[..]] [= ...] {, NAME [[..]] [= ...]} ;`
fn declare_variables(scan: &mut Scan, lines: &[(usize, String)], header: &[Token], first: usize) {
    let line_of = |t: &Token| lines[t.line].0;
    let mut p = 0;
    let mut uniform = None;
    // A fragment or vertex stage's interface (`in`, `out`, `varying`, `attribute`, `layout(location = N)`): not
    // the BRDF's inputs, dropped as `uniform` is, so that a shader pasted whole compiles.
    let mut interface: Vec<(usize, usize)> = Vec::new();
    while p < header.len() && (QUALIFIERS.contains(&header[p].text.as_str()) || header[p].text == "layout") {
        if header[p].text == "uniform" {
            uniform = Some(p);
        }
        let next = if header[p].text == "layout" && header.get(p + 1).is_some_and(|t| t.is("(")) {
            matching(header, p + 1) + 1
        } else {
            p + 1
        };
        if ["in", "out", "layout", "flat", "smooth", "noperspective", "centroid", "sample"]
            .contains(&header[p].text.as_str())
        {
            interface.push((p, next));
        }
        p = next;
    }
    // Only a stage's `in`/`out` brings its layout and interpolation qualifiers along; another layout (a
    // specialisation constant's) is the kernel's, and refused (`check_shader`).
    if !interface.iter().any(|&(k, _)| ["in", "out"].contains(&header[k].text.as_str())) {
        interface.clear();
    }
    if p >= header.len() || header[p].kind != Kind::Ident {
        return;
    }
    p += 1;
    while p < header.len() && header[p].is("[") {
        p = matching(header, p) + 1;
    }
    let Some(name) = header.get(p).filter(|t| t.kind == Kind::Ident) else {
        return;
    };
    if let Some(u) = uniform {
        scan.uniforms.push((line_of(name), name.text.clone()));
        scan.uniform_tokens.push(first + u);
    }
    if !interface.is_empty() {
        let what: Vec<String> =
            interface.iter().map(|&(from, to)| header[from..to].iter().map(|t| t.text.as_str()).collect()).collect();
        scan.interface.push((line_of(name), what.join(" "), name.text.clone()));
        for &(from, to) in &interface {
            scan.uniform_tokens.extend((from..to).map(|k| first + k));
        }
    }
    let mut push =
        |t: &Token| scan.globals.push(Global { name: t.text.clone(), line: line_of(t), kind: GlobalKind::Variable });
    push(name);
    let mut nest = 0;
    for k in p + 1..header.len() {
        let t = &header[k];
        if t.is("(") || t.is("[") || t.is("{") {
            nest += 1;
        } else if t.is(")") || t.is("]") || t.is("}") {
            nest -= 1;
        } else if nest == 0 && t.kind == Kind::Ident && header[k - 1].is(",") {
            push(t);
        }
    }
}

/// The parameter list between a function's parentheses, split at its top-level commas (`()` and `(void)`: none).
pub(super) fn split_params(tokens: &[Token]) -> Vec<Vec<String>> {
    if tokens.is_empty() || (tokens.len() == 1 && tokens[0].text == "void") {
        return Vec::new();
    }
    let mut params = vec![Vec::new()];
    let mut nest = 0;
    for t in tokens {
        if t.is("(") || t.is("[") {
            nest += 1;
        } else if t.is(")") || t.is("]") {
            nest -= 1;
        }
        if nest == 0 && t.is(",") {
            params.push(Vec::new());
        } else {
            params.last_mut().unwrap().push(t.text.clone());
        }
    }
    params
}

/// Token indices of struct members' names (`struct S { float a, b[2]; }`: `a`, `b`), which are reached after a
/// `.` and so are never renamed: an identifier in a struct body preceded by a type (or `,` or `]`) and followed
/// by `;`, `,` or `[`.
pub(super) fn struct_members(tokens: &[Token]) -> HashSet<usize> {
    let mut members = HashSet::new();
    for (s, t) in tokens.iter().enumerate() {
        if t.text != "struct" {
            continue;
        }
        let Some(open) = (s + 1..tokens.len().min(s + 3)).find(|&j| tokens[j].is("{")) else {
            continue;
        };
        let close = matching(tokens, open);
        for k in open + 1..close {
            let (prev, next) = (&tokens[k - 1], tokens.get(k + 1));
            let declarator = prev.kind == Kind::Ident || prev.is(",") || prev.is("]");
            if tokens[k].kind == Kind::Ident && declarator && next.is_some_and(|n| n.is(";") || n.is(",") || n.is("["))
            {
                members.insert(k);
            }
        }
    }
    members
}
