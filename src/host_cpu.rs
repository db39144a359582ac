//! The host CPU, as reports record it: lavapipe's costs are the CPU's (its JIT targets the host's vector
//! units), so a figure without the CPU that made it cannot be compared.

use serde::{Deserialize, Serialize};

/// What /proc/cpuinfo and CPUID say about the host (read back from saved reports with a missing field empty).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct HostCpu {
    pub vendor: String,
    pub family: String,
    pub model: String,
    pub stepping: String,
    pub model_name: String,
    /// The vector and bit-manipulation features the JIT may use (e.g. avx2, avx512f), as CPUID reports them.
    pub features: Vec<String>,
}

impl HostCpu {
    pub fn detect() -> Self {
        let text = std::fs::read_to_string("/proc/cpuinfo").unwrap_or_default();
        let field = |name: &str| {
            text.lines()
                .find(|l| l.split(':').next().is_some_and(|k| k.trim() == name))
                .and_then(|l| l.split_once(':'))
                .map_or(String::from("?"), |(_, v)| v.trim().to_string())
        };
        HostCpu {
            vendor: field("vendor_id"),
            family: field("cpu family"),
            model: field("model"),
            stepping: field("stepping"),
            model_name: field("model name"),
            features: cpu_features(),
        }
    }

    /// "vendor family F model M stepping S (model name)".
    pub fn describe(&self) -> String {
        format!(
            "{} family {} model {} stepping {} ({})",
            self.vendor, self.family, self.model, self.stepping, self.model_name
        )
    }

    /// The widest vector extension present: "AVX-512", "AVX2", ...
    pub fn vector_width(&self) -> &'static str {
        let has = |f: &str| self.features.iter().any(|x| x == f);
        if has("avx512f") {
            "AVX-512"
        } else if has("avx2") {
            "AVX2"
        } else if has("avx") {
            "AVX"
        } else {
            "SSE"
        }
    }
}

/// The CPU features of this process' host, as `is_x86_feature_detected!` sees them.
#[cfg(target_arch = "x86_64")]
pub fn cpu_features() -> Vec<String> {
    let mut f = Vec::new();
    macro_rules! probe {
        ($($name:tt),*) => { $( if std::arch::is_x86_feature_detected!($name) { f.push($name.to_string()); } )* };
    }
    probe!(
        "sse4.1", "sse4.2", "popcnt", "avx", "avx2", "fma", "f16c", "bmi1", "bmi2", "avx512f", "avx512dq", "avx512bw",
        "avx512vl", "avx512cd"
    );
    f
}

#[cfg(not(target_arch = "x86_64"))]
pub fn cpu_features() -> Vec<String> {
    vec![std::env::consts::ARCH.to_string()]
}

/// The memory the kernel says can be allocated without swapping (`MemAvailable` of /proc/meminfo), in bytes;
/// None where it cannot be read.
pub fn available_memory() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}

/// Bytes that lower the memory brdfprof plans with below `MemAvailable` (`available_memory`), so that the
/// refusals of sizes that do not fit can be tested without filling a machine's memory (docs/limits.md).
pub const MEMORY_LIMIT_ENV: &str = "BRDFPROF_MEMORY_LIMIT";

/// `MEMORY_LIMIT_ENV` when set: a whole number of bytes (an error names the variable otherwise).
pub fn memory_limit() -> anyhow::Result<Option<u64>> {
    match std::env::var(MEMORY_LIMIT_ENV) {
        Ok(v) if !v.trim().is_empty() => v
            .trim()
            .parse::<u64>()
            .map(Some)
            .map_err(|_| anyhow::anyhow!("{MEMORY_LIMIT_ENV}={v}: give a whole number of bytes")),
        _ => Ok(None),
    }
}

/// The memory a run may plan to use: `MemAvailable`, lowered by `MEMORY_LIMIT_ENV`; None where neither is
/// known. `where_from` says which applies, for messages.
pub fn memory_budget() -> Option<(u64, &'static str)> {
    let limit = memory_limit().ok().flatten();
    match (available_memory(), limit) {
        (Some(a), Some(l)) if l < a => Some((l, MEMORY_LIMIT_ENV)),
        (Some(a), _) => Some((a, "MemAvailable")),
        (None, Some(l)) => Some((l, MEMORY_LIMIT_ENV)),
        (None, None) => None,
    }
}
