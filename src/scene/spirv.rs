//! What a specialised kernel really contains, read from its SPIR-V: spirv-opt (SPIRV-Tools) sets the
//! specialisation constants, freezes and folds them, and removes dead branches, functions and code; what is left
//! is what the driver gets to compile. Used by `profile --scene` (when spirv-opt is installed) and by the tests
//! that check an effect no material uses is absent from the kernel.

use crate::gpu::SpecConstants;
use crate::shaders::Spirv;
use crate::spirv::{spec_default_values, spirv_opt};
use anyhow::{Result, anyhow};
use rspirv::dr::{self, Operand};
use rspirv::spirv::Op;
use serde::Serialize;
use std::process::Stdio;

/// The specialised module: the functions left after dead-code elimination (without inlining), and the
/// instruction count inside functions after spirv-opt -O (everything inlined).
#[derive(Clone, Debug, Serialize)]
pub struct Specialised {
    pub functions: Vec<String>,
    pub instructions: usize,
}

/// Specialises `source` with `constants` and reports what is left.
pub fn specialise(source: &Spirv, constants: &SpecConstants) -> Result<Specialised> {
    let words = &source.words;
    let values = spec_default_values(words, constants)?;
    let freeze: Vec<String> =
        ["--set-spec-const-default-value", values.as_str(), "--freeze-spec-const", "--fold-spec-const-op-composite"]
            .map(String::from)
            .to_vec();
    let with = |more: &[&str]| [freeze.clone(), more.iter().map(|s| s.to_string()).collect()].concat();
    let dce = spirv_opt(
        words,
        &with(&["--eliminate-dead-branches", "--eliminate-dead-functions", "--eliminate-dead-code-aggressive"]),
    )?;
    let dce = dr::load_words(&dce).map_err(|e| anyhow!("{}: {e}", source.name))?;
    let functions = dce
        .functions
        .iter()
        .filter_map(|f| f.def.as_ref()?.result_id)
        .filter_map(|id| {
            dce.debug_names.iter().find_map(|i| match (&i.operands[..], i.class.opcode) {
                ([Operand::IdRef(t), Operand::LiteralString(name)], Op::Name) if *t == id => {
                    Some(name.split('(').next().unwrap_or(name).to_string())
                }
                _ => None,
            })
        })
        .collect();
    let optimised = spirv_opt(words, &with(&["-O"]))?;
    let optimised = dr::load_words(&optimised).map_err(|e| anyhow!("{}: {e}", source.name))?;
    let instructions =
        optimised.functions.iter().map(|f| f.blocks.iter().map(|b| b.instructions.len() + 1).sum::<usize>()).sum();
    Ok(Specialised { functions, instructions })
}

/// True when spirv-opt can be run.
pub fn available() -> bool {
    crate::cleanup::command("spirv-opt")
        .arg("--version")
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .is_ok_and(|s| s.success())
}
