//! Files: inputs read with a bound on their size, output paths checked up front and written atomically (`io`),
//! and the disk cache of compiled outputs (`cache`), on the process layer's temporary paths and messages.

pub mod cache;
pub mod io;

use brdfprof_process::{cleanup, launch, messages};
