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

#[derive(clap::Args)]
pub struct ModelsArgs {
    /// Also write the terms, parameters, metals and presets as JSON to FILE (`-`: stdout, which then holds only
    /// the JSON; the table goes to stderr).
    #[arg(long, value_name = "FILE")]
    pub json: Option<std::path::PathBuf>,
}

/// The term tables as JSON: each term's name, GLSL id and citation; each preset's terms and source.
fn models_json() -> serde_json::Value {
    let terms = |names: Vec<&str>, ids: Vec<u32>, cites: Vec<&str>| -> Vec<serde_json::Value> {
        names
            .into_iter()
            .zip(ids)
            .zip(cites)
            .map(|((n, id), c)| serde_json::json!({"name": n, "id": id, "citation": c}))
            .collect()
    };
    let presets: Vec<serde_json::Value> = spec::PRESETS
        .iter()
        .map(|p| {
            serde_json::json!({"name": p.name, "d": p.d.name(), "vis": p.vis.name(), "f": p.f.name(), "source": p.source,
                "spec": ModelSpec::preset(p.name).expect("a preset").canonical()})
        })
        .collect();
    serde_json::json!({
        "d": terms(D::names(), D::ALL.iter().map(|t| t.id()).collect(), D::ALL.iter().map(|t| t.citation()).collect()),
        "vis": terms(Vis::names(), Vis::ALL.iter().map(|t| t.id()).collect(), Vis::ALL.iter().map(|t| t.citation()).collect()),
        "f": terms(F::names(), F::ALL.iter().map(|t| t.id()).collect(), F::ALL.iter().map(|t| t.citation()).collect()),
        "metals": Metal::names(),
        "presets": presets,
    })
}

impl super::Run for ModelsArgs {
    fn run(&self) -> Result<ExitCode> {
        models(self)
    }
}

pub fn models(args: &ModelsArgs) -> Result<ExitCode> {
    let outs = super::checked_outputs(&[("--json", args.json.as_deref())], &[])?;
    for (_, path) in &outs {
        brdfprof::export::json::write_json(path, &models_json())?;
    }
    out!("{}", models_text());
    Ok(ExitCode::SUCCESS)
}
