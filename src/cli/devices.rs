//! `brdfprof devices`: the Vulkan devices, or with `--targets` the compile-only targets.

use anyhow::Result;
use brdfprof::{export::markdown, gpu};
use clap::Args;
use std::process::ExitCode;

#[derive(Args)]
pub struct DevicesArgs {
    /// List the compile-only targets (`--device radv:FAMILY`, `nvidia:FAMILY`, `intel:FAMILY`, ...) instead: each
    /// vendor's compiler for GPU families this machine does not have, and where each of brdfprof's tools was found.
    #[arg(long)]
    pub targets: bool,
    /// Also write the list as JSON to FILE (`-`: stdout, which then holds only the JSON; the table goes to stderr).
    #[arg(long, value_name = "FILE")]
    pub json: Option<std::path::PathBuf>,
}

/// Where each of brdfprof's own tools was found (`tools::locate`), or that it is missing and the one command
/// that installs it.
fn tools_table() -> (String, Vec<serde_json::Value>) {
    let mut t = markdown::Table::new(["tool", "found", "where", "installed by"]);
    let mut json = Vec::new();
    for (name, var, install) in brdfprof::tools::TOOLS {
        let (dir, how) = brdfprof::tools::locate(name);
        let found = dir.exists();
        t.row([
            name.to_string(),
            if found { how.clone() } else { "missing".into() },
            dir.display().to_string(),
            format!("`{install}` (or ${var})"),
        ]);
        json.push(serde_json::json!({"tool": name, "found": found, "how": how, "dir": dir, "install": install, "variable": var}));
    }
    let text = format!(
        "## Tools\n\nbrdfprof's own tools, each found in the first of: its variable's folder, `share/brdfprof/tools` beside the binary (`make install`), the per-user data directory (`make setup`, `make mesa`), the build checkout's `.tools`.\n\n{}\n",
        t.markdown()
    );
    (text, json)
}

/// `devices --targets`: every vendor's families (`targets::VENDORS`) and whether its compiler is installed, and
/// the same as JSON.
fn targets_table() -> (String, serde_json::Value) {
    let mut json = Vec::new();
    let mut out = String::from(
        "Compile-only targets: each vendor's production compiler for GPU families this machine does not have (no GPU \
         needed; nothing executes). Commands that compile take them: inspect, check, sweep --cost-device, profile --scene --cost-device.\n\n",
    );
    for v in brdfprof::targets::VENDORS {
        let status = v.status().unwrap_or_else(|e| format!("{e:#}"));
        json.push(serde_json::json!({
            "prefix": v.prefix(),
            "title": v.title(),
            "compiler": status,
            "families": v.families().iter().map(|f| serde_json::json!({
                "device": format!("{}:{}", v.prefix(), f.name), "architecture": f.architecture, "products": f.products,
                "compiler": f.detail, "in_all": f.default})).collect::<Vec<_>>(),
        }));
        let mut t = markdown::Table::new([
            "--device",
            "architecture",
            "products",
            "compiler",
            &format!("in {}:all", v.prefix()),
        ]);
        for f in v.families() {
            t.row([
                format!("{}:{}", v.prefix(), f.name),
                f.architecture.into(),
                f.products.into(),
                f.detail,
                if f.default { "yes".into() } else { String::new() },
            ]);
        }
        out += &format!("## {}\n\n{}\n\nCompiler: {status}\n\n{}\n", v.prefix(), v.title(), t.markdown());
    }
    let (tools, tools_json) = tools_table();
    out += &tools;
    (out, serde_json::json!({"targets": json, "tools": tools_json}))
}

impl super::Run for DevicesArgs {
    fn run(&self) -> Result<ExitCode> {
        devices(self)
    }
}

pub fn devices(args: &DevicesArgs) -> Result<ExitCode> {
    let outs = super::checked_outputs(&[("--json", args.json.as_deref())], &[])?;
    if args.targets {
        let (text, json) = targets_table();
        for (_, path) in &outs {
            brdfprof::export::json::write_json(path, &json)?;
        }
        out!("{text}");
        return Ok(ExitCode::SUCCESS);
    }
    let infos = gpu::list_devices()?;
    for (_, path) in &outs {
        brdfprof::export::json::write_json(path, &serde_json::json!({ "devices": infos }))?;
    }
    let default = gpu::select_device(&infos, None).ok();
    let mut t = markdown::Table::new([
        "index",
        "name",
        "type",
        "driver",
        "API",
        "timestampPeriod ns",
        "ts bits",
        "maxStorageBufferRange",
        "maxWorkGroupCount.x",
        "fp16",
        "fp64",
        "exec. stats",
    ]);
    for d in &infos {
        let mark = if Some(d.index) == default {
            " (default)"
        } else if d.compile_only() {
            " (compiles only)"
        } else {
            ""
        };
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
    out!("{}", t.markdown());
    Ok(ExitCode::SUCCESS)
}
