//! What each statistic group depends on: its fingerprint, compared before its figures are.

use crate::check::timing::TimingRun;
use crate::inspect::callgrind;
use crate::schema::InspectReport;
use std::collections::BTreeMap;

/// The fingerprint key only a successful callgrind run can fill in (the CPU features valgrind shows the JIT).
pub(super) const JIT_FEATURES: &str = "jit-cpu-features";
/// The Mesa version a compile-only device's statistics depend on.
pub(super) const MESA: &str = "mesa";

/// "vendor family F model M stepping S (model name)" from /proc/cpuinfo: the host CPU as the JIT sees it.
pub fn host_cpu() -> String {
    crate::host_cpu::HostCpu::detect().describe()
}

/// What each group's figures depend on.
pub fn environment(inspect: &InspectReport, timing: Option<&TimingRun>) -> BTreeMap<String, BTreeMap<String, String>> {
    let p = &inspect.provenance;
    let text = |v: &serde_json::Value| v.as_str().map(str::to_string).unwrap_or_else(|| v.to_string());
    let device = text(&p["device"]["name"]);
    let driver = format!(
        "{} {} ({})",
        text(&p["device"]["driver_name"]),
        text(&p["device"]["driver_info"]),
        text(&p["device"]["driver_version"])
    );
    let env: Vec<String> =
        p["env"].as_object().map(|m| m.iter().map(|(k, v)| format!("{k}={}", text(v))).collect()).unwrap_or_default();
    let machine = |extra: Vec<(&str, String)>| -> BTreeMap<String, String> {
        let mut m: BTreeMap<String, String> = [("device", device.clone()), ("driver", driver.clone())]
            .into_iter()
            .map(|(k, v)| (k.to_string(), v))
            .collect();
        m.extend(extra.into_iter().map(|(k, v)| (k.to_string(), v)));
        m
    };
    let mut out = BTreeMap::new();
    // The front ends that compile a shader file's kernels at run time (glslang; slangc, naga_oil where used).
    let front: BTreeMap<String, String> = inspect
        .tools
        .iter()
        .filter(|(k, _)| *k == "glslang" || k.starts_with("front end of "))
        .map(|(k, v)| (k.clone(), v.clone()))
        .collect();
    out.insert("spirv".into(), front);
    out.insert("naga".into(), BTreeMap::new());
    out.insert(
        "spirv-O".into(),
        [("spirv-opt".to_string(), inspect.tools.get("spirv-opt").cloned().unwrap_or_default())].into(),
    );
    if let Some(target) = crate::targets::of_report(inspect) {
        // A compile-only target: its compiler's output depends on what the vendor says (the family and the
        // compiler's version), not on the host.
        out.insert("driver".into(), target.vendor.fingerprint(inspect));
    } else {
        out.insert("driver".into(), machine(vec![]));
    }
    if !inspect.callgrind_setup.is_empty() {
        // Callgrind counts the instructions lavapipe's JIT emits, which depend on the Mesa and LLVM versions
        // (device, driver), the environment, the workload, valgrind and the CPU features valgrind shows the
        // JIT (it hides AVX-512, for one): not on the host's CPU model, so the gate holds on any host with the
        // same features.
        let mut extra = vec![("driver-env", env.join(" "))];
        extra.extend(inspect.callgrind_setup.iter().map(|(k, v)| (k.as_str(), v.clone())));
        if let Some(cg) = &inspect.callgrind {
            extra.push((JIT_FEATURES, cg.jit_cpu_features.join(" ")));
        }
        out.insert("callgrind".into(), machine(extra));
    }
    if let Some(t) = timing {
        out.insert(
            "timing".into(),
            machine(vec![
                ("host-cpu", host_cpu()),
                ("cpu-features", callgrind::cpu_features().join(" ")),
                ("host-threads", text(&p["host_threads"])),
                ("driver-env", env.join(" ")),
                ("workload", format!("{}x{} pixels x {} lights", t.width, t.height, t.lights)),
                ("reference", t.reference.clone()),
            ]),
        );
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::schema::callgrind::CallgrindRun;

    fn report(host_model: &str, jit: &[&str], device: &str) -> InspectReport {
        InspectReport {
            provenance: serde_json::json!({
                "device": {"name": device, "driver_name": "radv", "driver_info": "Mesa 22.3.6", "driver_version": "22.3.6"},
                "mesa_version": "22.3.6",
                "env": {"MESA_SHADER_CACHE_DISABLE": "true"},
                "host_cpu": host_model,
                "cpu": {"model": host_model},
            }),
            kernels: String::new(),
            lights: 8,
            tools: BTreeMap::new(),
            columns: vec![],
            rows: vec![],
            section_notes: BTreeMap::new(),
            callgrind: Some(CallgrindRun {
                kernels: vec![],
                evaluations: 1,
                jit_cpu_features: jit.iter().map(|s| s.to_string()).collect(),
                valgrind: "valgrind-3.19.0".into(),
            }),
            callgrind_setup: [
                ("workload".to_string(), "64x64 pixels x 8 lights".to_string()),
                ("valgrind".to_string(), "valgrind-3.19.0".to_string()),
            ]
            .into(),
            vs_profile: None,
            cost: None,
            lines: Vec::new(),
            loop_trips: Vec::new(),
        }
    }

    #[test]
    fn callgrind_is_keyed_on_what_the_jit_sees_not_the_host_model() {
        let lvp = "llvmpipe (LLVM 15.0.6, 256 bits)";
        let amd = environment(&report("AMD EPYC family 26 model 2", &["avx", "avx2"], lvp), None);
        let intel = environment(&report("Intel Xeon family 6 model 207", &["avx", "avx2"], lvp), None);
        assert_eq!(
            amd["callgrind"], intel["callgrind"],
            "the same JIT features and tools on another CPU model gate alike"
        );
        assert!(!amd["callgrind"].contains_key("host-cpu"));
        for key in ["device", "driver", "driver-env", JIT_FEATURES, "valgrind", "workload"] {
            assert!(amd["callgrind"].contains_key(key), "{key}");
        }
        let wider = environment(&report("AMD EPYC family 26 model 2", &["avx", "avx2", "avx512f"], lvp), None);
        assert_ne!(amd["callgrind"], wider["callgrind"], "other JIT features: not comparable");
    }

    #[test]
    fn a_compile_only_device_is_keyed_on_its_family_and_mesa_only() {
        let navi = environment(&report("any", &[], "Null hardware (RADV NAVI21)"), None);
        assert_eq!(
            navi["driver"],
            [
                ("device".to_string(), "Null hardware (RADV NAVI21)".to_string()),
                (MESA.to_string(), "22.3.6".to_string())
            ]
            .into()
        );
    }
}
