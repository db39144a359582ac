//! The scene commands end to end: `scene --explain` and `scene FILE`; `render` writes every picture;
//! `profile --scene` prints what is compiled in and each effect's cost with a CI, and writes the JSON; malformed
//! scene files exit 2 with the JSON path of the problem, a missing image exits 2 naming the file, and nothing
//! is written. (Small G-buffers and short budgets: this checks plumbing, not figures.)

use crate::common;
use serde_json::Value;
use std::path::Path;

fn run(args: &[&str]) -> (i32, String, String) {
    let out = common::brdfprof().args(args).output().unwrap();
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

const SMALL: &str = r#"{
  "name": "small",
  "gbuffer": {"procedural": {"kind": "statues", "size": [96, 54], "statues": ["brushed", "paint"], "floor": "floor"}},
  "lights": [
    {"type": "directional", "direction": [0.3, -1.0, -0.4]},
    {"type": "point", "position": [-3.0, 3.0, 2.0], "intensity": 8.0},
    {"type": "spot", "position": [0.0, 5.0, 3.0], "direction": [0.0, -1.0, -0.6], "intensity": 30.0},
    {"type": "sphere", "position": [2.0, 2.5, 1.5], "radius": 0.4, "intensity": 10.0}
  ],
  "materials": [
    {"name": "brushed", "model": "ggx", "base_colour": [0.9, 0.9, 0.92], "metallic": 1.0, "roughness": 0.35, "effects": {"anisotropy": 0.7}},
    {"name": "paint", "model": "ggx", "base_colour": [0.5, 0.05, 0.05], "effects": {"clear_coat": {"strength": 1.0}}},
    {"name": "floor", "model": "blinn", "roughness": 0.7, "effects": {"diffuse": "lambert", "energy_compensation": true}}
  ],
  "render": {"models": ["ggx", "burley"], "grid": ["paint"], "lobe_roughness": [0.5]}
}"#;

fn write(dir: &Path, name: &str, text: &str) -> String {
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p.display().to_string()
}

#[test]
fn explain_and_check() {
    let (code, out, _) = run(&["scene", "--explain"]);
    assert_eq!(code, 0);
    assert!(
        out.contains("\"effects\"") && out.contains("representative point") && out.contains("\"sphere-grid\""),
        "{out}"
    );
    let dir = tempfile::tempdir().unwrap();
    let f = write(dir.path(), "s.json", SMALL);
    let (code, out, err) = run(&["scene", &f]);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("ggx:") && out.contains("anisotropy") && out.contains("clear-coat"), "{out}");
    assert!(out.contains("blinn:") && out.contains("energy-compensation") && out.contains("1 sphere"), "{out}");
}

#[test]
fn render_writes_every_picture() {
    let dir = tempfile::tempdir().unwrap();
    let f = write(dir.path(), "s.json", SMALL);
    let out = dir.path().join("out");
    let (code, stdout, err) = run(&["render", "--validate", "--scene", &f, "--out", out.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    assert!(!err.contains("validation ["), "{err}");
    for name in ["ggx.png", "burley.png", "diff-burley-vs-ggx.png", "grid.png", "lobes.png"] {
        let img = image::open(out.join(name)).unwrap_or_else(|e| panic!("{name}: {e}\n{stdout}"));
        assert!(img.width() > 50 && img.height() > 50);
    }
    let ggx = image::open(out.join("ggx.png")).unwrap().to_rgb8();
    assert_eq!((ggx.width(), ggx.height()), (96, 54));
    assert!(ggx.pixels().any(|p| p.0.iter().any(|&c| c > 128)), "the render is not all dark");
    assert!(err.contains("anisotropy needs d=ggx"), "burley renders drop anisotropy with a note: {err}");
}

#[test]
fn profile_scene_prints_what_is_compiled_in_and_effect_costs() {
    let dir = tempfile::tempdir().unwrap();
    let f = write(dir.path(), "s.json", SMALL);
    let json = dir.path().join("p.json");
    let (code, out, err) = run(&[
        "profile",
        "--validate",
        "--scene",
        &f,
        "--budget",
        "5",
        "--min-rounds",
        "6",
        "--json",
        json.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(!err.contains("validation ["), "{err}");
    assert!(out.contains("Compiled in") && out.contains("| ggx ") && out.contains("| blinn "), "{out}");
    for effect in ["anisotropy", "clear-coat", "diffuse", "energy-compensation"] {
        assert!(out.contains(&format!("| {effect}")), "no cost row for {effect}:\n{out}");
    }
    let report: Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let effects = report["effects"].as_array().unwrap();
    assert_eq!(effects.len(), 4);
    for e in effects {
        let x = &e["extra_ns_per_pixel"];
        assert!(
            x["lo"].as_f64().unwrap() <= x["median"].as_f64().unwrap()
                && x["median"].as_f64().unwrap() <= x["hi"].as_f64().unwrap()
        );
    }
    // Anisotropy (two lobes' worth of work on the brushed statue's pixels, per light) costs something measurable.
    let aniso = effects.iter().find(|e| e["effect"] == "anisotropy").unwrap();
    assert!(aniso["extra_spirv_instructions"].as_i64().unwrap() > 0);
    assert_eq!(report["kernels"].as_array().unwrap().len(), 2);
}

/// `--cost-device`: every kernel the profile times, compiled by each vendor's compiler (ACO on the frozen
/// SPIR-V; NVRTC and IGC on the translation, which first shades the scene's pixels on the host and agrees
/// with the Vulkan kernel), with modelled cycles per pixel and what each effect adds.
#[test]
fn profile_scene_cost_devices_compile_every_variant_on_each_vendor() {
    let dir = tempfile::tempdir().unwrap();
    let f = write(dir.path(), "s.json", SMALL);
    let json = dir.path().join("p.json");
    let targets = ["radv:navi21", "nvidia:sm_89", "intel:gen12lp"];
    let isa = dir.path().join("isa");
    let mut args = vec![
        "profile",
        "--validate",
        "--scene",
        &f,
        "--budget",
        "3",
        "--min-rounds",
        "2",
        "--json",
        json.to_str().unwrap(),
        "--isa",
        isa.to_str().unwrap(),
    ];
    for t in targets {
        args.extend(["--cost-device", t]);
    }
    let (code, out, err) = run(&args);
    assert_eq!(code, 0, "{err}");
    assert!(!err.contains("validation ["), "{err}");
    let report: Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let reports = report["targets"].as_array().unwrap();
    assert_eq!(reports.iter().map(|r| r["target"].as_str().unwrap()).collect::<Vec<_>>(), targets);
    for r in reports {
        let name = r["target"].as_str().unwrap();
        assert!(out.contains(&format!("{name} cycles/pixel")), "{out}");
        let kernels = r["kernels"].as_array().unwrap();
        assert_eq!(
            kernels.iter().map(|k| k["model"].as_str().unwrap()).collect::<Vec<_>>(),
            ["ggx", "blinn"],
            "{name}"
        );
        for k in kernels {
            // Cycles per pixel is the vendor's cost rule over one light (max of the busiest pipe and latency over
            // resident waves, per lane): the kernel's light loops are in it.
            let (c, s) = (k["cycles_per_pixel"].as_f64().unwrap(), &k["stats"]);
            let per_wave =
                s["busiest pipe (cycles/wave)"].as_f64().unwrap().max(s["latency / waves"].as_f64().unwrap());
            let expected = match name.split(':').next().unwrap() {
                "radv" => per_wave / 64.0,
                "nvidia" => per_wave / 32.0,
                _ => per_wave / s["SIMD Width"].as_f64().unwrap(),
            };
            assert!(c > 0.0 && (c - expected).abs() <= 1e-9 * expected, "{name} {}: {c} vs {expected}", k["model"]);
        }
        let pairs = |v: &Value| {
            v.as_array()
                .unwrap()
                .iter()
                .map(|e| (e["model"].as_str().unwrap().to_string(), e["effect"].as_str().unwrap().to_string()))
                .collect::<Vec<_>>()
        };
        assert_eq!(
            pairs(&r["effects"]),
            pairs(&report["effects"]),
            "{name}: the effects the profile measured, in its order"
        );
        let effects = r["effects"].as_array().unwrap();
        // Anisotropy (a second lobe per light) and the clear coat (a second specular lobe) add instructions on
        // every compiler: compiling them out must save modelled cycles.
        for e in effects.iter().filter(|e| e["effect"] == "anisotropy" || e["effect"] == "clear-coat") {
            assert!(e["extra_cycles_per_pixel"].as_f64().unwrap() > 0.0, "{name} {}: {e}", e["effect"]);
        }
        if name.starts_with("radv:") {
            assert!(r["translation"].as_object().unwrap().is_empty(), "ACO compiles the SPIR-V itself");
            assert!(r["compiler"].as_str().unwrap().starts_with("ACO (22."), "Mesa's version: {}", r["compiler"]);
            continue;
        }
        let options = r["options"].as_str().unwrap();
        assert!(options.contains("-use_fast_math") || options.contains("-cl-mad-enable"), "{name}: {options}");
        let notes = r["translation"].as_object().unwrap();
        assert_eq!(notes.len(), 6, "{name}: every variant's translation was checked: {notes:?}");
        for (label, note) in notes {
            let worst: f64 = note
                .as_str()
                .unwrap()
                .split("worst relative difference ")
                .nth(1)
                .unwrap()
                .split_whitespace()
                .next()
                .unwrap()
                .parse()
                .unwrap();
            assert!(worst <= 1e-3, "{name} {label}: {note}");
            assert!(
                note.as_str().unwrap().contains("pixels (") && !note.as_str().unwrap().contains("(0 lit)"),
                "{label}: {note}"
            );
        }
    }
    // --isa: each variant's compiler output per target, as `inspect --isa` writes it.
    for (file, marker) in [
        ("navi21/ggx-without-clear-coat.assembly.txt", "s_endpgm"),
        ("nvidia-sm_89/ggx-without-clear-coat.sass", "EXIT"),
        ("intel-gen12lp/blinn-without-diffuse.asm", "EOT"),
        ("intel-gen12lp/blinn.cl", "__kernel"),
    ] {
        let text = std::fs::read_to_string(isa.join(file)).unwrap_or_else(|e| panic!("{file}: {e}"));
        assert!(text.contains(marker), "{file} has no {marker}");
    }
    // An fp16 model's translation agrees within fp16's tolerance (the maths libraries differ by its ulps); a
    // family without fp16 (tahiti) leaves that kernel out with a note, and the others are still reported.
    let f16 =
        write(dir.path(), "f16.json", &SMALL.replace(r#""model": "blinn""#, r#""model": "burley,precision=f16""#));
    let (code, out, err) = run(&[
        "profile",
        "--scene",
        &f16,
        "--budget",
        "2",
        "--min-rounds",
        "2",
        "--json",
        json.to_str().unwrap(),
        "--cost-device",
        "nvidia:sm_89",
        "--cost-device",
        "radv:tahiti",
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(!err.contains("note: cache"), "the agreements' cache entries are valid: {err}");
    let report: Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let notes = report["targets"][0]["translation"].as_object().unwrap();
    assert!(
        notes.iter().any(|(label, note)| label.starts_with("burley,precision=f16")
            && note.as_str().unwrap().contains("(tolerance 5e-2)")),
        "{notes:?}"
    );
    let tahiti = &report["targets"][1];
    assert_eq!(
        tahiti["kernels"].as_array().unwrap().iter().map(|k| k["model"].as_str().unwrap()).collect::<Vec<_>>(),
        ["ggx"]
    );
    assert!(
        tahiti["notes"][0].as_str().unwrap().contains("not compiled for radv:tahiti: burley,precision=f16"),
        "{tahiti}"
    );
    assert!(
        out.contains("| burley,precision=f16 ") && out.contains(" - "),
        "a kernel tahiti left out is `-` in its column:\n{out}"
    );
    // A material whose BRDF has a loop brdfprof cannot count: its scene kernel counts the loop's body once, and
    // the target's notes say so, naming the loop's line.
    let loop16 = common::repo_root().join("tests/fixtures/brdf/micro/loop-16.brdf");
    let looped = SMALL.replace(r#""model": "blinn""#, &format!(r#""model": "{}""#, loop16.display()));
    let looped = write(dir.path(), "loop.json", &looped);
    let args = ["profile", "--scene", &looped, "--budget", "2", "--min-rounds", "2", "--json", json.to_str().unwrap()];
    let (code, _, err) = run(&[&args[..], &["--cost-device", "radv:navi21"]].concat());
    assert_eq!(code, 0, "{err}");
    let report: Value = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
    let notes = report["targets"][0]["notes"].to_string();
    assert!(
        notes.contains("Loops brdfprof cannot count from the source: loop-16 (")
            && notes.contains("loop-16.brdf:15)")
            && notes.contains("counts each loop's body once"),
        "{notes}"
    );
    // The cost devices are compile-only targets, and only a scene profile takes them.
    let (code, _, err) = run(&["profile", "--scene", &f, "--cost-device", "llvmpipe"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("--cost-device llvmpipe") && err.contains("compile-only target"), "{err}");
    let (code, _, err) = run(&["profile", "--cost-device", "radv:navi21"]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("--cost-device and --isa apply to --scene") && err.contains("inspect --device radv:navi21"),
        "{err}"
    );
    let (code, _, err) = run(&["profile", "--scene", &f, "--isa", isa.to_str().unwrap()]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("--isa") && err.contains("give --cost-device too"), "{err}");
}

#[test]
fn bad_scenes_exit_2_naming_the_problem() {
    let dir = tempfile::tempdir().unwrap();
    let cases = [
        (
            SMALL.replace(r#""roughness": 0.35"#, r#""roughness": "x""#),
            "materials[0].roughness: invalid type: string \"x\", expected f32",
        ),
        (SMALL.replace(r#""radius": 0.4"#, r#""radius": -1"#), "lights[3].radius"),
        (SMALL.replace(r#""model": "blinn""#, r#""model": "blin""#), "materials[2].model: unknown model `blin`"),
        (
            SMALL.replace(r#""floor": "floor"}}"#, r#""floor": "flor"}}"#),
            "gbuffer.procedural.floor: no material named `flor`",
        ),
        (SMALL.replace(r#""size": [96, 54]"#, r#""size": [96]"#), "gbuffer.procedural.size"),
    ];
    for (i, (text, expected)) in cases.iter().enumerate() {
        let f = write(dir.path(), &format!("bad{i}.json"), text);
        let out = dir.path().join(format!("out{i}"));
        let (code, _, err) = run(&["render", "--scene", &f, "--out", out.to_str().unwrap()]);
        assert_eq!(code, 2, "{expected}: {err}");
        assert!(err.contains(expected) && err.contains(&f), "expected `{expected}` naming {f} in: {err}");
        assert!(!out.exists(), "nothing is written for a bad scene");
    }
    let images = r#"{"gbuffer": {"images": {"normal": "missing-normal.png", "depth": "d.exr"}},
        "camera": {"position": [0, 0, 5], "look_at": [0, 0, 0]}, "lights": [], "materials": [{"name": "a", "model": "ggx"}]}"#;
    let f = write(dir.path(), "images.json", images);
    let (code, _, err) = run(&["scene", &f]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains(&dir.path().join("missing-normal.png").display().to_string()), "{err}");
    let (code, _, err) = run(&["profile", "--scene", &dir.path().join("nope.json").display().to_string()]);
    assert_eq!(code, 2);
    assert!(err.contains("nope.json"), "{err}");
}

#[test]
fn a_brdf_file_as_a_material_model_renders_as_its_preset() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::copy(common::repo_root().join("examples/brdf/ggx.brdf"), dir.path().join("mine.brdf")).unwrap();
    // The path is relative to the scene file, not to where brdfprof runs.
    let scene = SMALL
        .replace(r#""name": "small""#, r#""name": "file""#)
        .replace(r#""model": "ggx""#, r#""model": "mine.brdf,roughness=@roughness,f0=@f0""#)
        .replace(r#""anisotropy": 0.7"#, r#""anisotropy": 0.0"#)
        .replace("[96, 54]", "[192, 108]")
        .replace(r#""models": ["ggx", "burley"]"#, r#""models": ["mine.brdf,roughness=@roughness,f0=@f0"]"#);
    let f = write(dir.path(), "s.json", &scene);
    let builtin = write(
        dir.path(),
        "b.json",
        &scene
            .replace("mine.brdf,roughness=@roughness,f0=@f0", "ggx")
            .replace(r#""name": "file""#, r#""name": "builtin""#),
    );
    let out = dir.path().join("out");
    for (scene, sub) in [(&f, "file"), (&builtin, "builtin")] {
        let (code, _, err) = run(&["render", "--scene", scene, "--out", out.join(sub).to_str().unwrap()]);
        assert_eq!(code, 0, "{err}");
        assert!(!err.contains("validation ["), "{err}");
    }
    let png = |sub: &str, prefix: &str| {
        let path = std::fs::read_dir(out.join(sub))
            .unwrap()
            .map(|e| e.unwrap().path())
            .find(|p| p.file_name().unwrap().to_string_lossy().starts_with(prefix))
            .unwrap();
        image::open(path).unwrap().to_rgb8()
    };
    // The file by its label (its stem with its bindings), not its path: mine-roughness---roughness-f0---f0.png.
    let (a, b) = (png("file", "mine-roughness"), png("builtin", "ggx."));
    assert_eq!(a.dimensions(), b.dimensions());
    // Below the title, which names the model.
    let below = |img: &image::RgbImage| {
        img.enumerate_pixels().filter(|(_, y, _)| *y >= 20).map(|(_, _, p)| *p).collect::<Vec<_>>()
    };
    let worst = below(&a)
        .iter()
        .zip(below(&b).iter())
        .flat_map(|(p, q)| (0..3).map(move |c| (p[c] as i32 - q[c] as i32).abs()))
        .max()
        .unwrap();
    assert!(worst <= 1, "the file's picture differs from the preset's by {worst}/255");
}

#[test]
fn an_engine_entry_returning_f_nol_renders_as_its_twin_returning_f() {
    // tests/fixtures/brdf/engine: the same GGX as an engine's light function (f_s N.L, `returns f_nol`) and as
    // BRDF Explorer's BRDF (f_s); both bind their inputs in the file. The clear coat stays on (a file takes no
    // anisotropy: that replaces GGX's D and Vis).
    let dir = tempfile::tempdir().unwrap();
    let engine = common::repo_root().join("tests/fixtures/brdf/engine");
    let mut pictures = Vec::new();
    for file in ["engine-ggx", "engine-ggx-f"] {
        let model = engine.join(format!("{file}.brdf")).display().to_string();
        let scene = SMALL
            .replace(r#""model": "ggx""#, &format!(r#""model": "{model}""#))
            .replace(r#""anisotropy": 0.7"#, r#""anisotropy": 0.0"#)
            .replace(r#""models": ["ggx", "burley"]"#, &format!(r#""models": ["{model}"]"#));
        let f = write(dir.path(), &format!("{file}.json"), &scene);
        let out = dir.path().join(file);
        let (code, _, err) = run(&["render", "--scene", &f, "--out", out.to_str().unwrap()]);
        assert_eq!(code, 0, "{err}");
        assert!(!err.contains("validation ["), "{err}");
        let path = std::fs::read_dir(&out)
            .unwrap()
            .map(|e| e.unwrap().path())
            .find(|p| {
                p.file_name().unwrap().to_string_lossy().starts_with(file) && p.extension().is_some_and(|x| x == "png")
            })
            .unwrap();
        pictures.push(image::open(path).unwrap().to_rgb8());
    }
    let below = |img: &image::RgbImage| {
        img.enumerate_pixels().filter(|(_, y, _)| *y >= 20).map(|(_, _, p)| *p).collect::<Vec<_>>()
    };
    let (a, b) = (below(&pictures[0]), below(&pictures[1]));
    assert_eq!(a.len(), b.len());
    let worst =
        a.iter().zip(&b).flat_map(|(p, q)| (0..3).map(move |c| (p[c] as i32 - q[c] as i32).abs())).max().unwrap();
    assert!(worst <= 1, "the engine form's picture differs from the f form's by {worst}/255");
    assert!(a.iter().any(|p| p[0] > 10), "a lit picture");
}

/// Copies the files of `from` (and its folders) into `to`.
fn copy_tree(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).unwrap();
    for e in std::fs::read_dir(from).unwrap() {
        let p = e.unwrap().path();
        let dest = to.join(p.file_name().unwrap());
        if p.is_dir() {
            copy_tree(&p, &dest);
        } else {
            std::fs::copy(&p, &dest).unwrap();
        }
    }
}

#[test]
fn hlsl_and_wgsl_materials_render_as_their_glsl_twin() {
    // The UE-style HLSL and Bevy-style WGSL fixtures, copied beside the scene: their include
    // directories, as the model's path, are relative to the scene file.
    let dir = tempfile::tempdir().unwrap();
    copy_tree(&common::repo_root().join("tests/fixtures/hlsl/ue"), &dir.path().join("ue"));
    copy_tree(&common::repo_root().join("tests/fixtures/wgsl/bevy"), &dir.path().join("bevy"));
    std::fs::copy(common::repo_root().join("examples/brdf/ggx.brdf"), dir.path().join("twin.brdf")).unwrap();
    let models = [
        ("twin", "twin.brdf,roughness=@roughness,f0=@f0", "twin-roughness"),
        ("ue", "ue/ue-ggx.brdf,include=ue/Shaders,include-map=/Engine=ue/Engine", "ue-ggx."),
        ("bevy", "bevy/bevy-ggx.brdf,include=bevy/shaders", "bevy-ggx."),
    ];
    let mut pictures = Vec::new();
    for (name, model, prefix) in models {
        let scene = SMALL
            .replace(r#""name": "small""#, &format!(r#""name": "{name}""#))
            .replace(r#""model": "ggx""#, &format!(r#""model": "{model}""#))
            .replace(r#""anisotropy": 0.7"#, r#""anisotropy": 0.0"#)
            .replace(r#""models": ["ggx", "burley"]"#, &format!(r#""models": ["{model}"]"#));
        let f = write(dir.path(), &format!("{name}.json"), &scene);
        let out = dir.path().join("out").join(name);
        let (code, _, err) = run(&["render", "--scene", &f, "--out", out.to_str().unwrap()]);
        assert_eq!(code, 0, "{err}");
        assert!(!err.contains("validation ["), "{err}");
        let path = std::fs::read_dir(&out)
            .unwrap()
            .map(|e| e.unwrap().path())
            .find(|p| p.file_name().unwrap().to_string_lossy().starts_with(prefix))
            .unwrap_or_else(|| panic!("no {prefix}* in {}", out.display()));
        pictures.push(image::open(path).unwrap().to_rgb8());
    }
    // Below the title, which names the model: the same pixels.
    let below = |img: &image::RgbImage| {
        img.enumerate_pixels().filter(|(_, y, _)| *y >= 20).map(|(_, _, p)| *p).collect::<Vec<_>>()
    };
    let twin = below(&pictures[0]);
    assert!(twin.iter().any(|p| p[0] > 10), "a lit picture");
    for (k, name) in [(1, "HLSL"), (2, "WGSL")] {
        assert!(below(&pictures[k]) == twin, "the {name} material's picture differs from its GLSL twin's");
    }
}
