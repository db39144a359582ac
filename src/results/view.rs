//! A report's provenance as read back (`brdfprof report`, `--html`): every field optional, so that a report
//! written by an older brdfprof (or a compile-only target's, with less to say) still reads.

use serde::Deserialize;
use std::collections::BTreeMap;

#[derive(Clone, Debug, Default, Deserialize)]
#[serde(default)]
pub struct DeviceView {
    pub name: String,
    pub device_type: String,
    pub driver_name: String,
    pub driver_info: String,
    pub driver_version: String,
    pub api_version: String,
    pub shader_float16: bool,
}

#[derive(Clone, Debug, Default, Deserialize)]
#[serde(default)]
pub struct CpuView {
    pub vendor: String,
    pub family: String,
    pub model: String,
    pub stepping: String,
    pub model_name: String,
    pub features: Vec<String>,
}

/// `report::Provenance` as read back.
#[derive(Clone, Debug, Default, Deserialize)]
#[serde(default)]
pub struct ProvenanceView {
    pub tool: String,
    pub unix_time: u64,
    pub device: DeviceView,
    pub mesa_version: Option<String>,
    pub llvm_version: Option<String>,
    pub env: BTreeMap<String, String>,
    pub cpu: Option<CpuView>,
    pub host_cpu: Option<String>,
    pub host_threads: usize,
    /// The command line that wrote the report (reports from before it was recorded have none).
    pub command: Option<Vec<String>>,
    /// HLSL and WGSL models' front ends (model path -> front end).
    pub front_ends: BTreeMap<String, String>,
}
