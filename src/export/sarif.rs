//! SARIF 2.1.0 (OASIS), the format code-scanning services read: one result per finding, located at the source
//! lines it names, with stable rule ids and fingerprints so that a service tracks one regression across runs.

use serde_json::{Value, json};
use std::path::Path;

/// A rule a finding breaks.
pub struct Rule {
    pub id: &'static str,
    pub name: &'static str,
    pub short: &'static str,
    pub full: &'static str,
    /// What to do about it (SARIF's `help`, which GitHub's code scanning shows and its upload requires).
    pub help: &'static str,
}

/// A place a finding points at: a file, and a line of it where one is known.
#[derive(Clone, Debug, PartialEq)]
pub struct Place {
    pub file: String,
    pub line: Option<u32>,
    /// The line's text (the snippet), and what this place contributes (the related location's message).
    pub text: String,
    pub note: String,
}

/// One result: which rule, the message, where (the first place is the primary location), what fingerprints it
/// across runs (`identity`: the same regression has the same identity whatever its lines' numbers), and
/// properties.
pub struct Finding {
    pub rule: &'static Rule,
    pub message: String,
    pub places: Vec<Place>,
    pub identity: String,
    pub properties: Value,
}

/// A path as a SARIF URI reference: relative to `root` (with `uriBaseId` SRCROOT) where it lies below it or
/// is relative, else a file: URI; each byte outside RFC 3986's unreserved set and `/` percent-encoded.
fn uri(file: &str, root: &Path) -> (String, bool) {
    let encode = |s: &str| -> String {
        s.bytes()
            .map(|b| match b {
                b'A'..=b'Z' | b'a'..=b'z' | b'0'..=b'9' | b'-' | b'.' | b'_' | b'~' | b'/' => (b as char).to_string(),
                _ => format!("%{b:02X}"),
            })
            .collect()
    };
    let path = Path::new(file);
    match path.strip_prefix(root) {
        Ok(rel) => (encode(&rel.to_string_lossy()), true),
        Err(_) if path.is_relative() => (encode(file.trim_start_matches("./")), true),
        Err(_) => (format!("file://{}", encode(file)), false),
    }
}

fn location(p: &Place, root: &Path) -> Value {
    let (uri, relative) = uri(&p.file, root);
    let mut artifact = json!({ "uri": uri });
    if relative {
        artifact["uriBaseId"] = "SRCROOT".into();
    }
    let mut physical = json!({ "artifactLocation": artifact });
    if let Some(line) = p.line {
        physical["region"] = json!({ "startLine": line });
        if !p.text.is_empty() {
            physical["region"]["snippet"] = json!({ "text": p.text });
        }
    }
    json!({ "physicalLocation": physical })
}

/// SHA-256 of `text`, hex: a fingerprint.
fn digest(text: &str) -> String {
    use sha2::Digest;
    sha2::Sha256::digest(text.as_bytes()).iter().map(|b| format!("{b:02x}")).collect()
}

fn result(f: &Finding, rules: &[&Rule], root: &Path) -> Value {
    let mut r = json!({
        "ruleId": f.rule.id,
        "ruleIndex": rules.iter().position(|x| x.id == f.rule.id).unwrap_or(0),
        "level": "error",
        "message": { "text": f.message },
        // GitHub matches an alert across runs by primaryLocationLineHash (it computes one from the line's text
        // where a log has none): the finding's own identity (rule, model, target) keeps one alert per regression
        // as the lines above it move.
        "partialFingerprints": {
            "brdfprofFinding/v1": digest(&format!("{}\n{}", f.rule.id, f.identity)),
            "primaryLocationLineHash": format!("{}:1", &digest(&format!("{}\n{}", f.rule.id, f.identity))[..16]),
        },
        "properties": f.properties,
    });
    if let Some((first, rest)) = f.places.split_first() {
        r["locations"] = json!([location(first, root)]);
        if !rest.is_empty() {
            let related: Vec<Value> = rest
                .iter()
                .enumerate()
                .map(|(k, p)| {
                    let mut l = location(p, root);
                    l["id"] = (k + 1).into();
                    l["message"] = json!({ "text": p.note });
                    l
                })
                .collect();
            r["relatedLocations"] = related.into();
        }
    }
    r
}

/// The SARIF log of one run of `tool` (its name and version) over `findings`, paths relative to `root`.
pub fn log(version: &str, rules: &[&Rule], findings: &[Finding], root: &Path, properties: Value) -> Value {
    let rules_json: Vec<Value> = rules
        .iter()
        .map(|r| {
            json!({
                "id": r.id,
                "name": r.name,
                "shortDescription": { "text": r.short },
                "fullDescription": { "text": r.full },
                "help": { "text": r.help, "markdown": r.help },
                "defaultConfiguration": { "level": "error" },
            })
        })
        .collect();
    let (root_uri, _) = uri(&format!("{}/", root.display()), Path::new("/nonexistent-root"));
    json!({
        "$schema": "https://json.schemastore.org/sarif-2.1.0.json",
        "version": "2.1.0",
        "runs": [{
            "tool": { "driver": { "name": "brdfprof", "version": version, "semanticVersion": version, "rules": rules_json } },
            "originalUriBaseIds": { "SRCROOT": { "uri": root_uri } },
            "results": findings.iter().map(|f| result(f, rules, root)).collect::<Vec<_>>(),
            "properties": properties,
        }]
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paths_become_uri_references_under_the_source_root() {
        let root = Path::new("/repo");
        assert_eq!(uri("/repo/shaders/my lobe.brdf", root), ("shaders/my%20lobe.brdf".into(), true));
        assert_eq!(uri("./shaders/a.brdf", root), ("shaders/a.brdf".into(), true));
        assert_eq!(uri("/elsewhere/a#b.brdf", root), ("file:///elsewhere/a%23b.brdf".into(), false));
    }
}
