//! ACO's statistics of a report's kernels (RADV, real or compile-only) and what they say per BRDF evaluation.
//!
//! ACO (Mesa's AMD compiler, `aco_statistics.cpp`) estimates, per kernel: Latency, "issue cycles plus stall
//! cycles" of one wave, and Inverse Throughput, "estimated busy cycles to execute one wave": cycles per wave64
//! per SIMD, with as many waves in flight as the register budget allows (Subgroups per SIMD) hiding latency.
//! ACO normalises the throughput to 64 invocations whatever the wave size (it scales waves per cycle by
//! wave_size / 64), so one evaluation (one invocation x one light) costs
//! `Inverse Throughput / (64 x lights per kernel)` SIMD cycles; with Mesa 22.3's wave64 compute kernels that is
//! Inverse Throughput / (wave size x lights). The same minus the memory-only kernel's is the BRDF's own cost.

use super::InspectReport;
use crate::profile::workload::{steady_block, BASELINE_LABEL};
use crate::report::{sig, Table};
use serde::{Deserialize, Serialize};

/// Invocations ACO's Inverse Throughput is normalised to.
pub const THROUGHPUT_INVOCATIONS: f64 = 64.0;

/// One kernel's ACO figures.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct AcoRow {
    pub model: String,
    pub instructions: f64,
    pub vgprs: f64,
    pub sgprs: f64,
    /// Spilled VGPRs + spilled SGPRs.
    pub spills: f64,
    pub latency: f64,
    pub inverse_throughput: f64,
    /// Occupancy: waves of this kernel one SIMD holds at once.
    pub subgroups_per_simd: f64,
    /// The wave size the driver compiled for.
    pub wave_size: Option<f64>,
    /// SIMD cycles per BRDF evaluation: inverse throughput / (64 x lights per kernel).
    pub cycles_per_eval: f64,
    /// The same minus the memory-only kernel's (None for that kernel).
    pub net_cycles_per_eval: Option<f64>,
}

/// A device's ACO table.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct AcoTable {
    pub device: String,
    /// The RADV family of a compile-only device (None for a real GPU).
    pub family: Option<String>,
    pub architecture: Option<String>,
    /// Lights per kernel (the kernel inspect compiles: at most one light block).
    pub lights_per_kernel: u32,
    pub rows: Vec<AcoRow>,
}

/// The value of driver statistic `name` of any executable, summed (a compute pipeline has one).
fn driver_stat(stats: &std::collections::BTreeMap<String, f64>, name: &str) -> Option<f64> {
    let suffix = format!("/{name}");
    let v: Vec<f64> = stats.iter().filter(|(k, _)| k.starts_with("driver/") && k.ends_with(&suffix) && k.matches('/').count() == 2).map(|(_, v)| *v).collect();
    (!v.is_empty()).then(|| v.iter().sum())
}

/// ACO's table of a report, or None when its driver reported no ACO statistics (not RADV).
pub fn table(report: &InspectReport) -> Option<AcoTable> {
    let lights = steady_block(report.lights).0;
    let per = THROUGHPUT_INVOCATIONS * f64::from(lights);
    let mut rows: Vec<AcoRow> = Vec::new();
    for r in &report.rows {
        let Some(it) = driver_stat(&r.stats, "Inverse Throughput") else { continue };
        let get = |n: &str| driver_stat(&r.stats, n).unwrap_or(0.0);
        rows.push(AcoRow {
            model: r.model.clone(),
            instructions: get("Instructions"),
            vgprs: get("VGPRs"),
            sgprs: get("SGPRs"),
            spills: get("Spilled VGPRs") + get("Spilled SGPRs"),
            latency: get("Latency"),
            inverse_throughput: it,
            subgroups_per_simd: get("Subgroups per SIMD"),
            wave_size: r.stats.get(super::driver::SUBGROUP_SIZE).copied(),
            cycles_per_eval: it / per,
            net_cycles_per_eval: None,
        });
    }
    if rows.is_empty() {
        return None;
    }
    if let Some(base) = rows.iter().find(|r| r.model == BASELINE_LABEL).map(|r| r.cycles_per_eval) {
        for r in rows.iter_mut().filter(|r| r.model != BASELINE_LABEL) {
            r.net_cycles_per_eval = Some(r.cycles_per_eval - base);
        }
    }
    let device = report.provenance["device"]["name"].as_str().unwrap_or("?").to_string();
    let target = crate::gpu::targets::family_of_device(&device);
    Some(AcoTable {
        device,
        family: target.map(|t| t.family.to_string()),
        architecture: target.map(|t| t.architecture.to_string()),
        lights_per_kernel: lights,
        rows,
    })
}

impl AcoTable {
    /// "navi21 (RDNA 2)" or the device name.
    pub fn label(&self) -> String {
        match (&self.family, &self.architecture) {
            (Some(f), Some(a)) => format!("{f} ({a})"),
            _ => self.device.clone(),
        }
    }

    pub fn row(&self, model: &str) -> Option<&AcoRow> {
        self.rows.iter().find(|r| r.model == model)
    }

    pub fn markdown(&self) -> String {
        let mut t = Table::new([
            "model", "Instructions", "VGPRs", "SGPRs", "spills", "Latency", "Inverse Throughput", "Subgroups per SIMD", "wave", "cycles/eval", "net cycles/eval", "net vs ggx",
        ]);
        let reference = self.row(crate::brdf::spec::REFERENCE_MODEL).and_then(|r| r.net_cycles_per_eval);
        let n = |v: f64| super::format_value(v);
        for r in &self.rows {
            t.row([
                r.model.clone(),
                n(r.instructions),
                n(r.vgprs),
                n(r.sgprs),
                n(r.spills),
                n(r.latency),
                n(r.inverse_throughput),
                n(r.subgroups_per_simd),
                r.wave_size.map_or("-".into(), n),
                sig(r.cycles_per_eval, 4),
                r.net_cycles_per_eval.map_or("-".into(), |v| sig(v, 4)),
                match (r.net_cycles_per_eval, reference) {
                    (Some(v), Some(g)) if g > 0.0 => format!("{:.2}", v / g),
                    _ => "-".into(),
                },
            ]);
        }
        format!(
            "### ACO statistics, {} ({} lights per kernel; cycles/eval = Inverse Throughput / (64 x {}), SIMD cycles)\n\n{}",
            self.label(),
            self.lights_per_kernel,
            self.lights_per_kernel,
            t.markdown()
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::inspect::Row;
    use std::collections::BTreeMap;

    #[test]
    fn cycles_per_eval_is_inverse_throughput_per_64_lanes_and_light() {
        let row = |model: &str, it: f64| Row {
            model: model.into(),
            spec: None,
            stats: [("driver/Compute Shader/Inverse Throughput".to_string(), it), ("driver/Compute Shader/VGPRs".to_string(), 40.0), (super::super::driver::SUBGROUP_SIZE.to_string(), 64.0)].into(),
            notes: BTreeMap::new(),
        };
        let report = InspectReport {
            provenance: serde_json::json!({"device": {"name": "Null hardware (RADV NAVI21)"}}),
            kernels: String::new(),
            lights: 8,
            tools: BTreeMap::new(),
            columns: vec![],
            rows: vec![row("ggx", 1536.0), row(BASELINE_LABEL, 512.0)],
            section_notes: BTreeMap::new(),
            callgrind: None,
            callgrind_setup: BTreeMap::new(),
            vs_profile: None,
            aco: None,
        };
        let t = table(&report).unwrap();
        assert_eq!(t.family.as_deref(), Some("navi21"));
        assert_eq!(t.rows[0].cycles_per_eval, 3.0);
        assert_eq!(t.rows[0].net_cycles_per_eval, Some(2.0));
        assert_eq!(t.rows[1].net_cycles_per_eval, None);
        assert_eq!(t.rows[0].vgprs, 40.0);
        assert!(t.markdown().contains("| ggx "));
    }
}
