//! `loop-passes=N` (`spirv::loops`): a file's loops at a fixed count of header passes per entry, the compiles
//! `targets::trips` prices a model's own loops from. Real glslang and spirv-opt, the host translation's own
//! count of loop-header passes, and spirv-val on every module made.

use brdfprof::model::{KernelKind, Model};
use brdfprof::shaders::Shaders;
use brdfprof::translate::verify::loop_passes;

fn loops(words: &[u32]) -> usize {
    brdfprof::spirv::loops::count(words).unwrap()
}

fn spirv_val(words: &[u32], what: &str) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("k.spv");
    std::fs::write(&path, bytemuck::cast_slice::<u32, u8>(words)).unwrap();
    let out = std::process::Command::new("spirv-val").arg(&path).output().expect("spirv-val runs");
    assert!(out.status.success(), "{what}: spirv-val: {}", String::from_utf8_lossy(&out.stderr));
}

/// A `for` loop (exit test before the body, loop-16) and a `do` loop (after it) run exactly the passes asked in
/// their eval kernels (whose loop the host translation counts); the `for` loop's shading kernel has it written
/// out for the compilers, valid SPIR-V throughout, and the `do` loop's is refused (spirv-opt's `--loop-unroll`
/// writes out loops tested at the top only), which `targets::trips` reports as a loop counted once.
#[test]
fn a_files_loops_run_the_passes_asked_and_are_written_out_for_the_compilers() {
    let shaders = Shaders::embedded();
    let dir = tempfile::tempdir().unwrap();
    let do_loop = dir.path().join("do-loop.brdf");
    std::fs::write(
        &do_loop,
        "analytic\n::begin shader\nvec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y) {\n    float x = dot(N, L);\n    int i = 0;\n    do {\n        x = x * 0.5 + dot(N, V);\n        i++;\n    } while (i < 3 + int(step(4.0, x)));\n    return vec3(x);\n}\n::end shader\n",
    )
    .unwrap();
    let loop16 = crate::common::repo_root().join("tests/fixtures/brdf/micro/loop-16.brdf");
    // Unset: loop-16 runs 16 iterations and the exit test, the do loop 3 passes.
    for (file, own, written_out) in [(&loop16, 17.0, true), (&do_loop, 3.0, false)] {
        let file = file.to_str().unwrap();
        let model = Model::parse(file).unwrap();
        assert_eq!(loop_passes(&model, &shaders).unwrap(), own, "{file}");
        assert_eq!(loops(&model.kernel(KernelKind::Shade, &shaders).unwrap().spirv.words), 1, "{file}");
        for n in [2, 3, 5] {
            let what = format!("{file},loop-passes={n}");
            let m = Model::parse(&what).unwrap();
            assert_eq!(loop_passes(&m, &shaders).unwrap(), f64::from(n), "{what}");
            let eval = m.kernel(KernelKind::Eval, &shaders).unwrap().spirv.words;
            assert_eq!(loops(&eval), 1, "{what}: loops in the eval kernel");
            spirv_val(&eval, &what);
            match m.kernel(KernelKind::Shade, &shaders) {
                Ok(shade) if written_out => {
                    assert_eq!(loops(&shade.spirv.words), 0, "{what}: loops in the shading kernel");
                    spirv_val(&shade.spirv.words, &what);
                }
                Err(e) if !written_out => {
                    let e = format!("{e:#}");
                    assert!(e.contains("do-loop.brdf: loop-passes=") && e.contains("cannot write out"), "{e}");
                }
                other => panic!("{what}: {:?}", other.map(|_| "written out")),
            }
        }
    }
}

#[test]
fn a_count_of_passes_out_of_range_is_refused_naming_the_file_and_the_key() {
    let file = crate::common::repo_root().join("tests/fixtures/brdf/micro/loop-16.brdf");
    for bad in ["1", "x", "257"] {
        let text = format!("{},loop-passes={bad}", file.display());
        let e = format!("{:#}", Model::parse(&text).unwrap_err());
        assert!(
            e.contains("loop-16.brdf") && e.contains(&format!("`loop-passes={bad}`")) && e.contains("2 to 256"),
            "{e}"
        );
    }
}

/// `targets::trips` makes twins of a file of one loop brdfprof cannot count (loop-16: its passes 17, the twins'
/// 2 and 3, labelled after the model) and none of a file of two loops, whose passes one count cannot price: that
/// model is named with the reason and its loops' body counted once.
#[test]
fn a_model_is_priced_at_its_passes_only_where_one_count_prices_its_loops() {
    use brdfprof::targets::trips::{Trips, is_twin};
    let shaders = Shaders::embedded();
    let dir = tempfile::tempdir().unwrap();
    let two = dir.path().join("two-loops.brdf");
    std::fs::write(
        &two,
        "analytic\n::begin shader\nvec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y) {\n    float x = dot(N, L);\n    int n = 4 + int(step(4.0, x));\n    for (int i = 0; i < n; i++) { x = x * 0.5 + dot(N, V); }\n    for (int i = 0; i < n; i++) { x = x * 0.25 + dot(N, V); }\n    return vec3(x);\n}\n::end shader\n",
    )
    .unwrap();
    let loop16 = crate::common::repo_root().join("tests/fixtures/brdf/micro/loop-16.brdf");
    let models = [Model::parse(loop16.to_str().unwrap()).unwrap(), Model::parse(two.to_str().unwrap()).unwrap()];
    let trips = Trips::of(&models, &shaders);
    assert_eq!(trips.len(), 2);
    let twins = trips[0].fixed.as_ref().unwrap().as_ref().unwrap();
    let counts: Vec<(u32, String, f64)> = twins.iter().map(|(n, m, p)| (*n, m.label(), *p)).collect();
    assert_eq!(counts, [(2, "loop-16.loop-passes=2".to_string(), 2.0), (3, "loop-16.loop-passes=3".to_string(), 3.0)]);
    assert!(twins.iter().all(|(_, m, _)| is_twin(m)) && !is_twin(&models[0]));
    assert_eq!(trips[0].passes, Ok(17.0));
    let why = trips[1].fixed.as_ref().unwrap().as_ref().unwrap_err();
    assert!(why.contains("2 loops"), "{why}");
    let note = Trips::note(&trips, &["loop-16".to_string()]).unwrap();
    assert!(note.contains("loop-16 (") && note.contains("evaluation, priced at them"), "{note}");
    assert!(
        note.contains("two-loops (") && note.contains("each loop's body counted once (the file has 2 loops"),
        "{note}"
    );
    // On a target that did not price loop-16's twins, its note says so.
    let note = Trips::note(&trips, &[]).unwrap();
    assert!(
        !note.contains("evaluation, priced at them") && note.contains("were not both priced on this target"),
        "{note}"
    );
}
