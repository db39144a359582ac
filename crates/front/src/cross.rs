//! SPIR-V back to GLSL: spirv-cross writes the front end's SPIR-V as Vulkan GLSL 450, and `view` keeps what a
//! `.brdf` shader section would hold: the shader's types, globals and functions (each SPIR-V instruction an
//! expression, with every evaluation order and literal as the front end fixed it), without the stub entry, the
//! parameters' own declarations (the composition declares them) and the compute layout. A global the source
//! initialises at run time (an HLSL `static` with a non-constant initialiser, which glslang assigns at the top
//! of `main`) becomes a global initialiser again, as GLSL allows.

use super::STUB;
use anyhow::{Context, Result, anyhow, bail};
use std::path::Path;
use std::sync::OnceLock;

/// spirv-cross's flags: Vulkan GLSL 450, as brdfprof's kernels are written.
pub const FLAGS: [&str; 4] = ["--version", "450", "--vulkan-semantics", "--force-temporary"];

/// spirv-cross on `words`: its GLSL.
pub fn to_glsl(words: &[u32], model: &Path) -> Result<String> {
    to_glsl_with(words, model, &[])
}

/// The source location (`#line N "FILE"`: N) of each line of `to_glsl`'s output, by index: spirv-cross's
/// `--emit-line-directives` output of the same SPIR-V is that output with `#line` directives (and the extension
/// they need) between its lines. None where a line has none; empty where the two do not line up.
pub fn line_origins(words: &[u32], plain: &str, model: &Path) -> Result<Vec<Option<usize>>> {
    Ok(line_files(words, plain, model)?.into_iter().map(|l| l.map(|(_, n)| n)).collect())
}

/// `line_origins` with each line's file as the SPIR-V's line table names it (`#line N "FILE"`).
pub fn line_files(words: &[u32], plain: &str, model: &Path) -> Result<Vec<Option<(String, usize)>>> {
    let directed = to_glsl_with(words, model, &["--emit-line-directives"])?;
    let mut at = None;
    let mut out = Vec::new();
    let mut text = Vec::new();
    for l in directed.lines() {
        if let Some(rest) = l.trim_start().strip_prefix("#line ") {
            let (n, file) = rest.split_once(' ').unwrap_or((rest, ""));
            at = n.trim().parse().ok().map(|n| (file.trim().trim_matches('"').to_string(), n));
        } else if !l.contains("GL_GOOGLE_cpp_style_line_directive") {
            out.push(at.clone());
            text.push(l);
        }
    }
    Ok(if text == plain.lines().collect::<Vec<_>>() { out } else { Vec::new() })
}

fn to_glsl_with(words: &[u32], model: &Path, extra: &[&str]) -> Result<String> {
    let dir = crate::cleanup::TempDir::new().context("cannot create a temporary directory for spirv-cross")?;
    let path = dir.path().join("shader.spv");
    std::fs::write(&path, words.iter().flat_map(|w| w.to_le_bytes()).collect::<Vec<u8>>())
        .with_context(|| format!("cannot write {}", path.display()))?;
    let mut cmd = crate::cleanup::command("spirv-cross");
    crate::launch::bound_memory(&mut cmd)?;
    cmd.arg(&path).args(FLAGS).args(extra);
    let what = format!("{} (spirv-cross)", model.display());
    let out = match crate::launch::output(&mut cmd, &what) {
        Ok(o) => o,
        Err(e) if e.downcast_ref::<std::io::Error>().is_some() => {
            bail!("cannot run spirv-cross ({e}): install spirv-cross, or run `make setup`")
        }
        Err(e) => return Err(e),
    };
    if !out.status.success() {
        bail!("{what} failed on the front end's SPIR-V:\n{}", String::from_utf8_lossy(&out.stderr).trim());
    }
    String::from_utf8(out.stdout).map_err(|_| anyhow!("{what} wrote text that is not UTF-8"))
}

/// The name a top-level line of spirv-cross's output declares: the identifier before the function's `(`, or
/// before a declaration's `=` / `;` / `[`.
fn declared_name(line: &str) -> &str {
    let head = line.split(['(', '=', ';', '[']).next().unwrap_or("").trim();
    head.rsplit(' ').next().unwrap_or("")
}

/// The precision qualifiers spirv-cross writes before a relaxed-precision variable's type.
const PRECISIONS: [&str; 3] = ["mediump ", "highp ", "lowp "];

/// `TYPE NAME;` or `TYPE NAME = VALUE;` (a precision qualifier before TYPE allowed): (TYPE, NAME).
pub fn plain_declaration(line: &str) -> Option<(&str, &str)> {
    let l = PRECISIONS.iter().fold(line, |l, p| l.strip_prefix(p).unwrap_or(l));
    let head = l.split(" = ").next()?.trim_end_matches(';');
    let (ty, name) = head.split_once(' ')?;
    (!name.contains(' ') && !ty.is_empty() && l.ends_with(';')).then_some((ty, name))
}

/// A resource (a uniform or storage block, a texture) in the shader: a model is a function of its inputs and
/// parameters. `name` as the shader declares it (the block's name).
#[derive(Debug)]
pub struct Resource {
    pub name: String,
    /// The members of a block (`uniform _Global { float Gloss; }`: `Gloss`), in order.
    pub members: Vec<String>,
    pub model: String,
}

/// The block spirv-cross names HLSL's implicit constant buffer `$Global`, which holds every global declared
/// without `static` (or `const`): HLSL's globals are uniforms unless `static`.
pub const HLSL_GLOBALS: &str = "_Global";

impl Resource {
    /// The message without the model's name (for a caller that locates the resource in the source).
    pub fn message(&self) -> String {
        match self.members.first().filter(|_| self.name == HLSL_GLOBALS) {
            Some(m) => format!(
                "`{m}` is a global without `static`, which HLSL makes a uniform of its implicit constant buffer $Global (a resource): a model is a function of its inputs and parameters; declare it `static` (a private global of the shader) or make it a parameter of the file"
            ),
            None => format!(
                "the shader uses the resource `{}` (a constant buffer, structured buffer or texture): a model is a function of its inputs and parameters; declare each value it reads as a parameter",
                self.name
            ),
        }
    }

    /// The name the message is about, as the shader declares it: the global of `$Global`, else the resource.
    pub fn declared(&self) -> &str {
        self.members.first().filter(|_| self.name == HLSL_GLOBALS).unwrap_or(&self.name)
    }
}

impl std::fmt::Display for Resource {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}: {}", self.model, self.message())
    }
}

impl std::error::Error for Resource {}

/// The name of a resource spirv-cross declares on `line` (`layout(...) uniform Material`, `uniform sampler2D t;`).
fn resource_name(line: &str) -> &str {
    let l = line.rfind(')').map_or(line, |i| &line[i + 1..]);
    l.trim().trim_end_matches(';').rsplit(' ').next().unwrap_or(l)
}

/// The members of the block declared at `lines[0]` (`layout(...) uniform B` then `{`, one member a line, `}`):
/// none for a declaration that is no block.
fn block_members(lines: &[&str]) -> Vec<String> {
    if lines.get(1) != Some(&"{") {
        return Vec::new();
    }
    lines[2..]
        .iter()
        .take_while(|l| !l.starts_with('}'))
        .map(|l| declared_name(l).to_string())
        .filter(|n| !n.is_empty())
        .collect()
}

/// What `view` collects: the kept lines, the globals the stub's prologue initialises, and where the first
/// function starts.
#[derive(Default)]
struct View {
    lines: Vec<String>,
    initialised: Vec<String>,
    first_function: Option<usize>,
}

/// The index after the line `close` that ends the block starting at `open` (a function's `}` or a struct's
/// `};`, at column 0).
fn block_end(lines: &[&str], open: usize, close: &str) -> usize {
    (open..lines.len()).find(|&j| lines[j] == close).map_or(lines.len(), |j| j + 1)
}

/// spirv-cross's GLSL cut down to the shader's declarations and functions (module doc): `params` are the
/// parameters whose plain declarations (`float roughness;`) are dropped. A resource (a uniform or storage
/// block, a texture) is refused: a model is a function of its inputs and parameters.
pub fn view(glsl: &str, params: &[&str], model: &Path) -> Result<Vec<String>> {
    let lines: Vec<&str> = glsl.lines().collect();
    let mut v = View::default();
    let mut i = 0;
    while i < lines.len() {
        let l = lines[i];
        let closing = lines[i..].iter().position(|s| s.starts_with('}')).map(|k| i + k);
        if l.starts_with("#version") || l.starts_with("layout(local_size") {
            i += 1;
        } else if let Some(end) = closing
            .filter(|&e| l.starts_with("layout(") && lines[e].contains(&format!("}} {};", super::slang::OUT_BUFFER)))
        {
            // Slang's stub stores into a buffer of brdfprof's (`slang::OUT_BUFFER`): dropped with the stub.
            i = end + 1;
        } else if l.starts_with("layout(") || l.starts_with("uniform ") || l.starts_with("buffer ") {
            bail!(Resource {
                name: resource_name(l).to_string(),
                members: block_members(&lines[i..]),
                model: model.display().to_string()
            });
        } else if l.starts_with("struct ") {
            let end = block_end(&lines, i, "};");
            v.lines.extend(lines[i..end].iter().map(|s| s.to_string()));
            i = end;
        } else if lines.get(i + 1) == Some(&"{") {
            let end = block_end(&lines, i + 1, "}");
            function(&mut v, &lines[i..end], model)?;
            i = end;
        } else {
            // A parameter's own declaration: `TYPE NAME;`, or naga's zero-initialised `TYPE NAME = ZERO;`, with
            // any precision qualifier spirv-cross writes for a relaxed-precision variable.
            let name = declared_name(l);
            let own = params.contains(&name) && plain_declaration(l).is_some_and(|(_, n)| n == name);
            if !own {
                v.lines.push(l.to_string());
            }
            i += 1;
        }
    }
    let at = v.first_function.unwrap_or(v.lines.len());
    v.lines.splice(at..at, v.initialised);
    Ok(v.lines)
}

/// One function of spirv-cross's output (its lines, `}` included): kept, or dropped (the stub, and `main`,
/// whose assignments before the stub's call become global initialisers).
fn function(v: &mut View, f: &[&str], model: &Path) -> Result<()> {
    match declared_name(f[0]).trim_start_matches('_') {
        "main" => prologue(v, &f[2..f.len() - 1], model),
        name if name == STUB => Ok(()),
        _ => {
            v.first_function.get_or_insert(v.lines.len());
            v.lines.extend(f.iter().map(|s| s.to_string()));
            Ok(())
        }
    }
}

/// `main`'s statements before its call of the stub (glslang's HLSL globals initialised at run time; naga's
/// `main` is the stub itself and has none): `NAME = EXPR;` joins NAME's declaration, `TYPE T = EXPR;` (a
/// temporary) becomes a global; anything else is refused.
fn prologue(v: &mut View, body: &[&str], model: &Path) -> Result<()> {
    let Some(call) = body.iter().position(|s| s.trim().trim_start_matches('_').starts_with(&format!("{STUB}("))) else {
        return Ok(());
    };
    for s in body[..call].iter().map(|s| s.trim()) {
        let (lhs, rhs) = s.split_once(" = ").ok_or_else(|| anyhow!("{}: spirv-cross's translation sets a global with `{s}`, which brdfprof cannot make an initialiser; initialise the global with a constant expression", model.display()))?;
        if lhs.contains(' ') {
            v.initialised.push(s.to_string());
            continue;
        }
        let decl =
            v.lines.iter().position(|l| plain_declaration(l).is_some_and(|(_, n)| n == lhs) && !l.contains(" = "));
        let Some(decl) = decl else {
            bail!(
                "{}: spirv-cross's translation sets `{lhs}` (`{s}`), which it does not declare as a global",
                model.display()
            )
        };
        let line = v.lines.remove(decl);
        let ty = line.rsplit_once(' ').map_or("", |(t, _)| t).to_string();
        if let Some(f) = v.first_function.as_mut().filter(|f| **f > decl) {
            *f -= 1;
        }
        v.initialised.push(format!("{ty} {lhs} = {rhs}"));
    }
    Ok(())
}

/// spirv-cross's version: its `--revision`, or where that names no version (Debian's build prints "(Debian
/// package)"), the Debian package's.
pub fn describe() -> String {
    static V: OnceLock<String> = OnceLock::new();
    V.get_or_init(|| {
        let revision =
            crate::glslang::first_line_of(crate::cleanup::command("spirv-cross").arg("--revision")).unwrap_or_default();
        let package = || {
            crate::glslang::first_line_of(crate::cleanup::command("dpkg-query").args([
                "-W",
                "-f=${Version}",
                "spirv-cross",
            ]))
        };
        let version = if revision.chars().any(|c| c.is_ascii_digit()) {
            revision
        } else {
            package().map_or(revision, |p| format!("{p} (Debian)"))
        };
        format!("SPIR-V to GLSL by spirv-cross {} ({})", version.trim(), FLAGS.join(" "))
    })
    .clone()
}

#[cfg(test)]
mod tests {
    use super::*;

    const GLSL: &str = "#version 450\nlayout(local_size_x = 1, local_size_y = 1, local_size_z = 1) in;\n\nstruct S\n{\n    float a;\n};\n\nvec3 LUMA;\nfloat roughness;\nconst float K[2] = float[](1.0, 2.0);\n\nvec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y)\n{\n    return L * roughness * LUMA;\n}\n\nvoid _brdfprof_stub()\n{\n    vec3 v = vec3(0.0);\n}\n\nvoid main()\n{\n    vec3 _12 = normalize(vec3(1.0));\n    LUMA = _12 * 2.0;\n    _brdfprof_stub();\n}\n";

    #[test]
    fn the_view_keeps_the_shader_and_moves_run_time_initialisers() {
        let v = view(GLSL, &["roughness"], Path::new("m.hlsl")).unwrap();
        let text = v.join("\n");
        assert_eq!(
            text,
            "\nstruct S\n{\n    float a;\n};\n\nconst float K[2] = float[](1.0, 2.0);\n\nvec3 _12 = normalize(vec3(1.0));\nvec3 LUMA = _12 * 2.0;\nvec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y)\n{\n    return L * roughness * LUMA;\n}\n\n"
        );
        let bad = GLSL.replace("    LUMA = _12 * 2.0;\n", "    LUMA.x = 1.0;\n");
        assert!(format!("{:#}", view(&bad, &[], Path::new("m.hlsl")).unwrap_err()).contains("`LUMA.x = 1.0;`"));
        let resource =
            GLSL.replace("vec3 LUMA;\n", "layout(set = 0, binding = 0, std140) uniform Mat\n{\n    float k;\n} mat;\n");
        let r = view(&resource, &[], Path::new("m.hlsl")).unwrap_err().downcast::<Resource>().unwrap();
        assert_eq!((r.name.as_str(), r.members.as_slice(), r.declared()), ("Mat", ["k".to_string()].as_slice(), "Mat"));
        let globals = GLSL.replace(
            "vec3 LUMA;\n",
            "layout(set = 0, binding = 0, std140) uniform _Global\n{\n    float Gloss;\n    vec3 Tint;\n} _31;\n",
        );
        let r = view(&globals, &[], Path::new("m.hlsl")).unwrap_err().downcast::<Resource>().unwrap();
        assert_eq!(r.declared(), "Gloss");
        assert!(r.message().starts_with("`Gloss` is a global without `static`"), "{}", r.message());
        let relaxed =
            GLSL.replace("float roughness;", "mediump float roughness;").replace("vec3 LUMA;", "mediump vec3 LUMA;");
        let v = view(&relaxed, &["roughness"], Path::new("m.hlsl")).unwrap().join("\n");
        assert!(!v.contains("roughness;") && v.contains("mediump vec3 LUMA = _12 * 2.0;"), "{v}");
        assert_eq!(plain_declaration("mediump float _length;"), Some(("float", "_length")));
        assert_eq!(plain_declaration("vec3 BRDF(vec3 L)"), None);
    }
}
