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

/// One `::error` line per finding (the first `MAX_ANNOTATIONS`, the largest first as the caller orders them),
/// at its primary place, and a `::notice` counting those left out.
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
    if findings.len() > MAX_ANNOTATIONS {
        out += &format!(
            "::notice title=brdfprof::{} more findings not annotated (GitHub shows at most {MAX_ANNOTATIONS} per step): the report, the step summary and the SARIF log list every one\n",
            findings.len() - MAX_ANNOTATIONS
        );
    }
    out
}

/// Appends `markdown` to the step summary `path` (through `messages::safe_text`) in one write to a file opened
/// for appending, as GitHub's runner and other steps append to it: reports of concurrent steps all stay, and
/// what the file held is not read or rewritten (non-UTF-8 bytes included). Cut with a note where the file would
/// pass `MAX_SUMMARY_BYTES`; where it is already too full for the note, nothing is appended and a warning names
/// `--summary` (the report is on stdout, and the command's verdict and other outputs stand).
pub fn append_summary(path: &Path, markdown: &str) -> Result<()> {
    use std::io::Write;
    let markdown = crate::messages::safe_text(markdown);
    let held = std::fs::metadata(path).map_or(0, |m| if m.is_file() { m.len() as usize } else { 0 });
    const CUT: &str =
        "\n\n(cut here: GitHub takes at most 1 MiB of step summary; the full report is brdfprof's stdout)\n";
    let room = MAX_SUMMARY_BYTES.saturating_sub(held);
    let text = if markdown.len() <= room {
        markdown
    } else if room > CUT.len() {
        let mut end = room - CUT.len();
        while !markdown.is_char_boundary(end) {
            end -= 1;
        }
        format!("{}{CUT}", &markdown[..end])
    } else {
        crate::messages::warning(format!(
            "--summary {}: the step summary already holds {held} bytes, and GitHub takes at most {MAX_SUMMARY_BYTES}: this report is not appended (it is on stdout)",
            crate::messages::escape_line(&path.display().to_string())
        ));
        return Ok(());
    };
    let mut f = std::fs::OpenOptions::new()
        .append(true)
        .create(true)
        .open(path)
        .map_err(|e| anyhow::anyhow!("--summary {}: cannot open it to append: {e}", path.display()))?;
    f.write_all(text.as_bytes()).map_err(|e| anyhow::anyhow!("--summary {}: cannot append: {e}", path.display()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::export::sarif::{Place, Rule};

    const RULE: Rule = Rule { id: "r", name: "Cost, rose: 100%", short: "", full: "", help: "" };

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
        // Full: nothing appended, no error (the verdict and the other outputs stand).
        append_summary(&path, "# one more\n").unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), text);
    }

    /// Appenders running at once all keep their report, and what the file held stays byte for byte.
    #[test]
    fn concurrent_appends_keep_every_report_and_the_earlier_bytes() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("summary.md");
        std::fs::write(&path, b"earlier \xff\xfe\n").unwrap();
        std::thread::scope(|s| {
            for i in 0..6 {
                let path = &path;
                s.spawn(move || append_summary(path, &format!("# report {i}\n{}\n", "x".repeat(20_000))).unwrap());
            }
        });
        let bytes = std::fs::read(&path).unwrap();
        assert!(bytes.starts_with(b"earlier \xff\xfe\n"));
        let text = String::from_utf8_lossy(&bytes);
        for i in 0..6 {
            assert_eq!(text.matches(&format!("# report {i}\n")).count(), 1, "report {i}");
        }
        append_summary(&path, "x\n::stop-commands::T\n").unwrap();
        assert!(!String::from_utf8_lossy(&std::fs::read(&path).unwrap()).lines().any(|l| l.starts_with("::")));
    }
}
