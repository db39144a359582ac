//! `brdfprof devices`: the Vulkan devices, or with `--targets` the compile-only targets.

use anyhow::Result;
use brdfprof::{export::markdown, gpu};
use clap::Args;
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
    let mut out = String::from(
        "Compile-only targets: each vendor's production compiler for GPU families this machine does not have (no GPU \
         needed; nothing executes). Commands that compile take them: inspect, check, sweep --cost-device, profile --scene --cost-device.\n\n",
    );
    for v in brdfprof::targets::VENDORS {
        let status = v.status().unwrap_or_else(|e| format!("{e:#}"));
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
    out
}

pub fn devices(args: &DevicesArgs) -> Result<ExitCode> {
    if args.targets {
        out!("{}", targets_table());
        return Ok(ExitCode::SUCCESS);
    }
    let infos = gpu::list_devices()?;
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
