//! The `eval` CSV format. Read as bytes and decoded line by line, so that a byte that is not UTF-8 is named
//! by its line and byte column; a UTF-8 byte order mark before the header is skipped; fields may be quoted as
//! RFC 4180 says (`"nx"`, `"0.5"`, `""` for a quote inside quotes; a quoted field cannot span lines). Every
//! error names the file, the line and the column (`in.csv:3: column 6 `vz`: `x` is not a number`).

use crate::brdf::Sample;
use crate::brdf::guards::MIN_VECTOR;
use anyhow::{Result, anyhow, bail};
use std::borrow::Cow;
use std::path::Path;

/// Columns `eval` needs, in any order; others are ignored.
pub const SAMPLE_COLUMNS: [&str; 13] =
    ["nx", "ny", "nz", "vx", "vy", "vz", "lx", "ly", "lz", "roughness", "f0r", "f0g", "f0b"];

/// Optional tangent columns: all three or none.
pub const TANGENT_COLUMNS: [&str; 3] = ["tx", "ty", "tz"];

/// What an eval CSV holds: the samples, the tangents where it has `tx,ty,tz`, and each optional column asked
/// for that the file has (in the order asked), one value per row.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct EvalInput {
    pub samples: Vec<Sample>,
    pub tangents: Option<Vec<[f32; 3]>>,
    pub columns: Vec<(String, Vec<f32>)>,
    /// The 1-based column number of each of `columns`.
    pub column_numbers: Vec<usize>,
    /// The file line of each row.
    pub lines: Vec<usize>,
}

/// Reads `eval` input: every value a finite number, vectors non-zero, roughness and F0 in [0, 1].
pub fn read_samples_csv(path: &Path) -> Result<Vec<Sample>> {
    Ok(read_eval_csv(path, &[])?.samples)
}

/// Reads an eval CSV with the tangents and the `optional` columns it has (values finite).
pub fn read_eval_csv(path: &Path, optional: &[&str]) -> Result<EvalInput> {
    read_eval_csv_with(path, &Columns { optional, ..Columns::default() })
}

/// What an eval CSV must and may hold besides the geometry (nx..lz), for one model.
#[derive(Clone, Copy, Debug, Default)]
pub struct Columns<'a> {
    /// Further columns read where the file has them (a `.brdf` parameter's), in this order.
    pub optional: &'a [&'a str],
    /// Sample columns (`roughness`, `f0r`, ...) only required to be finite: a `.brdf` model that reads no input
    /// from them takes them as its own parameter's column.
    pub relaxed: &'a [&'a str],
    /// Sample columns the model does not read, which may then be absent (their value is `UNREAD_VALUES`').
    pub unread: &'a [&'a str],
}

/// The value of an absent sample column that the model does not read (`Columns::unread`): roughness 0.5, F0
/// 0.04, for the record only, as nothing reads them.
pub const UNREAD_VALUES: [f32; 4] = [0.5, 0.04, 0.04, 0.04];

/// `read_eval_csv` for a model's `Columns`.
pub fn read_eval_csv_with(path: &Path, columns: &Columns) -> Result<EvalInput> {
    let bytes = super::read_input(path)?;
    parse_eval_csv_with(&bytes, &path.display().to_string(), columns)
}

/// `read_samples_csv` of bytes already read; `name` prefixes errors.
pub fn parse_samples_csv(input: impl AsRef<[u8]>, name: &str) -> Result<Vec<Sample>> {
    Ok(parse_eval_csv(input.as_ref(), name, &[])?.samples)
}

const BOM: &[u8] = b"\xEF\xBB\xBF";

/// `read_eval_csv` of bytes already read; `name` prefixes errors.
pub fn parse_eval_csv(bytes: &[u8], name: &str, optional: &[&str]) -> Result<EvalInput> {
    parse_eval_csv_with(bytes, name, &Columns { optional, ..Columns::default() })
}

/// The lines of `bytes`, numbered from 1, ended by `\n`, `\r\n` or a lone `\r` (an old Mac's line ends).
fn split_lines(bytes: &[u8]) -> impl Iterator<Item = (usize, &[u8])> {
    let mut rest = Some(bytes);
    std::iter::from_fn(move || {
        let b = rest?;
        match b.iter().position(|&c| c == b'\n' || c == b'\r') {
            Some(i) => {
                let next = if b[i..].starts_with(b"\r\n") { i + 2 } else { i + 1 };
                rest = Some(&b[next..]);
                Some(&b[..i])
            }
            None => {
                rest = None;
                Some(b)
            }
        }
    })
    .enumerate()
    .map(|(i, l)| (i + 1, l))
}

/// `parse_eval_csv` for a model's `Columns` (`read_eval_csv_with`).
pub fn parse_eval_csv_with(bytes: &[u8], name: &str, columns: &Columns) -> Result<EvalInput> {
    let bom = if bytes.starts_with(BOM) { BOM.len() } else { 0 };
    let mut lines = split_lines(&bytes[bom..]);
    let mut decoded = std::iter::from_fn(move || {
        lines
            .find(|(_, l)| !l.trim_ascii().is_empty())
            .map(|(line, bytes)| decode(name, line, bytes, if line == 1 { bom } else { 0 }))
    });
    let (header_line, header) = decoded
        .next()
        .ok_or_else(|| anyhow!("{name}: empty file; expected a header with columns {}", SAMPLE_COLUMNS.join(",")))??;
    let mut layout = Layout::new(name, header_line, header, columns)?;
    layout.relaxed = SAMPLE_COLUMNS.map(|c| columns.relaxed.contains(&c));
    let mut input = EvalInput {
        tangents: layout.tangents.map(|_| Vec::new()),
        columns: layout.optional.iter().map(|(n, _)| (n.clone(), Vec::new())).collect(),
        column_numbers: layout.optional.iter().map(|(_, i)| i + 1).collect(),
        ..Default::default()
    };
    for item in decoded {
        let (line, text) = item?;
        layout.read_row(name, line, text, &mut input)?;
    }
    Ok(input)
}

/// One line as UTF-8; `offset` bytes (a BOM) came before it, for the column of an error.
fn decode<'a>(name: &str, line: usize, bytes: &'a [u8], offset: usize) -> Result<(usize, &'a str)> {
    std::str::from_utf8(bytes).map(|s| (line, s)).map_err(|e| {
        let at = e.valid_up_to();
        anyhow!(
            "{name}:{line}: byte column {}: byte 0x{:02x} is not UTF-8 (save the file as UTF-8)",
            offset + at + 1,
            bytes[at]
        )
    })
}

/// Splits a line into fields: unquoted fields trimmed, quoted fields ("...", `""` a quote) taken as written.
/// An error gives the 1-based number of the field at fault and why.
pub fn split_fields(line: &str) -> Result<Vec<Cow<'_, str>>, (usize, &'static str)> {
    let mut fields = Vec::new();
    let mut rest = line;
    loop {
        let start = rest.trim_start_matches([' ', '\t']);
        let (field, after) = if let Some(quoted) = start.strip_prefix('"') {
            let (field, after) =
                unquote(quoted).ok_or((fields.len() + 1, "a quoted field is not closed on its line"))?;
            let after = after.trim_start_matches([' ', '\t']);
            if !(after.is_empty() || after.starts_with(',')) {
                return Err((fields.len() + 1, "text after the closing quote (a quote inside quotes is written \"\")"));
            }
            (field, after)
        } else {
            let end = start.find(',').unwrap_or(start.len());
            (Cow::Borrowed(start[..end].trim()), &start[end..])
        };
        fields.push(field);
        match after.strip_prefix(',') {
            Some(next) => rest = next,
            None => return Ok(fields),
        }
    }
}

/// The text of a quoted field (after its opening quote) and what follows its closing quote.
fn unquote(s: &str) -> Option<(Cow<'_, str>, &str)> {
    let mut owned: Option<String> = None;
    let mut from = 0;
    loop {
        let q = from + s[from..].find('"')?;
        if s[q + 1..].starts_with('"') {
            owned.get_or_insert_with(String::new).push_str(&s[from..=q]);
            from = q + 2;
        } else {
            let field = match owned {
                Some(mut o) => {
                    o.push_str(&s[from..q]);
                    Cow::Owned(o)
                }
                None => Cow::Borrowed(&s[..q]),
            };
            return Some((field, &s[q + 1..]));
        }
    }
}

/// Where each column the reader needs is, from the header.
struct Layout {
    width: usize,
    names: Vec<String>,
    /// Field index of each of SAMPLE_COLUMNS; None for an absent column the model does not read.
    samples: [Option<usize>; 13],
    tangents: Option<[usize; 3]>,
    /// Optional columns present: name and field index.
    optional: Vec<(String, usize)>,
    /// Which of SAMPLE_COLUMNS need only be finite (no [0, 1] range).
    relaxed: [bool; 13],
}

impl Layout {
    fn new(name: &str, line: usize, header: &str, columns: &Columns) -> Result<Layout> {
        let names: Vec<String> = split_fields(header)
            .map_err(|(col, why)| anyhow!("{name}:{line}: header column {col}: {why}"))?
            .into_iter()
            .map(Cow::into_owned)
            .collect();
        for (i, n) in names.iter().enumerate().filter(|(_, n)| !n.is_empty()) {
            if let Some(j) = names[..i].iter().position(|m| m == n) {
                bail!("{name}:{line}: columns {} and {} are both named `{n}`; name each column once", j + 1, i + 1);
            }
        }
        let find = |c: &str| names.iter().position(|n| n == c);
        let needed: Vec<&str> = SAMPLE_COLUMNS
            .iter()
            .enumerate()
            .filter(|(k, c)| *k < 9 || !columns.unread.contains(c))
            .map(|(_, c)| *c)
            .collect();
        let missing: Vec<&str> = needed.iter().copied().filter(|c| find(c).is_none()).collect();
        if !missing.is_empty() {
            bail!(
                "{name}:{line}: header lacks column(s) {} (the model reads {})",
                missing.join(", "),
                needed.join(",")
            );
        }
        let samples = SAMPLE_COLUMNS.map(find); // absent ones are unread material columns (checked above)
        let tangents = match TANGENT_COLUMNS.map(find) {
            [Some(x), Some(y), Some(z)] => Some([x, y, z]),
            [None, None, None] => None,
            found => {
                let has = |want: bool| {
                    TANGENT_COLUMNS
                        .iter()
                        .zip(found)
                        .filter(|(_, f)| f.is_some() == want)
                        .map(|(c, _)| *c)
                        .collect::<Vec<_>>()
                        .join(", ")
                };
                bail!(
                    "{name}:{line}: header has tangent column(s) {} but lacks {} (tangents need all of {})",
                    has(true),
                    has(false),
                    TANGENT_COLUMNS.join(",")
                );
            }
        };
        let mut wanted: Vec<(String, usize)> = Vec::new();
        for c in columns.optional {
            if let Some(i) = find(c).filter(|_| !wanted.iter().any(|(n, _)| n == c)) {
                wanted.push((c.to_string(), i));
            }
        }
        Ok(Layout { width: names.len(), names, samples, tangents, optional: wanted, relaxed: [false; 13] })
    }

    /// Reads one data row into `input`.
    fn read_row(&self, name: &str, line: usize, text: &str, input: &mut EvalInput) -> Result<()> {
        let fields = split_fields(text).map_err(|(col, why)| anyhow!("{name}:{line}: column {col}: {why}"))?;
        if fields.len() != self.width {
            bail!("{name}:{line}: {} fields, but the header has {}", fields.len(), self.width);
        }
        let value = |col: usize| -> Result<f32> { number(name, line, col, &self.names[col], &fields[col]) };
        let mut v = [0f32; 13];
        for (k, col) in self.samples.iter().enumerate() {
            v[k] = match col {
                Some(col) => value(*col)?,
                None => UNREAD_VALUES[k - 9],
            };
        }
        for (first, label) in [(0, "n"), (3, "v"), (6, "l")] {
            nonzero(name, line, &format!("{label}x,{label}y,{label}z"), &v[first..first + 3])?;
        }
        for k in 9..13 {
            if let Some(col) = self.samples[k].filter(|_| !self.relaxed[k] && !(0.0..=1.0).contains(&v[k])) {
                bail!("{name}:{line}: column {} `{}`: {} is outside [0, 1]", col + 1, SAMPLE_COLUMNS[k], v[k]);
            }
        }
        input.samples.push(Sample {
            n: [v[0], v[1], v[2]],
            v: [v[3], v[4], v[5]],
            l: [v[6], v[7], v[8]],
            roughness: v[9],
            f0: [v[10], v[11], v[12]],
        });
        input.lines.push(line);
        if let (Some(cols), Some(out)) = (self.tangents, input.tangents.as_mut()) {
            let t = [value(cols[0])?, value(cols[1])?, value(cols[2])?];
            nonzero(name, line, &TANGENT_COLUMNS.join(","), &t)?;
            out.push(t);
        }
        for ((_, col), (_, out)) in self.optional.iter().zip(input.columns.iter_mut()) {
            out.push(value(*col)?);
        }
        Ok(())
    }
}

/// A finite number; errors name the line, the 0-based field `col` (shown 1-based) and its column.
fn number(name: &str, line: usize, col: usize, column: &str, raw: &str) -> Result<f32> {
    let raw = raw.trim();
    let x: f32 =
        raw.parse().map_err(|_| anyhow!("{name}:{line}: column {} `{column}`: `{raw}` is not a number", col + 1))?;
    if !x.is_finite() {
        bail!("{name}:{line}: column {} `{column}`: `{raw}` is not finite", col + 1);
    }
    Ok(x)
}

/// A vector whose largest component reaches MIN_VECTOR (what the kernels can normalise: GPUs may flush
/// smaller values to zero).
fn nonzero(name: &str, line: usize, columns: &str, v: &[f32]) -> Result<()> {
    let largest = v.iter().fold(0f32, |m, x| m.max(x.abs()));
    let shown = v
        .iter()
        .map(|&x| if x != 0.0 && x.abs() < 1e-4 { format!("{x:e}") } else { x.to_string() })
        .collect::<Vec<_>>()
        .join(", ");
    if largest == 0.0 {
        bail!("{name}:{line}: columns {columns}: zero-length vector ({shown})");
    }
    if f64::from(largest) < MIN_VECTOR {
        bail!(
            "{name}:{line}: columns {columns}: vector too short to normalise ({shown}): its largest component is below {MIN_VECTOR:e} (FLT_MIN), where GPUs may flush values to zero; scale it up"
        );
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    const HEADER: &str = "roughness,nx,ny,nz,vx,vy,vz,lx,ly,lz,f0r,f0g,f0b,extra";
    const ROW: &str = "0.5,0,0,1,0,0.6,0.8,0.6,0,0.8,0.04,0.05,0.06,x";

    fn err(text: impl AsRef<[u8]>) -> String {
        parse_samples_csv(text, "in.csv").unwrap_err().to_string()
    }

    #[test]
    fn columns_in_any_order_and_extra_ignored() {
        let s = parse_samples_csv(format!("{HEADER}\n0.5,0,0,1,0,0.6,0.8,0.6,0,0.8,0.04,0.05,0.06,hello\n"), "in.csv")
            .unwrap();
        assert_eq!(s.len(), 1);
        assert_eq!((s[0].roughness, s[0].n, s[0].f0), (0.5, [0.0, 0.0, 1.0], [0.04, 0.05, 0.06]));
    }

    #[test]
    fn errors_name_line_and_column() {
        let e = err(format!("{HEADER}\n{ROW}\n0.5,0,0,1,0,abc,0.8,0.6,0,0.8,0.04,0.05,0.06,x\n"));
        assert!(e.contains("in.csv:3: column 6 `vy`: `abc` is not a number"), "{e}");
        let e = err("nx,ny,nz\n");
        assert!(e.contains("in.csv:1: header lacks column(s) vx"), "{e}");
        assert!(err("\n\n").contains("empty file"));
        let e = err(format!("{HEADER}\n0.5,0,0,0,0,0.6,0.8,0.6,0,0.8,0.04,0.05,0.06,x\n"));
        assert!(e.contains("in.csv:2: columns nx,ny,nz: zero-length vector"), "{e}");
        let e = err(format!("{HEADER}\nNaN,0,0,1,0,0.6,0.8,0.6,0,0.8,0.04,0.05,0.06,x\n"));
        assert!(e.contains("column 1 `roughness`: `NaN` is not finite"), "{e}");
        let e = err(format!("{HEADER}\n{ROW},9\n"));
        assert!(e.contains("in.csv:2: 15 fields, but the header has 14"), "{e}");
    }

    #[test]
    fn a_byte_that_is_not_utf8_names_line_and_byte_column() {
        let mut bytes = format!("{HEADER}\n{ROW}\n").into_bytes();
        bytes.extend_from_slice(b"0.5,0,0,1,\xff,0.6,0.8,0.6,0,0.8,0.04,0.05,0.06,x\n");
        let e = err(&bytes);
        assert!(e.contains("in.csv:3: byte column 11: byte 0xff is not UTF-8"), "{e}");
        // A multi-byte character is fine where it is ignored; the header's column counts the BOM.
        assert!(
            parse_samples_csv(format!("{HEADER}\n0.5,0,0,1,0,0.6,0.8,0.6,0,0.8,0.04,0.05,0.06,é\n"), "in.csv").is_ok()
        );
        let e = err(b"\xEF\xBB\xBFnx,\xc3\n");
        assert!(e.contains("in.csv:1: byte column 7: byte 0xc3"), "{e}");
    }

    #[test]
    fn a_bom_and_quoted_fields_are_accepted() {
        let quoted_header = HEADER.split(',').map(|c| format!("\"{c}\"")).collect::<Vec<_>>().join(",");
        let quoted_row = "\"0.5\", \"0\" ,0,1,0,0.6,0.8,0.6,0,0.8,0.04,0.05,0.06,\"say \"\"hi\"\", x\"";
        let s = parse_samples_csv(format!("\u{feff}{quoted_header}\r\n{quoted_row}\r\n"), "in.csv").unwrap();
        assert_eq!((s.len(), s[0].roughness, s[0].n), (1, 0.5, [0.0, 0.0, 1.0]));
        assert_eq!(split_fields("a,\"b,\"\"c\"\"\", d ,").unwrap(), ["a", "b,\"c\"", "d", ""]);
        let e = err(format!("{HEADER}\n0.5,\"0,0,1,0,0.6,0.8,0.6,0,0.8,0.04,0.05,0.06,x\n"));
        assert!(e.contains("in.csv:2: column 2: a quoted field is not closed"), "{e}");
        let e = err(format!("{HEADER}\n0.5,\"0\"1,0,1,0,0.6,0.8,0.6,0,0.8,0.04,0.05,0.06,x\n"));
        assert!(e.contains("in.csv:2: column 2: text after the closing quote"), "{e}");
    }

    #[test]
    fn a_column_named_twice_names_both() {
        let e = err(format!("{HEADER},ny\n{ROW},0\n"));
        assert!(e.contains("in.csv:1: columns 3 and 15 are both named `ny`"), "{e}");
    }

    #[test]
    fn tangents_and_optional_columns() {
        let text = format!("{HEADER},tz,ty,tx,aniso\n{ROW},0,0,1,0.5\n{ROW},0,2,0,-1\n");
        let input = parse_eval_csv(text.as_bytes(), "in.csv", &["aniso", "extra_missing"]).unwrap();
        assert_eq!(input.tangents, Some(vec![[1.0, 0.0, 0.0], [0.0, 2.0, 0.0]]));
        assert_eq!(input.columns, vec![("aniso".to_string(), vec![0.5, -1.0])]);
        assert_eq!(parse_eval_csv(format!("{HEADER}\n{ROW}\n").as_bytes(), "in.csv", &[]).unwrap().tangents, None);
        let e =
            parse_eval_csv(format!("{HEADER},tz,tx\n{ROW},0,1\n").as_bytes(), "in.csv", &[]).unwrap_err().to_string();
        assert!(e.contains("in.csv:1: header has tangent column(s) tx, tz but lacks ty"), "{e}");
        let e = parse_eval_csv(format!("{HEADER},tx,ty,tz\n{ROW},0,0,0\n").as_bytes(), "in.csv", &[])
            .unwrap_err()
            .to_string();
        assert!(e.contains("in.csv:2: columns tx,ty,tz: zero-length vector"), "{e}");
        let e = parse_eval_csv(format!("{HEADER},tx,ty,tz\n{ROW},1,inf,0\n").as_bytes(), "in.csv", &[])
            .unwrap_err()
            .to_string();
        assert!(e.contains("in.csv:2: column 16 `ty`: `inf` is not finite"), "{e}");
        let e = parse_eval_csv(format!("{HEADER},aniso\n{ROW},nan\n").as_bytes(), "in.csv", &["aniso"])
            .unwrap_err()
            .to_string();
        assert!(e.contains("in.csv:2: column 15 `aniso`: `nan` is not finite"), "{e}");
    }

    #[test]
    fn a_tiny_vector_is_named_for_what_it_is() {
        let e = err(format!("{HEADER}\n0.5,0,0,1e-40,0,0.6,0.8,0.6,0,0.8,0.04,0.05,0.06,x\n"));
        assert!(
            e.contains("in.csv:2: columns nx,ny,nz: vector too short to normalise (0, 0, 1e-40)")
                && e.contains("FLT_MIN"),
            "{e}"
        );
        assert!(!e.contains("zero-length"), "{e}");
    }

    #[test]
    fn cr_only_line_ends_and_row_lines() {
        let input = parse_eval_csv(format!("{HEADER}\r{ROW}\r\r{ROW}\r").as_bytes(), "in.csv", &[]).unwrap();
        assert_eq!((input.samples.len(), input.lines.clone()), (2, vec![2, 4]));
        let e = err(format!("{HEADER}\r{ROW}\r0.5,0,0,1,0,x,0.8,0.6,0,0.8,0.04,0.05,0.06,x\r"));
        assert!(e.contains("in.csv:3: column 6 `vy`"), "{e}");
    }

    #[test]
    fn relaxed_sample_columns_need_only_be_finite() {
        let row = "5,0,0,1,0,0.6,0.8,0.6,0,0.8,0.04,0.05,0.06,x";
        assert!(err(format!("{HEADER}\n{row}\n")).contains("column 1 `roughness`: 5 is outside [0, 1]"));
        let input = parse_eval_csv_with(
            format!("{HEADER}\n{row}\n").as_bytes(),
            "in.csv",
            &Columns { optional: &["roughness"], relaxed: &["roughness"], unread: &[] },
        )
        .unwrap();
        assert_eq!(
            (input.columns.clone(), input.column_numbers.clone()),
            (vec![("roughness".to_string(), vec![5.0])], vec![1])
        );
    }
}
