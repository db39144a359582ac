//! Files in and out: the `eval` CSV format (`csv`: errors name file, line and column); bounded reads, output
//! paths checked up front and atomic writes are `brdfprof_files::io`'s, re-exported here.

pub mod csv;

pub use brdfprof_files::io::*;
pub use csv::{
    Columns, EvalInput, SAMPLE_COLUMNS, TANGENT_COLUMNS, parse_eval_csv, parse_samples_csv, read_eval_csv,
    read_eval_csv_with, read_samples_csv,
};
