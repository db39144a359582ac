//! `eval`'s CSV reader end to end: a BOM, quoted fields and CRLF line ends are read; a byte that is not
//! UTF-8 and a column named twice exit 2 naming the line and column, with no output written.

use crate::common::run_in;

const HEADER: &str = "nx,ny,nz,vx,vy,vz,lx,ly,lz,roughness,f0r,f0g,f0b";
const ROW: &str = "0,0,1,0,0.6,0.8,0.6,0,0.8,0.5,0.04,0.04,0.04";

#[test]
fn a_bom_quoted_fields_and_crlf_are_read() {
    let dir = tempfile::tempdir().unwrap();
    let quoted = |line: &str| line.split(',').map(|f| format!("\"{f}\"")).collect::<Vec<_>>().join(",");
    std::fs::write(dir.path().join("plain.csv"), format!("{HEADER}\n{ROW}\n")).unwrap();
    std::fs::write(dir.path().join("excel.csv"), format!("\u{feff}{}\r\n{}\r\n", quoted(HEADER), quoted(ROW))).unwrap();
    run_in(dir.path(), &["eval", "--model", "ggx", "--input", "plain.csv", "--output", "plain-out.csv"]).ok();
    run_in(dir.path(), &["eval", "--model", "ggx", "--input", "excel.csv", "--output", "excel-out.csv"]).ok();
    let read = |name: &str| std::fs::read_to_string(dir.path().join(name)).unwrap();
    assert_eq!(read("excel-out.csv"), read("plain-out.csv"));
    assert_eq!(read("plain-out.csv").lines().count(), 2);
}

#[test]
fn bad_bytes_and_twice_named_columns_name_where() {
    let dir = tempfile::tempdir().unwrap();
    let mut latin1 = format!("{HEADER},note\n{ROW},ok\n{ROW},caf").into_bytes();
    latin1.extend_from_slice(b"\xe9\n");
    std::fs::write(dir.path().join("latin1.csv"), latin1).unwrap();
    std::fs::write(dir.path().join("twice.csv"), format!("{HEADER},nz\n{ROW},1\n")).unwrap();
    let eval = |input: &str| run_in(dir.path(), &["eval", "--model", "ggx", "--input", input, "--output", "out.csv"]);
    eval("latin1.csv").fails(2, &format!("latin1.csv:3: byte column {}: byte 0xe9 is not UTF-8", ROW.len() + 5));
    eval("twice.csv").fails(2, "twice.csv:1: columns 3 and 14 are both named `nz`");
    assert!(!dir.path().join("out.csv").exists());
}
