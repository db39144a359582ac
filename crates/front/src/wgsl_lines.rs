//! The user's file and line of each statement of a WGSL shader composed by naga_oil, for per-line cost: naga's
//! spans place every statement in the text naga parsed, naga_oil's composition tags each span with its module,
//! and naga's SPIR-V writer turns spans into `OpLine`s, which spirv-cross writes as `#line` directives.
//!
//! naga_oil keeps the spans of an imported module's items as (module index << `SPAN_SHIFT`) + the byte offset in
//! that module's naga input, which is the header it writes for the module's imports followed by the module's
//! preprocessed text (naga_oil 0.23, compose/mod.rs). The header's length is not exported, so each function
//! calibrates it: the function's span starts at its `fn` keyword and ends at its closing brace, which must both
//! be found in the preprocessed text at one offset; a function that does not calibrate (a later naga_oil laying
//! spans out otherwise) names no lines rather than wrong ones.

use naga_oil::compose::{Composer, ShaderDefValue};
use std::collections::{BTreeMap, HashMap};

/// naga_oil 0.23's `SPAN_SHIFT` (compose/mod.rs; not exported): the bits of a span's offset below the module index.
const SPAN_SHIFT: u32 = 21;

/// A user's file, line and the line's text (trimmed).
pub type Origin = (String, usize, String);

/// One module of the composition: the file as messages name it, its text as naga parsed it (the preprocessor
/// keeps every line in place), its own lines (ended as naga_oil ends them, a lone `\r` included), and the lines
/// of it that brdfprof wrote (no user line).
struct Module {
    file: String,
    parsed: String,
    lines: Vec<String>,
    generated: Vec<usize>,
    /// The byte offset of each line's start in `parsed`.
    starts: Vec<usize>,
}

impl Module {
    fn new(file: String, parsed: String, text: String, generated: Vec<usize>) -> Module {
        let starts = std::iter::once(0).chain(parsed.match_indices('\n').map(|(k, _)| k + 1)).collect();
        Module { file, parsed, lines: super::includes::split_lines(&text), generated, starts }
    }

    /// The 1-based line of byte `at` of `parsed`.
    fn line(&self, at: usize) -> usize {
        self.starts.partition_point(|&s| s <= at)
    }
}

/// Where the statements of a composed module lie in the user's files.
#[derive(Default)]
pub struct Places {
    modules: HashMap<usize, Module>,
}

impl Places {
    /// The places of a composition: `top` the shader brdfprof composed (file `shown`, with `generated` lines of
    /// its own), `defs` the shader defs it was composed with, `files` each imported module's file and text.
    pub fn new(
        composer: &Composer,
        (shown, top, generated): (&str, &str, Vec<usize>),
        defs: &HashMap<String, ShaderDefValue>,
        files: &[(String, String)],
    ) -> Places {
        let preprocessor = naga_oil::compose::preprocess::Preprocessor::default();
        let mut modules = HashMap::new();
        // naga_oil's make_naga_module: line ends made `\n`, the module's own `#define`s added to the defs.
        let mut sanitized = top.replace("\r\n", "\n").replace('\r', "\n");
        if !sanitized.ends_with('\n') {
            sanitized.push('\n');
        }
        if let Ok(meta) = preprocessor.get_preprocessor_metadata(&sanitized, true) {
            let mut all = defs.clone();
            all.extend(meta.defines);
            if let Ok(out) = preprocessor.preprocess(&meta.cleaned_source, &all) {
                let text = top.to_string();
                modules.insert(0, Module::new(shown.to_string(), out.preprocessed_source, text, generated));
            }
        }
        for (&index, name) in &composer.module_index {
            let Some(def) = composer.module_sets.get(name) else { continue };
            let Ok(out) = preprocessor.preprocess(&def.sanitized_source, defs) else { continue };
            let text = files.iter().find(|(f, _)| *f == def.file_path).map_or(&def.sanitized_source, |(_, t)| t);
            modules
                .insert(index, Module::new(def.file_path.clone(), out.preprocessed_source, text.clone(), Vec::new()));
        }
        Places { modules }
    }

    /// Gives every statement of `module` a span of its own line in a table instead of its place in naga's input:
    /// statement spans become `id..id + 1`, which naga's `Span::location` over the returned source (newlines only)
    /// writes as line `id + 1`. Returns that source and the table: `table[id]` the user's place of line `id + 1`,
    /// None for the statements of no user line (brdfprof's stub and glue, a function that does not calibrate).
    pub fn relabel(&self, module: &mut naga::Module) -> (String, Vec<Option<Origin>>) {
        let mut ids = Ids { table: vec![None], by_place: BTreeMap::new() };
        let handles: Vec<_> = module.functions.iter().map(|(h, _)| h).collect();
        for h in handles {
            let span = module.functions.get_span(h);
            let f = &mut module.functions[h];
            let place = f.name.as_deref().and_then(|name| self.calibrate(name, span));
            relabel_block(&mut f.body, &mut |s| match &place {
                Some((index, offset)) => ids.of(self, *index, *offset, s),
                None => 0,
            });
        }
        for e in &mut module.entry_points {
            relabel_block(&mut e.function.body, &mut |_| 0);
        }
        ("\n".repeat(ids.table.len() + 1), ids.table)
    }

    /// (module index, offset of its preprocessed text in naga's input) for function `name` (as the composed
    /// module names it) whose span is `span`: where its `fn` keyword and closing brace both lie at one offset.
    fn calibrate(&self, name: &str, span: naga::Span) -> Option<(usize, usize)> {
        let range = span.to_range()?;
        let index = range.start >> SPAN_SHIFT;
        if range.end >> SPAN_SHIFT != index {
            return None;
        }
        let (start, end) = (range.start & mask(), range.end & mask());
        let parsed = &self.modules.get(&index)?.parsed;
        let bare = name.split("X_naga_oil_mod_X").next().unwrap_or(name);
        let at = declaration(parsed, bare)?;
        let offset = start.checked_sub(at)?;
        let close = end.checked_sub(offset)?;
        (close >= 1 && parsed.as_bytes().get(close - 1) == Some(&b'}')).then_some((index, offset))
    }
}

fn mask() -> usize {
    (1 << SPAN_SHIFT) - 1
}

/// The byte offset of the `fn` of function `name`'s declaration in `text`.
fn declaration(text: &str, name: &str) -> Option<usize> {
    let ident = |c: char| c.is_ascii_alphanumeric() || c == '_';
    text.match_indices("fn").map(|(k, _)| k).find(|&k| {
        let rest = &text[k + 2..];
        !text[..k].ends_with(ident)
            && rest.starts_with(char::is_whitespace)
            && rest.trim_start().strip_prefix(name).is_some_and(|r| r.trim_start().starts_with('('))
    })
}

/// The table of places, each user line once.
struct Ids {
    table: Vec<Option<Origin>>,
    by_place: BTreeMap<(usize, usize), usize>,
}

impl Ids {
    /// The id of the line span `s` of module `index` (its text at `offset` in naga's input) lies on; 0 (no
    /// place) for an undefined span, another module's, or a line brdfprof wrote.
    fn of(&mut self, places: &Places, index: usize, offset: usize, s: naga::Span) -> usize {
        let Some(range) = s.to_range() else { return 0 };
        let Some(m) = places.modules.get(&index) else { return 0 };
        if range.start >> SPAN_SHIFT != index {
            return 0;
        }
        let Some(at) = (range.start & mask()).checked_sub(offset).filter(|&a| a <= m.parsed.len()) else {
            return 0;
        };
        let line = m.line(at);
        if m.generated.contains(&line) {
            return 0;
        }
        *self.by_place.entry((index, line)).or_insert_with(|| {
            let text = m.lines.get(line - 1).map_or("", |l| l.trim()).to_string();
            self.table.push(Some((m.file.clone(), line, text)));
            self.table.len() - 1
        })
    }
}

/// Sets the span of every statement of `block`, nested blocks included, to `id(its span)..+1`.
fn relabel_block(block: &mut naga::Block, id: &mut impl FnMut(naga::Span) -> usize) {
    use naga::Statement as S;
    for (statement, span) in block.span_iter_mut() {
        if let Some(span) = span {
            let k = id(*span) as u32;
            *span = naga::Span::new(k, k + 1);
        }
        match statement {
            S::Block(b) => relabel_block(b, id),
            S::If { accept, reject, .. } => {
                relabel_block(accept, id);
                relabel_block(reject, id);
            }
            S::Loop { body, continuing, .. } => {
                relabel_block(body, id);
                relabel_block(continuing, id);
            }
            S::Switch { cases, .. } => cases.iter_mut().for_each(|c| relabel_block(&mut c.body, id)),
            _ => {}
        }
    }
}
