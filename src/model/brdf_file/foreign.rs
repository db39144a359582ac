//! A shader in HLSL or WGSL (`::begin shader hlsl|wgsl`, or a plain `.hlsl`/`.ush`/`.wgsl` file): its front end
//! (`crate::model::front`) compiles it to SPIR-V, with the file's parameters declared in the shader's own
//! language and each declared entry's call written in it, and spirv-cross brings it back as the GLSL that
//! every later step of this module reads as it reads a GLSL shader (renaming, composition into the kernels).
//! BRDF Explorer's entry and the declared entries are checked on the shader's own source, so that messages
//! name its files and lines.

use super::*;
use crate::model::front::{self, cross, hlsl, includes::Expanded, wgsl, Glue, GlueArg};

/// The shader's GLSL, numbered from 1, for the steps after this one; sets the file's loops, whether it
/// defines `BRDF`, each entry's glue function and the front end.
pub(super) fn translate(file: &mut BrdfFile) -> Result<Vec<(usize, String)>> {
    if let Some(p) = file.params.iter().find(|p| p.name.starts_with(front::GENERATED_PREFIX)) {
        bail!(at(&file.path, p.line, format!("`{}`: names starting with `{}` are brdfprof's own in an {} shader", p.name, front::GENERATED_PREFIX, file.language.name())));
    }
    let (spirv, source) = match file.language {
        Language::Hlsl => hlsl_spirv(file)?,
        _ => wgsl_spirv(file)?,
    };
    let text = cross::to_glsl(&spirv, &file.path)?;
    check_param_names(file, &text)?;
    let params: Vec<&str> = file.params.iter().map(|p| p.name.as_str()).collect();
    let glsl = cross::view(&text, &params, &file.path).map_err(|e| match e.downcast::<cross::Resource>() {
        Ok(r) => match locate(&source, &r.name) {
            Some(at) => anyhow!("{at}: {}", r.message()),
            None => anyhow!("{r}"),
        },
        Err(e) => e,
    })?;
    for (k, e) in file.entries.iter_mut().enumerate() {
        e.glue = Some(glue_name(k));
    }
    file.front_end = Some(front::describe(file.language));
    Ok(glsl.into_iter().enumerate().map(|(i, l)| (i + 1, l)).collect())
}

/// The shader's source lines with their files and lines (HLSL: with its includes), where a name is looked for.
type Source = Vec<(String, usize, String)>;

/// `FILE:LINE:COLUMN` of the first whole-word occurrence of `name` in `source`.
fn locate(source: &Source, name: &str) -> Option<String> {
    let ident = |c: char| c.is_ascii_alphanumeric() || c == '_';
    source.iter().find_map(|(f, n, text)| {
        let i = text.match_indices(name).map(|(i, _)| i).find(|&i| !text[..i].ends_with(ident) && !text[i + name.len()..].starts_with(ident))?;
        Some(format!("{f}:{n}:{}", text[..i].chars().count() + 1))
    })
}

/// spirv-cross writes a global named like a GLSL built-in function (`length`, `dot`) as `_NAME`: a parameter
/// of that name would then not be the composition's, so it is refused at its line.
fn check_param_names(file: &BrdfFile, glsl: &str) -> Result<()> {
    for p in &file.params {
        let escaped = format!("_{}", p.name);
        if glsl.lines().any(|l| cross::plain_declaration(l).is_some_and(|(_, n)| n == escaped)) {
            bail!(at(&file.path, p.line, format!("parameter `{}`: the name of a GLSL built-in, which the translation into GLSL renames (`{escaped}`); give the parameter another name", p.name)));
        }
    }
    Ok(())
}

fn glue_name(k: usize) -> String {
    format!("{}entry{k}", front::GENERATED_PREFIX)
}

/// The directory a model's own includes are found beside (empty for a bare file name: the working directory,
/// which messages then leave out).
fn model_dir(path: &Path) -> PathBuf {
    path.parent().map_or_else(PathBuf::new, Path::to_path_buf)
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
/// (`front::includes`), then each entry's glue and the stub. BRDF Explorer's entry and the declared entries are
/// checked on glslang's preprocessed text (where every macro and `#if` is resolved), at their files' lines.
fn hlsl_spirv(file: &mut BrdfFile) -> Result<(Vec<u32>, Source)> {
    let mut x = Expanded::new(&file.path);
    for p in &file.params {
        x.push(hlsl::param_decl(&p.name, p.glsl_type()), 0, p.line);
    }
    x.include_section(&model_dir(&file.path), &file.source, &file.includes)?;
    let pre = hlsl::preprocess(&x, &file.defines, &file.path)?.map_err(|m| anyhow!("{m}"))?;
    let glues = check_hlsl(file, &x, &pre)?;
    for (g, e) in glues.iter().zip(&file.entries) {
        x.push(hlsl::glue(g), 0, e.line);
    }
    x.push(hlsl::stub(&stub_calls(file, &glues)), 0, file.shader_begin);
    let spirv = hlsl::compile(&x, &file.defines, &file.path)?.map_err(|m| anyhow!("{m}"))?;
    let source = x.lines.iter().zip(&x.origins).map(|(l, &(f, n))| (x.files[f].clone(), n, l.clone())).collect();
    Ok((spirv, source))
}

/// On the preprocessed HLSL `pre` (line for line with `x`): the loops, `BRDF`'s signature, each entry
/// (`check_entry`, with HLSL's `float3`), and the glue of each.
fn check_hlsl(file: &mut BrdfFile, x: &Expanded, pre: &str) -> Result<Vec<Glue>> {
    let numbered: Vec<(usize, String)> = (1..=x.lines.len()).map(|n| (n, String::new())).collect();
    let lines = number_lines(&file.path, &numbered, pre.lines(), 1)?;
    let tokens = tokenize(&file.path, &lines)?;
    let scan = scan_globals(&file.path, &lines, &tokens)?;
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
    let brdf = globals::check_brdf(&scanned, file.shader_begin, &scan.globals, &globals::HLSL_SIGNATURE);
    file.defines_brdf = brdf.is_ok();
    if file.entries.is_empty() {
        brdf?;
    }
    let mut glues = Vec::new();
    for (k, e) in file.entries.iter().enumerate() {
        let types = globals::check_entry(&scanned, e, &scan.globals, &globals::HLSL_SIGNATURE)?;
        glues.push(glue(k, e, &types.into_iter().map(Some).collect::<Vec<_>>()));
    }
    Ok(glues)
}

/// The WGSL shader composed and compiled: the section, the parameters as private globals, each entry's glue
/// and the stub, through naga_oil and naga (`front::wgsl`).
fn wgsl_spirv(file: &mut BrdfFile) -> Result<(Vec<u32>, Source)> {
    let mut top = wgsl::Top::new(&file.source);
    for p in &file.params {
        top.push(&wgsl::param_decl(&p.name, p.glsl_type()), p.line, &format!("parameter `{}`", p.name));
    }
    let tokens = tokenize(&file.path, &file.source)?;
    file.loops = loops(&file.source, &tokens);
    file.defines_brdf = wgsl::defines_brdf(&file.source);
    if file.entries.is_empty() && !file.defines_brdf {
        bail!(at(&file.path, file.shader_begin, format!("the shader defines no function `BRDF` at global scope (brdfprof calls `{WGSL_BRDF}`)")));
    }
    let glues = wgsl_glues(file, &top)?;
    for (g, e) in glues.iter().zip(&file.entries) {
        top.push(&wgsl::glue(g), e.line, &format!("entry `{}`", e.name));
    }
    top.push(&wgsl::stub(&stub_calls(file, &glues)), file.shader_begin, &format!("the shader's `BRDF` as brdfprof calls it, `{WGSL_BRDF}`"));
    let module = wgsl::compose(&file.path, &top, &file.defines, &file.includes)?;
    let model = file.path.display().to_string();
    Ok((wgsl::emit_spirv(&module, &file.path)?, file.source.iter().map(|(n, l)| (model.clone(), *n, l.clone())).collect()))
}

const WGSL_BRDF: &str = "fn BRDF(L: vec3<f32>, V: vec3<f32>, N: vec3<f32>, X: vec3<f32>, Y: vec3<f32>) -> vec3<f32>";

/// Each entry's glue. An entry with `@out`/`@scratch` arguments needs its function's parameter types, read
/// from naga's module of the shader composed once without glue; any other is checked by naga at its call.
fn wgsl_glues(file: &BrdfFile, top: &wgsl::Top) -> Result<Vec<Glue>> {
    let mut glues = Vec::new();
    for (k, e) in file.entries.iter().enumerate() {
        globals::check_special_args(&file.path, e, "WGSL")?;
        let types = if e.args.iter().any(|a| a.starts_with('@')) { wgsl_types(file, top, e)? } else { Vec::new() };
        glues.push(glue(k, e, &types));
    }
    Ok(glues)
}

/// The types of entry `e`'s function's parameters, checked against its `@out`/`@scratch` arguments.
fn wgsl_types(file: &BrdfFile, top: &wgsl::Top, e: &Entry) -> Result<Vec<Option<String>>> {
    let fail = |m: String| anyhow!(at(&file.path, e.line, m));
    let found = wgsl::parameter_types(&file.path, top, &file.defines, &file.includes, &e.name)?;
    let types = found.ok_or_else(|| fail(format!("entry `{}`: neither the shader nor a module it imports defines a function `{}`", e.name, e.name)))?;
    if types.len() != e.args.len() {
        return Err(fail(format!("entry `{}` takes {} arguments and the declaration gives {}", e.name, types.len(), e.args.len())));
    }
    for (k, (a, t)) in e.args.iter().zip(&types).enumerate().filter(|(_, (a, _))| a.starts_with('@')) {
        match t.as_deref() {
            None => return Err(fail(format!("entry `{}`: parameter {} of `{a}` has a type brdfprof cannot declare (an array or a runtime-sized type)", e.name, k + 1))),
            Some(t) if a == globals::OUT_ARG && t != "vec3<f32>" => return Err(fail(format!("entry `{}`: the `{a}` parameter {} is `{t}`; the value is a vec3<f32>", e.name, k + 1))),
            _ => {}
        }
    }
    Ok(types)
}
