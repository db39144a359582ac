//! The command line end to end: eval's CSV round trip and its errors, device and output checks made before
//! anything is measured, scene names, cleanup on signals, and fuzzed inputs.

#[path = "../common/mod.rs"]
mod common;

mod brdf_models;
mod cache;
mod compare;
mod devices;
mod diff;
mod eval;
mod eval_csv;
mod fuzz;
mod limits;
mod nvidia;
mod outputs;
mod radv;
mod scenes;
mod signals;
