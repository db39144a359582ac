//! spv/ must be what glslang makes of glsl/ today: recompiles every kernel of glsl/kernels.txt with the
//! flags of glsl/build-spv.sh and compares bytes with the embedded SPIR-V.

mod common;
use brdfprof::shaders::KERNELS;
use std::process::Command;

#[test]
fn spv_matches_glsl() {
    let root = common::repo_root();
    let dir = tempfile::tempdir().unwrap();
    let mut stale = Vec::new();
    for k in KERNELS {
        let out = dir.path().join(format!("{}.spv", k.name));
        let mut cmd = Command::new("glslangValidator");
        cmd.args(["-V", "--target-env", "vulkan1.1"]);
        for d in k.defines {
            cmd.arg(format!("-D{d}"));
        }
        cmd.arg("-o").arg(&out).arg(root.join("glsl").join(k.source));
        let status = cmd.output().expect("glslangValidator (install glslang-tools, or run `make setup`)");
        assert!(status.status.success(), "{} does not compile:\n{}", k.source, String::from_utf8_lossy(&status.stdout));
        if std::fs::read(&out).unwrap() != k.spirv {
            stale.push(k.name);
        }
    }
    assert!(stale.is_empty(), "spv/ is stale against glsl/ for {stale:?}: run `make spv` and commit spv/");
}

#[test]
fn kernel_list_covers_every_spv_file() {
    let listed: Vec<String> = KERNELS.iter().map(|k| format!("{}.spv", k.name)).collect();
    for entry in std::fs::read_dir(common::repo_root().join("spv")).unwrap() {
        let name = entry.unwrap().file_name().to_string_lossy().into_owned();
        assert!(listed.contains(&name), "spv/{name} is not in glsl/kernels.txt");
    }
}
