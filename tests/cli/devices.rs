//! `--device` with an empty or blank value is an error on every command that opens a device (a blank name
//! is a substring of every device's name, so it would silently pick device 0).

use crate::common::{self, run_in};

#[test]
fn an_empty_or_blank_device_is_refused_by_every_gpu_command() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::write(d.join("in.csv"), "nx,ny,nz,vx,vy,vz,lx,ly,lz,roughness,f0r,f0g,f0b\n0,0,1,0,0.6,0.8,0.6,0,0.8,0.5,0.04,0.04,0.04\n").unwrap();
    let baseline = common::repo_root().join("results/baseline-llvmpipe.json");
    let scene = common::repo_root().join("scenes/sphere-grid.json");
    let (baseline, scene) = (baseline.to_str().unwrap(), scene.to_str().unwrap());
    let commands: [&[&str]; 8] = [
        &["eval", "--model", "ggx", "--input", "in.csv", "--output", "out.csv"],
        &["profile", "--model", "ggx", "--size", "8x8"],
        &["profile", "--scene", scene],
        &["sweep", "--model", "ggx", "--size", "8x8"],
        &["stability", "--model", "ggx"],
        &["inspect", "--model", "ggx", "--no-callgrind"],
        &["check", "--baseline", baseline, "--rounds", "0", "--no-callgrind"],
        &["render", "--scene", scene, "--out", "pictures"],
    ];
    for args in commands {
        for device in ["--device=", "--device= ", "--device=\t"] {
            let run = run_in(d, &[args, &[device]].concat()).fails(2, &format!("invalid value '{}' for '--device <DEVICE>': empty", &device[9..]));
            assert!(run.stdout.is_empty(), "{args:?} {device:?} printed: {}", run.stdout);
        }
    }
    assert_eq!(std::fs::read_dir(d).unwrap().count(), 1, "nothing but the input in the directory");
}
