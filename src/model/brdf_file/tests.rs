use super::*;
use crate::shaders::{GlslangError, glslang};

const PATH: &str = "dir/t.brdf";

fn parse_str(text: &str) -> Result<BrdfFile> {
    parse(Path::new(PATH), text.as_bytes())
}

fn ok(text: &str) -> BrdfFile {
    parse_str(text).unwrap_or_else(|e| panic!("{e:#}"))
}

/// The error of parsing `text`, which must name `line`.
fn fails_at(text: &str, line: usize, needle: &str) {
    let e = format!("{:#}", parse_str(text).expect_err("should fail"));
    assert!(e.starts_with(&format!("{PATH}:{line}: ")), "expected line {line}: {e}");
    assert!(e.contains(needle), "expected `{needle}` in: {e}");
}

/// A minimal valid file around `params` and a shader body.
fn file(params: &str, shader: &str) -> String {
    format!("analytic\n::begin parameters\n{params}::end parameters\n::begin shader\n{shader}::end shader\n")
}

const BRDF: &str = "vec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y) { return vec3(1.0); }\n";

#[test]
fn errors_name_file_and_line() {
    fails_at("", 1, "empty file");
    fails_at("  \n\n", 1, "empty file");
    fails_at("bparam\n", 1, "`bparam` files are not supported");
    fails_at("# analytic\n", 1, "expected `analytic`");
    fails_at("analytic\n\n::begin shader\nvec3 a\0;\n", 4, "NUL byte at byte 31");
    let mut bytes = b"analytic\n::begin shader\n\n// \xff\n".to_vec();
    let e = format!("{:#}", parse(Path::new(PATH), &bytes).unwrap_err());
    assert!(e.starts_with("dir/t.brdf:4: not UTF-8 text: byte 28 of the file is 0xff"), "{e}");
    bytes.clear();
    fails_at("analytic\n::begin parameters\n::begin shader\n", 3, "inside section `parameters` (begun at line 2)");
    fails_at("analytic\n::begin parameters\n::end shader\n", 3, "does not close section `parameters`");
    fails_at("analytic\n::end shader\n", 2, "outside any section");
    fails_at("analytic\n::begin\n", 2, "names no section");
    fails_at("analytic\n\n::begin shader\nvec3 BRDF();\n", 3, "section `shader` has no `::end shader`");
    fails_at(&file("int n 0 1 0\n", BRDF), 3, "unknown parameter type `int`");
    fails_at(&file("float n 0 1\n", BRDF), 3, "too few values, expected `float NAME MIN MAX DEFAULT`");
    fails_at(&file("color c 1 1\n", BRDF), 3, "expected `color NAME R G B`");
    fails_at(&file("bool b\n", BRDF), 3, "expected `bool NAME DEFAULT`");
    fails_at(&file("float n 0 x 1\n", BRDF), 3, "MAX of `n`: `x` is not a finite number");
    fails_at(&file("float n 0 1 inf\n", BRDF), 3, "DEFAULT of `n`: `inf` is not a finite number");
    fails_at(&file("color c 1 NaN 1\n", BRDF), 3, "G of `c`: `NaN`");
    fails_at(&file("bool b 2\n", BRDF), 3, "`2` is not 0 or 1");
    fails_at(&file("bool b true\n", BRDF), 3, "`true` is not 0 or 1");
    fails_at(&file("float n 0 1 0\n\nbool n 1\n", BRDF), 5, "parameter `n` is declared twice (first at line 3)");
    for bad in ["1x", "float", "gl_x", "a-b", "vec3"] {
        fails_at(&file(&format!("float {bad} 0 1 0\n"), BRDF), 3, &format!("`{bad}` is not a valid GLSL identifier"));
    }
    fails_at("analytic\n::begin parameters\nfloat n 0 1 0\n::end parameters\n", 1, "no shader section");
    fails_at(&file("", "\nfloat f() { return 1.0; }\n"), 4, "defines no function `BRDF`");
    fails_at(
        &file("", "// vec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y) { }\nvec3 f() { return BRDF(); }\n"),
        4,
        "defines no function `BRDF`",
    );
    fails_at(
        &file("", "\nvec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y);\n"),
        6,
        "`BRDF` is declared but not defined",
    );
    fails_at(
        &file("", "\nfloat BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y) { return 1.0; }\n"),
        6,
        "`BRDF` must be defined as `vec3 BRDF(vec3 L",
    );
    fails_at(&file("", "\n\nvec3 BRDF(vec3 L, vec3 V) { return L; }\n"), 7, "must be defined as");
    fails_at(&file("", &format!("{BRDF}/* never\nclosed\n")), 6, "`/*` comment is never closed");
    fails_at(
        &file("float m 0 1 0\n", &format!("{BRDF}\nconst float m = 1.0;\n")),
        8,
        "`m` is both a parameter (line 3) and a global",
    );
    fails_at(
        &format!("{}::begin shader\n{BRDF}::end shader\n", file("", BRDF)),
        7,
        "a second shader section (the first begins at line 4)",
    );
    fails_at(&file("", &format!("{BRDF}uniform Block {{ float k; }};\n")), 6, "interface blocks are not supported");
    let e = format!("{:#}", load(Path::new("/nonexistent/x.brdf")).unwrap_err());
    assert!(e.starts_with("cannot read /nonexistent/x.brdf"), "{e}");
}

#[test]
fn parameters_of_each_type_with_defaults_and_warnings() {
    let f = ok(&file(
        "float m 0.001 .3 .1\nbool on 1 # a comment\nbool off 0\ncolor tint .82 .67 1e-1\nfloat k 0 1 2 extra words\n",
        BRDF,
    ));
    let kinds: Vec<(&str, FileParamKind, usize)> = f.params.iter().map(|p| (p.name.as_str(), p.kind, p.line)).collect();
    assert_eq!(
        kinds,
        [
            ("m", FileParamKind::Float { min: 0.001, max: 0.3, default: 0.1 }, 3),
            ("on", FileParamKind::Bool { default: true }, 4),
            ("off", FileParamKind::Bool { default: false }, 5),
            ("tint", FileParamKind::Color { default: [0.82, 0.67, 0.1] }, 6),
            ("k", FileParamKind::Float { min: 0.0, max: 1.0, default: 2.0 }, 7),
        ]
    );
    assert_eq!(
        f.warnings,
        [
            "dir/t.brdf:7: `k`'s default 2 is outside its slider range [0, 1]",
            "dir/t.brdf:7: `extra words` after `k` is ignored (BRDF Explorer ignores it too)"
        ]
    );
    assert_eq!(f.name, "t");
    assert_eq!(
        f.default_constants(),
        "const float brdf_f_m = 0.1;\nconst bool brdf_f_on = true;\nconst bool brdf_f_off = false;\nconst vec3 brdf_f_tint = vec3(0.82, 0.67, 0.1);\nconst float brdf_f_k = 2.0;\n"
    );
}

#[test]
fn sections_warnings_is_func_and_hash() {
    let text = format!(
        "analytic extra\nstray text\n::begin notes\nanything\n::end notes\n::begin isFunc\nvec3 sampleBRDF() {{ }}\n::end isFunc\n::begin shader\n{BRDF}::end shader\n"
    );
    let f = ok(&text);
    assert!(f.has_is_func);
    assert_eq!(
        f.warnings,
        [
            "dir/t.brdf:2: text outside any section is ignored",
            "dir/t.brdf:3: don't know what to do with section `notes`: its content is ignored"
        ]
    );
    // sha256 of the text, as `sha256sum` gives it.
    assert_eq!(ok(&file("", BRDF)).hash, hex(&Sha256::digest(file("", BRDF).as_bytes())));
    assert_eq!(hex(&Sha256::digest(b"abc")), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
    assert!(
        !ok(&format!("analytic\n::begin isFunc\n# only a comment\n::end isFunc\n::begin shader\n{BRDF}::end shader\n"))
            .has_is_func
    );
    // CRLF line ends and a byte order mark.
    let crlf = format!("\u{feff}{}", file("float n 0 1 0.5\n", BRDF).replace('\n', "\r\n"));
    let f = ok(&crlf);
    assert_eq!(f.params[0].kind, FileParamKind::Float { min: 0.0, max: 1.0, default: 0.5 });
    assert!(f.shader.iter().all(|(_, l)| !l.contains('\r')));
}

#[test]
fn comments_blank_and_hash_lines_keep_numbering() {
    let f = ok(
        "analytic\n::begin shader\n\n#version 450\n  # indented\n// a comment\n/* a\n # in a comment\nb */\nvec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y) { return vec3(1.0); }\n::end shader\n",
    );
    let numbers: Vec<usize> = f.shader.iter().map(|(n, _)| *n).collect();
    assert_eq!(numbers, (3..=10).collect::<Vec<_>>());
    assert_eq!(f.shader[1], (4, String::new()));
    assert_eq!(f.shader[2], (5, String::new()));
    assert_eq!(f.shader[5], (8, String::new()));
    assert_eq!(
        f.shader[3],
        (6, "// a comment".to_string()),
        "no directive is kept, so no preprocessor runs and the text is as written"
    );
    let r = f.renamed_shader();
    assert_eq!(r.lines.iter().map(|l| l.0).collect::<Vec<_>>(), numbers);
    assert_eq!(r.lines[7].1, "vec3 brdf_f_BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y) { return vec3(1.0); }");
    assert_eq!(f.line_directive(), "#line 3 \"dir/t.brdf\"");
    let dropped: Vec<&String> = f.warnings.iter().filter(|w| w.contains("is dropped")).collect();
    assert_eq!(dropped.len(), 3, "every dropped `#` line is named: {dropped:?}");
    assert!(
        dropped[0].contains(":4")
            && dropped[0].contains("`#version 450`")
            && dropped[0].contains("sets `#version 450`"),
        "{}",
        dropped[0]
    );
    assert!(
        dropped[1].contains(":5")
            && dropped[1].contains("`# indented`")
            && dropped[1].contains("BRDF Explorer comment"),
        "{}",
        dropped[1]
    );
}

/// An engine-style quality switch, in the style of Filament's `surface_brdf.fs` (written for this test): the
/// branch the defines select is the code, line for line, and the file's own macros are expanded.
const QUALITY_SWITCH: &str = "#define QUALITY_LOW 0\n#define QUALITY_HIGH 1\n#ifndef QUALITY\n#define QUALITY QUALITY_LOW\n#endif\n#define F90 1.0\n\
    #if QUALITY == QUALITY_HIGH\nfloat f5(float u) { return pow(1.0 - u, 5.0) * F90; }\n#else\nfloat f5(float u) { return 1.0 - u; }\n#endif\n";

#[test]
fn the_preprocessor_selects_the_branch_the_defines_select() {
    let f = ok(&file("", &format!("{QUALITY_SWITCH}{BRDF}")));
    assert!(!f.warnings.iter().any(|w| w.contains("dropped")), "directives are kept: {:?}", f.warnings);
    let line = |f: &BrdfFile, n: usize| f.shader.iter().find(|l| l.0 == n).map(|l| l.1.trim().to_string()).unwrap();
    // The shader begins at line 5 (`file`): #if at 11, the high branch at 12, the low one at 14.
    assert_eq!(f.shader.len(), f.source.len());
    assert_eq!(line(&f, 12), "");
    assert!(line(&f, 14).replace(' ', "").contains("return1.0-u"), "{}", line(&f, 14));
    let high = f.with_defines(&[("QUALITY".into(), "1".into())]).unwrap();
    assert!(
        line(&high, 12).replace(' ', "").contains("pow(1.0-u,5.0)*1.0"),
        "the high branch with F90 expanded: {}",
        line(&high, 12)
    );
    assert_eq!(line(&high, 14), "");
    assert!(high.renamed_shader().text().contains("brdf_f_f5"), "the selected branch's function is renamed");
    assert_eq!(high.renamed_shader().renamed.iter().filter(|n| *n == "f5").count(), 1);
    let flag = f.with_defines(&[("QUALITY".into(), "QUALITY_HIGH".into())]).unwrap();
    assert_eq!(line(&flag, 12), line(&high, 12), "a define's value is expanded with the file's own macros");
}

#[test]
fn preprocessor_errors_and_refused_directives_name_the_line() {
    let shader = |s: &str| file("", &format!("{s}{BRDF}"));
    let e = parse_str(&shader("#if 1\nfloat a;\n")).unwrap_err().to_string();
    assert!(e.contains("dir/t.brdf:") && e.contains("preprocessor") && e.contains("#endif"), "{e}");
    let e = parse_str(&shader("float a;\n#error quality level not supported\n")).unwrap_err().to_string();
    assert!(e.contains("dir/t.brdf:6: preprocessor:") && e.contains("quality level not supported"), "{e}");
    // An include is looked for (beside the file, then the include directories) and named where it is missing.
    let e = format!("{:#}", parse_str(&shader("#include \"common.glsl\"\n")).unwrap_err());
    assert!(e.starts_with(&format!("{PATH}:5:10: cannot find include `common.glsl`")), "{e}");
    let f = ok(&file("float k 0 1 0.5\n", BRDF));
    assert!(f.with_defines(&[("k".into(), "1".into())]).unwrap_err().to_string().contains("is the file's parameter"));
    let defined = ok(&shader("float a = SCALE;\n")).with_defines(&[("SCALE".into(), "2.5".into())]).unwrap();
    assert!(defined.shader.iter().any(|l| l.1.contains("float a = 2.5;")), "{:?}", defined.shader);
}

/// A file in BRDF Explorer's dialect: a global PI, helpers, its own `reflect`, a function whose parameter is
/// named like a file parameter, a local named like its function, a struct with a member named like a
/// global, swizzles, bool parameters in `?:` and `if`, and desktop GL's implicit int -> float conversions.
const DIALECT: &str = "analytic
# a test file
::begin parameters
float m 0.01 1 0.3
float n 1 100 10 # the exponent
bool useF 1
color tint 1 0.5 0.25
::end parameters

::begin shader
const float PI = 3.14159265358979;
# TWO 2, a BRDF Explorer comment
float sqr(float x) { return x*x; }
struct Lobe { float PI; float w, v[2]; };
vec3 reflect(vec3 I, vec3 N) { return 2*dot(I,N)*N - I; }
float spike(float m, float t) { float spike = m*t; return spike; }
Lobe lobe(float w) { float v[2]; v[0] = w; v[1] = 1; return Lobe(PI, w, v); }
float clamp01(float u) { return clamp(1-u, 0, 1); }
vec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y)
{
vec3 R = reflect(L, N);
Lobe l = lobe(n);
if (dot(N, L) < 0) return vec3(0);
float s = pow(max(0, dot(R, V)), n) * l.w + l.PI * 0 + pow(clamp01(R.z), 2);
float F = useF ? mix(1, 0.5, m) : 1;
if (useF) F *= 2/(1+n);
return tint * s * F * sqr(spike(m, 2)) * V.xyz + vec3(l.v[1], 0, 0);
}
::end shader
";

#[test]
fn renames_globals_and_parameters_everywhere_but_members() {
    let f = ok(DIALECT);
    let r = f.renamed_shader();
    assert_eq!(r.prefix, "brdf_f_");
    assert_eq!(
        r.renamed,
        ["m", "n", "useF", "tint", "PI", "sqr", "Lobe", "reflect", "spike", "lobe", "clamp01", "BRDF"]
    );
    let text = r.text();
    for expected in [
        "const float brdf_f_PI = 3.14159265358979;",
        "float brdf_f_sqr(float x) { return x*x; }",
        "struct brdf_f_Lobe { float PI; float w, v[2]; };",
        "vec3 brdf_f_reflect(vec3 I, vec3 N) { return 2*dot(I,N)*N - I; }",
        "float brdf_f_spike(float brdf_f_m, float t) { float brdf_f_spike = brdf_f_m*t; return brdf_f_spike; }",
        "brdf_f_Lobe brdf_f_lobe(float w) { float v[2]; v[0] = w; v[1] = 1; return brdf_f_Lobe(brdf_f_PI, w, v); }",
        "vec3 R = brdf_f_reflect(L, N);",
        "brdf_f_Lobe l = brdf_f_lobe(brdf_f_n);",
        "pow(max(0, dot(R, V)), brdf_f_n) * l.w + l.PI * 0 + pow(brdf_f_clamp01(R.z), 2);",
        "float F = brdf_f_useF ? mix(1, 0.5, brdf_f_m) : 1;",
        "return brdf_f_tint * s * F * brdf_f_sqr(brdf_f_spike(brdf_f_m, 2)) * V.xyz + vec3(l.v[1], 0, 0);",
    ] {
        assert!(text.contains(expected), "missing `{expected}` in:\n{text}");
    }
    assert_eq!(r.lines.len(), f.shader.len());
    assert_eq!(r.lines[1], (12, String::new()), "the `#` comment line is dropped");
    assert_eq!(f.glsl_name("BRDF"), "brdf_f_BRDF");
    assert_eq!(
        r.original_names("'brdf_f_sqr' : no matching overloaded function found for brdf_f_Lobe, brdf_f_x"),
        "'sqr' : no matching overloaded function found for Lobe, brdf_f_x"
    );
}

#[test]
fn prefix_avoids_names_the_file_uses_and_double_underscores() {
    let f = ok(&file("float k 0 1 0\n", &format!("float brdf_f_k = 1.0; // brdf_f1 in a comment\n{BRDF}")));
    assert_eq!(f.renamed_shader().prefix, "brdf_f2_");
    assert_eq!(f.glsl_name("k"), "brdf_f2_k");
    let f = ok(&file("bool _x 0\n", "vec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y) { return _x ? L : V; }\n"));
    let r = f.renamed_shader();
    assert_eq!(r.prefix, "brdf_f");
    assert!(
        r.text().contains("vec3 brdf_fBRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y) { return brdf_f_x ? L : V; }"),
        "{}",
        r.text()
    );
}

#[test]
fn uniform_on_a_global_is_dropped_with_a_warning() {
    let f = ok(&file("", &format!("uniform float k;\n{BRDF}")));
    assert_eq!(f.warnings.len(), 1);
    assert!(f.warnings[0].starts_with("dir/t.brdf:5: `uniform` dropped from `k`"), "{}", f.warnings[0]);
    assert_eq!(f.renamed_shader().lines[0].1, " float brdf_f_k;");
}

#[test]
fn global_declarations() {
    let lines: Vec<(usize, String)> = "const float A = 1.0, B[2] = float[2](1.0, f(2.0, 3.0)), C = 2.0;\nvec3 g(vec3 a, float b[2]);\nfloat h(void) { return 1.0; }\nstruct S { float x; } s1, s2;\nconst float W[2] = { 1.0, 2.0 };\nprecision highp float;\nhighp float j;"
        .lines()
        .enumerate()
        .map(|(i, l)| (i + 1, l.to_string()))
        .collect();
    let tokens = tokenize(Path::new(PATH), &lines).unwrap();
    let scan = scan_globals(Path::new(PATH), &lines, &tokens).unwrap();
    let names: Vec<(&str, usize)> = scan.globals.iter().map(|g| (g.name.as_str(), g.line)).collect();
    assert_eq!(
        names,
        [("A", 1), ("B", 1), ("C", 1), ("g", 2), ("h", 3), ("S", 4), ("s1", 4), ("s2", 4), ("W", 5), ("j", 7)]
    );
    assert_eq!(
        scan.globals[3].kind,
        GlobalKind::Function {
            defined: false,
            returns: "vec3".into(),
            params: vec![
                vec!["vec3".into(), "a".into()],
                vec!["float".into(), "b".into(), "[".into(), "2".into(), "]".into()]
            ]
        }
    );
    assert_eq!(scan.globals[4].kind, GlobalKind::Function { defined: true, returns: "float".into(), params: vec![] });
}

/// Writes `source` to a temporary directory and compiles it as the kernels are compiled; the log on failure.
fn compile(source: &str) -> std::result::Result<(), String> {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("composed.comp");
    std::fs::write(&path, source).unwrap();
    glslang(&path, &[], &[], "a test kernel")
        .map(|_| ())
        .map_err(|e| e.downcast_ref::<GlslangError>().map_or_else(|| format!("{e:#}"), |g| g.log.clone()))
}

/// A tiny compute kernel around the file: its parameters as constants at their defaults, the renamed shader
/// (after a `#line` directive naming the file, with `directive`), and a main writing BRDF to a buffer.
/// Returns the source and the composed line holding the shader's first line.
fn compose(f: &BrdfFile, directive: bool) -> (String, usize) {
    let r = f.renamed_shader();
    let mut head = String::from("#version 450\n");
    if directive {
        head += "#extension GL_GOOGLE_cpp_style_line_directive : require\n";
    }
    head += "layout(local_size_x = 1) in;\nlayout(std430, binding = 0) buffer Result { vec4 result[]; };\n";
    head += &f.default_constants();
    if directive {
        head += &format!("{}\n", f.line_directive());
    }
    let first = head.lines().count() + 1;
    let mut source = head + &r.text();
    if directive {
        source += &format!("#line {} \"composed.comp\"\n", source.lines().count() + 2);
    }
    source += &format!(
        "void main() {{\n    vec3 N = vec3(0.0, 0.0, 1.0), X = vec3(1.0, 0.0, 0.0), Y = vec3(0.0, 1.0, 0.0);\n    vec3 L = normalize(vec3(0.3, 0.2, 1.0)), V = normalize(vec3(-0.2, 0.1, 1.0));\n    result[0] = vec4({}(L, V, N, X, Y), 0.0);\n}}\n",
        f.glsl_name("BRDF")
    );
    (source, first)
}

#[test]
fn renamed_dialect_compiles_with_glslang() {
    let f = ok(DIALECT);
    for directive in [true, false] {
        let (source, _) = compose(&f, directive);
        compile(&source).unwrap_or_else(|log| panic!("{log}\n{source}"));
    }
}

/// glslang in Vulkan mode accepts desktop GL's implicit int -> float conversions: nothing to rewrite.
#[test]
fn glslang_accepts_implicit_int_to_float() {
    let shader = "float a(float x) { return pow(x, 2); }
float b(float Fd90, float FL) { return mix(1, Fd90, FL); }
float c(float x) { return 2/(1+x); }
float d(float NdotL) { if (NdotL < 0) return 0; return clamp(1-NdotL, 0, 1) + max(0, NdotL); }
float e(float x) { float y = 1; y += flag ? 1 : 0.5; if (flag) y *= 2; return x > 0 ? y : 1; }
vec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y) { return vec3(a(1.0) + b(1.0, 0.5) + c(1.0) + d(0.2) + e(1.0), 0, 1) * min(1, 2 * dot(N, L)); }
";
    let f = ok(&file("bool flag 1\n", shader));
    let (source, _) = compose(&f, true);
    compile(&source).unwrap_or_else(|log| panic!("{log}\n{source}"));
}

/// Without the rename, glslang refuses a file's own `reflect` (a built-in's name) in Vulkan mode.
#[test]
fn glslang_refuses_a_built_in_redefined_without_the_rename() {
    let shader = "vec3 reflect(vec3 I, vec3 N) { return 2*dot(I,N)*N - I; }\nvec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y) { return reflect(L, N); }\n";
    let f = ok(&file("", shader));
    let raw = format!(
        "#version 450\nlayout(local_size_x = 1) in;\n{}void main() {{ }}\n",
        f.shader.iter().map(|(_, l)| format!("{l}\n")).collect::<String>()
    );
    let log = compile(&raw).expect_err("glslang accepts a redefined reflect");
    assert!(log.contains("overloaded functions must have the same parameter precision qualifiers"), "{log}");
    compile(&compose(&f, false).0).unwrap();
}

/// An error in the file comes back as `FILE:LINE: ...` with the original names, by either mechanism.
#[test]
fn remap_log_names_the_file_line() {
    let shader = "float sqr(float x) { return x*x; }\n\n// a comment\nvec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y)\n{\n    return vec3(sqr(1.0, k)) + foo;\n}\n";
    let f = ok(&file("float k 0 1 0.5\n", shader));
    let r = f.renamed_shader();
    // With the directive, glslang reports the file itself; `line_of` is not needed.
    let (source, _) = compose(&f, true);
    let log = compile(&source).unwrap_err();
    assert!(log.contains("ERROR: dir/t.brdf:11: 'brdf_f_sqr' : no matching overloaded function found"), "{log}");
    assert_eq!(f.remap_log(&r, &log, |_| None), "dir/t.brdf:11: 'sqr' : no matching overloaded function found\n");
    // Without it, through a line map of the composed source.
    let (source, first) = compose(&f, false);
    let log = compile(&source).unwrap_err();
    let line_of = |l: usize| (first..first + f.shader.len()).contains(&l).then(|| l - first + f.shader[0].0);
    assert_eq!(f.remap_log(&r, &log, line_of), "dir/t.brdf:11: 'sqr' : no matching overloaded function found\n");
    // Messages about other sources are kept; warnings say so; counts and the rest are dropped.
    let log = "composed.comp\nWARNING: dir/t.brdf:8: 'brdf_f_k' : something odd \nERROR: composed.comp:30: 'x' : undeclared identifier \nERROR: C:\\a b\\c:1.comp:3: '' : compilation terminated \nERROR: 2 compilation errors.  No code generated.\n\nERROR: Linking compute stage: Missing entry point: Each stage requires one entry point\n";
    assert_eq!(
        f.remap_log(&r, log, |_| None),
        "dir/t.brdf:8: warning: 'k' : something odd\nERROR: composed.comp:30: 'x' : undeclared identifier\n"
    );
    assert_eq!(split_location("C:\\a b\\c:1.comp:3: msg"), Some(("C:\\a b\\c:1.comp", 3, "msg")));
}

/// The thesis models as .brdf files (examples/brdf/) parse, and their renamed shaders compile.
#[test]
fn example_files_parse_and_compile() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/brdf");
    for (name, params) in [("ggx", 2), ("blinn", 2), ("cook-torrance", 2), ("burley", 3)] {
        let f = load(&dir.join(format!("{name}.brdf"))).unwrap();
        assert_eq!((f.name.as_str(), f.params.len()), (name, params));
        assert!(f.warnings.is_empty(), "{:?}", f.warnings);
        assert_eq!(
            f.params[0],
            FileParam {
                name: "roughness".into(),
                kind: FileParamKind::Float { min: 0.0, max: 1.0, default: 0.5 },
                line: f.params[0].line
            }
        );
        assert_eq!(f.params[1].kind, FileParamKind::Color { default: [0.04; 3] });
        let r = f.renamed_shader();
        for host in ["PI", "pow5", "safe_normalize", "guard_cosine", "MIN_COSINE", "F_Schlick"] {
            assert!(r.renamed.iter().any(|n| n == host), "{name}: `{host}` not renamed");
        }
        let (source, _) = compose(&f, true);
        compile(&source).unwrap_or_else(|log| panic!("{name}: {log}"));
    }
}

#[test]
fn cr_only_line_ends_parse_as_lines() {
    let text = file("float n 0 1 0.5\n", BRDF).replace('\n', "\r");
    let f = ok(&text);
    assert_eq!((f.params.len(), f.params[0].line), (1, 3));
    assert!(f.shader.iter().any(|(n, l)| *n == 6 && l.starts_with("vec3 BRDF")), "{:?}", f.shader);
    let mixed =
        "analytic\r\n::begin shader\r\rvec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y) { return L; }\n::end shader\n";
    assert_eq!(ok(mixed).shader.iter().find(|(_, l)| !l.is_empty()).unwrap().0, 4);
}

#[test]
fn layout_qualifiers_are_refused_at_their_line() {
    fails_at(&file("", &format!("{BRDF}layout(local_size_x = 7) in;\n")), 6, "`layout(...)` is not supported");
    // In a comment it is just a word.
    ok(&file("", &format!("// layout(std430) is not for us\n{BRDF}")));
}

#[test]
fn values_beyond_fp32_are_refused() {
    fails_at(&file("float k 0 1 1e39\n", BRDF), 3, "DEFAULT of `k`: `1e39` is beyond fp32's range");
    fails_at(&file("color c 1 -1e39 0\n", BRDF), 3, "G of `c`: `-1e39` is beyond fp32's range");
    ok(&file("float k 0 1e39 0.5\n", BRDF)); // a slider bound, never compiled
}

/// Each loop with its trip count where the header gives one (lavapipe stops every loop at 65535).
#[test]
fn loops_are_found_with_their_trip_counts() {
    let shader = "float f(float x) {
for (int i = 0; i < 100000; i++) x += 1.0;
for (uint i = 10u; i >= 1u; i -= 3u) x += 1.0;
for (float t = 0.0; t <= 1.0; t += 0.25) x += t;
for (int i = 0; i != 7; i += 2) x += 1.0;
for (int i = 0; i < 10; i--) x += 1.0;
for (int i = 0; i < n; i++) x += 1.0;
while (x > 0.0) x -= 1.0;
do { x += 1.0; } while (x < 3.0);
return x;
}
vec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y) { return vec3(f(1.0)); }
";
    let f = ok(&file("float n 0 10 1\n", shader));
    let got: Vec<(usize, &str, Option<u64>)> = f.loops.iter().map(|l| (l.line, l.keyword, l.trip_count)).collect();
    assert_eq!(
        got,
        [
            (7, "for", Some(100000)),
            (8, "for", Some(4)),
            (9, "for", Some(5)),
            (10, "for", None),
            (11, "for", None),
            (12, "for", None),
            (13, "while", None),
            (14, "do", None)
        ]
    );
    assert!(ok(&file("", BRDF)).loops.is_empty());
    assert_eq!(iterations(5.0, "<", 5.0, 1.0), Some(0));
    assert_eq!(iterations(0.0, ">", 5.0, -1.0), Some(0));
    assert_eq!(iterations(10.0, ">", 0.0, -1.0), Some(10));
}

/// Reading a file (tokens, globals, renaming, all done once at parse) is linear in its size: four times
/// the functions take about four times as long (the quadratic list lookup renaming once had took sixteen
/// times, 12.5 s for 100,000 functions). The best of three runs each, and a bound (11x) between the two, so
/// a loaded machine (8.2x seen with four builds running) does not decide it.
#[test]
fn renaming_is_linear_in_the_number_of_functions() {
    let of = |n: usize| {
        let body: String = (0..n).map(|i| format!("float f{i}(float x) {{ return x + {i}.0; }}\n")).collect();
        let text = file("float k 0 1 0.5\n", &format!("{body}{BRDF}"));
        let mut parsed = None;
        let best = (0..3)
            .map(|_| {
                let t = std::time::Instant::now();
                let f = ok(&text);
                let elapsed = t.elapsed().as_secs_f64();
                assert_eq!(f.renamed_shader().renamed.len(), n + 2);
                parsed = Some(f);
                elapsed
            })
            .fold(f64::INFINITY, f64::min);
        (best, parsed.expect("parsed"))
    };
    let (small, _) = of(10_000);
    let (large, f) = of(40_000);
    assert!(f.renamed_shader().text().contains("float brdf_f_f39999(float x)"));
    assert!(
        large / small < 11.0,
        "10,000 functions: {small:.3} s, 40,000: {large:.3} s (linear: about 4x; quadratic: 16x)"
    );
}

#[test]
fn wgsl_tokens_nest_their_comments_and_wgsl_loop_headers_are_counted() {
    let lines = |t: &str| t.lines().enumerate().map(|(i, l)| (i + 1, l.to_string())).collect::<Vec<_>>();
    let text = lines(
        "/* a /* b */ for (;;) {} */ x\nfn f() -> f32 {\n  for (var i: i32 = 0; i < 100000; i++) {}\n  loop { break; }\n  while (true) {}\n  for (var j = 0x1Fu; j > 0u; j--) {}\n  return 0x1.8p-1f;\n}\n",
    );
    let tokens = tokenize_wgsl(Path::new("m.wgsl"), &text).unwrap();
    assert_eq!(tokens[0].text, "x");
    assert!(tokens.iter().any(|t| t.text == "0x1.8p-1f"), "a hex float with a signed exponent is one number");
    let got: Vec<(usize, &str, Option<u64>, Option<String>)> =
        wgsl_loops(&text, &tokens).into_iter().map(|(l, f)| (l.line, l.keyword, l.trip_count, f)).collect();
    let f = Some("f".to_string());
    assert_eq!(
        got,
        [
            (3, "for", Some(100000), f.clone()),
            (4, "loop", None, f.clone()),
            (5, "while", None, f.clone()),
            (6, "for", Some(31), f)
        ]
    );
    // GLSL's block comments do not nest: `*/` ends the first.
    assert_eq!(
        tokenize(Path::new("m.glsl"), &lines("/* a /* b */ c */"))
            .unwrap()
            .iter()
            .map(|t| t.text.as_str())
            .collect::<String>(),
        "c*/"
    );
}

#[test]
fn global_initialisers_know_the_parameters_they_read_through_globals_and_functions() {
    let shader = "float a = k * 2.0, b[2] = float[2](a, 1.0);\nconst float c = 3.0;\nfloat d = c * 2.0;\nfloat twice(float x) { return x * r; }\nstruct S { float k; };\nfloat e = twice(d);\nfloat g;\nfloat h = g + 1.0;\n";
    let f = ok(&file("float k 0 1 0.5\nfloat r 0 1 0.5\n", &format!("{shader}{BRDF}")));
    let got: Vec<(&str, Vec<&str>, &str)> = f
        .renamed_shader()
        .initialisers
        .iter()
        .map(|i| (i.name.as_str(), i.reads.iter().map(String::as_str).collect(), i.assignment.as_str()))
        .collect();
    assert_eq!(
        got,
        [
            ("a", vec!["k"], "brdf_f_a = brdf_f_k * 2.0;"),
            ("b", vec!["k"], "brdf_f_b = float[2](brdf_f_a, 1.0);"),
            ("d", vec![], "brdf_f_d = brdf_f_c * 2.0;"),
            ("e", vec!["r"], "brdf_f_e = brdf_f_twice(brdf_f_d);"),
            ("h", vec![], "brdf_f_h = brdf_f_g + 1.0;"),
        ]
    );
}
