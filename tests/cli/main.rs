//! The command line end to end: eval's CSV round trip and its errors.

#[path = "../common/mod.rs"]
mod common;

mod eval;
