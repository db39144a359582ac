//! `brdfprof models`: the terms (with citations), parameters, metals and presets that model specs can name.

use anyhow::Result;
use brdfprof::brdf::terms::{PARAMS, ParamKind};
use brdfprof::brdf::{D, F, Metal, ModelSpec, Vis, spec};
use brdfprof::export::markdown;
use std::process::ExitCode;

fn section(out: &mut String, title: &str, headers: &[&str], rows: Vec<Vec<String>>) {
    let mut t = markdown::Table::new(headers.iter().copied());
    for r in rows {
        t.row(r);
    }
    *out += &format!("{title}\n\n{}\n", t.markdown());
}

/// Every term with its citation, the parameters, metals and presets: the term tables as text.
pub fn models_text() -> String {
    let mut out = String::new();
    let rows = |names: Vec<&str>, cites: Vec<&str>| {
        names.into_iter().zip(cites).map(|(n, c)| vec![n.to_string(), c.to_string()]).collect()
    };
    section(&mut out, "D (d=)", &["name", "source"], rows(D::names(), D::ALL.iter().map(|t| t.citation()).collect()));
    section(
        &mut out,
        "Visibility (vis=)",
        &["name", "source"],
        rows(Vis::names(), Vis::ALL.iter().map(|t| t.citation()).collect()),
    );
    section(
        &mut out,
        "Fresnel (f=; a term that reads the metal also as f=NAME-<metal>)",
        &["name", "source"],
        rows(F::names(), F::ALL.iter().map(|t| t.citation()).collect()),
    );
    section(
        &mut out,
        "Metals (metal=)",
        &["name", "source"],
        rows(Metal::names(), Metal::ALL.iter().map(|t| t.citation()).collect()),
    );
    let params = PARAMS
        .iter()
        .map(|p| {
            let range = match p.kind {
                ParamKind::Number { default, min, max, .. } => format!("[{min}, {max}], default {default}"),
                ParamKind::Metal => format!("{}, default gold", Metal::names().join(", ")),
            };
            vec![format!("{}=", p.name), range, p.about.to_string()]
        })
        .collect();
    section(&mut out, "Parameters (read by the terms that use them)", &["key", "values", "about"], params);
    section(
        &mut out,
        "Precision (precision=)",
        &["name", "source"],
        vec![
            vec!["f32".into(), "fp32 arithmetic".into()],
            vec!["f16".into(), "fp16 arithmetic (needs shaderFloat16)".into()],
        ],
    );
    let presets = spec::PRESETS
        .iter()
        .map(|p| {
            vec![
                p.name.to_string(),
                format!("{} = {}", p.source, ModelSpec::preset(p.name).expect("a preset").canonical()),
            ]
        })
        .collect();
    section(&mut out, "Presets", &["name", "source"], presets);
    out
}

pub fn models() -> Result<ExitCode> {
    out!("{}", models_text());
    Ok(ExitCode::SUCCESS)
}
