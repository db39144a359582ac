//! GitHub Actions' workflow commands and step summary: `::error file=F,line=L,title=T::message` lines on
//! stdout (the runner shows at most 10 errors per step), and Markdown appended to `$GITHUB_STEP_SUMMARY`
//! (at most 1 MiB per step).

use super::sarif::Finding;
use anyhow::Result;
use std::path::Path;

/// The most error annotations GitHub shows for one step.
pub const MAX_ANNOTATIONS: usize = 10;

/// The largest step summary GitHub accepts.
pub const MAX_SUMMARY_BYTES: usize = 1 << 20;

/// A workflow command's message: `%`, CR and LF escaped.
fn data(text: &str) -> String {
    text.replace('%', "%25").replace('\r', "%0D").replace('\n', "%0A")
}

/// A workflow command's property value: as `data`, and `:` and `,`.
fn property(text: &str) -> String {
    data(text).replace(':', "%3A").replace(',', "%2C")
}

/// One `::error` line per finding (the first `MAX_ANNOTATIONS`), at its primary place.
pub fn annotations(findings: &[Finding]) -> String {
    let mut out = String::new();
    for f in findings.iter().take(MAX_ANNOTATIONS) {
        let mut props = Vec::new();
        if let Some(p) = f.places.first() {
            props.push(format!("file={}", property(&p.file)));
            if let Some(line) = p.line {
                props.push(format!("line={line}"));
            }
        }
        props.push(format!("title={}", property(f.rule.name)));
        out += &format!("::error {}::{}\n", props.join(","), data(&f.message));
    }
    out
}

/// Appends `markdown` to the step summary `path` (written whole and atomically, its earlier content kept),
/// cut with a note where the file would pass `MAX_SUMMARY_BYTES`.
pub fn append_summary(path: &Path, markdown: &str) -> Result<()> {
    let mut text = match std::fs::metadata(path) {
        Ok(m) if m.is_file() => {
            String::from_utf8_lossy(&crate::io::read_bounded(path, MAX_SUMMARY_BYTES as u64)?).into_owned()
        }
        _ => String::new(),
    };
    const CUT: &str =
        "\n\n(cut here: GitHub takes at most 1 MiB of step summary; the full report is brdfprof's stdout)\n";
    let room = MAX_SUMMARY_BYTES.saturating_sub(text.len());
    if markdown.len() <= room {
        text += markdown;
    } else if room > CUT.len() {
        let mut end = room - CUT.len();
        while !markdown.is_char_boundary(end) {
            end -= 1;
        }
        text += &markdown[..end];
        text += CUT;
    }
    crate::io::write_output(path, text.as_bytes())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::export::sarif::{Place, Rule};

    const RULE: Rule = Rule { id: "r", name: "Cost, rose: 100%", short: "", full: "" };

    #[test]
    fn workflow_commands_escape_their_data_and_properties() {
        let f = Finding {
            rule: &RULE,
            message: "50% more\nin two lines".into(),
            places: vec![Place { file: "a,b:c.brdf".into(), line: Some(7), text: String::new(), note: String::new() }],
            identity: String::new(),
            properties: serde_json::Value::Null,
        };
        assert_eq!(
            annotations(&[f]),
            "::error file=a%2Cb%3Ac.brdf,line=7,title=Cost%2C rose%3A 100%25::50%25 more%0Ain two lines\n"
        );
    }

    #[test]
    fn the_step_summary_is_appended_to_and_cut_at_its_limit() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("summary.md");
        std::fs::write(&path, "earlier\n").unwrap();
        append_summary(&path, "# report\n").unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "earlier\n# report\n");
        append_summary(&path, &"é".repeat(MAX_SUMMARY_BYTES)).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        assert!(text.len() <= MAX_SUMMARY_BYTES && text.ends_with("stdout)\n"), "{}", text.len());
    }
}
