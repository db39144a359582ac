//! `brdfprof devices`, `brdfprof models` and the GLSL generator.

use anyhow::{Context, Result};
use brdfprof::brdf::terms::{ParamKind, PARAMS};
use brdfprof::brdf::{spec, Metal, ModelSpec, D, F, Vis};
use brdfprof::{gpu, results};
use clap::Args;
use std::path::Path;
use std::process::ExitCode;

#[derive(Args)]
pub struct DevicesArgs {
    /// List the compile-only targets (`--device radv:FAMILY`, `nvidia:FAMILY`, `intel:FAMILY`) instead: each vendor's compiler
    /// for GPU families this machine does not have.
    #[arg(long)]
    pub targets: bool,
}

/// `devices --targets`: every vendor's families (`targets::VENDORS`) and whether its compiler is installed.
fn targets_table() -> String {
    let mut out = String::from("Compile-only targets: each vendor's production compiler for GPU families this machine does not have (no GPU \
         needed; nothing executes). Commands that compile take them: inspect, check, sweep --cost-device, profile --scene --cost-device.\n\n");
    for v in brdfprof::targets::VENDORS {
        let status = v.status().unwrap_or_else(|e| format!("{e:#}"));
        let mut t = results::Table::new(["--device", "architecture", "products", "compiler", &format!("in {}:all", v.prefix())]);
        for f in v.families() {
            t.row([format!("{}:{}", v.prefix(), f.name), f.architecture.into(), f.products.into(), f.detail, if f.default { "yes".into() } else { String::new() }]);
        }
        out += &format!("## {}\n\n{}\n\nCompiler: {status}\n\n{}\n", v.prefix(), v.title(), t.markdown());
    }
    out
}

pub fn devices(args: &DevicesArgs) -> Result<ExitCode> {
    if args.targets {
        print!("{}", targets_table());
        return Ok(ExitCode::SUCCESS);
    }
    let infos = gpu::list_devices()?;
    let default = gpu::select_device(&infos, None).ok();
    let mut t = results::Table::new([
        "index", "name", "type", "driver", "API", "timestampPeriod ns", "ts bits", "maxStorageBufferRange", "maxWorkGroupCount.x", "fp16", "fp64", "exec. stats",
    ]);
    for d in &infos {
        let mark = if Some(d.index) == default { " (default)" } else if d.compile_only() { " (compiles only)" } else { "" };
        t.row([
            format!("{}{mark}", d.index),
            d.name.clone(),
            d.device_type.clone(),
            format!("{} {} ({})", d.driver_name, d.driver_info, d.driver_version),
            d.api_version.clone(),
            d.timestamp_period.to_string(),
            d.timestamp_valid_bits.to_string(),
            d.max_storage_buffer_range.to_string(),
            d.max_compute_work_group_count[0].to_string(),
            d.shader_float16.to_string(),
            d.shader_float64.to_string(),
            d.pipeline_executable_properties.to_string(),
        ]);
    }
    print!("{}", t.markdown());
    Ok(ExitCode::SUCCESS)
}

fn section(out: &mut String, title: &str, headers: &[&str], rows: Vec<Vec<String>>) {
    let mut t = results::Table::new(headers.iter().copied());
    for r in rows {
        t.row(r);
    }
    *out += &format!("{title}\n\n{}\n", t.markdown());
}

/// Every term with its citation, the parameters, metals and presets: the term tables as text.
pub fn models_text() -> String {
    let mut out = String::new();
    let rows = |names: Vec<&str>, cites: Vec<&str>| names.into_iter().zip(cites).map(|(n, c)| vec![n.to_string(), c.to_string()]).collect();
    section(&mut out, "D (d=)", &["name", "source"], rows(D::names(), D::ALL.iter().map(|t| t.citation()).collect()));
    section(&mut out, "Visibility (vis=)", &["name", "source"], rows(Vis::names(), Vis::ALL.iter().map(|t| t.citation()).collect()));
    section(&mut out, "Fresnel (f=; a term that reads the metal also as f=NAME-<metal>)", &["name", "source"], rows(F::names(), F::ALL.iter().map(|t| t.citation()).collect()));
    section(&mut out, "Metals (metal=)", &["name", "source"], rows(Metal::names(), Metal::ALL.iter().map(|t| t.citation()).collect()));
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
    section(&mut out, "Precision (precision=)", &["name", "source"], vec![vec!["f32".into(), "fp32 arithmetic".into()], vec!["f16".into(), "fp16 arithmetic (needs shaderFloat16)".into()]]);
    let presets = spec::PRESETS.iter().map(|p| vec![p.name.to_string(), format!("{} = {}", p.source, ModelSpec::preset(p.name).expect("a preset").canonical())]).collect();
    section(&mut out, "Presets", &["name", "source"], presets);
    out
}

pub fn models() -> Result<ExitCode> {
    print!("{}", models_text());
    Ok(ExitCode::SUCCESS)
}

/// Writes glsl/generated/ (`make spv`).
pub fn generate_glsl(dir: &Path) -> Result<ExitCode> {
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    for (name, text) in brdfprof::kernels::generated_glsl() {
        let path = dir.join(name);
        brdfprof::io::write_output(&path, text.as_bytes())?;
        println!("{}", path.display());
    }
    Ok(ExitCode::SUCCESS)
}
