//! WGSL through naga_oil and naga (Bevy's own toolchain): naga_oil resolves `#import`, `#ifdef`/`#else`/`#endif`
//! and `#define_import_path` (the modules found in the include directories, a quoted import as a path like an
//! HLSL include), with `--define`s as its shader defs; naga validates the module and writes SPIR-V with its
//! runtime checks off (no index clamping, no loop bounding: `emit_spirv`), which spirv-cross brings back as
//! GLSL. Messages come back at FILE:LINE:COLUMN as naga_oil locates them (its preprocessor keeps every line in
//! place); lines brdfprof appends to the shader (parameters, glue, stub) name what they came from.

use super::{Glue, Includes, STUB};
use anyhow::{Context, Result, anyhow, bail};
use naga_oil::compose::{
    ComposableModuleDescriptor, Composer, ComposerError, NagaModuleDescriptor, ShaderDefValue, ShaderLanguage,
    ShaderType,
};
use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};

/// The search for modules under the include directories: this many folders deep, this many folders and `.wgsl`
/// files at most (beyond either, the search stops with an error naming the folder), and the first
/// `MODULE_HEAD` bytes of each file scanned for its `#define_import_path` (Bevy's modules declare it in their
/// first lines), so a large file nothing imports is never read whole.
const MAX_DEPTH: usize = 8;
const MAX_DIRS: usize = 10_000;
const MAX_FILES: usize = 20_000;
const MODULE_HEAD: u64 = 1 << 20;

/// The shader naga_oil composes: the model's section at its own line numbers (blank lines before it), then
/// the lines brdfprof appends, each with the model file's line it stands for and what it is.
#[derive(Clone, Debug, Default)]
pub struct Top {
    pub text: String,
    pub lines: usize,
    /// 1-based line of the text -> (the model file's line, what it is).
    pub generated: BTreeMap<usize, (usize, String)>,
}

impl Top {
    /// The section `lines` (numbered as in the model file) at their own line numbers.
    pub fn new(lines: &[(usize, String)]) -> Self {
        let mut top = Top::default();
        for (n, l) in lines {
            while top.lines + 1 < *n {
                top.text.push('\n');
                top.lines += 1;
            }
            top.text += l;
            top.text.push('\n');
            top.lines += 1;
        }
        top
    }

    /// Appends a generated line standing for the model file's line `origin`.
    pub fn push(&mut self, text: &str, origin: usize, what: &str) {
        self.text += text;
        self.text.push('\n');
        self.lines += 1;
        self.generated.insert(self.lines, (origin, what.to_string()));
    }
}

/// A parameter as a WGSL module-scope private variable of its type.
pub fn param_decl(name: &str, glsl_type: &str) -> String {
    let ty = match glsl_type {
        "vec3" => "vec3<f32>",
        "float" => "f32",
        other => other,
    };
    format!("var<private> {name}: {ty};")
}

/// A glue function on one line (`hlsl::glue`'s WGSL form): an `@out`/`@scratch` argument is a pointer to a
/// local of the parameter's type, starting at its zero value.
pub fn glue(g: &Glue) -> String {
    let signature =
        format!("fn {}(L: vec3<f32>, V: vec3<f32>, N: vec3<f32>, X: vec3<f32>, Y: vec3<f32>) -> vec3<f32>", g.name);
    g.write(&signature, |ty, l| format!("var {l}: {ty} = {ty}(); "), |l| format!("&{l}"))
}

/// The compute entry that calls each of `calls`, on one line.
pub fn stub(calls: &[String]) -> String {
    let body: String = calls.iter().map(|c| format!(" v += {c}(v, v, v, v, v);")).collect();
    format!("@compute @workgroup_size(1) fn {STUB}() {{ var v = vec3<f32>(0.0);{body} }}")
}

/// `--define`s as naga_oil's shader defs: NAME alone is true; a value is `true`, `false`, an integer (i32), or
/// one with a `u` suffix (u32). naga_oil's `#ifdef NAME` asks only whether NAME is defined, so `NAME=false`
/// takes an `#ifdef NAME` branch too (as Bevy's `ShaderDefVal::Bool(_, false)` does); it is for `#if NAME ==
/// false`.
pub fn shader_defs(defines: &[(String, String)], model: &Path) -> Result<HashMap<String, ShaderDefValue>> {
    defines
        .iter()
        .map(|(n, v)| {
            let value = match v.as_str() {
                "" | "true" => ShaderDefValue::Bool(true),
                "false" => ShaderDefValue::Bool(false),
                v => match (v.parse::<i32>(), v.strip_suffix('u').map(str::parse::<u32>)) {
                    (Ok(i), _) => ShaderDefValue::Int(i),
                    (_, Some(Ok(u))) => ShaderDefValue::UInt(u),
                    _ => bail!("{}: define {n}={v}: a WGSL shader def is true, false, an integer or an integer with a `u` suffix (naga_oil's ShaderDefValue)", model.display()),
                },
            };
            Ok((n.clone(), value))
        })
        .collect()
}

/// A walk of include directories for `.wgsl` files: the folders entered (by device and inode, so a symbolic
/// link back to a folder already entered, or a loop of them, is not walked again) and the files found.
#[derive(Default)]
struct Walk {
    entered: std::collections::HashSet<(u64, u64)>,
    files: Vec<PathBuf>,
}

impl Walk {
    /// Every `.wgsl` file under `dir` (to `MAX_DEPTH`, skipping hidden entries; the empty directory is the
    /// working one, whose files are named without `./`), in sorted order; Err past `MAX_DIRS` or `MAX_FILES`.
    fn add(&mut self, dir: &Path, depth: usize, root: &Path) -> Result<()> {
        use std::os::unix::fs::MetadataExt;
        let at = if dir.as_os_str().is_empty() { Path::new(".") } else { dir };
        let Ok(meta) = std::fs::metadata(at) else { return Ok(()) };
        if !self.entered.insert((meta.dev(), meta.ino())) {
            return Ok(());
        }
        if self.entered.len() > MAX_DIRS {
            bail!(
                "{}: the search for WGSL modules entered more than {MAX_DIRS} folders (at most {MAX_DEPTH} deep) under it; name a narrower include folder",
                super::shown_dir(root)
            );
        }
        let Ok(entries) = std::fs::read_dir(at) else { return Ok(()) };
        let named = |p: PathBuf| {
            if dir.as_os_str().is_empty() { p.strip_prefix(".").map(Path::to_path_buf).unwrap_or(p) } else { p }
        };
        let mut paths: Vec<PathBuf> = entries
            .filter_map(|e| e.ok().map(|e| named(e.path())))
            .filter(|p| !p.file_name().is_some_and(|n| n.to_string_lossy().starts_with('.')))
            .collect();
        paths.sort();
        for p in paths {
            if p.extension().is_some_and(|e| e == "wgsl") && p.is_file() {
                if self.files.len() >= MAX_FILES {
                    bail!(
                        "{}: more than {MAX_FILES} .wgsl files under it to search for modules; name a narrower include folder",
                        super::shown_dir(root)
                    );
                }
                self.files.push(p);
            } else if depth < MAX_DEPTH && p.is_dir() {
                self.add(&p, depth + 1, root)?;
            }
        }
        Ok(())
    }
}

fn read_text(path: &Path) -> Result<String> {
    String::from_utf8(crate::io::read_input(path)?)
        .map_err(|e| anyhow!("{} is not UTF-8 text (byte {})", path.display(), e.utf8_error().valid_up_to()))
}

/// The module `path` declares with `#define_import_path`, from its first `MODULE_HEAD` bytes (whole lines).
fn declared_module(path: &Path) -> Option<String> {
    use std::io::Read;
    let (file, _) = crate::io::open_regular(path).ok()?;
    let mut head = Vec::new();
    file.take(MODULE_HEAD).read_to_end(&mut head).ok()?;
    if head.len() as u64 == MODULE_HEAD {
        head.truncate(head.iter().rposition(|&b| b == b'\n').unwrap_or(0));
    }
    naga_oil::compose::get_preprocessor_data(&String::from_utf8_lossy(&head)).0
}

/// The modules the include directories (recursively) and the model's own directory declare with
/// `#define_import_path NAME`: NAME -> every file that declares it, in that order (an import of a name two
/// files declare is refused, naming both). Built when an import first names a module, so a shader that
/// imports none (or only quoted paths) never walks a folder.
struct ModuleIndex<'a> {
    model_dir: PathBuf,
    includes: &'a Includes,
    built: std::cell::OnceCell<BTreeMap<String, Vec<PathBuf>>>,
}

impl<'a> ModuleIndex<'a> {
    fn new(model_dir: &Path, includes: &'a Includes) -> Self {
        ModuleIndex { model_dir: model_dir.to_path_buf(), includes, built: Default::default() }
    }

    fn get(&self) -> Result<&BTreeMap<String, Vec<PathBuf>>> {
        if let Some(index) = self.built.get() {
            return Ok(index);
        }
        let mut walk = Walk::default();
        for d in &self.includes.dirs {
            walk.add(d, 0, d)?;
        }
        walk.add(&self.model_dir, MAX_DEPTH, &self.model_dir)?;
        let mut index: BTreeMap<String, Vec<PathBuf>> = BTreeMap::new();
        for f in walk.files {
            if let Some(name) = declared_module(&f) {
                index.entry(name).or_default().push(f);
            }
        }
        Ok(self.built.get_or_init(|| index))
    }
}

/// The file an import names: a quoted path as a quoted HLSL include is found (`Includes::find`, beside the
/// importing file `dir`), a module name through the index.
fn resolve(import: &str, dir: &Path, includes: &Includes, index: &ModuleIndex) -> Result<Option<PathBuf>> {
    let Some(path) = import.strip_prefix('"').and_then(|p| p.strip_suffix('"')) else {
        // `a::b::item` names item of module `a::b`: the longest prefix that is a module.
        let index = index.get()?;
        let mut name = import;
        loop {
            match index.get(name).map(Vec::as_slice) {
                Some([one]) => return Ok(Some(one.clone())),
                Some([a, b, ..]) => bail!(
                    "`{name}` is declared by two modules, {} and {} (`#define_import_path {name}`); brdfprof will not pick one: keep one of them out of the include directories and the model's folder",
                    a.display(),
                    b.display()
                ),
                _ => {}
            }
            let Some((prefix, _)) = name.rsplit_once("::") else { return Ok(None) };
            name = prefix;
        }
    };
    Ok(includes.find(path, Some(dir)))
}

/// The 1-based line and column where `text` imports `import` (its `#import` line), else 1:1.
fn import_at(text: &str, import: &str) -> (usize, usize) {
    let key = import.trim_matches('"').rsplit("::").last().unwrap_or(import);
    text.lines()
        .enumerate()
        .find(|(_, l)| l.trim_start().starts_with("#import") && l.contains(key))
        .map_or((1, 1), |(i, l)| (i + 1, l.find(key).unwrap_or(0) + 1))
}

/// naga_oil composition state: the composer and the modules added or being added.
struct Modules<'a> {
    composer: Composer,
    includes: &'a Includes,
    index: ModuleIndex<'a>,
    added: Vec<String>,
    stack: Vec<String>,
    /// Each module's file as messages name it, and its text, in the order added.
    files: Vec<(String, String)>,
    /// The shader defs given (`--define`, `define=`).
    defs: HashMap<String, ShaderDefValue>,
}

impl Modules<'_> {
    /// Adds the modules `text` (the file `shown`, in directory `dir`) imports, each after its own imports; an
    /// import found nowhere is left for naga_oil to report where it is live.
    fn add_imports_of(&mut self, text: &str, shown: &str, dir: &Path) -> Result<()> {
        for import in naga_oil::compose::get_preprocessor_data(text).1.into_iter().map(|i| i.import) {
            if self.added.contains(&import) {
                continue;
            }
            if let Some(k) = self.stack.iter().position(|s| *s == import) {
                let (line, col) = import_at(text, &import);
                bail!("{shown}:{line}:{col}: import cycle: {} -> {import}", self.stack[k..].join(" -> "));
            }
            let found = resolve(&import, dir, self.includes, &self.index).map_err(|e| {
                let (line, col) = import_at(text, &import);
                anyhow!("{shown}:{line}:{col}: {e:#}")
            })?;
            let Some(path) = found else { continue };
            let source = read_text(&path).map_err(|e| {
                let (line, col) = import_at(text, &import);
                anyhow!("{shown}:{line}:{col}: {e:#}")
            })?;
            // naga_oil names the module by it in its messages: no control character of a file name there.
            let file = crate::messages::escape_line(&path.display().to_string());
            self.stack.push(import.clone());
            self.add_imports_of(&source, &file, &super::dir_of(&path))?;
            self.stack.pop();
            let as_name = import.starts_with('"').then(|| import.clone());
            let desc = ComposableModuleDescriptor {
                source: &source,
                file_path: &file,
                language: ShaderLanguage::Wgsl,
                as_name,
                ..Default::default()
            };
            if let Err(e) = self.composer.add_composable_module(desc) {
                let graph: Vec<(String, String)> =
                    self.files.iter().cloned().chain([(file.clone(), source.clone())]).collect();
                bail!("{}{}", located(&e, &self.composer, None, &graph), missing_defs_note(&graph, &self.defs));
            }
            self.added.push(import);
            self.files.push((file, source));
        }
        Ok(())
    }
}

/// A naga_oil error as `FILE:LINE:COLUMN: message` (from its codespan report's `┌─ FILE:LINE:COLUMN` line),
/// a generated line of `top` named by what it stands for.
fn located(e: &ComposerError, composer: &Composer, top: Option<(&str, &Top)>, files: &[(String, String)]) -> String {
    let report = e.emit_to_string(composer);
    let message = report.lines().find_map(|l| l.strip_prefix("error: ")).unwrap_or("").trim().to_string();
    let notes: Vec<&str> = report.lines().filter_map(|l| l.trim().strip_prefix("= ")).collect();
    let labels: Vec<&str> = report
        .lines()
        .filter_map(|l| l.split_once('^').map(|(_, r)| r.trim_start_matches('^').trim()))
        .filter(|l| !l.is_empty())
        .collect();
    let Some(at) = report.lines().find_map(|l| l.split_once("┌─ ").map(|(_, r)| r.trim().to_string())) else {
        let user = |l: &usize, f: &str| top.is_none_or(|(shown, t)| f != shown || !t.generated.contains_key(l));
        return cause(&report, files, user).unwrap_or_else(|| report.trim().to_string());
    };
    let mut parts = at.rsplitn(3, ':');
    let (col, line, file) = (
        parts.next().unwrap_or("1"),
        parts.next().and_then(|l| l.parse::<usize>().ok()).unwrap_or(1),
        parts.next().unwrap_or(""),
    );
    let mut detail: Vec<&str> = labels.into_iter().chain(notes).filter(|d| *d != message).collect();
    detail.dedup();
    let tail = if detail.is_empty() { String::new() } else { format!(" ({})", detail.join("; ")) };
    match top.filter(|(shown, _)| *shown == file).and_then(|(_, t)| t.generated.get(&line)) {
        Some((origin, what)) => format!("{file}:{origin}:1: {what}: {message}{tail}"),
        None => format!("{file}:{line}:{col}: {message}{tail}"),
    }
}

/// Builtins a compute kernel has no derivatives for: the derivatives and implicit-derivative sampling.
const DERIVATIVES: [&str; 12] = [
    "dpdx",
    "dpdy",
    "fwidth",
    "dpdxCoarse",
    "dpdxFine",
    "dpdyCoarse",
    "dpdyFine",
    "fwidthCoarse",
    "fwidthFine",
    "textureSample",
    "textureSampleBias",
    "textureSampleCompare",
];

/// The cause in the user's text of a naga error that names no location (a validation error of the composed
/// module, a parser failure), as `FILE:LINE:COLUMN: message` with naga's own words beside it: a derivative
/// (naga: "Uses operations forbidden at this stage"), an array sized by an `override` (naga: "... Override is
/// either not present, or inaccessible yet"), the most deeply nested parentheses (naga's parser: "internal WGSL
/// front end error"). `user(line, file)` says whether a line is the user's (not brdfprof's own).
fn cause(report: &str, files: &[(String, String)], user: impl Fn(&usize, &str) -> bool) -> Option<String> {
    let naga = report.lines().find_map(|l| l.strip_prefix("error: ")).unwrap_or("").trim();
    let code = |line: &str| line.split("//").next().unwrap_or("").to_string();
    let lines = || {
        files
            .iter()
            .flat_map(|(f, t)| t.lines().enumerate().map(move |(i, l)| (f.as_str(), i + 1, l)))
            .filter(|(f, n, _)| user(n, f))
    };
    let at = |f: &str, n: usize, l: &str, k: usize| format!("{f}:{n}:{}", l[..k].chars().count() + 1);
    let call = |l: &str, name: &str| {
        let ident = |c: char| c.is_ascii_alphanumeric() || c == '_';
        l.match_indices(name)
            .map(|(k, _)| k)
            .find(|&k| !l[..k].ends_with(ident) && l[k + name.len()..].trim_start().starts_with('('))
    };
    if report.contains("Uses operations forbidden at this stage") {
        return lines().find_map(|(f, n, l)| {
            let l = code(l);
            DERIVATIVES.iter().find_map(|d| call(&l, d).map(|k| (d, k))).map(|(d, k)| {
                format!("{}: `{d}` needs a fragment stage's derivatives, and brdfprof runs the BRDF in a compute kernel, which has none; pass the value in as a parameter (naga: the compute stage forbids the operation)", at(f, n, &l, k))
            })
        });
    }
    if report.contains("Override is either not present") {
        let overrides: Vec<String> = lines()
            .filter_map(|(_, _, l)| {
                code(l)
                    .trim_start()
                    .strip_prefix("override ")
                    .map(|r| r.trim_start().chars().take_while(|c| c.is_ascii_alphanumeric() || *c == '_').collect())
            })
            .collect();
        return lines().find_map(|(f, n, l)| {
            let l = code(l);
            let k = l.find("array<")?;
            let size = l[k..].split('>').next()?.rsplit(',').next()?.trim().to_string();
            overrides.contains(&size).then(|| {
                format!("{}: `{}>` is sized by the override `{size}`, which naga cannot size an array by here; make `{size}` a `const` (naga: {naga})", at(f, n, &l, k), l[k..].split('>').next().unwrap_or(""))
            })
        });
    }
    if report.contains("internal WGSL front end error") {
        let deepest = lines()
            .map(|(f, n, l)| {
                let (mut depth, mut max, mut where_) = (0usize, 0usize, 0usize);
                for (k, c) in l.char_indices() {
                    match c {
                        '(' => {
                            depth += 1;
                            if depth > max {
                                (max, where_) = (depth, k);
                            }
                        }
                        ')' => depth = depth.saturating_sub(1),
                        _ => {}
                    }
                }
                (max, f, n, l, where_)
            })
            .max_by_key(|(max, ..)| *max)?;
        let (max, f, n, l, k) = deepest;
        return (max > 0).then(|| {
            format!("{}: an expression nested {max} parentheses deep, past the depth naga's WGSL parser handles; split it into `let`s (naga: {naga})", at(f, n, l, k))
        });
    }
    None
}

/// The shader defs `files` (name, text) use and `defs` lacks, each at its first use: `#if NAME ...` (naga_oil
/// refuses an unknown def there) and `#{NAME}` (left in the text unsubstituted); `#ifdef`/`#ifndef` read an
/// absent def as false, so they need none. Each as (NAME, `FILE:LINE:COLUMN \`use\``).
fn missing_defs(files: &[(String, String)], defs: &HashMap<String, ShaderDefValue>) -> Vec<(String, String)> {
    let ident = |t: &str| t.chars().take_while(|c| c.is_ascii_alphanumeric() || *c == '_').collect::<String>();
    let mut out: Vec<(String, String)> = Vec::new();
    for (file, text) in files {
        for (i, line) in text.lines().enumerate() {
            let mut uses: Vec<(usize, String)> = Vec::new();
            let trimmed = line.trim_start();
            let directive = trimmed.strip_prefix("#else").map_or(trimmed, str::trim_start);
            if let Some(rest) = directive.strip_prefix("#if").filter(|r| r.starts_with([' ', '\t'])) {
                let name = ident(rest.trim_start());
                let col = line.len() - rest.trim_start().len();
                uses.push((col, name));
            }
            for (k, _) in line.match_indices("#{") {
                uses.push((k + 2, ident(&line[k + 2..])));
            }
            for (col, name) in uses {
                if !name.is_empty() && !defs.contains_key(&name) && !out.iter().any(|(n, _)| *n == name) {
                    let at = format!("{file}:{}:{} `{}`", i + 1, line[..col].chars().count() + 1, line.trim());
                    out.push((name, at));
                }
            }
        }
    }
    out
}

/// A message's tail naming the shader defs the import graph uses and no define gives, with the flag to pass.
fn missing_defs_note(files: &[(String, String)], defs: &HashMap<String, ShaderDefValue>) -> String {
    let missing = missing_defs(files, defs);
    if missing.is_empty() {
        return String::new();
    }
    let uses: Vec<String> = missing.iter().map(|(n, at)| format!("{n} ({at})")).collect();
    let flags: Vec<String> = missing.iter().map(|(n, _)| format!("--define {n}=VALUE")).collect();
    format!(
        "; shader defs the shader and its imports use that no define gives: {}; pass {}",
        uses.join(", "),
        flags.join(" ")
    )
}

/// A composed shader: naga's module, and the files of the modules it imports (as messages name them, with
/// their text).
pub struct Composed {
    pub module: naga::Module,
    pub files: Vec<(String, String)>,
    /// Where its statements lie in the user's files (`compose_placed`; none from `compose`).
    pub places: super::wgsl_lines::Places,
}

/// naga_oil's composition of `top` (the model's section plus brdfprof's lines) under `defines`, its imports
/// found through `includes` and the model's directory: the naga module, or Err(messages at FILE:LINE:COLUMN).
pub fn compose(model: &Path, top: &Top, defines: &[(String, String)], includes: &Includes) -> Result<Composed> {
    compose_with(model, top, (defines, includes), false)
}

/// `compose`, with the places of its statements in the user's files (`Composed::places`), which `emit_spirv`
/// numbers for per-line cost.
pub fn compose_placed(model: &Path, top: &Top, defines: &[(String, String)], includes: &Includes) -> Result<Composed> {
    compose_with(model, top, (defines, includes), true)
}

fn compose_with(
    model: &Path,
    top: &Top,
    (defines, includes): (&[(String, String)], &Includes),
    placed: bool,
) -> Result<Composed> {
    let model_dir = super::dir_of(model);
    let shader_defs = shader_defs(defines, model)?;
    let shown = model.display().to_string();
    let mut m = Modules {
        composer: Composer::default().with_capabilities(SHADER_CAPABILITIES),
        includes,
        index: ModuleIndex::new(&model_dir, includes),
        added: Vec::new(),
        stack: Vec::new(),
        files: Vec::new(),
        defs: shader_defs.clone(),
    };
    m.add_imports_of(&top.text, &shown, &model_dir)?;
    let desc = NagaModuleDescriptor {
        source: &top.text,
        file_path: &shown,
        shader_type: ShaderType::Wgsl,
        shader_defs,
        additional_imports: &[],
    };
    let module = m.composer.make_naga_module(desc).map_err(|e| {
        let hint = match e.inner {
            naga_oil::compose::ComposerErrorInner::ImportNotFound(..) => format!("; brdfprof looks for a module's `#define_import_path` in the .wgsl files of {}, and for a quoted import as for an HLSL include (beside the importing file, in the include directories, under a mapped prefix)", searched(&model_dir, includes)),
            _ => String::new(),
        };
        let graph: Vec<(String, String)> = std::iter::once((shown.clone(), top.text.clone())).chain(m.files.clone()).collect();
        anyhow!("{}{hint}{}", located(&e, &m.composer, Some((&shown, top)), &graph), missing_defs_note(&graph, &m.defs))
    })?;
    let places = match placed {
        true => {
            let generated = top.generated.keys().copied().collect();
            super::wgsl_lines::Places::new(&m.composer, (&shown, &top.text, generated), &m.defs, &m.files)
        }
        false => Default::default(),
    };
    Ok(Composed { module, files: m.files, places })
}

/// What naga may accept in a user's WGSL: its defaults (multisampled shading, cube array textures) and `enable f16` (the kernels run where the device has
/// shaderFloat16, as for a GLSL model's fp16, `Model::check_support`).
const SHADER_CAPABILITIES: naga::valid::Capabilities = naga::valid::Capabilities::SHADER_FLOAT16
    .union(naga::valid::Capabilities::MULTISAMPLED_SHADING)
    .union(naga::valid::Capabilities::CUBE_ARRAY_TEXTURES);

/// The directories searched for modules, as a message lists them.
fn searched(model_dir: &Path, includes: &Includes) -> String {
    let mut dirs: Vec<String> = includes.dirs.iter().map(|d| format!("{} (and below)", d.display())).collect();
    dirs.push(super::shown_dir(model_dir));
    dirs.join(", ")
}

/// `text` through naga_oil's preprocessor under `defines`: `#ifdef` branches not taken and directives blanked,
/// line for line (the text itself where it does not preprocess, which composing it has reported).
pub fn preprocessed(text: &str, defines: &[(String, String)], model: &Path) -> String {
    let defs = shader_defs(defines, model).unwrap_or_default();
    naga_oil::compose::preprocess::Preprocessor::default()
        .preprocess(text, &defs)
        .map_or_else(|_| text.to_string(), |p| p.preprocessed_source)
}

/// The module's SPIR-V for its stub entry: naga's validation, `override`s at their defaults, and naga's SPIR-V
/// writer with every name kept (`DEBUG`), no index clamping (`Unchecked`, naga's default) and no loop
/// bounding; integer division keeps WGSL's defined result for a zero divisor (naga's wrapper). Each statement
/// carries an `OpLine` whose line is its index in the returned table of the user's places
/// (`wgsl_lines::Places::relabel`).
pub fn emit_spirv(composed: &Composed, model: &Path) -> Result<(Vec<u32>, Vec<Option<super::wgsl_lines::Origin>>)> {
    use naga::valid::{ValidationFlags, Validator};
    let module = &composed.module;
    let what = model.display();
    let info = Validator::new(ValidationFlags::all(), SHADER_CAPABILITIES)
        .validate(module)
        .map_err(|e| anyhow!("{what}: naga's validation: {}", e.emit_to_string("")))?;
    let (module, info) = naga::back::pipeline_constants::process_overrides(module, &info, None, &Default::default())
        .map_err(|e| anyhow!("{what}: the overrides at their defaults: {e}"))?;
    let mut module = module.into_owned();
    let (lines, table) = composed.places.relabel(&mut module);
    let file_name = model.display().to_string();
    let options = naga::back::spv::Options {
        flags: naga::back::spv::WriterFlags::DEBUG,
        force_loop_bounding: false,
        debug_info: Some(naga::back::spv::DebugInfo {
            source_code: &lines,
            file_name: &file_name,
            language: naga::back::spv::SourceLanguage::Unknown,
        }),
        ..Default::default()
    };
    let pipeline =
        naga::back::spv::PipelineOptions { shader_stage: naga::ShaderStage::Compute, entry_point: STUB.to_string() };
    let words = naga::back::spv::write_vec(&module, &info, &options, Some(&pipeline))
        .with_context(|| format!("{what}: naga's SPIR-V writer"))?;
    Ok((words, table))
}

/// A naga type as WGSL writes it (scalars, vectors, matrices, structs by their undecorated name).
fn type_text(module: &naga::Module, ty: naga::Handle<naga::Type>) -> Option<String> {
    use naga::{ScalarKind as K, TypeInner as T};
    let scalar = |s: naga::Scalar| match (s.kind, s.width) {
        (K::Float, 4) => Some("f32"),
        (K::Float, 2) => Some("f16"),
        (K::Sint, 4) => Some("i32"),
        (K::Uint, 4) => Some("u32"),
        (K::Bool, _) => Some("bool"),
        _ => None,
    };
    let t = &module.types[ty];
    match t.inner {
        T::Scalar(s) => scalar(s).map(str::to_string),
        T::Vector { size, scalar: s } => Some(format!("vec{}<{}>", size as u8, scalar(s)?)),
        T::Matrix { columns, rows, scalar: s } => Some(format!("mat{}x{}<{}>", columns as u8, rows as u8, scalar(s)?)),
        T::Struct { .. } => t.name.as_deref().map(undecorated),
        T::Pointer { base, .. } => type_text(module, base),
        _ => None,
    }
}

/// A naga_oil item name without its module decoration (`fooX_naga_oil_mod_XABCX` -> `foo`).
fn undecorated(name: &str) -> String {
    name.split("X_naga_oil_mod_X").next().unwrap_or(name).to_string()
}

/// A function's parameters (name, WGSL type where `type_text` writes one; a pointer as its pointee) and its
/// result type, as naga's module has them.
pub type Signature = (Vec<(String, Option<String>)>, Option<String>);

/// The signature of function `callee` (its last path segment, undecorated) in `module`; None when there is no
/// such function.
pub fn signature(module: &naga::Module, callee: &str) -> Option<Signature> {
    let name = callee.rsplit("::").next().unwrap_or(callee);
    let f = module
        .functions
        .iter()
        .map(|(_, f)| f)
        .find(|f| f.name.as_deref().map(undecorated).as_deref() == Some(name))?;
    let params = f.arguments.iter().map(|a| (a.name.clone().unwrap_or_default(), type_text(module, a.ty))).collect();
    Some((params, f.result.as_ref().and_then(|r| type_text(module, r.ty))))
}

/// The undecorated names of `module`'s functions: what the composition kept.
pub fn function_names(module: &naga::Module) -> std::collections::HashSet<String> {
    module.functions.iter().filter_map(|(_, f)| f.name.as_deref().map(undecorated)).collect()
}

/// The parameter types of `callee` (as `signature`), a function of the shader composed as `bare` or of a
/// module the shader `top` imports: naga_oil keeps only the imported functions a shader calls, so each
/// imported module is composed on its own to find it there.
pub fn parameter_types(
    model: &Path,
    top: &Top,
    bare: &naga::Module,
    defines: &[(String, String)],
    includes: &Includes,
    callee: &str,
) -> Result<Option<Vec<Option<String>>>> {
    let types = |m: &naga::Module| signature(m, callee).map(|(p, _)| p.into_iter().map(|(_, t)| t).collect());
    if let Some(t) = types(bare) {
        return Ok(Some(t));
    }
    let model_dir = super::dir_of(model);
    let index = ModuleIndex::new(&model_dir, includes);
    for import in declared_imports(&top.text) {
        let Some(path) = resolve(&import, &model_dir, includes, &index)? else { continue };
        let lines: Vec<(usize, String)> =
            read_text(&path)?.lines().enumerate().map(|(i, l)| (i + 1, l.to_string())).collect();
        if let Some(t) = types(&compose(&path, &Top::new(&lines), defines, includes)?.module) {
            return Ok(Some(t));
        }
    }
    Ok(None)
}

/// The module paths of `text`'s `#import` lines, used or not (naga_oil's own list holds the used ones):
/// `#import a::b::{x, y}` -> `a::b`, `#import a::b::x` -> `a::b::x` (`resolve` finds its module), a quoted path
/// as written.
fn declared_imports(text: &str) -> Vec<String> {
    text.lines()
        .filter_map(|l| l.trim_start().strip_prefix("#import"))
        .filter_map(|rest| {
            let rest = rest.trim();
            let path = match rest.find('{') {
                Some(b) => rest[..b].trim().trim_end_matches("::"),
                None => rest.split_whitespace().next().unwrap_or(""),
            };
            (!path.is_empty()).then(|| path.to_string())
        })
        .collect()
}

/// The front end, with versions, as reports state it.
pub fn describe() -> String {
    "naga_oil 0.23.0 (#import, #ifdef, #define_import_path), naga 30.0.1 (wgsl-in, validation, spv-out without index clamping or loop bounding)".to_string()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::GlueArg;

    /// The version Cargo.lock pins for `package`.
    fn locked(package: &str) -> String {
        let lock = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/../../Cargo.lock")).unwrap();
        let entry =
            lock.split("[[package]]").find(|e| e.lines().any(|l| l.trim() == format!("name = \"{package}\""))).unwrap();
        entry.lines().find_map(|l| l.trim().strip_prefix("version = \"")).unwrap().trim_end_matches('"').to_string()
    }

    #[test]
    fn generated_text() {
        let g = Glue {
            name: "brdfprof_entry0".into(),
            callee: "lighting::direct".into(),
            args: vec![GlueArg::Expr("N".into()), GlueArg::Out("vec3<f32>".into())],
        };
        assert_eq!(
            glue(&g),
            "fn brdfprof_entry0(L: vec3<f32>, V: vec3<f32>, N: vec3<f32>, X: vec3<f32>, Y: vec3<f32>) -> vec3<f32> { var brdfprof_arg1: vec3<f32> = vec3<f32>(); lighting::direct(N, &brdfprof_arg1); return brdfprof_arg1; }"
        );
        assert_eq!(param_decl("f0", "vec3"), "var<private> f0: vec3<f32>;");
        let top = Top::new(&[(3, "fn BRDF(L: vec3<f32>) {}".into()), (5, "x".into())]);
        assert_eq!((top.text.as_str(), top.lines), ("\n\nfn BRDF(L: vec3<f32>) {}\n\nx\n", 5));
        let defs = shader_defs(
            &[("A".into(), "".into()), ("B".into(), "-2".into()), ("C".into(), "3u".into())],
            Path::new("m"),
        )
        .unwrap();
        assert_eq!(
            (defs["A"], defs["B"], defs["C"]),
            (ShaderDefValue::Bool(true), ShaderDefValue::Int(-2), ShaderDefValue::UInt(3))
        );
        assert!(
            format!("{:#}", shader_defs(&[("A".into(), "0.5".into())], Path::new("m")).unwrap_err())
                .contains("define A=0.5")
        );
        assert!(
            describe().starts_with(&format!("naga_oil {} (", locked("naga_oil")))
                && describe().contains(&format!("naga {} (", locked("naga"))),
            "describe() names the versions Cargo.lock pins"
        );
        assert_eq!(
            declared_imports("#import a::b::{x, y}\n  #import a::c::f\n#import \"p/q.wgsl\" f, g\n// #import no\n"),
            ["a::b", "a::c::f", "\"p/q.wgsl\""]
        );
    }
}
