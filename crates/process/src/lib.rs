//! The process layer every part of brdfprof stands on: the one launcher of child processes (`launch`: limits,
//! bounded output, uncancellable calls bounded on a thread), cleanup of children and temporary paths on signals
//! (`cleanup`), and every warning, note, error and progress line on stderr (`messages`).

pub mod cleanup;
pub mod launch;
pub mod messages;
