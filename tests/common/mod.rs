//! Helpers shared by the integration tests. Every GPU test runs on the default device (lavapipe in CI) under
//! the Khronos validation layer and fails on any validation message.
#![allow(dead_code)]

use brdfprof::gpu::{Gpu, GpuOptions};
use std::path::PathBuf;

pub fn gpu() -> Gpu {
    Gpu::new(&GpuOptions { device: std::env::var("BRDFPROF_TEST_DEVICE").ok(), validation: true })
        .expect("a Vulkan device with the validation layer (run `make setup`)")
}

pub fn assert_no_validation_messages(gpu: &Gpu) {
    let messages = gpu.validation_messages();
    assert!(messages.is_empty(), "{} validation message(s):\n{}", messages.len(), messages.join("\n"));
}

/// |gpu - reference| / max(|reference|, 1e-3): the error measure.
pub fn rel_err(gpu: f64, reference: f64) -> f64 {
    (gpu - reference).abs() / reference.abs().max(1e-3)
}

pub fn brdfprof() -> std::process::Command {
    let mut c = std::process::Command::new(env!("CARGO_BIN_EXE_brdfprof"));
    c.env_remove("BRDFPROF_VALIDATION");
    c
}

/// The file `dir/PREFIX<device>.EXT` a command wrote for the default device, whatever that device's name.
pub fn device_file(dir: &std::path::Path, prefix: &str, suffix: &str) -> PathBuf {
    let matches: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| {
            let name = p.file_name().unwrap().to_string_lossy();
            name.starts_with(prefix) && name.ends_with(suffix) && !name[prefix.len()..name.len() - suffix.len()].contains('-')
        })
        .collect();
    assert_eq!(matches.len(), 1, "one {prefix}<device>{suffix} in {}: {matches:?}", dir.display());
    matches[0].clone()
}

pub fn repo_root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The largest error and where it happened.
#[derive(Debug, Default, Clone)]
pub struct Worst {
    pub err: f64,
    pub what: String,
}

impl Worst {
    pub fn update(&mut self, err: f64, what: impl FnOnce() -> String) {
        if err > self.err || err.is_nan() {
            self.err = if err.is_nan() { f64::INFINITY } else { err };
            self.what = what();
        }
    }
}
