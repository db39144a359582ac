//! Driver statistics through VK_KHR_pipeline_executable_properties (RADV, ANV, NVIDIA, ...; not lavapipe
//! 22.3): every statistic every executable of a pipeline reports, verbatim, plus a small alias table so that
//! register, instruction and spill counts line up across vendors under common keys.

use crate::gpu::Gpu;
use anyhow::{Context, Result};
use ash::vk;
use std::ffi::CStr;

/// One statistic as the driver reports it.
#[derive(Clone, Debug, PartialEq)]
pub struct DriverStat {
    /// The executable's name (e.g. "Compute Shader"), then the statistic's.
    pub executable: String,
    pub name: String,
    pub description: String,
    pub value: f64,
}

/// Common key <- the vendor names that mean it (Mesa RADV/ACO, AMDVLK, Intel ANV, NVIDIA's driver). Values of
/// every matching statistic in every executable are summed (RADV's spilled SGPRs and VGPRs make `spills`).
pub const ALIASES: &[(&str, &[&str])] = &[
    ("registers", &["VGPRs", "numUsedVgprs", "Register Count"]),
    ("scalar-registers", &["SGPRs", "numUsedSgprs"]),
    ("instructions", &["Instructions", "Instruction Count"]),
    ("code-bytes", &["Code size", "Binary Size"]),
    ("spills", &["Spilled VGPRs", "Spilled SGPRs", "Spill Count"]),
    ("fills", &["Fill Count"]),
    ("scratch-bytes", &["Scratch size", "Scratch Memory Size"]),
    ("branches", &["Branches"]),
];

/// The statistics of `pipeline`, or None when the device lacks VK_KHR_pipeline_executable_properties.
pub fn statistics(gpu: &Gpu, pipeline: vk::Pipeline) -> Result<Option<Vec<DriverStat>>> {
    let Some(ext) = &gpu.executable_properties else { return Ok(None) };
    let info = vk::PipelineInfoKHR::default().pipeline(pipeline);
    // SAFETY: the pipeline was created on this device with CAPTURE_STATISTICS (Kernel::new sets it whenever
    // the extension is enabled) and lives through these calls.
    let executables = unsafe { ext.get_pipeline_executable_properties(&info) }.context("vkGetPipelineExecutablePropertiesKHR")?;
    let mut out = Vec::new();
    for (index, exe) in executables.iter().enumerate() {
        let exe_name = text(exe.name_as_c_str());
        let exe_info = vk::PipelineExecutableInfoKHR::default().pipeline(pipeline).executable_index(index as u32);
        // SAFETY: as above; index < the executable count the driver returned.
        let stats = unsafe { ext.get_pipeline_executable_statistics(&exe_info) }.context("vkGetPipelineExecutableStatisticsKHR")?;
        out.extend(stats.iter().map(|s| DriverStat {
            executable: exe_name.clone(),
            name: text(s.name_as_c_str()),
            description: text(s.description_as_c_str()),
            value: value(s),
        }));
    }
    Ok(Some(out))
}

fn text(r: std::result::Result<&CStr, std::ffi::FromBytesUntilNulError>) -> String {
    r.map(|s| s.to_string_lossy().into_owned()).unwrap_or_default()
}

fn value(s: &vk::PipelineExecutableStatisticKHR) -> f64 {
    // SAFETY: `format` says which member of the union the driver wrote.
    unsafe {
        match s.format {
            vk::PipelineExecutableStatisticFormatKHR::BOOL32 => f64::from(s.value.b32),
            vk::PipelineExecutableStatisticFormatKHR::INT64 => s.value.i64 as f64,
            vk::PipelineExecutableStatisticFormatKHR::UINT64 => s.value.u64 as f64,
            vk::PipelineExecutableStatisticFormatKHR::FLOAT64 => s.value.f64,
            _ => f64::NAN,
        }
    }
}

/// Statistic keys: `driver/<executable>/<name>` for each statistic, `driver/<alias>` for each alias that some
/// statistic matched.
pub fn stats(all: &[DriverStat]) -> Vec<(String, f64)> {
    let mut out: Vec<(String, f64)> = all.iter().map(|s| (format!("driver/{}/{}", s.executable, s.name), s.value)).collect();
    for (alias, names) in ALIASES {
        let matching: Vec<f64> = all.iter().filter(|s| names.iter().any(|n| n.eq_ignore_ascii_case(&s.name))).map(|s| s.value).collect();
        if !matching.is_empty() {
            out.push((format!("driver/{alias}"), matching.iter().sum()));
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn stat(name: &str, value: f64) -> DriverStat {
        DriverStat { executable: "Compute Shader".into(), name: name.into(), description: String::new(), value }
    }

    #[test]
    fn vendor_names_line_up_under_aliases() {
        // RADV/ACO names.
        let radv = stats(&[stat("VGPRs", 24.0), stat("SGPRs", 16.0), stat("Spilled VGPRs", 2.0), stat("Spilled SGPRs", 1.0), stat("Instructions", 310.0)]);
        let get = |s: &[(String, f64)], k: &str| s.iter().find(|(key, _)| key == k).map(|(_, v)| *v);
        assert_eq!(get(&radv, "driver/registers"), Some(24.0));
        assert_eq!(get(&radv, "driver/spills"), Some(3.0));
        assert_eq!(get(&radv, "driver/instructions"), Some(310.0));
        assert_eq!(get(&radv, "driver/Compute Shader/VGPRs"), Some(24.0));
        // NVIDIA and ANV names reach the same keys.
        let nv = stats(&[stat("Register Count", 40.0), stat("Binary Size", 4096.0)]);
        assert_eq!((get(&nv, "driver/registers"), get(&nv, "driver/code-bytes")), (Some(40.0), Some(4096.0)));
        let anv = stats(&[stat("Instruction Count", 200.0), stat("Spill Count", 0.0)]);
        assert_eq!((get(&anv, "driver/instructions"), get(&anv, "driver/spills")), (Some(200.0), Some(0.0)));
        assert_eq!(get(&anv, "driver/registers"), None);
    }
}
