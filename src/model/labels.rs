//! What tables, charts and output files call a model: its `name=` label, else a short default
//! (`Model::label`), which `distinguish` lengthens only as far as models given together need.

use super::{BASELINE_LABEL, LABEL_KEY, Model, file_model::FileModel};
use anyhow::{Result, bail};
use std::path::Path;

/// The characters of a label: it names output files.
const LABEL_CHARS: &str = "A-Z a-z 0-9 - _ . + =";
const MAX_LABEL: usize = 64;

fn label_char(c: char) -> bool {
    c.is_ascii_alphanumeric() || "-_.+=".contains(c)
}

fn valid(label: &str) -> bool {
    !label.is_empty() && label.len() <= MAX_LABEL && label.chars().all(label_char) && !label.starts_with(['-', '.'])
}

/// Splits a `name=LABEL` item off a model text; a label is a file-name-safe word.
pub(super) fn split_label(text: &str) -> Result<(String, Option<String>)> {
    let (mut rest, mut label) = (Vec::new(), None);
    for item in text.split(',') {
        match item.trim().strip_prefix(LABEL_KEY).and_then(|r| r.trim_start().strip_prefix('=')) {
            Some(_) if label.is_some() => bail!("`{text}`: {LABEL_KEY}= is given twice"),
            Some(l) => label = Some(l.trim().to_string()),
            None => rest.push(item),
        }
    }
    if let Some(l) = &label {
        if !valid(l) {
            bail!(
                "`{text}`: {LABEL_KEY}={l}: a label is 1 to {MAX_LABEL} of {LABEL_CHARS} (not starting with - or .), as it names output files"
            );
        }
        if l == BASELINE_LABEL {
            bail!("`{text}`: {LABEL_KEY}={l} is the memory-only baseline kernel's label; give another name");
        }
    }
    Ok((rest.join(","), label))
}

/// Fails when two different models of one run share a label (each names a row, a chart point and an output
/// file); the same model given twice (`diff` of a preset with itself) is not ambiguous.
pub fn check_labels(models: &[Model], flag: &str) -> Result<()> {
    for (i, m) in models.iter().enumerate() {
        if let Some(o) = models[..i].iter().find(|o| o.label() == m.label() && *o != m) {
            bail!(
                "{flag} {} and {flag} {}: both are labelled `{}`; give one of them its own {LABEL_KEY}=",
                o.name(),
                m.name(),
                m.label()
            );
        }
    }
    Ok(())
}

/// Gives each unlabelled `.brdf`/shader file that shares its default label with a different model of the run
/// a label that tells it apart, and says so: its file name where the files' names differ (`brdf.hlsl`,
/// `brdf.wgsl`), its folder where only folders do, then `+` and each define the others do not all share
/// (`lit+QUALITY=1`). A label is set only where the result is a valid label that no other model of the run
/// already has; `check_labels` refuses what stays ambiguous.
pub fn distinguish(models: Vec<Model>) -> Vec<Model> {
    let mut out = models.clone();
    let mut renamed = Vec::new();
    for (i, m) in models.iter().enumerate() {
        let Some(f) = m.file().filter(|f| f.label.is_none()) else { continue };
        let rivals: Vec<&FileModel> =
            models.iter().filter(|o| o.label() == m.label() && *o != m).filter_map(Model::file).collect();
        if rivals.is_empty() {
            continue;
        }
        let Some(label) = distinct_label(f, &m.label(), &rivals) else { continue };
        let taken = models.iter().any(|o| o.label() == label);
        if label != m.label() && valid(&label) && !taken {
            renamed.push(format!("`{label}` ({})", m.name()));
            out[i] = m.clone().with_label(Some(label));
        }
    }
    if !renamed.is_empty() {
        crate::messages::note(format!(
            "models given together share a default label; called {} (give {LABEL_KEY}= to choose)",
            renamed.join(", ")
        ));
    }
    out
}

/// None where nothing but the default label's own parts tells `f` from its rivals (a rival then takes the label
/// that differs).
fn distinct_label(f: &FileModel, label: &str, rivals: &[&FileModel]) -> Option<String> {
    let path = Path::new(&f.path);
    let part = |p: Option<&std::ffi::OsStr>| p.map(|n| n.to_string_lossy().into_owned());
    let file_name = |p: &str| part(Path::new(p).file_name());
    let stem_len = label.find(',').unwrap_or(label.len());
    let mut head = label[..stem_len].to_string();
    if rivals.iter().any(|r| file_name(&r.path) != file_name(&f.path)) {
        head = part(path.file_name()).unwrap_or(head);
    } else if rivals.iter().any(|r| r.path != f.path) {
        let folder = path.parent().and_then(|p| part(p.file_name())).filter(|p| !p.is_empty());
        head = folder.map_or(head.clone(), |d| format!("{d}-{head}"));
    }
    // The parameters a default label names after the stem, as label characters.
    let params = label[stem_len..].replace(',', "+");
    let defines: String = f
        .define_items()
        .into_iter()
        .filter(|d| !rivals.iter().all(|r| r.define_items().contains(d)))
        .map(|d| format!("+{d}"))
        .collect();
    if head == label[..stem_len] && defines.is_empty() {
        return None;
    }
    Some((head + &params + &defines).chars().map(|c| if label_char(c) { c } else { '_' }).collect())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::models_from_args;

    const FILE: &str = "tests/fixtures/brdf/quality-switch.brdf";

    fn labels(models: &[String]) -> Result<Vec<String>> {
        Ok(models_from_args(models, &[], &[])?.iter().map(Model::label).collect())
    }

    #[test]
    fn defines_join_a_label_only_where_they_tell_models_given_together_apart() {
        let one = format!("{FILE},define=QUALITY_LEVEL=1,define=EXTRA");
        assert_eq!(labels(&[one.clone()]).unwrap(), ["quality-switch"], "alone, a file is its stem");
        let two = labels(&[FILE.into(), one.clone(), format!("{FILE},define=QUALITY_LEVEL=0,define=EXTRA")]).unwrap();
        let plus = |d: &str| format!("quality-switch+QUALITY_LEVEL={d}+EXTRA");
        assert_eq!(two, ["quality-switch".to_string(), plus("1"), plus("0")], "EXTRA: the plain file lacks it");
        let pair = [one.clone(), format!("{FILE},define=QUALITY_LEVEL=0,define=EXTRA")];
        assert_eq!(labels(&pair).unwrap()[1], "quality-switch+QUALITY_LEVEL=0", "a define all share is left out");
        let models = models_from_args(&[FILE.into(), one], &[], &[]).unwrap();
        let back = Model::parse(&models[1].name()).unwrap();
        assert_eq!(back, models[1], "a child process parsing the name gets the same label");
        assert_eq!(
            models[1].canonical(),
            Model::parse(&format!("{FILE},define=QUALITY_LEVEL=1,define=EXTRA")).unwrap().canonical()
        );
        let bound = labels(&[format!("{FILE},scale=2"), format!("{FILE},scale=2,define=QUALITY_LEVEL=1")]).unwrap();
        assert_eq!(bound, ["quality-switch,scale=2", "quality-switch+scale=2+QUALITY_LEVEL=1"]);
    }

    #[test]
    fn files_of_one_stem_are_told_apart_by_file_name_then_folder() {
        let dir = tempfile::tempdir().unwrap();
        let text = std::fs::read_to_string(FILE).unwrap();
        let hlsl = "float3 BRDF(float3 L, float3 V, float3 N, float3 X, float3 Y) { return dot(N, L).xxx; }\n";
        for (p, text) in [("a/brdf.brdf", text.as_str()), ("b/brdf.brdf", &text), ("a/brdf.hlsl", hlsl)] {
            let p = dir.path().join(p);
            std::fs::create_dir_all(p.parent().unwrap()).unwrap();
            std::fs::write(&p, text).unwrap();
        }
        let at = |p: &str| dir.path().join(p).to_string_lossy().into_owned();
        assert_eq!(labels(&[at("a/brdf.brdf"), at("b/brdf.brdf")]).unwrap(), ["a-brdf", "b-brdf"]);
        let e = labels(&[at("a/brdf.brdf"), at("a/brdf.brdf") + ",name=x", at("a/brdf.brdf") + ",name=x,scale=2"]);
        assert!(format!("{:#}", e.unwrap_err()).contains("both are labelled `x`"), "given labels are never changed");
        assert_eq!(labels(&[at("a/brdf.brdf"), at("a/brdf.hlsl")]).unwrap(), ["brdf.brdf", "brdf.hlsl"]);
        let e = labels(&[at("a/brdf.brdf"), format!("{},include={}", at("a/brdf.brdf"), at("b"))]).unwrap_err();
        assert!(format!("{e:#}").contains("give one of them its own name="), "{e:#}");
    }
}
