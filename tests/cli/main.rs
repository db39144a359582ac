//! The command line end to end, the binary run as a user runs it: eval's CSV round trip and its errors, `.brdf`
//! models through every command, the kernel cache, device and output checks made before anything is measured,
//! limits, cleanup on signals, `compare`, fuzzed inputs; and README and docs/ against the tree (`docs`). The
//! compile-only targets' own tests are tests/targets.
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
// The targets binary's helper, of which this binary uses a part.
#[allow(dead_code)]
#[path = "../targets/compile_only.rs"]
mod compile_only;
mod devices;
mod diff;
mod docs;
mod engine_entries;
mod eval;
mod eval_csv;
mod fuzz;
mod gate;
mod hostile;
mod limits;
mod outputs;
mod report;
mod shader_languages;
mod signals;
mod slang_and_includes;
mod stability;
mod swiftshader;
