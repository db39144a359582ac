//! The command line end to end, the binary run as a user runs it: eval's CSV round trip and its errors, `.brdf`
//! models through every command, the kernel cache, device and output checks made before anything is measured,
//! limits, cleanup on signals, compile-only targets' reports and `compare`, fuzzed inputs; and README and docs/
//! against the tree (`docs`).
//!
//! What goes here: a test that runs `brdfprof` (or a script) and checks its exit status, output and files, and
//! that does not time kernels. Not here: library calls against f64 twins (tests/kernels), anything about scenes
//! (tests/scenes), timing or callgrind gates (tests/timed, which runs one test at a time).

#[path = "../common/mod.rs"]
mod common;

mod brdf_models;
mod cache;
mod ci;
mod compare;
mod compile_only;
mod cost_pairs;
mod devices;
mod diff;
mod docs;
mod engine_entries;
mod eval;
mod eval_csv;
mod fuzz;
mod gate;
mod hostile;
mod intel;
mod limits;
mod measured;
mod mesa_shims;
mod microkernels;
mod nvidia;
mod outputs;
mod radv;
mod report;
mod shader_languages;
mod signals;
mod slang_and_includes;
mod source_lines;
mod stability;
mod swiftshader;
mod transcendentals;
mod translation_corpus;
mod translation_faults;
