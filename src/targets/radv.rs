//! `--device radv:FAMILY`: the GPU families whose real compiler (Mesa RADV's ACO) brdfprof runs on a machine
//! without an AMD GPU. With `RADV_FORCE_FAMILY=<family>` in the environment before the Vulkan loader starts,
//! RADV offers a "Null hardware (RADV <FAMILY>)" device: it has no queue that executes anything, but pipeline
//! creation runs ACO for that family and VK_KHR_pipeline_executable_properties returns ACO's statistics.
//! brdfprof runs itself as a child with the variable set (`mesa_noop`), so neither the user's environment
//! nor the parent's devices change.
//!
//! ACO's cost model (`aco_statistics.cpp`): Latency, "issue cycles plus stall cycles" of one wave, and Inverse
//! Throughput, "estimated busy cycles to execute one wave": cycles per wave64 per SIMD, with as many waves in
//! flight as the register budget allows (Subgroups per SIMD) hiding latency. ACO normalises the throughput to
//! 64 invocations whatever the wave size, so one evaluation (one invocation x one light) costs
//! `Inverse Throughput / (64 x lights per kernel)` SIMD cycles.

use super::cost::{self, TargetCost};
use super::mesa_noop::{self, NoopDriver};
use super::{Request, Run};
use super::radv_families::{family_of_device, null_device_name, FAMILIES, FORCE_FAMILY_VAR};
use crate::inspect::InspectReport;
use anyhow::Result;
use std::collections::BTreeMap;

/// Invocations ACO's Inverse Throughput is normalised to.
pub const THROUGHPUT_INVOCATIONS: f64 = 64.0;

/// The ACO statistics the cost table shows beside cycles/eval.
pub const SHOWN: [&str; 7] = ["Instructions", "VGPRs", "SGPRs", "Spilled VGPRs", "Latency", "Inverse Throughput", "Subgroups per SIMD"];

pub struct Radv;
pub static RADV: Radv = Radv;

fn device_name(report: &InspectReport) -> &str {
    report.provenance["device"]["name"].as_str().unwrap_or("?")
}

impl super::Vendor for Radv {
    fn prefix(&self) -> &'static str {
        "radv"
    }

    fn name(&self) -> &'static str {
        "AMD"
    }

    fn title(&self) -> &'static str {
        "AMD: Mesa RADV's ACO compiler, run in a child process with RADV_FORCE_FAMILY set (its null device compiles, nothing executes)"
    }

    fn families(&self) -> Vec<super::Family> {
        FAMILIES.iter().map(|f| super::Family { name: f.family, architecture: f.architecture, products: f.products, detail: format!("{}, wave{}", f.gfx, f.wave_size), default: f.default }).collect()
    }

    fn status(&self) -> Result<String> {
        Ok("Mesa RADV (ACO), the system's Vulkan driver".into())
    }

    fn needs_verification(&self) -> bool {
        false
    }

    fn compile(&self, families: &[usize], request: &Request) -> Result<Vec<Run>> {
        mesa_noop::compile("radv", families, &[], request)
    }

    fn compile_raw(&self, families: &[usize], kernels: &[super::RawKernel], request: &Request) -> Result<Vec<Run>> {
        if kernels.is_empty() {
            anyhow::bail!("radv: no raw kernel to compile");
        }
        mesa_noop::compile("radv", families, kernels, request)
    }

    fn cost(&self, report: &InspectReport) -> Option<TargetCost> {
        let family = family_of_device(device_name(report));
        let header = TargetCost {
            device: device_name(report).to_string(),
            target: family.map(|f| format!("radv:{}", f.family)),
            family: family.map(|f| f.family.to_string()),
            architecture: family.map(|f| f.architecture.to_string()),
            compiler: "ACO".into(),
            model: "cycles/eval = Inverse Throughput / (64 x lights per kernel)".into(),
            unit: "SIMD cycles".into(),
            lights_per_kernel: 0,
            columns: SHOWN.iter().map(|s| s.to_string()).collect(),
            rows: Vec::new(),
        };
        cost::table(report, header, |stats, lights| cost::driver_stat(stats, "Inverse Throughput").map(|it| it / (THROUGHPUT_INVOCATIONS * f64::from(lights))))
    }

    fn family_of(&self, report: &InspectReport) -> Option<usize> {
        let f = family_of_device(device_name(report))?;
        FAMILIES.iter().position(|x| x == f)
    }

    fn fingerprint(&self, report: &InspectReport) -> BTreeMap<String, String> {
        // ACO's output depends on the family (the device) and the Mesa version alone, not on the host.
        mesa_noop::fingerprint(report)
    }

    fn noop(&self) -> Option<&dyn NoopDriver> {
        Some(self)
    }
}

impl NoopDriver for Radv {
    fn compiler(&self) -> &'static str {
        "ACO"
    }

    fn environment(&self, family: usize) -> Result<Vec<(String, String)>> {
        Ok(vec![(FORCE_FAMILY_VAR.to_string(), FAMILIES[family].family.to_string())])
    }

    fn isa_folder(&self, family: usize) -> String {
        // RADV's listings were DIR/<family>/ before other drivers joined it.
        FAMILIES[family].family.to_string()
    }

    fn device(&self, family: usize) -> Option<String> {
        Some(null_device_name(&FAMILIES[family]))
    }

    fn install_hint(&self) -> String {
        "Is Mesa's AMD Vulkan driver installed? On Debian/Ubuntu as root: `apt-get install mesa-vulkan-drivers` (it ships \
         /usr/share/vulkan/icd.d/radeon_icd.*.json), or run `make setup`"
            .into()
    }
}

#[cfg(test)]
mod tests {
    use super::super::{parse, Vendor};
    use super::*;
    use crate::inspect::Row;

    #[test]
    fn parses_families_all_and_lists() {
        assert!(parse("0").unwrap().is_none());
        assert!(parse("llvmpipe").unwrap().is_none());
        assert_eq!(parse("radv:navi21").unwrap().unwrap()[0].info().name, "navi21");
        assert_eq!(parse("RADV:Vangogh").unwrap().unwrap()[0].info().architecture, "RDNA 2 Steam Deck APU");
        let all = parse("radv:all").unwrap().unwrap();
        assert!(all.len() >= 6 && all.iter().any(|t| t.info().name == "vega10") && all.iter().any(|t| t.info().name == "gfx1100"));
        assert_eq!(parse("radv:navi21,navi21,vega10").unwrap().unwrap().len(), 2);
        let e = parse("radv:navi31").unwrap_err().to_string();
        assert!(e.contains("unknown AMD family `navi31`") && e.contains("tahiti") && e.contains("gfx1100"), "{e}");
        assert!(parse("radv:").unwrap_err().to_string().contains("give a family"));
    }

    #[test]
    fn cycles_per_eval_is_inverse_throughput_per_64_lanes_and_light() {
        let row = |model: &str, it: f64| Row {
            model: model.into(),
            spec: None,
            stats: [("driver/Compute Shader/Inverse Throughput".to_string(), it), ("driver/Compute Shader/VGPRs".to_string(), 40.0)].into(),
            notes: BTreeMap::new(),
        };
        let mut report = crate::inspect::tests::empty_report("Null hardware (RADV NAVI21)");
        report.rows = vec![row("ggx", 1536.0), row(crate::inspect::BASELINE_LABEL, 512.0)];
        let t = RADV.cost(&report).unwrap();
        assert_eq!(t.family.as_deref(), Some("navi21"));
        assert_eq!(t.rows[0].cycles_per_eval, 3.0);
        assert_eq!(t.rows[0].net_cycles_per_eval, Some(2.0));
        assert_eq!(t.rows[1].net_cycles_per_eval, None);
        assert_eq!(t.stat(&t.rows[0], "VGPRs"), Some(40.0));
        assert!(t.markdown().contains("| ggx "));
        assert_eq!(RADV.fingerprint(&report)["device"], "Null hardware (RADV NAVI21)");
    }
}
