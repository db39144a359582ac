//! What a callgrind run of lavapipe's JIT code recorded: the instructions each kernel executed, and the
//! report keys they give per evaluation.

use crate::model::BASELINE_LABEL;
use serde::{Deserialize, Serialize};

/// Instructions executed by one kernel's JIT code in the measured dispatch.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct KernelIr {
    /// The spec's name, or "baseline".
    pub label: String,
    pub jit_ir: u64,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct CallgrindRun {
    pub kernels: Vec<KernelIr>,
    pub evaluations: u64,
    pub jit_cpu_features: Vec<String>,
    pub valgrind: String,
}

impl CallgrindRun {
    pub fn ir_of(&self, label: &str) -> Option<u64> {
        self.kernels.iter().find(|k| k.label == label).map(|k| k.jit_ir)
    }

    /// `callgrind/ir-per-eval` and, for models, `callgrind/net-ir-per-eval` (minus the baseline kernel's).
    pub fn stats(&self, label: &str) -> Vec<(String, f64)> {
        let e = self.evaluations as f64;
        let Some(ir) = self.ir_of(label) else { return Vec::new() };
        let mut out = vec![("callgrind/ir-per-eval".to_string(), ir as f64 / e)];
        if let (Some(base), true) = (self.ir_of(BASELINE_LABEL), label != BASELINE_LABEL) {
            out.push(("callgrind/net-ir-per-eval".to_string(), (ir as f64 - base as f64) / e));
        }
        out
    }
}
