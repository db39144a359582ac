//! Cost per source line (`inspect --lines`): a `.brdf` file with one line planted to cost more
//! than any other (a loop of eight `pow`s of distinct bases, tests/fixtures/brdf/lines/costly-line.brdf) is compiled
//! with line information by NVRTC (sm_89) and IGC (gen12lp); that line must come first, the lines must account
//! for the kernel's instructions and its binding pipe, the line-annotated compile must be the costed one's code,
//! and the Markdown and HTML reports must show it.

use crate::common;
use crate::compile_only::inspect_json;

const TARGETS: [&str; 2] = ["nvidia:sm_89", "intel:gen12lp"];

/// The fixture and the line of its planted statement (the one that says so).
fn fixture() -> (std::path::PathBuf, u64) {
    let path = common::repo_root().join("tests/fixtures/brdf/lines/costly-line.brdf");
    let text = std::fs::read_to_string(&path).unwrap();
    let line = text.lines().position(|l| l.contains("// the costly line")).expect("the fixture marks its costly line")
        as u64
        + 1;
    (path, line)
}

#[test]
fn the_planted_line_comes_first_on_every_target_that_names_lines() {
    let dir = tempfile::tempdir().unwrap();
    let (path, planted) = fixture();
    let model = path.to_str().unwrap();
    let all = inspect_json(dir.path(), "lines", &TARGETS, &["--lines", "--model", model], "Cost per source line");
    let md = std::fs::read_to_string(dir.path().join("lines.md")).unwrap();
    assert!(md.contains("planted += pow(NoH"), "the Markdown quotes the planted line:\n{md}");
    for (target, report) in TARGETS.iter().zip(all["reports"].as_array().unwrap()) {
        let kernels = report["lines"].as_array().unwrap_or_else(|| panic!("{target}: no lines in the report"));
        assert_eq!(kernels.len(), 3, "{target}: ggx, ggx,guards=off and the file");
        for k in kernels {
            let what = format!("{target} {}", k["model"]);
            // The line-annotated compile is the costed code: the same instruction sequence, no note.
            assert_eq!(k.get("note"), None, "{what}: {}", k["note"]);
            let lines = k["lines"].as_array().unwrap();
            let counted: u64 = lines.iter().map(|l| l["instructions"].as_u64().unwrap()).sum::<u64>()
                + k["unattributed"].as_u64().unwrap();
            assert_eq!(counted, k["instructions"].as_u64().unwrap(), "{what}: every instruction counted once");
            assert!(
                k["unattributed"].as_u64().unwrap() * 20 < k["instructions"].as_u64().unwrap(),
                "{what}: most instructions name a source line: {}",
                k["unattributed"]
            );
            // The lines share the binding pipe's cycles: never more than the kernel's, most of them.
            let pipe = k["binding_pipe"].as_str().unwrap();
            let on_pipe: f64 = lines.iter().map(|l| l["binding"].as_f64().unwrap()).sum();
            let row = report["cost"]["rows"].as_array().unwrap().iter().find(|r| r["model"] == k["model"]).unwrap();
            let term = row["terms"]
                .as_array()
                .unwrap()
                .iter()
                .find(|t| t[0] == pipe)
                .unwrap_or_else(|| panic!("{what}: no term {pipe}"))[1]
                .as_f64()
                .unwrap();
            assert!(
                on_pipe <= term + 1e-9 && on_pipe >= 0.9 * term,
                "{what}: lines {on_pipe} of the kernel's {pipe} {term}"
            );
            assert!(
                lines.windows(2).all(|w| w[0]["binding"].as_f64() >= w[1]["binding"].as_f64()),
                "{what}: ranked by the binding pipe"
            );
            if k["model"] == "ggx" || k["model"] == "ggx,guards=off" {
                assert!(
                    lines.iter().all(|l| l["file"].as_str().unwrap().starts_with("glsl/")),
                    "{what}: the built-in kernel's lines are glsl/'s"
                );
                continue;
            }
            let first = &lines[0];
            assert!(
                first["file"].as_str().unwrap().ends_with("costly-line.brdf")
                    && first["line"].as_u64() == Some(planted),
                "{what}: the first line is {first}, not the planted line {planted}"
            );
            assert!(first["text"].as_str().unwrap().contains("pow("), "{what}: {first}");
            assert!(
                first["binding"].as_f64().unwrap() > lines[1]["binding"].as_f64().unwrap(),
                "{what}: {first} ahead of {}",
                lines[1]
            );
        }
    }
    let page = dir.path().join("lines.html");
    common::run(&["report", dir.path().join("lines.json").to_str().unwrap(), "--out", page.to_str().unwrap()]).ok();
    let html = std::fs::read_to_string(&page).unwrap();
    assert!(
        html.contains("Cost per source line") && html.contains(&format!("costly-line.brdf:{planted}")),
        "the HTML report has the lines"
    );
}

#[test]
fn lines_need_a_target_whose_compiler_names_them() {
    let (path, _) = fixture();
    for device in ["radv:navi21", "lavapipe"] {
        common::run(&["inspect", "--no-callgrind", "--lines", "--device", device, "--model", path.to_str().unwrap()])
            .fails(2, "--lines");
    }
}

/// An HLSL model's cost per line lands on the user's .ush files and lines (glslang's line information through
/// spirv-cross's `#line` directives), with their text: the costliest line is a line of the headers, not of the
/// front end's GLSL; the few lines spirv-cross wrote with no location keep the front end's GLSL text.
#[test]
fn an_hlsl_models_lines_are_its_own_files_lines_with_their_text() {
    let ue = common::repo_root().join("tests/fixtures/hlsl/ue");
    let at = |p: &str| ue.join(p).display().to_string();
    let engine = format!("/Engine={}", at("Engine"));
    let args = ["--model", &at("ue-ggx.brdf"), "--include-dir", &at("Shaders"), "--include-map", &engine];
    let files = [at("Shaders/SpecularTerms.ush"), at("Engine/Private/Common.ush")];
    lines_land_on_the_users_files("ue-ggx", &args, &files, "(its HLSL as GLSL)");
}

/// A WGSL model's cost per line lands on its imported modules' files and lines (naga's statement spans, placed
/// by naga_oil's module tags, through naga's `OpLine`s and spirv-cross's `#line` directives), with their text.
#[test]
fn a_wgsl_models_lines_are_its_modules_lines_with_their_text() {
    let bevy = common::repo_root().join("tests/fixtures/wgsl/bevy");
    let at = |p: &str| bevy.join(p).display().to_string();
    let args = ["--model", &at("bevy-ggx.brdf"), "--include-dir", &at("shaders")];
    let files = [at("shaders/pbr_lighting.wgsl"), at("shaders/utils.wgsl")];
    lines_land_on_the_users_files("bevy-ggx", &args, &files, "(its WGSL as GLSL)");
}

/// DXC-era HLSL that Slang's slangc compiles (glslang refuses it): its lines too are the file's own, through
/// slangc's line tables (`-g1`).
#[test]
fn a_slang_compiled_models_lines_are_its_own_files_lines() {
    let file = common::repo_root().join("tests/fixtures/hlsl/slang/dxc-era.hlsl").display().to_string();
    lines_land_on_the_users_files("dxc-era", &["--model", &file], &[file.clone()], "(its HLSL as GLSL)");
}

/// A Slang model's lines are its own file's and those of the module it imports (slangc's line tables name
/// the module by its path); a GLSL model's those of the header it includes.
#[test]
fn slang_modules_and_glsl_includes_keep_their_files_lines() {
    let dir = common::repo_root().join("tests/fixtures/slang");
    let file = |name: &str| dir.join(name).display().to_string();
    let include = dir.display().to_string();
    lines_land_on_the_users_files(
        "ggx-d",
        &["--model", &file("ggx-d.slang"), "--include-dir", &include],
        &[file("ggx-d.slang"), file("Rendering/Microfacet.slang")],
        "(its Slang as GLSL)",
    );
    lines_land_on_the_users_files(
        "ggx-d-glsl",
        &["--model", &file("ggx-d-glsl.brdf")],
        &[file("ggx-d-glsl.brdf"), file("common.glsl")],
        "(its GLSL and includes as GLSL)",
    );
}

/// `inspect --lines` on NVIDIA of model `name` (`args`): its costliest line is one of `files`', each of those files' lines is shown with its own text, every file has lines, at most a fifth of
/// the lines are left on the front end's GLSL (named with `glsl_suffix`), and every instruction counts once.
fn lines_land_on_the_users_files(name: &str, args: &[&str], files: &[String], glsl_suffix: &str) {
    let dir = tempfile::tempdir().unwrap();
    let mut extra = vec!["--lines"];
    extra.extend(args);
    let all = inspect_json(dir.path(), name, &["nvidia:sm_89"], &extra, "Cost per source line");
    // One device: the JSON is its report.
    let k = all["lines"].as_array().unwrap().iter().find(|k| k["model"] == name).unwrap().clone();
    let lines = k["lines"].as_array().unwrap();
    let model: Vec<&serde_json::Value> = lines.iter().filter(|l| !l["harness"].as_bool().unwrap_or(false)).collect();
    let file = |l: &serde_json::Value| l["file"].as_str().unwrap().to_string();
    assert!(files.iter().any(|f| file(model[0]) == *f), "{name}: the costliest line is one of {files:?}: {}", model[0]);
    for f in files {
        let text = std::fs::read_to_string(f).unwrap();
        let on: Vec<_> = model.iter().filter(|l| file(l) == *f).collect();
        assert!(!on.is_empty(), "{name}: {f} has lines");
        for l in on {
            let n = l["line"].as_u64().unwrap() as usize;
            assert_eq!(l["text"].as_str().unwrap(), text.lines().nth(n - 1).unwrap().trim(), "{l}");
        }
    }
    let glsl = model.iter().filter(|l| file(l).ends_with(glsl_suffix)).count();
    assert!(
        glsl * 5 < model.len(),
        "{name}: most lines are the user's: {glsl} of {} left on the front end's GLSL",
        model.len()
    );
    let counted: u64 =
        lines.iter().map(|l| l["instructions"].as_u64().unwrap()).sum::<u64>() + k["unattributed"].as_u64().unwrap();
    assert_eq!(counted, k["instructions"].as_u64().unwrap(), "{name}: every instruction counted once");
}

/// A GLSL file with non-ASCII text in a comment: glslang's `-g` build cuts the embedded source by bytes, which
/// left strings no UTF-8 reader accepts; the lines are still named, each at the file's own line.
#[test]
fn a_non_ascii_comment_keeps_the_lines() {
    let dir = tempfile::tempdir().unwrap();
    let model = dir.path().join("umlaut.brdf");
    let comment = "// Rauhigkeit nach Burley (gr\u{f6}\u{df}er = rauer, \u{2264} 1)";
    std::fs::write(
        &model,
        format!("analytic\n::begin shader\n{comment}\nvec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y) {{\n    float nl = max(dot(N, L), 0.0);\n    return vec3(nl * nl);\n}}\n::end shader\n"),
    )
    .unwrap();
    let all = inspect_json(
        dir.path(),
        "umlaut",
        &["nvidia:sm_89"],
        &["--lines", "--model", model.to_str().unwrap()],
        "Cost per source line",
    );
    let report = all.get("reports").map_or(&all, |r| &r[0]);
    let k = report["lines"].as_array().unwrap().iter().find(|k| k["model"] == "umlaut").unwrap().clone();
    let named: Vec<(String, u64)> = k["lines"]
        .as_array()
        .unwrap()
        .iter()
        .map(|l| (l["file"].as_str().unwrap().to_string(), l["line"].as_u64().unwrap()))
        .collect();
    assert!(named.iter().any(|(f, n)| f.ends_with("umlaut.brdf") && *n == 5), "{named:?}");
    // The harness's lines (glsl/, for a model of the user's files) are marked and ranked apart from the model's.
    for l in k["lines"].as_array().unwrap() {
        let harness = l["harness"].as_bool().unwrap_or(false);
        assert_eq!(harness, l["file"].as_str().unwrap().starts_with("glsl/"), "{l}");
    }
    let md = std::fs::read_to_string(dir.path().join("umlaut.md")).unwrap();
    let section = &md[md.find("#### umlaut: the costliest source lines of the model").expect("the model's table")..];
    let table = section.split("\n\n").nth(1).unwrap();
    assert!(!table.contains("glsl/shade.glsl") && section.contains("The harness's own lines"), "{section}");
}

/// Files with classic Mac line ends (a lone `\r`, as some editors still write) keep each line's number and its
/// text, in GLSL, HLSL and WGSL alike: every line a compiler counts is one line of the report.
#[test]
fn lone_cr_line_ends_keep_each_lines_number_and_text() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let body = ["    float a = max(dot(N, L), 0.0);", "    float b = pow(a, 7.3);"];
    let files = [
        (
            "cr-glsl.brdf",
            format!(
                "analytic\r::begin shader\rvec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y) {{\r{}\r{}\r    return vec3(a * b);\r}}\r::end shader\r",
                body[0], body[1]
            ),
            4,
        ),
        (
            "cr-hlsl.hlsl",
            format!(
                "float3 BRDF(float3 L, float3 V, float3 N, float3 X, float3 Y) {{\r{}\r{}\r    return (a * b).xxx;\r}}\r",
                body[0], body[1]
            ),
            2,
        ),
        (
            "cr-wgsl.wgsl",
            format!(
                "fn BRDF(L: vec3<f32>, V: vec3<f32>, N: vec3<f32>, X: vec3<f32>, Y: vec3<f32>) -> vec3<f32> {{\r{}\r{}\r    return vec3<f32>(a * b);\r}}\r",
                body[0].replace("float", "let"),
                body[1].replace("float", "let")
            ),
            2,
        ),
    ];
    let mut args = vec!["--lines".to_string()];
    for (name, text, _) in &files {
        std::fs::write(d.join(name), text).unwrap();
        args.extend(["--model".to_string(), d.join(name).display().to_string()]);
    }
    let args: Vec<&str> = args.iter().map(String::as_str).collect();
    let all = inspect_json(d, "cr", &["nvidia:sm_89"], &args, "Cost per source line");
    for (name, text, first) in &files {
        let lines: Vec<&str> = text.split('\r').collect();
        let k = all["lines"]
            .as_array()
            .unwrap()
            .iter()
            .find(|k| k["model"] == name.split('.').next().unwrap())
            .unwrap_or_else(|| panic!("{name}: no lines"));
        let named: Vec<(u64, String)> = k["lines"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|l| l["file"].as_str().unwrap().ends_with(name))
            .map(|l| (l["line"].as_u64().unwrap(), l["text"].as_str().unwrap_or("").to_string()))
            .collect();
        for n in [*first, first + 1] {
            let want = lines[n as usize - 1].trim();
            assert!(named.iter().any(|(m, t)| *m == n && t == want), "{name}: line {n} `{want}` in {named:?}");
        }
    }
}

/// A non-ASCII character in a model's path (`café.brdf`, `shäders/lobe.brdf`): glslang garbles any byte above
/// 0x7f in a `#line` directive's file name, so brdfprof gives it the name percent-encoded and reads it back; the
/// lines are named at the user's file with their text on nvidia: and intel:.
#[test]
fn a_non_ascii_path_keeps_the_lines() {
    let dir = tempfile::tempdir().unwrap();
    let folder = dir.path().join("sh\u{e4}ders");
    std::fs::create_dir(&folder).unwrap();
    let model = folder.join("caf\u{e9}.brdf");
    std::fs::write(
        &model,
        "analytic\n::begin shader\nvec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y) {\n    float nl = max(dot(N, L), 0.0);\n    return vec3(pow(nl, 3.5));\n}\n::end shader\n",
    )
    .unwrap();
    let all = inspect_json(
        dir.path(),
        "accents",
        &["nvidia:sm_89", "intel:gen12lp"],
        &["--lines", "--model", model.to_str().unwrap()],
        "Cost per source line",
    );
    for report in all["reports"].as_array().unwrap() {
        let k = report["lines"].as_array().unwrap().iter().find(|k| k["model"] == "caf\u{e9}").unwrap().clone();
        let line = k["lines"]
            .as_array()
            .unwrap()
            .iter()
            .find(|l| l["file"].as_str().unwrap().ends_with("sh\u{e4}ders/caf\u{e9}.brdf") && l["line"] == 5)
            .unwrap_or_else(|| panic!("{}: no line 5 of the file: {k}", report["provenance"]["target"]));
        assert_eq!(line["text"], "return vec3(pow(nl, 3.5));");
    }
}
