//! A shader in HLSL or WGSL (`::begin shader hlsl|wgsl`, or a plain `.hlsl`/`.ush`/`.wgsl` file): its front end
//! (`crate::model::front`) compiles it to SPIR-V, with the file's parameters declared in the shader's own
//! language and each declared entry's call written in it, and spirv-cross brings it back as the GLSL that
//! every later step of this module reads as it reads a GLSL shader (renaming, composition into the kernels).
//! BRDF Explorer's entry and the declared entries are checked on the shader's own source, so that messages
//! name its files and lines.

use super::*;
use crate::model::front::{self, Glue, GlueArg, cross, hlsl, includes::Expanded, slang, wgsl};
use std::collections::HashMap;

/// The stack the front ends run on. naga's WGSL front end recurses once per operand of an expression (a
/// 20,000-term sum overflowed the main thread's 8 MiB and aborted the process); generated shaders (fitted
/// polynomials, tabulated lobes) reach such sizes. Only the pages used are ever touched.
const FRONT_END_STACK: usize = 1 << 30;

/// The shader's GLSL, numbered from 1, for the steps after this one; sets the file's loops, whether it
/// defines `BRDF`, each entry's glue function and the front end. Runs on a thread of its own with
/// `FRONT_END_STACK`.
pub(super) fn translate(file: &mut BrdfFile) -> Result<Vec<(usize, String)>> {
    std::thread::scope(|scope| {
        std::thread::Builder::new()
            .name("front end".into())
            .stack_size(FRONT_END_STACK)
            .spawn_scoped(scope, || translate_here(file))
            .map_err(|e| anyhow!("cannot start the front end's thread: {e}"))?
            .join()
            .unwrap_or_else(|panic| std::panic::resume_unwind(panic))
    })
}

fn translate_here(file: &mut BrdfFile) -> Result<Vec<(usize, String)>> {
    if let Some(p) = file.params.iter().find(|p| p.name.starts_with(front::GENERATED_PREFIX)) {
        bail!(at(
            &file.path,
            p.line,
            format!(
                "`{}`: names starting with `{}` are brdfprof's own in an {} shader",
                p.name,
                front::GENERATED_PREFIX,
                file.language.name()
            )
        ));
    }
    check_reserved_names(file)?;
    check_param_spelling(file)?;
    // `places[k]`: the user's place of SPIR-V line k + 1 (the expanded HLSL's lines; a WGSL statement's own).
    let (spirv, source, mut places, front_end) = match file.language {
        Language::Hlsl => {
            let (spirv, source, front_end) = hlsl_spirv(file)?;
            let places = source.iter().cloned().map(Some).collect();
            (spirv, source, places, front_end)
        }
        Language::Glsl => {
            let (spirv, source) = glsl_spirv(file)?;
            let places = source.iter().cloned().map(Some).collect();
            (spirv, source, places, Some(front::glsl::describe()))
        }
        Language::Slang => {
            let (spirv, source) = slang_language_spirv(file)?;
            let places = source.iter().cloned().map(Some).collect();
            (spirv, source, places, None)
        }
        _ => {
            let (spirv, source, places) = wgsl_spirv(file)?;
            (spirv, source, places, None)
        }
    };
    let text = cross::to_glsl(&spirv, &file.path)?;
    let at = match file.language {
        Language::Slang => module_places(&cross::line_files(&spirv, &text, &file.path)?, &mut places),
        _ => cross::line_origins(&spirv, &text, &file.path)?,
    };
    check_param_names(file, &text)?;
    let params: Vec<&str> = file.params.iter().map(|p| p.name.as_str()).collect();
    let glsl = cross::view(&text, &params, &file.path).map_err(|e| match e.downcast::<cross::Resource>() {
        Ok(r) => match locate(&source, r.declared()) {
            Some(at) => anyhow!("{at}: {}", r.message()),
            None => anyhow!("{r}"),
        },
        Err(e) => e,
    })?;
    for (k, e) in file.entries.iter_mut().enumerate() {
        e.glue = Some(glue_name(k));
    }
    let replaced: Vec<String> =
        file.includes.overrides.iter().map(|(n, f)| format!("`{n}` by {}", f.display())).collect();
    let replaced =
        if replaced.is_empty() { String::new() } else { format!("; headers replaced: {}", replaced.join(", ")) };
    file.front_end = Some(front_end.unwrap_or_else(|| front::describe(file.language)) + &replaced);
    file.front_end_origins = origins(&text, &at, &glsl, &places);
    Ok(glsl.into_iter().enumerate().map(|(i, l)| (i + 1, l)).collect())
}

/// The user's file, line and text of each line of `view` (the kept lines of spirv-cross's output `plain`, in
/// order, each as it was there): `at[k]` is the SPIR-V's line of `plain`'s line k, `places` the user's place of
/// each SPIR-V line. A line `view` moved (an initialiser) or spirv-cross wrote without a location has none.
fn origins(
    plain: &str,
    at: &[Option<usize>],
    view: &[String],
    places: &[Option<(String, usize, String)>],
) -> Vec<Option<std::sync::Arc<(String, usize, String)>>> {
    if at.is_empty() {
        return Vec::new();
    }
    let shared: Vec<Option<std::sync::Arc<(String, usize, String)>>> = places
        .iter()
        .map(|p| {
            p.as_ref().map(|(file, line, text)| std::sync::Arc::new((file.clone(), *line, text.trim().to_string())))
        })
        .collect();
    let lines: Vec<&str> = plain.lines().collect();
    let mut next = 0;
    view.iter()
        .map(|v| {
            let k = (next..lines.len()).find(|&k| lines[k] == v)?;
            next = k + 1;
            shared.get(at[k]?.checked_sub(1)?)?.clone()
        })
        .collect()
}

/// Refuses a name of the section's code starting with `brdfprof_` (in any case): brdfprof writes such names into
/// the shader (its stub, the entries' glue, the include guards), where the user's would clash with them.
/// `#include` and `#import` lines name files, not identifiers.
fn check_reserved_names(file: &BrdfFile) -> Result<()> {
    let code: Vec<(usize, String)> = file
        .source
        .iter()
        .map(|(n, l)| {
            (
                *n,
                if l.trim_start().starts_with("#include") || l.trim_start().starts_with("#import") {
                    String::new()
                } else {
                    l.clone()
                },
            )
        })
        .collect();
    let tokens =
        if file.language == Language::Wgsl { tokenize_wgsl(&file.path, &code)? } else { tokenize(&file.path, &code)? };
    let place = |t: &Token| {
        let (n, text) = &code[t.line];
        format!("{}:{n}:{}", file.path.display(), text[..t.start].chars().count() + 1)
    };
    let reserved =
        |t: &&Token| t.kind == Kind::Ident && t.text.to_ascii_lowercase().starts_with(front::GENERATED_PREFIX);
    if let Some(t) = tokens.iter().find(reserved) {
        bail!(
            "{}: `{}`: names starting with `{}` (in any case) are brdfprof's own (the stub, glue and include guards it writes into the shader); give it another name",
            place(t),
            t.text,
            front::GENERATED_PREFIX
        )
    }
    // Storage one invocation shares with its workgroup: the kernels run the model once per invocation with no
    // barrier, so such a variable would be read while others write it (and a translation loses its zeroing).
    let shared = |(k, t): &(usize, &Token)| {
        t.kind == Kind::Ident
            && match file.language {
                Language::Wgsl => t.text == "workgroup" && *k > 0 && tokens[*k - 1].text == "<",
                _ => t.text == "groupshared",
            }
    };
    if let Some((_, t)) = tokens.iter().enumerate().find(shared) {
        bail!(
            "{}: `{}` storage is shared by a workgroup's invocations, which brdfprof's kernels run as independent evaluations with no barrier; make it a local (function) variable",
            place(t),
            t.text
        )
    }
    Ok(())
}

/// Refuses, at its declaration, a parameter name the translation into GLSL would rename, so that the value
/// brdfprof binds could never reach it: GLSL reserves names with two underscores in a row and `gl_`, and
/// spirv-cross names its own temporaries `_N`.
fn check_param_spelling(file: &BrdfFile) -> Result<()> {
    for p in &file.params {
        let why = if p.name.contains("__") {
            "GLSL reserves names with two underscores in a row"
        } else if p.name.starts_with("gl_") {
            "GLSL reserves names starting with `gl_`"
        } else if p.name.strip_prefix('_').is_some_and(|d| !d.is_empty() && d.bytes().all(|b| b.is_ascii_digit())) {
            "spirv-cross names its own temporaries `_N`"
        } else {
            continue;
        };
        bail!(at(
            &file.path,
            p.line,
            format!(
                "parameter `{}`: the translation into GLSL would rename it ({why}), so its value would never arrive; give the parameter another name",
                p.name
            )
        ));
    }
    Ok(())
}

/// The shader's source lines with their files and lines (HLSL: with its includes), where a name is looked for.
type Source = Vec<(String, usize, String)>;

/// `FILE:LINE:COLUMN` of the first whole-word occurrence of `name` in `source`'s code (not in a comment).
fn locate(source: &Source, name: &str) -> Option<String> {
    let ident = |c: char| c.is_ascii_alphanumeric() || c == '_';
    let code = front::includes::code_lines(&source.iter().map(|(_, n, text)| (*n, text.clone())).collect::<Vec<_>>());
    source.iter().zip(code).find_map(|((f, n, _), code)| {
        let text = code.text;
        let i = text
            .match_indices(name)
            .map(|(i, _)| i)
            .find(|&i| !text[..i].ends_with(ident) && !text[i + name.len()..].starts_with(ident))?;
        Some(format!("{f}:{n}:{}", text[..i].chars().count() + 1))
    })
}

/// spirv-cross writes a global named like a GLSL built-in function (`length`, `dot`) as `_NAME`: a parameter
/// of that name would then not be the composition's, so it is refused at its line.
fn check_param_names(file: &BrdfFile, glsl: &str) -> Result<()> {
    for p in &file.params {
        let escaped = format!("_{}", p.name);
        let declares = |name: &str| glsl.lines().any(|l| cross::plain_declaration(l).is_some_and(|(_, n)| n == name));
        // Renamed only where its own name is gone: a shader global `_x` beside parameter `x` is no renaming.
        if !declares(&p.name) && declares(&escaped) {
            bail!(at(
                &file.path,
                p.line,
                format!(
                    "parameter `{}`: the name of a GLSL built-in, which the translation into GLSL renames (`{escaped}`); give the parameter another name",
                    p.name
                )
            ));
        }
    }
    Ok(())
}

fn glue_name(k: usize) -> String {
    format!("{}entry{k}", front::GENERATED_PREFIX)
}

/// The functions the stub calls: `BRDF` where the shader defines it, and every glue function.
fn stub_calls(file: &BrdfFile, glues: &[Glue]) -> Vec<String> {
    file.defines_brdf.then(|| "BRDF".to_string()).into_iter().chain(glues.iter().map(|g| g.name.clone())).collect()
}

/// The glue of entry `k` given its parameters' types (`types[i]` for each `@out`/`@scratch` argument).
fn glue(k: usize, e: &Entry, types: &[Option<String>]) -> Glue {
    let args = e.args.iter().enumerate().map(|(i, a)| {
        let ty = || types.get(i).cloned().flatten().unwrap_or_default();
        match a.as_str() {
            globals::OUT_ARG => GlueArg::Out(ty()),
            globals::SCRATCH_ARG => GlueArg::Scratch(ty()),
            expr => GlueArg::Expr(expr.to_string()),
        }
    });
    Glue { name: glue_name(k), callee: e.name.clone(), args: args.collect() }
}

/// The HLSL shader compiled: the parameters as `static` globals, the section with its includes
/// (`front::includes`; each `#line` dropped with a warning, as in a GLSL shader), then each entry's glue and
/// the stub, each line brdfprof writes named by what it stands for in messages. BRDF Explorer's entry and the
/// declared entries are checked on glslang's preprocessed text (where every macro and `#if` is resolved), at
/// their files' lines. Where glslang refuses the shader (or crashes), Slang's slangc compiles it with a stub of
/// its own (`slang`), and the front end's description says so (the third value).
fn hlsl_spirv(file: &mut BrdfFile) -> Result<(Vec<u32>, Source, Option<String>)> {
    let mut x = Expanded::new(&file.path);
    for p in &file.params {
        if hlsl::is_keyword(&p.name) {
            bail!(at(
                &file.path,
                p.line,
                format!(
                    "parameter `{}`: a keyword of HLSL (glslang's HLSL front end reads it as one), so no variable of the shader can be named so; give the parameter another name",
                    p.name
                )
            ));
        }
        x.push_generated(hlsl::param_decl(&p.name, p.glsl_type()), p.line, format!("parameter `{}`", p.name));
    }
    x.include_section(&file.path, &file.source, &file.includes)?;
    for (f, n, text) in &x.dropped {
        file.warnings.push(dropped_hash_line(Path::new(&x.files[*f]), *n, text));
    }
    let pre = hlsl::preprocess(&x, &file.defines, &file.path)?.map_err(|m| anyhow!("{m}"))?;
    let pre = narrow_overloads(file, &mut x, &pre)?;
    let glues = check_hlsl(file, &x, &pre)?;
    for (g, e) in glues.iter().zip(&file.entries) {
        x.push_generated(hlsl::glue(g), e.line, format!("entry `{}`", e.name));
    }
    let calls = stub_calls(file, &glues);
    x.push_generated(
        hlsl::stub(&calls),
        file.shader_begin,
        format!("the shader's `BRDF` as brdfprof calls it, `{}`", globals::HLSL_SIGNATURE.text),
    );
    let (spirv, front_end) = match file.hlsl_front_end {
        HlslFrontEnd::Slang => slang_spirv(file, &x, &calls, None)?,
        HlslFrontEnd::Glslang => (hlsl::compile(&x, &file.defines, &file.path)?.map_err(|m| anyhow!("{m}"))?, None),
        HlslFrontEnd::Auto => match hlsl::compile(&x, &file.defines, &file.path)? {
            Ok(words) => (words, None),
            Err(refused) => slang_spirv(file, &x, &calls, Some(&refused))?,
        },
    };
    let source = x.lines.iter().zip(&x.origins).map(|(l, &(f, n))| (x.files[f].clone(), n, l.clone())).collect();
    Ok((spirv, source, front_end))
}

/// A Slang shader compiled by slangc as Slang: the parameters as `static` globals, the section with its
/// `#include`s expanded (`--include-override` and `--include-map` as for HLSL; `import`ed modules are slangc's
/// to find, in the model's folder and the include directories), each entry's glue and the stub. slangc's own
/// preprocessor reads the text (variadic macros, `__VA_ARGS__`); `BRDF` and the entries are checked on the
/// text with its directives blanked, as slangc's preprocessor writes no line-for-line text to read them on (a
/// `BRDF` a macro defines is not seen: declare entries for it).
fn slang_language_spirv(file: &mut BrdfFile) -> Result<(Vec<u32>, Source)> {
    let mut x = Expanded::new(&file.path);
    for p in &file.params {
        if hlsl::is_keyword(&p.name) {
            bail!(at(
                &file.path,
                p.line,
                format!("parameter `{}`: a keyword of Slang's HLSL syntax; give the parameter another name", p.name)
            ));
        }
        x.push_generated(hlsl::param_decl(&p.name, p.glsl_type()), p.line, format!("parameter `{}`", p.name));
    }
    x.include_section(&file.path, &file.source, &file.includes)?;
    for (f, n, text) in &x.dropped {
        file.warnings.push(dropped_hash_line(Path::new(&x.files[*f]), *n, text));
    }
    let code = front::includes::code_lines(&x.lines.iter().cloned().enumerate().collect::<Vec<_>>());
    let mut continued = false;
    let blanked: Vec<String> = x
        .lines
        .iter()
        .zip(&code)
        .map(|(l, c)| {
            let directive = continued || c.text.trim_start().starts_with('#');
            continued = directive && l.trim_end().ends_with('\\');
            if directive { String::new() } else { l.clone() }
        })
        .collect();
    let glues = check_hlsl(file, &x, &(blanked.join("\n") + "\n"))?;
    for (g, e) in glues.iter().zip(&file.entries) {
        x.push_generated(hlsl::glue(g), e.line, format!("entry `{}`", e.name));
    }
    let calls = stub_calls(file, &glues);
    x.push_generated(
        slang::stub(&calls),
        file.shader_begin,
        format!("the shader's `BRDF` as brdfprof calls it, `{}`", globals::HLSL_SIGNATURE.text),
    );
    let search: Vec<PathBuf> =
        std::iter::once(front::dir_of(&file.path)).chain(file.includes.dirs.iter().cloned()).collect();
    let spirv = match slang::compile(&x, &file.defines, &file.path, slang::Dialect::Slang, &search)? {
        Some(Ok(words)) => words,
        Some(Err(messages)) => bail!("{messages}\n(Slang's slangc refused the shader)"),
        None => bail!(
            "{}: a Slang shader needs Slang's slangc, which is not installed: run `make setup`",
            file.path.display()
        ),
    };
    let source = x.lines.iter().zip(&x.origins).map(|(l, &(f, n))| (x.files[f].clone(), n, l.clone())).collect();
    Ok((spirv, source))
}

/// The SPIR-V line of each line of spirv-cross's output as an index into `places` (1-based), from the file and
/// line slangc's line table gives it (`named`): the expanded text's lines are `places`' own; a module slangc
/// imported has its lines appended, each with its text as the file has it.
fn module_places(
    named: &[Option<(String, usize)>],
    places: &mut Vec<Option<(String, usize, String)>>,
) -> Vec<Option<usize>> {
    let mut added: HashMap<(String, usize), usize> = HashMap::new();
    let mut texts: HashMap<String, Vec<String>> = HashMap::new();
    named
        .iter()
        .map(|n| {
            let (file, line) = n.as_ref()?;
            if file.starts_with(slang::MAIN_NAME) {
                return Some(*line);
            }
            if let Some(&k) = added.get(&(file.clone(), *line)) {
                return Some(k);
            }
            let lines = texts.entry(file.clone()).or_insert_with(|| {
                crate::io::read_bounded(Path::new(file), crate::io::MAX_INPUT_BYTES)
                    .map(|b| String::from_utf8_lossy(&b).lines().map(str::to_string).collect())
                    .unwrap_or_default()
            });
            let text = lines.get(line.checked_sub(1)?)?.clone();
            places.push(Some((file.clone(), *line, text)));
            added.insert((file.clone(), *line), places.len());
            Some(places.len())
        })
        .collect()
}

/// DXC's minimum-precision overloads that collide once 32-bit (`front::overloads`): each dropped from the
/// text both front ends compile (its lines replaced by their preprocessed text with the definition blanked),
/// said once at its file's line. Returns the preprocessed text the checks read, line for line with `x`.
fn narrow_overloads(file: &BrdfFile, x: &mut Expanded, pre: &str) -> Result<String> {
    let numbered: Vec<(usize, String)> = (1..=x.lines.len()).map(|n| (n, String::new())).collect();
    let lines = number_lines(&file.path, &numbered, pre.lines(), 1)?;
    let text: String = lines.iter().map(|(_, l)| format!("{l}\n")).collect();
    let Some((out, dropped)) = front::overloads::drop_narrow_collisions(&text) else { return Ok(pre.to_string()) };
    for ((n, old), new) in lines.iter().zip(out.lines()) {
        if old != new {
            x.lines[n - 1] = new.to_string();
        }
    }
    for d in dropped {
        let k = text[..d.offset].matches('\n').count();
        let (f, line) = lines.get(k).and_then(|(n, _)| x.origin(n - 1)).unwrap_or(("?", 0));
        crate::messages::input_note(format!("{f}:{line}: {}", d.note));
    }
    Ok(out)
}

/// The shader compiled by Slang's slangc, chosen (`refused` None: `hlsl-front-end=slang`) or after glslang
/// refused it (`refused`: glslang's messages), with the front end's description; an error with both front ends'
/// messages where slangc refuses it too, or naming `make setup` where slangc is not installed.
fn slang_spirv(
    file: &BrdfFile,
    x: &Expanded,
    calls: &[String],
    refused: Option<&str>,
) -> Result<(Vec<u32>, Option<String>)> {
    let mut s = x.clone();
    if let Some(stub) = s.lines.last_mut() {
        *stub = front::slang::stub(calls);
    }
    let compiled = front::slang::compile(&s, &file.defines, &file.path, slang::Dialect::Hlsl, &[])?;
    let Some(refused) = refused else {
        let chosen = format!("{}=slang", HlslFrontEnd::KEY);
        return match compiled {
            Some(Ok(words)) => Ok((
                words,
                Some(format!("HLSL: {} (chosen: {chosen}); {}", front::slang::describe(), cross::describe())),
            )),
            Some(Err(slang)) => bail!("{slang}\n(Slang's slangc, chosen by {chosen}, refused the shader)"),
            None => bail!(
                "{}: {chosen}: Slang's slangc is not installed: run `make setup` (or leave the choice to brdfprof: glslang, then slangc where it is installed)",
                file.path.display()
            ),
        };
    };
    let first = refused.lines().next().unwrap_or_default();
    match compiled {
        Some(Ok(words)) => {
            crate::messages::note_once(format!(
                "{}: glslang's HLSL front end refused the shader ({first}); Slang's slangc compiled it",
                file.path.display()
            ));
            let described = format!(
                "HLSL: {} (glslang refused the shader: {first}); {}",
                front::slang::describe(),
                cross::describe()
            );
            Ok((words, Some(described)))
        }
        Some(Err(slang)) => bail!("{refused}\n(Slang's slangc, tried after glslang, refused the shader too:\n{slang})"),
        None => bail!(
            "{refused}\n(glslang's HLSL front end refused the shader; Slang's slangc, which takes DXC-era HLSL, is not installed: run `make setup`)"
        ),
    }
}

/// On the preprocessed HLSL `pre` (line for line with `x`): the loops, `BRDF`'s signature, each entry
/// (`check_entry`, with HLSL's `float3`), and the glue of each.
fn check_hlsl(file: &mut BrdfFile, x: &Expanded, pre: &str) -> Result<Vec<Glue>> {
    Ok(check_expanded(file, x, pre, &globals::HLSL_SIGNATURE)?.glues)
}

/// What the checks of an expanded text read: its preprocessed lines, their tokens and globals, and the glue.
struct Checked {
    lines: Vec<(usize, String)>,
    tokens: Vec<Token>,
    scan: Scan,
    glues: Vec<Glue>,
}

/// `check_hlsl` in the language of `sig`.
fn check_expanded(file: &mut BrdfFile, x: &Expanded, pre: &str, sig: &globals::Signature) -> Result<Checked> {
    let numbered: Vec<(usize, String)> = (1..=x.lines.len()).map(|n| (n, String::new())).collect();
    let lines = number_lines(&file.path, &numbered, pre.lines(), 1)?;
    // The directives the preprocessor passes through (`#version`, `#extension`, `#pragma`) are no declarations.
    let code: Vec<(usize, String)> = (lines.iter())
        .map(|(n, l)| (*n, if l.trim_start().starts_with('#') { String::new() } else { l.clone() }))
        .collect();
    let tokens = tokenize(&file.path, &code)?;
    let scan = scan_globals(&file.path, &code, &tokens)?;
    let model = file.path.display().to_string();
    let origin = |n: usize| x.origin(n.saturating_sub(1)).map_or((model.clone(), n), |(f, l)| (f.to_string(), l));
    file.loops = loops(&lines, &tokens)
        .into_iter()
        .map(|l| {
            let (f, line) = origin(l.line);
            Loop { file: (f != model).then_some(f), line, ..l }
        })
        .collect();
    let path = file.path.clone();
    let scanned = globals::Lines { path: &path, origin: Some(&origin) };
    let brdf = globals::check_brdf(&scanned, file.shader_begin, &scan.globals, sig);
    file.defines_brdf = brdf.is_ok();
    if file.entries.is_empty() {
        brdf?;
    }
    let mut glues = Vec::new();
    for (k, e) in file.entries.iter().enumerate() {
        let types = globals::check_entry(&scanned, e, &scan.globals, sig)?;
        glues.push(glue(k, e, &types.into_iter().map(Some).collect::<Vec<_>>()));
    }
    Ok(Checked { lines, tokens, scan, glues })
}

/// A GLSL shader that includes files: the version line, the parameters as globals, the section with its
/// includes expanded (`front::includes`), glslang's preprocessor, the checks on its text (as HLSL's), each
/// entry's glue and the `main` stub, compiled by glslang's GLSL front end (`front::glsl`). A `uniform` or a
/// stage's `in`/`out` qualifier is dropped from a global as in a GLSL shader composed as written, said at its
/// file's line.
fn glsl_spirv(file: &mut BrdfFile) -> Result<(Vec<u32>, Source)> {
    let mut x = Expanded::new(&file.path);
    x.push_generated(front::glsl::VERSION, file.shader_begin, "the kernel's `#version 450`");
    for p in &file.params {
        x.push_generated(front::glsl::param_decl(&p.name, p.glsl_type()), p.line, format!("parameter `{}`", p.name));
    }
    x.include_section(&file.path, &file.source, &file.includes)?;
    for (f, n, text) in &x.dropped {
        file.warnings.push(dropped_hash_line(Path::new(&x.files[*f]), *n, text));
    }
    let pre = front::glsl::preprocess(&x, &file.defines, &file.path)?.map_err(|m| anyhow!("{m}"))?;
    let checked = check_expanded(file, &x, &pre, &globals::GLSL_SIGNATURE)?;
    let mut lines: Vec<String> = checked.lines.iter().map(|(_, l)| l.clone()).collect();
    let place = |k: usize| x.origin(k).map_or_else(|| file.path.display().to_string(), |(f, l)| format!("{f}:{l}"));
    let line_of_global = |name: &str| {
        checked.tokens.iter().find(|t| t.kind == Kind::Ident && t.text == name).map(|t| t.line).unwrap_or(0)
    };
    for (_, name) in &checked.scan.uniforms {
        file.warnings.push(format!("{}: `uniform` dropped from `{name}`: Vulkan GLSL has no uniforms outside blocks, so it is a private global nothing sets (declare it as a parameter instead)", place(line_of_global(name))));
    }
    for (_, qualifier, name) in &checked.scan.interface {
        file.warnings.push(format!("{}: `{qualifier}` dropped from `{name}`: a fragment or vertex stage's interface, not the BRDF's inputs (brdfprof calls the BRDF function with N, V, L and its parameters), so it is a private global here", place(line_of_global(name))));
    }
    // Dropped from the last token of a line to the first, so that earlier byte ranges stay valid.
    let mut dropped: Vec<&Token> = checked.scan.uniform_tokens.iter().map(|&i| &checked.tokens[i]).collect();
    dropped.sort_by_key(|t| std::cmp::Reverse((t.line, t.start)));
    for t in dropped {
        lines[t.line].replace_range(t.start..t.end, &" ".repeat(t.end - t.start));
    }
    let mut compiled = x.clone();
    compiled.lines = lines;
    compiled.lines[0] = front::glsl::VERSION.to_string();
    for (g, e) in checked.glues.iter().zip(&file.entries) {
        compiled.push_generated(front::glsl::glue(g), e.line, format!("entry `{}`", e.name));
    }
    let calls = stub_calls(file, &checked.glues);
    compiled.push_generated(
        front::glsl::stub(&calls),
        file.shader_begin,
        format!("the shader's `BRDF` as brdfprof calls it, `{}`", globals::GLSL_SIGNATURE.text),
    );
    let spirv = front::glsl::compile(&compiled, &file.defines, &file.path)?.map_err(|m| anyhow!("{m}"))?;
    // The user's lines as written (before the preprocessor), then the lines brdfprof wrote.
    let source = (compiled.lines.iter().enumerate().zip(&compiled.origins))
        .map(|((k, l), &(f, n))| (compiled.files[f].clone(), n, x.lines.get(k).unwrap_or(l).clone()))
        .collect();
    Ok((spirv, source))
}

/// The WGSL shader's SPIR-V, its lines (as messages locate a declaration) and the user's place of each SPIR-V
/// line (`wgsl::emit_spirv`).
type WgslSpirv = (Vec<u32>, Source, Vec<Option<(String, usize, String)>>);

/// The WGSL shader composed and compiled: the section, the parameters as private globals, each entry's glue
/// and the stub, through naga_oil and naga (`front::wgsl`). The shader with its parameters alone is composed
/// first: `BRDF`'s signature and the entries' parameter types are read from naga's module of it.
fn wgsl_spirv(file: &mut BrdfFile) -> Result<WgslSpirv> {
    check_statement_sizes(file)?;
    let mut top = wgsl::Top::new(&file.source);
    for p in &file.params {
        top.push(&wgsl::param_decl(&p.name, p.glsl_type()), p.line, &format!("parameter `{}`", p.name));
    }
    let bare = wgsl::compose(&file.path, &top, &file.defines, &file.includes)?;
    file.defines_brdf = check_wgsl_brdf(file, &top, &bare.module)?;
    let glues = wgsl_glues(file, &top, &bare.module)?;
    for (g, e) in glues.iter().zip(&file.entries) {
        top.push(&wgsl::glue(g), e.line, &format!("entry `{}`", e.name));
    }
    top.push(
        &wgsl::stub(&stub_calls(file, &glues)),
        file.shader_begin,
        &format!("the shader's `BRDF` as brdfprof calls it, `{WGSL_BRDF}`"),
    );
    let composed = wgsl::compose_placed(&file.path, &top, &file.defines, &file.includes)?;
    file.loops = wgsl_loops_of(file, &top, &composed)?;
    let model = file.path.display().to_string();
    let (spirv, places) = wgsl::emit_spirv(&composed, &file.path)?;
    Ok((spirv, file.source.iter().map(|(n, l)| (model.clone(), *n, l.clone())).collect(), places))
}

/// The most operators (and opening brackets) one WGSL statement may hold: naga's front end recurses once per
/// operand, so this bounds the stack it needs to well within `FRONT_END_STACK` (a 100,000-term sum parsed, and
/// lavapipe compiled it in 68 s on the 2-core VM of docs/limits.md).
const MAX_STATEMENT_OPERATORS: usize = 200_000;

/// Refuses a statement of the WGSL section larger than `MAX_STATEMENT_OPERATORS` at the line it starts on.
fn check_statement_sizes(file: &BrdfFile) -> Result<()> {
    let (mut count, mut start) = (0usize, None);
    for (n, line) in &file.source {
        for c in line.split("//").next().unwrap_or("").chars() {
            match c {
                ';' | '{' | '}' => (count, start) = (0, None),
                '+' | '-' | '*' | '/' | '%' | '&' | '|' | '^' | '<' | '>' | '(' | '[' | ',' => {
                    count += 1;
                    let first = *start.get_or_insert(*n);
                    if count > MAX_STATEMENT_OPERATORS {
                        bail!(at(
                            &file.path,
                            first,
                            format!(
                                "a statement of more than {MAX_STATEMENT_OPERATORS} operators: brdfprof's WGSL front end (naga) takes at most that many in one statement; split it"
                            )
                        ));
                    }
                }
                _ => {}
            }
        }
    }
    Ok(())
}

const WGSL_BRDF: &str = "fn BRDF(L: vec3<f32>, V: vec3<f32>, N: vec3<f32>, X: vec3<f32>, Y: vec3<f32>) -> vec3<f32>";

/// Whether the shader defines `BRDF` with BRDF Explorer's signature in WGSL (five `vec3<f32>` to a
/// `vec3<f32>`, as naga's module `bare` types it). Without entries it must: a `BRDF` of another signature is
/// refused at its `fn` (FILE:LINE:COLUMN), a shader without one at the section's first line.
fn check_wgsl_brdf(file: &BrdfFile, top: &wgsl::Top, bare: &naga::Module) -> Result<bool> {
    let vec3 = Some("vec3<f32>".to_string());
    let found = wgsl::signature(bare, "BRDF");
    if found
        .as_ref()
        .is_some_and(|(params, result)| params.len() == 5 && params.iter().all(|(_, t)| *t == vec3) && *result == vec3)
    {
        return Ok(true);
    }
    if !file.entries.is_empty() {
        return Ok(false);
    }
    let Some((params, result)) = found else {
        bail!(at(
            &file.path,
            file.shader_begin,
            format!("the shader defines no function `BRDF` at global scope (brdfprof calls `{WGSL_BRDF}`)")
        ));
    };
    let shown = |t: &Option<String>| t.clone().unwrap_or_else(|| "?".into());
    let params: Vec<String> = params.iter().map(|(n, t)| format!("{n}: {}", shown(t))).collect();
    let actual =
        format!("fn BRDF({}){}", params.join(", "), result.as_ref().map_or(String::new(), |r| format!(" -> {r}")));
    let lines: Vec<(usize, String)> = wgsl::preprocessed(&top.text, &file.defines, &file.path)
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.to_string()))
        .collect();
    let tokens = tokenize_wgsl(&file.path, &lines)?;
    let at_fn = tokens
        .windows(2)
        .find(|w| w[0].text == "fn" && w[1].text == "BRDF")
        .map(|w| (lines[w[0].line].0, lines[w[0].line].1[..w[0].start].chars().count() + 1));
    let (line, column) = at_fn.unwrap_or((file.shader_begin, 1));
    bail!(
        "{}:{line}:{column}: `BRDF` must be defined as `{WGSL_BRDF}`; the shader's is `{actual}`",
        file.path.display()
    )
}

/// The WGSL shader's loops and those of the modules it imports, each at its own file and line, read from
/// naga_oil's preprocessed text (an `#ifdef` branch not taken has none); a module's only in the functions the
/// composition kept (naga_oil leaves out the imported functions nothing calls).
fn wgsl_loops_of(file: &BrdfFile, top: &wgsl::Top, composed: &wgsl::Composed) -> Result<Vec<Loop>> {
    let model = file.path.display().to_string();
    let kept = wgsl::function_names(&composed.module);
    let mut out = Vec::new();
    for (k, (shown, text)) in
        std::iter::once((&model, &top.text)).chain(composed.files.iter().map(|(f, t)| (f, t))).enumerate()
    {
        let lines: Vec<(usize, String)> = wgsl::preprocessed(text, &file.defines, &file.path)
            .lines()
            .enumerate()
            .map(|(i, l)| (i + 1, l.to_string()))
            .collect();
        let tokens = tokenize_wgsl(Path::new(shown), &lines)?;
        for (l, function) in wgsl_loops(&lines, &tokens) {
            if k == 0 || function.is_some_and(|f| kept.contains(&f)) {
                out.push(Loop { file: (k > 0).then(|| shown.clone()), ..l });
            }
        }
    }
    Ok(out)
}

/// Each entry's glue. An entry with `@out`/`@scratch` arguments needs its function's parameter types, read
/// from naga's module of the shader composed without glue (`bare`); any other is checked by naga at its call.
fn wgsl_glues(file: &BrdfFile, top: &wgsl::Top, bare: &naga::Module) -> Result<Vec<Glue>> {
    let mut glues = Vec::new();
    for (k, e) in file.entries.iter().enumerate() {
        globals::check_special_args(&file.path, e, "WGSL")?;
        let types =
            if e.args.iter().any(|a| a.starts_with('@')) { wgsl_types(file, top, bare, e)? } else { Vec::new() };
        glues.push(glue(k, e, &types));
    }
    Ok(glues)
}

/// The types of entry `e`'s function's parameters, checked against its `@out`/`@scratch` arguments.
fn wgsl_types(file: &BrdfFile, top: &wgsl::Top, bare: &naga::Module, e: &Entry) -> Result<Vec<Option<String>>> {
    let fail = |m: String| anyhow!(at(&file.path, e.line, m));
    let found = wgsl::parameter_types(&file.path, top, bare, &file.defines, &file.includes, &e.name)?;
    let types = found.ok_or_else(|| {
        fail(format!("entry `{}`: neither the shader nor a module it imports defines a function `{}`", e.name, e.name))
    })?;
    if types.len() != e.args.len() {
        return Err(fail(format!(
            "entry `{}` takes {} arguments and the declaration gives {}",
            e.name,
            types.len(),
            e.args.len()
        )));
    }
    for (k, (a, t)) in e.args.iter().zip(&types).enumerate().filter(|(_, (a, _))| a.starts_with('@')) {
        match t.as_deref() {
            None => {
                return Err(fail(format!(
                    "entry `{}`: parameter {} of `{a}` has a type brdfprof cannot declare (an array or a runtime-sized type)",
                    e.name,
                    k + 1
                )));
            }
            Some(t) if a == globals::OUT_ARG && t != "vec3<f32>" => {
                return Err(fail(format!(
                    "entry `{}`: the `{a}` parameter {} is `{t}`; the value is a vec3<f32>",
                    e.name,
                    k + 1
                )));
            }
            _ => {}
        }
    }
    Ok(types)
}
