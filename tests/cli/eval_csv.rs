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

/// Eval requires only the material columns the model reads. A conductor's Fresnel reads no F0 and a
/// `.brdf` file with no binding reads neither roughness nor F0: their CSVs may leave those out, with the same
/// output as with them; a model that reads a column still requires it, by name.
#[test]
fn only_the_columns_the_model_reads_are_required() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let geometry = "0,0,1,0,0.6,0.8,0.6,0,0.8";
    let rows = ["0.5", "0.3"];
    std::fs::write(
        d.join("full.csv"),
        format!("{HEADER}\n{}", rows.iter().map(|r| format!("{geometry},{r},0.04,0.04,0.04\n")).collect::<String>()),
    )
    .unwrap();
    std::fs::write(
        d.join("no-f0.csv"),
        format!(
            "nx,ny,nz,vx,vy,vz,lx,ly,lz,roughness\n{}",
            rows.iter().map(|r| format!("{geometry},{r}\n")).collect::<String>()
        ),
    )
    .unwrap();
    std::fs::write(d.join("geometry.csv"), format!("nx,ny,nz,vx,vy,vz,lx,ly,lz\n{geometry}\n{geometry}\n")).unwrap();
    let read = |name: &str| std::fs::read_to_string(d.join(name)).unwrap();
    let copper = "d=ggx,vis=smith-ggx-correlated,f=conductor,metal=copper";
    run_in(d, &["eval", "--model", copper, "--input", "full.csv", "--output", "a.csv"]).ok();
    run_in(d, &["eval", "--model", copper, "--input", "no-f0.csv", "--output", "b.csv"]).ok();
    assert_eq!(read("a.csv"), read("b.csv"), "F0 is not read by a conductor");
    assert_ne!(read("a.csv").lines().nth(1), read("a.csv").lines().nth(2), "roughness is read: the rows differ");
    run_in(d, &["eval", "--model", "ggx", "--input", "no-f0.csv", "--output", "c.csv"])
        .fails(2, "header lacks column(s) f0r, f0g, f0b");
    run_in(d, &["eval", "--model", copper, "--input", "geometry.csv", "--output", "c.csv"])
        .fails(2, "header lacks column(s) roughness");
    let file = crate::common::repo_root().join("tests/fixtures/brdf/quality-switch.brdf").display().to_string();
    run_in(d, &["eval", "--model", &file, "--input", "full.csv", "--output", "e.csv"]).ok();
    run_in(d, &["eval", "--model", &file, "--input", "geometry.csv", "--output", "f.csv"]).ok();
    assert_eq!(read("e.csv"), read("f.csv"), "a file with no binding reads no material column");
    let bound = format!("{}/examples/brdf/ggx.brdf,roughness=@roughness", crate::common::repo_root().display());
    run_in(d, &["eval", "--model", &bound, "--input", "geometry.csv", "--output", "g.csv"])
        .fails(2, "header lacks column(s) roughness");
}
