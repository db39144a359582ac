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
    for bad in ["1", "x", "70000"] {
        let text = format!("{},loop-passes={bad}", file.display());
        let e = format!("{:#}", Model::parse(&text).unwrap_err());
        assert!(
            e.contains("loop-16.brdf") && e.contains(&format!("`loop-passes={bad}`")) && e.contains("2 to 65536"),
            "{e}"
        );
    }
}
