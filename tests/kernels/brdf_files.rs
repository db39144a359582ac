//! `.brdf` files as models on the GPU, through the same `Model` and kernels as the built-in specs: the thesis
//! models written as files (examples/brdf/) compute what their presets compute, the tangent frame follows its
//! documented rule, and glslang's errors come back at the file's own lines.

use crate::common;
use brdfprof::brdf::{Sample, THESIS_MODELS, samples};
use brdfprof::kernels::{self, AlbedoCell, EvalExtras, RunLimits};
use brdfprof::model::file_model::{TANGENT_PARALLEL, tangent_frame};
use brdfprof::model::{KernelKind, Model};
use glam::DVec3;
use std::path::{Path, PathBuf};

fn example(name: &str) -> PathBuf {
    common::repo_root().join("examples/brdf").join(format!("{name}.brdf"))
}

/// The example file of a thesis model with roughness and F0 bound to the inputs, as the presets read them.
fn bound(name: &str) -> Model {
    Model::parse(&format!("{},roughness=@roughness,f0=@f0", example(name).display())).unwrap()
}

#[test]
fn example_files_match_their_presets_on_100000_samples() {
    let gpu = common::gpu();
    let per_model = 100_000 / THESIS_MODELS.len();
    for (i, name) in THESIS_MODELS.iter().enumerate() {
        let s = samples::well_conditioned(per_model, 40 + i as u64, 0.05, 0.2..1.0);
        let got = kernels::eval(&gpu, &bound(name), &s, RunLimits::default()).unwrap();
        let builtin = kernels::eval(&gpu, &Model::parse(name).unwrap(), &s, RunLimits::default()).unwrap();
        let mut worst = common::Worst::default();
        for ((g, b), sample) in got.iter().zip(&builtin).zip(&s) {
            for c in 0..3 {
                worst.update(common::rel_err(g[c] as f64, b[c] as f64), || {
                    format!("{sample:?} channel {c}: file {} built-in {}", g[c], b[c])
                });
            }
        }
        println!("{name:14} max rel diff to the built-in over {per_model} samples: {:.2e}", worst.err);
        assert!(worst.err <= 1e-4, "{name}.brdf: max relative difference {:.3e} at {}", worst.err, worst.what);
    }
    common::assert_no_validation_messages(&gpu);
}

#[test]
fn example_files_albedo_matches_their_presets() {
    let gpu = common::gpu();
    let cells: Vec<AlbedoCell> = [0.1f32, 0.5, 1.0]
        .iter()
        .flat_map(|&nov| [0.2f32, 0.6, 1.0].map(|roughness| AlbedoCell { nov, roughness, f0: [0.04, 0.5, 1.0] }))
        .collect();
    for name in THESIS_MODELS {
        let file = kernels::albedo(&gpu, &bound(name), &cells).unwrap();
        let builtin = kernels::albedo(&gpu, &Model::parse(name).unwrap(), &cells).unwrap();
        for ((f, b), cell) in file.iter().zip(&builtin).zip(&cells) {
            for c in 0..3 {
                assert!(
                    (f.e[c] - b.e[c]).abs() <= 1e-4,
                    "{name}: {cell:?} channel {c}: file E {} built-in E {}",
                    f.e[c],
                    b.e[c]
                );
            }
        }
    }
    common::assert_no_validation_messages(&gpu);
}

/// The HLSL and WGSL fixtures (tests/fixtures/hlsl/ue, tests/fixtures/wgsl/bevy), with the
/// directories their includes and imports are in.
fn foreign(language: &str) -> Model {
    let root = common::repo_root().join("tests/fixtures");
    let ue = root.join("hlsl/ue");
    let text = match language {
        "hlsl" => format!(
            "{},include={},include-map=/Engine={}",
            ue.join("ue-ggx.brdf").display(),
            ue.join("Shaders").display(),
            ue.join("Engine").display()
        ),
        _ => format!(
            "{},include={}",
            root.join("wgsl/bevy/bevy-ggx.brdf").display(),
            root.join("wgsl/bevy/shaders").display()
        ),
    };
    Model::parse(&text).unwrap()
}

#[test]
fn hlsl_and_wgsl_files_compute_their_glsl_twins_bits_and_albedo() {
    let gpu = common::gpu();
    let s = samples::well_conditioned(100_000, 30, 0.05, 0.0..1.0);
    let twin = kernels::eval(&gpu, &bound("ggx"), &s, RunLimits::default()).unwrap();
    let cells: Vec<AlbedoCell> = [0.1f32, 0.5, 1.0]
        .iter()
        .flat_map(|&nov| [0.2f32, 0.6, 1.0].map(|roughness| AlbedoCell { nov, roughness, f0: [0.04, 0.5, 1.0] }))
        .collect();
    let twin_albedo = kernels::albedo(&gpu, &bound("ggx"), &cells).unwrap();
    for language in ["hlsl", "wgsl"] {
        let model = foreign(language);
        let got = kernels::eval(&gpu, &model, &s, RunLimits::default()).unwrap();
        let differ = got.iter().zip(&twin).filter(|(g, t)| g.map(f32::to_bits) != t.map(f32::to_bits)).count();
        assert_eq!(differ, 0, "{language}: {differ} of {} samples differ from the GLSL twin's bits", s.len());
        let albedo = kernels::albedo(&gpu, &model, &cells).unwrap();
        for ((a, t), cell) in albedo.iter().zip(&twin_albedo).zip(&cells) {
            assert_eq!(a.e, t.e, "{language}: {cell:?}");
        }
    }
    common::assert_no_validation_messages(&gpu);
}

/// A file returning its tangent X (or Y) as the colour.
fn frame_file(dir: &Path) -> Model {
    let path = dir.join("frame.brdf");
    std::fs::write(&path, "analytic\n::begin parameters\nbool bitangent 0\n::end parameters\n::begin shader\nvec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y) { return bitangent ? Y : X; }\n::end shader\n").unwrap();
    Model::parse(&path.display().to_string()).unwrap()
}

#[test]
fn tangent_frame_follows_its_documented_rule() {
    let gpu = common::gpu();
    let dir = tempfile::tempdir().unwrap();
    let x_model = frame_file(dir.path());
    let y_model = x_model.with_params(&["bitangent=1".into()]).unwrap();
    let mut s: Vec<Sample> = samples::well_conditioned(2_000, 7, 0.05, 0.2..1.0);
    // Normals everywhere on the sphere, the poles (Duff's basis switches sign at z = 0) included.
    for (i, n) in
        [[0.0, 0.0, 1.0], [0.0, 0.0, -1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.3, -0.2, -0.93]].iter().enumerate()
    {
        s[i].n = *n;
    }
    for (i, x) in s.iter_mut().enumerate().skip(5) {
        let t = i as f32 * 0.7;
        x.n = [t.cos() * (t * 0.3).sin(), t.sin() * (t * 0.3).sin(), (t * 0.3).cos()];
    }
    // Given tangents: generic, parallel to N (falls back to the basis) and zero (no tangent).
    let tangents: Vec<[f32; 3]> = s
        .iter()
        .enumerate()
        .map(|(i, x)| match i % 3 {
            0 => [0.6, -0.3, 0.2],
            1 => x.n.map(|c| 2.0 * c),
            _ => [0.0; 3],
        })
        .collect();
    for (model, bitangent) in [(&x_model, false), (&y_model, true)] {
        for given in [None, Some(tangents.as_slice())] {
            let got = kernels::eval_with(
                &gpu,
                model,
                &s,
                &EvalExtras { tangents: given, ..Default::default() },
                RunLimits::default(),
            )
            .unwrap();
            for (i, (g, x)) in got.iter().zip(&s).enumerate() {
                let n = DVec3::from(x.n.map(f64::from)).normalize();
                let t = given.map_or(DVec3::ZERO, |t| DVec3::from(t[i].map(f64::from)));
                let xf = tangent_frame(n, t);
                let want = if bitangent { n.cross(xf) } else { xf };
                for c in 0..3 {
                    assert!(
                        (g[c] as f64 - want[c]).abs() <= 2e-5,
                        "sample {i} (N {n:?}, t {t:?}, Y {bitangent}): GPU {g:?}, rule {want:?}"
                    );
                }
                assert!(
                    xf.dot(n).abs() < 1e-12 && (xf.length() - 1.0).abs() < 1e-12,
                    "X is a unit vector orthogonal to N"
                );
            }
        }
    }
    common::assert_no_validation_messages(&gpu);
}

#[test]
fn the_parallel_threshold_is_the_same_on_both_sides() {
    let glsl = std::fs::read_to_string(common::repo_root().join("glsl/brdf.glsl")).unwrap();
    let line = glsl
        .lines()
        .find(|l| l.contains("const float FILE_TANGENT_PARALLEL"))
        .expect("brdf.glsl defines FILE_TANGENT_PARALLEL");
    let value: f64 = line.split('=').nth(1).unwrap().trim().trim_end_matches(';').parse().unwrap();
    assert_eq!(value, TANGENT_PARALLEL);
}

#[test]
fn glslang_errors_name_the_file_line() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("typo.brdf");
    std::fs::write(&path, "analytic\n# a comment\n::begin parameters\nfloat k 0 1 0.5\n::end parameters\n::begin shader\nvec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y)\n{\n    return vec3(k * foo);\n}\n::end shader\n").unwrap();
    let model = Model::parse(&path.display().to_string()).unwrap();
    let e = format!("{:#}", model.kernel(KernelKind::Eval, kernels::embedded()).unwrap_err());
    assert!(e.contains(&format!("{}:9: 'foo' : undeclared identifier", path.display())), "{e}");
    assert!(!e.contains("brdf_f"), "renamed identifiers are shown by their own names: {e}");
}

#[test]
fn every_kernel_kind_a_file_can_run_compiles() {
    let model = bound("burley");
    for kind in [
        KernelKind::Eval,
        KernelKind::Shade,
        KernelKind::ShadeFloat,
        KernelKind::Albedo,
        KernelKind::Scene,
        KernelKind::SceneAlbedo,
    ] {
        let k = model.kernel(kind, kernels::embedded()).unwrap_or_else(|e| panic!("{kind:?}: {e:#}"));
        assert!(k.spirv.words.len() > 100, "{kind:?}");
    }
    assert!(model.kernel(KernelKind::Terms, kernels::embedded()).is_err(), "a file has no separate terms");
}

/// The limit the loop warnings state: lavapipe ends a loop of 100,000 iterations after
/// `LAVAPIPE_LOOP_LIMIT` (65535), and runs one of 1,000 to its end. Other drivers are not lavapipe.
#[test]
fn lavapipe_ends_every_loop_at_the_stated_limit() {
    let gpu = common::gpu();
    if !gpu.info.name.starts_with("llvmpipe") {
        eprintln!("skipped: {} is not lavapipe", gpu.info.name);
        return;
    }
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("count.brdf");
    std::fs::write(&path, "analytic\n::begin parameters\nfloat n 0 1000000 10\n::end parameters\n::begin shader\nvec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y)\n{\n    float c = 0.0;\n    for (int i = 0; i < int(n); i++) c += 1.0;\n    return vec3(c);\n}\n::end shader\n").unwrap();
    let s = samples::well_conditioned(4, 3, 0.05, 0.2..1.0);
    for (n, expected) in [(1000u64, 1000u64), (100_000, brdfprof::model::brdf_file::LAVAPIPE_LOOP_LIMIT)] {
        let model = Model::parse(&format!("{},n={n}", path.display())).unwrap();
        let got = kernels::eval(&gpu, &model, &s, RunLimits::default()).unwrap();
        assert!(
            got.iter().all(|v| v[0] as u64 == expected),
            "a loop of {n} iterations counted {:?} on lavapipe",
            got[0]
        );
    }
    common::assert_no_validation_messages(&gpu);
}

/// What brdfprof says about `path`: each warning of the file (`warning: ...`), then either the error (`error:
/// ...`, glslang's messages remapped to the file included) or `compiles` once the file's eval kernel compiled.
fn messages_about(path: &Path) -> String {
    let mut out = String::new();
    let model = brdfprof::model::brdf_file::load(path).and_then(|f| {
        for w in &f.warnings {
            out += &format!("warning: {w}\n");
        }
        Model::parse(&path.display().to_string())
    });
    match model.and_then(|m| m.kernel(KernelKind::Eval, &brdfprof::shaders::Shaders::embedded())) {
        Ok(_) => out += "compiles\n",
        Err(e) => out += &format!("error: {e:#}\n"),
    }
    out
}

/// Bad and odd `.brdf` files with what brdfprof must say about them (tests/fixtures/brdf/messages/NAME.brdf
/// -> NAME.out, as naga's tests/in -> tests/out): format errors, the preprocessor's, glslang's remapped to the
/// file's lines and names, and the warnings. `BLESS=1` writes the .out files from what brdfprof says now
/// (read the diff before committing it).
#[test]
fn bad_files_give_the_expected_messages() {
    let dir = Path::new("tests/fixtures/brdf/messages");
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "brdf"))
        .collect();
    files.sort();
    assert!(files.len() >= 20, "{} fixtures", files.len());
    let bless = std::env::var_os("BLESS").is_some();
    let mut wrong = Vec::new();
    for f in &files {
        let got = messages_about(f);
        let expected_path = f.with_extension("out");
        if bless {
            std::fs::write(&expected_path, &got).unwrap();
            continue;
        }
        let expected = std::fs::read_to_string(&expected_path)
            .unwrap_or_else(|_| panic!("{} has no {}", f.display(), expected_path.display()));
        if got != expected {
            wrong.push(format!("{}:\n--- expected\n{expected}--- got\n{got}", f.display()));
        }
    }
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}

/// The renaming's promise (src/model/brdf_file/rename.rs): no identifier of glsl/ starts with the prefix a
/// file's names are given, so a renamed name can never meet one of the kernels'.
#[test]
fn glsl_declares_no_identifier_with_the_file_prefix() {
    let mut found = Vec::new();
    let mut stack = vec![common::repo_root().join("glsl")];
    while let Some(dir) = stack.pop() {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                stack.push(path);
            } else if path.extension().is_some_and(|e| e == "glsl" || e == "comp") {
                let text = std::fs::read_to_string(&path).unwrap();
                for (n, line) in text.lines().enumerate() {
                    for word in line.split(|c: char| !(c == '_' || c.is_ascii_alphanumeric())) {
                        if word.starts_with("brdf_f") {
                            found.push(format!("{}:{}: {word}", path.display(), n + 1));
                        }
                    }
                }
            }
        }
    }
    assert!(found.is_empty(), "glsl/ uses the .brdf file prefix `brdf_f`: {found:?}");
}
