//! Driver statistics (`gpu::Kernel::executables`: VK_KHR_pipeline_executable_properties) as report keys:
//! every statistic every executable of a pipeline reports, verbatim, plus a small alias table so that
//! register, instruction and spill counts line up across vendors under common keys.

pub use crate::gpu::DriverStat;

/// The executable's subgroup (wave) size as the driver reports it with its properties (not a statistic).
pub const SUBGROUP_SIZE: &str = "driver/subgroup-size";

/// Common key <- the vendor names that mean it (Mesa RADV/ACO, AMDVLK, Intel ANV, NVIDIA's driver). Values of
/// every matching statistic in every executable are summed (RADV's spilled SGPRs and VGPRs make `spills`).
pub const ALIASES: &[(&str, &[&str])] = &[
    ("registers", &["VGPRs", "numUsedVgprs", "Register Count"]),
    ("scalar-registers", &["SGPRs", "numUsedSgprs"]),
    ("instructions", &["Instructions", "Instruction Count"]),
    ("code-bytes", &["Code size", "Binary Size"]),
    // ANV's Spill Count counts spilled values; NVIDIA's Spill Bytes (ptxas) is their bytes: either says a kernel spills.
    ("spills", &["Spilled VGPRs", "Spilled SGPRs", "Spill Count", "Spill Bytes"]),
    ("fills", &["Fill Count"]),
    ("scratch-bytes", &["Scratch size", "Scratch Memory Size"]),
    ("branches", &["Branches"]),
    // ACO's (RADV) cycle estimates of one wave: issue plus stall cycles, and busy cycles per wave64.
    ("latency", &["Latency"]),
    ("inverse-throughput", &["Inverse Throughput"]),
    // NVIDIA's compile-only targets: SM cycles of one warp at the guide's issue rates (`targets::nvidia`).
    ("issue-cycles", &["Issue Cycles"]),
];

/// Statistic keys: `driver/<executable>/<name>` for each statistic, `driver/<alias>` for each alias that some
/// statistic matched.
pub fn stats(all: &[DriverStat]) -> Vec<(String, f64)> {
    let mut out: Vec<(String, f64)> =
        all.iter().map(|s| (format!("driver/{}/{}", s.executable, s.name), s.value)).collect();
    for (alias, names) in ALIASES {
        let matching: Vec<f64> =
            all.iter().filter(|s| names.iter().any(|n| n.eq_ignore_ascii_case(&s.name))).map(|s| s.value).collect();
        if !matching.is_empty() {
            out.push((format!("driver/{alias}"), matching.iter().sum()));
        }
    }
    out
}

/// A pipeline's statistics as row keys (`stats`), with the wave size the driver compiled for
/// (VkPipelineExecutablePropertiesKHR::subgroupSize) where it states one.
pub fn executable_stats(executables: Vec<crate::gpu::PipelineExecutable>) -> Vec<(String, f64)> {
    let mut out = Vec::new();
    if let Some(size) = executables.iter().map(|e| e.subgroup_size).max().filter(|s| *s > 0) {
        out.push((SUBGROUP_SIZE.to_string(), f64::from(size)));
    }
    out.extend(stats(&executables.into_iter().flat_map(|e| e.stats).collect::<Vec<_>>()));
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
        let radv = stats(&[
            stat("VGPRs", 24.0),
            stat("SGPRs", 16.0),
            stat("Spilled VGPRs", 2.0),
            stat("Spilled SGPRs", 1.0),
            stat("Instructions", 310.0),
        ]);
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
