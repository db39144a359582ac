//! Helpers shared by the integration tests. Every GPU test runs on the default device (lavapipe in CI) under
//! the Khronos validation layer and fails on any validation message; every CLI invocation goes through `run`.
#![allow(dead_code)]

use brdfprof::brdf::spec::with_each_param_sample;
use brdfprof::brdf::{D, F, ModelSpec, Vis};
use brdfprof::gpu::{Gpu, GpuOptions};
use brdfprof::model::Model;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

pub fn gpu() -> Gpu {
    Gpu::new(&GpuOptions { device: std::env::var("BRDFPROF_TEST_DEVICE").ok(), validation: true, ..Default::default() })
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

/// The brdfprof binary, with the validation layer on (BRDFPROF_VALIDATION=1) and the test device.
pub fn brdfprof() -> Command {
    let mut c = Command::new(env!("CARGO_BIN_EXE_brdfprof"));
    c.env("BRDFPROF_VALIDATION", "1");
    if let Ok(d) = std::env::var("BRDFPROF_TEST_DEVICE") {
        c.env("BRDFPROF_TEST_DEVICE", d);
    }
    c
}

/// What a CLI invocation did.
pub struct Run {
    pub code: Option<i32>,
    pub stdout: String,
    pub stderr: String,
}

impl Run {
    fn of(out: Output) -> Run {
        Run {
            code: out.status.code(),
            stdout: String::from_utf8_lossy(&out.stdout).into_owned(),
            stderr: String::from_utf8_lossy(&out.stderr).into_owned(),
        }
    }

    /// Asserts exit 0 and no validation message; returns self.
    pub fn ok(self) -> Run {
        assert_eq!(self.code, Some(0), "exit status {:?}; stderr:\n{}", self.code, self.stderr);
        self.no_validation()
    }

    /// Asserts exit `code` with `needle` in stderr.
    pub fn fails(self, code: i32, needle: &str) -> Run {
        assert_eq!(self.code, Some(code), "expected exit {code}, got {:?}; stderr:\n{}", self.code, self.stderr);
        assert!(self.stderr.contains(needle), "expected `{needle}` in stderr:\n{}", self.stderr);
        self.no_validation()
    }

    pub fn no_validation(self) -> Run {
        assert!(!self.stderr.contains("validation ["), "validation messages:\n{}", self.stderr);
        self
    }
}

/// Runs `brdfprof ARGS` (validation on) in the current directory.
pub fn run(args: &[&str]) -> Run {
    Run::of(brdfprof().args(args).output().expect("brdfprof runs"))
}

/// Runs `brdfprof ARGS` (validation on) in `dir`.
pub fn run_in(dir: &Path, args: &[&str]) -> Run {
    Run::of(brdfprof().args(args).current_dir(dir).output().expect("brdfprof runs"))
}

/// The file `dir/PREFIX<device>.EXT` a command wrote for the default device, whatever that device's name.
pub fn device_file(dir: &Path, prefix: &str, suffix: &str) -> PathBuf {
    let matches: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| {
            let name = p.file_name().unwrap().to_string_lossy();
            name.starts_with(prefix)
                && name.ends_with(suffix)
                && !name[prefix.len()..name.len() - suffix.len()].contains('-')
        })
        .collect();
    assert_eq!(matches.len(), 1, "one {prefix}<device>{suffix} in {}: {matches:?}", dir.display());
    matches[0].clone()
}

pub fn repo_root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The Rust source folders of the workspace: the application's src/ and each leaf crate's src/.
pub fn source_dirs() -> Vec<PathBuf> {
    let root = repo_root();
    let mut dirs = vec![root.join("src")];
    let mut crates: Vec<PathBuf> =
        std::fs::read_dir(root.join("crates")).unwrap().map(|e| e.unwrap().path().join("src")).collect();
    crates.sort();
    dirs.extend(crates);
    dirs
}

/// A model of the term library.
pub fn model(spec: ModelSpec) -> Model {
    Model::spec(spec)
}

/// Every D of the table, with each sample of the parameters it reads (Vis implicit, F none).
pub fn every_d() -> Vec<ModelSpec> {
    D::ALL.iter().flat_map(|&d| with_each_param_sample(ModelSpec::new(d, Vis::Implicit, F::None))).collect()
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

/// Uniform numbers in [0, 1) from a xorshift64 generator seeded with `seed`: the tests' reproducible samples.
pub fn uniform(seed: u64) -> impl FnMut() -> f64 {
    let mut x = seed;
    move || {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        (x >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// The first three columns of every row of a CSV `eval` wrote (its header skipped): the outputs.
pub fn csv_values(path: &Path) -> Vec<[f64; 3]> {
    std::fs::read_to_string(path)
        .unwrap()
        .lines()
        .skip(1)
        .map(|l| {
            let v: Vec<f64> = l.split(',').map(|x| x.parse().unwrap()).collect();
            [v[0], v[1], v[2]]
        })
        .collect()
}
