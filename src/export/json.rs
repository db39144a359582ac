//! Saved JSON reports: their `kind`, the provenance every report records (where and how it was measured),
//! and atomic writes, pretty or compact.

use crate::gpu::DeviceInfo;
use anyhow::Result;
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::Path;

/// Environment variables that change what a Vulkan driver does (Mesa, lavapipe, loader, vendors).
pub fn driver_environment() -> BTreeMap<String, String> {
    const PREFIXES: [&str; 9] = ["LP_", "MESA_", "GALLIUM_", "GALLIVM_", "VK_", "RADV_", "ACO_", "NV_", "__GL"];
    std::env::vars().filter(|(k, _)| PREFIXES.iter().any(|p| k.starts_with(p))).collect()
}

/// What a report records about where it was measured. `report` and `--html` read it back as this same type:
/// a field that an older brdfprof, or a compile-only target with less to say, did not write reads as its
/// default, and the Options below are always Some when written (so they serialize as the bare value).
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
#[serde(default)]
pub struct Provenance {
    pub tool: String,
    pub unix_time: u64,
    pub device: DeviceInfo,
    pub mesa_version: Option<String>,
    pub llvm_version: Option<String>,
    pub env: BTreeMap<String, String>,
    pub host_cpu: Option<String>,
    /// Family, model, stepping and vector features: lavapipe's costs are this CPU's (None: a report from
    /// before it was recorded).
    pub cpu: Option<crate::host_cpu::HostCpu>,
    pub host_threads: usize,
    /// The command line that wrote the report (None: a report from before it was recorded).
    pub command: Option<Vec<String>>,
    /// What translated each HLSL or WGSL model into the kernels' GLSL, with versions (model path -> front
    /// end; docs/hlsl.md, docs/wgsl.md); absent when every model is GLSL or built in.
    #[serde(skip_serializing_if = "BTreeMap::is_empty")]
    pub front_ends: BTreeMap<String, String>,
}

impl Provenance {
    pub fn new(device: &DeviceInfo) -> Self {
        let (mesa, llvm) = device.mesa_llvm();
        let host_cpu = std::fs::read_to_string("/proc/cpuinfo").ok().and_then(|t| {
            t.lines()
                .find(|l| l.starts_with("model name"))
                .and_then(|l| l.split(':').nth(1))
                .map(|s| s.trim().to_string())
        });
        Provenance {
            tool: format!("brdfprof {}", env!("CARGO_PKG_VERSION")),
            unix_time: std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).map_or(0, |d| d.as_secs()),
            device: device.clone(),
            mesa_version: mesa,
            llvm_version: llvm,
            env: driver_environment(),
            host_cpu,
            cpu: Some(crate::host_cpu::HostCpu::detect()),
            host_threads: std::thread::available_parallelism().map_or(1, |n| n.get()),
            command: Some(std::env::args().collect()),
            front_ends: crate::model::front::used(),
        }
    }
}

/// Compact JSON, for reports whose numeric arrays would balloon when pretty-printed.
pub fn write_json_compact(path: &Path, value: &impl Serialize) -> Result<()> {
    let mut text = serde_json::to_string(value)?;
    text.push('\n');
    crate::io::write_output(path, text.as_bytes())
}

/// Writes `<stem>.md` (`markdown`), `<stem>.json` (`value`, compact) and `<stem>.png` (`chart`); returns their
/// paths.
pub fn write_md_json_png(
    stem: &Path,
    kind: Kind,
    value: &impl Serialize,
    markdown: &str,
    chart: impl FnOnce(&Path) -> Result<()>,
) -> Result<Vec<std::path::PathBuf>> {
    let (md, json, png) = (stem.with_extension("md"), stem.with_extension("json"), stem.with_extension("png"));
    write_report_compact(&json, kind, value)?;
    crate::io::write_markdown(&md, markdown)?;
    chart(&png)?;
    Ok(vec![md, json, png])
}

pub fn write_json(path: &Path, value: &impl Serialize) -> Result<()> {
    let mut text = serde_json::to_string_pretty(value)?;
    text.push('\n');
    crate::io::write_output(path, text.as_bytes())
}

/// What a saved JSON report is: its top-level `"kind"`, which `report` and `compare` read instead of
/// guessing from its keys (docs/commands.md lists them; `diff` writes its own).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    Profile,
    SceneProfile,
    Sweep,
    SweepCost,
    SweepFrontiers,
    Stability,
    Inspect,
    InspectDevices,
    Compare,
    Baseline,
}

impl Kind {
    pub const ALL: [Kind; 10] = [
        Kind::Profile,
        Kind::SceneProfile,
        Kind::Sweep,
        Kind::SweepCost,
        Kind::SweepFrontiers,
        Kind::Stability,
        Kind::Inspect,
        Kind::InspectDevices,
        Kind::Compare,
        Kind::Baseline,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Kind::Profile => "profile",
            Kind::SceneProfile => "scene-profile",
            Kind::Sweep => "sweep",
            Kind::SweepCost => "sweep-cost",
            Kind::SweepFrontiers => "sweep-frontiers",
            Kind::Stability => "stability",
            Kind::Inspect => "inspect",
            Kind::InspectDevices => "inspect-devices",
            Kind::Compare => "compare",
            Kind::Baseline => "baseline",
        }
    }

    pub fn parse(name: &str) -> Option<Kind> {
        Kind::ALL.into_iter().find(|k| k.name() == name)
    }
}

/// `value`'s JSON text with `"kind"` as its first key (`value` must serialize as an object without one).
fn with_kind(kind: Kind, value: &impl Serialize, pretty: bool) -> Result<String> {
    let text = if pretty { serde_json::to_string_pretty(value)? } else { serde_json::to_string(value)? };
    let rest =
        text.strip_prefix('{').ok_or_else(|| anyhow::anyhow!("a {} report that is not a JSON object", kind.name()))?;
    let empty = rest.trim_start().starts_with('}');
    let sep = if empty { "" } else { "," };
    Ok(if pretty {
        format!("{{\n  \"kind\": \"{}\"{sep}{rest}\n", kind.name())
    } else {
        format!("{{\"kind\":\"{}\"{sep}{rest}\n", kind.name())
    })
}

/// `write_json` of a saved report, its `kind` first.
pub fn write_report(path: &Path, kind: Kind, value: &impl Serialize) -> Result<()> {
    crate::io::write_output(path, with_kind(kind, value, true)?.as_bytes())
}

/// `write_json_compact` of a saved report, its `kind` first.
pub fn write_report_compact(path: &Path, kind: Kind, value: &impl Serialize) -> Result<()> {
    crate::io::write_output(path, with_kind(kind, value, false)?.as_bytes())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_saved_report_names_its_kind_first() {
        #[derive(Serialize)]
        struct R {
            a: u32,
        }
        for pretty in [false, true] {
            let text = with_kind(Kind::Sweep, &R { a: 1 }, pretty).unwrap();
            let v: serde_json::Value = serde_json::from_str(&text).unwrap();
            assert_eq!((v["kind"].as_str(), v["a"].as_u64()), (Some("sweep"), Some(1)), "{text}");
            assert!(text.trim_start_matches(['{', ' ', '\n']).starts_with("\"kind\""), "{text}");
        }
        let empty = with_kind(Kind::Compare, &serde_json::json!({}), true).unwrap();
        assert_eq!(serde_json::from_str::<serde_json::Value>(&empty).unwrap()["kind"], "compare");
        for k in Kind::ALL {
            assert_eq!(Kind::parse(k.name()), Some(k));
        }
    }
}
