//! The process layer every part of brdfprof stands on: the one launcher of child processes (`launch`: limits,
//! bounded output, uncancellable calls bounded on a thread), cleanup of children and temporary paths on signals
//! (`cleanup`), every warning, note, error and progress line on stderr (`messages`), and where the tools brdfprof
//! installs for itself are found (`tools`).

pub mod cleanup;
pub mod launch;
pub mod messages;
pub mod tools;
