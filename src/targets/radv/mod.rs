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

pub mod env;

pub use brdfprof_isa_cost::{aco as aco_perfinfo, amd as families};

use super::cost;
use super::cost::schedule::Schedule;
use super::mesa_noop::{self, NoopDriver};
use super::{Request, Run};
use crate::gpu::CompilerLog;
use crate::schema::InspectReport;
use crate::schema::cost::TargetCost;
use anyhow::Result;
use families::{FAMILIES, FORCE_FAMILY_VAR, Family, family_of_device, null_device_name};
use std::collections::BTreeMap;

/// Invocations ACO's Inverse Throughput is normalised to.
pub const THROUGHPUT_INVOCATIONS: f64 = 64.0;

/// The ACO statistics the cost table shows beside cycles/eval (and the rule's figures, `cost::schedule_table`).
pub const SHOWN: [&str; 5] = ["Instructions", "VGPRs", "Spilled VGPRs", "Latency", "Inverse Throughput"];

/// Asks ACO for its per-instruction schedule (`aco_perfinfo`), beside the user's own ACO_DEBUG flags.
const PERFINFO: &str = "perfinfo";

/// The rule's figures of one ACO kernel (`cost::schedule`), from its perfinfo statistics: every
/// instruction once at ACO's own resource costs for `family` (vector instructions twice for wave64 on
/// GFX10+, as ACO dual-issues them for workgroups over 32 invocations), the clocks summed, ACO's num_waves.
pub fn schedule(stats: &BTreeMap<String, f64>, family: &Family) -> Option<Schedule> {
    use aco_perfinfo::{Arch, CLOCKS, Class, Resource, WAVES, count_name, usage};
    let arch = Arch { gfx10: family.gfx_major() >= 10, fast_fma: family.fast_fma() };
    let dual = if arch.gfx10 && family.wave_size == 64 { 2.0 } else { 1.0 };
    let mut busy: BTreeMap<Resource, f64> = Resource::ALL.iter().map(|r| (*r, 0.0)).collect();
    for c in Class::ALL {
        let n = cost::driver_stat(stats, &count_name(c))?;
        for (r, cycles) in usage(c, arch) {
            *busy.entry(r).or_default() += n * cycles * if c.is_vector() { dual } else { 1.0 };
        }
    }
    Some(Schedule {
        pipes: busy.into_iter().map(|(r, c)| (r.name().to_string(), c)).collect(),
        latency: Some(cost::driver_stat(stats, CLOCKS)?),
        resident_waves: Some(cost::driver_stat(stats, WAVES)?),
    })
}

/// A pipeline's stderr under ACO_DEBUG=perfinfo, as the logged executable's statistics (`aco_perfinfo::read`).
fn read_log(log: &str) -> Result<(Vec<crate::gpu::DriverStat>, Vec<String>)> {
    let (stats, rest) = aco_perfinfo::read(log)?;
    Ok((super::logged(stats), rest))
}

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
        FAMILIES
            .iter()
            .map(|f| super::Family {
                name: f.family,
                architecture: f.architecture,
                products: f.products,
                detail: format!("{}, wave{}", f.gfx, f.wave_size),
                default: f.default,
            })
            .collect()
    }

    fn status(&self) -> Result<String> {
        Ok("Mesa RADV (ACO), the system's Vulkan driver".into())
    }

    fn needs_verification(&self) -> bool {
        false
    }

    fn compile(&self, families: &[usize], request: &Request) -> Result<Vec<Run>> {
        mesa_noop::parent::compile("radv", families, &[], request)
    }

    fn compile_raw(&self, families: &[usize], kernels: &[super::RawKernel], request: &Request) -> Result<Vec<Run>> {
        if kernels.is_empty() {
            anyhow::bail!("radv: no raw kernel to compile");
        }
        mesa_noop::parent::compile("radv", families, kernels, request)
    }

    fn cost(&self, report: &InspectReport) -> Option<TargetCost> {
        let family = family_of_device(device_name(report));
        let header = |model: String| TargetCost {
            device: device_name(report).to_string(),
            target: family.map(|f| format!("radv:{}", f.family)),
            family: family.map(|f| f.family.to_string()),
            architecture: family.map(|f| f.architecture.to_string()),
            compiler: "ACO".into(),
            model,
            unit: "SIMD cycles".into(),
            lights_per_kernel: 0,
            columns: SHOWN.iter().map(|s| s.to_string()).collect(),
            rows: Vec::new(),
            absent: Vec::new(),
            failed: Vec::new(),
            checked: None,
        };
        // ACO's per-instruction schedule where the report has it (the compile-only targets), else (a real
        // RADV GPU) its Inverse Throughput, branch weights and all.
        let perfinfo = family.filter(|f| report.rows.iter().any(|r| schedule(&r.stats, f).is_some()));
        match perfinfo {
            Some(f) => {
                let rule = format!(
                    "{}; ACO's resource costs and per-instruction clocks (ACO_DEBUG=perfinfo) with every instruction once, ACO's num_waves; / (64 x lights per kernel); ACO's own Latency and Inverse Throughput (its branch weights) beside",
                    super::cost::schedule::RULE
                );
                cost::schedule_table(report, header(rule), |stats| Some((schedule(stats, f)?, THROUGHPUT_INVOCATIONS)))
            }
            None => cost::table(
                report,
                header("cycles/eval = Inverse Throughput / (64 x lights per kernel)".into()),
                |row, lights| {
                    cost::driver_stat(&row.stats, "Inverse Throughput")
                        .map(|it| it / (THROUGHPUT_INVOCATIONS * f64::from(lights)))
                },
            ),
        }
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
        let debug = match std::env::var("ACO_DEBUG") {
            Ok(d) if d.split(',').any(|f| f.trim() == PERFINFO) => d,
            Ok(d) if !d.trim().is_empty() => format!("{d},{PERFINFO}"),
            _ => PERFINFO.to_string(),
        };
        Ok(vec![(FORCE_FAMILY_VAR.to_string(), FAMILIES[family].family.to_string()), ("ACO_DEBUG".to_string(), debug)])
    }

    fn compiler_log(&self) -> Option<CompilerLog> {
        Some(CompilerLog { read: read_log, beside_properties: true })
    }

    fn is_noise(&self, line: &str) -> bool {
        // The perfinfo of RADV's own shaders, compiled when its device opens.
        aco_perfinfo::is_printed_line(line)
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
    use super::super::{Vendor, parse};
    use super::*;
    use crate::schema::Row;

    #[test]
    fn parses_families_all_and_lists() {
        assert!(parse("0").unwrap().is_none());
        assert!(parse("llvmpipe").unwrap().is_none());
        assert_eq!(parse("radv:navi21").unwrap().unwrap()[0].info().name, "navi21");
        assert_eq!(parse("RADV:Vangogh").unwrap().unwrap()[0].info().architecture, "RDNA 2 Steam Deck APU");
        let all = parse("radv:all").unwrap().unwrap();
        assert!(
            all.len() >= 6
                && all.iter().any(|t| t.info().name == "vega10")
                && all.iter().any(|t| t.info().name == "gfx1100")
        );
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
            stats: [
                ("driver/Compute Shader/Inverse Throughput".to_string(), it),
                ("driver/Compute Shader/VGPRs".to_string(), 40.0),
            ]
            .into(),
            notes: BTreeMap::new(),
        };
        let mut report = crate::schema::tests::empty_report("Null hardware (RADV NAVI21)");
        report.rows = vec![row("ggx", 1536.0), row(crate::model::BASELINE_LABEL, 512.0)];
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
