//! The compile-only targets end to end, the binary run as a user runs it: each vendor's compiler statistics and
//! cost tables (radv, nvidia, intel, and Mesa's drivers on their noop shims), the cost rule's microkernel and
//! measured-reference suites, one-operation pairs, transcendentals, cost per source line, and the translations
//! (the corpus priced against its f64 evaluation, the faults a translation or its tools can meet).
//!
//! What goes here: a test whose subject is a compile-only target's report or the rule that prices it. Not here: a
//! command's own behaviour that merely names a target (tests/cli), timing gates (tests/timed).

#[path = "../common/mod.rs"]
mod common;

mod compile_only;
mod cost_pairs;
mod intel;
mod measured;
mod mesa_shims;
mod microkernels;
mod nvidia;
mod radv;
mod source_lines;
mod transcendentals;
mod translation_corpus;
mod translation_faults;
