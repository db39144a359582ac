//! What a specialised kernel really contains, read from its SPIR-V: spirv-opt (SPIRV-Tools) sets the
//! specialisation constants, freezes and folds them, and removes dead branches, functions and code; what is left
//! is what the driver gets to compile. Used by `profile --scene` (when spirv-opt is installed) and by the tests
//! that check an effect no material uses is absent from the kernel.

use crate::gpu::SpecConstants;
use crate::shaders::KernelSource;
use anyhow::{anyhow, bail, Context, Result};
use rspirv::dr::{self, Operand};
use rspirv::spirv::{Decoration, Op};
use serde::Serialize;
use std::io::Write;
use std::process::{Command, Stdio};

/// The specialised module: the functions left after dead-code elimination (without inlining), and the
/// instruction count inside functions after spirv-opt -O (everything inlined).
#[derive(Clone, Debug, Serialize)]
pub struct Specialised {
    pub functions: Vec<String>,
    pub instructions: usize,
}

/// `--set-spec-const-default-value` text for `constants`, typed from the module's own declarations.
fn spec_values(module: &dr::Module, constants: &SpecConstants) -> Result<String> {
    let mut parts = Vec::new();
    for (id, bytes) in constants.values() {
        let target = module
            .annotations
            .iter()
            .find(|i| {
                i.class.opcode == Op::Decorate
                    && i.operands.get(1) == Some(&Operand::Decoration(Decoration::SpecId))
                    && i.operands.get(2) == Some(&Operand::LiteralBit32(id))
            })
            .and_then(|i| match i.operands[0] {
                Operand::IdRef(t) => Some(t),
                _ => None,
            });
        let Some(target) = target else { continue };
        let ty = module.types_global_values.iter().find(|i| i.result_id == Some(target)).and_then(|i| i.result_type);
        let is_float = ty.is_some_and(|t| module.types_global_values.iter().any(|i| i.result_id == Some(t) && i.class.opcode == Op::TypeFloat));
        let value = if is_float { format!("{}", f32::from_ne_bytes(bytes)) } else { format!("{}", i32::from_ne_bytes(bytes)) };
        parts.push(format!("{id}:{value}"));
    }
    Ok(parts.join(" "))
}

fn spirv_opt(words: &[u32], args: &[&str]) -> Result<Vec<u32>> {
    let mut child = Command::new("spirv-opt")
        .args(args)
        .args(["-", "-o", "-"])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .context("spirv-opt not found (install spirv-tools, or run `make setup`)")?;
    child.stdin.take().unwrap().write_all(bytemuck::cast_slice(words))?;
    let out = child.wait_with_output()?;
    if !out.status.success() {
        bail!("spirv-opt failed: {}", String::from_utf8_lossy(&out.stderr));
    }
    Ok(bytemuck::pod_collect_to_vec(&out.stdout))
}

/// Specialises `source` with `constants` and reports what is left.
pub fn specialise(source: &KernelSource, constants: &SpecConstants) -> Result<Specialised> {
    let words = source.words();
    let module = dr::load_words(&words).map_err(|e| anyhow!("{}: {e}", source.name))?;
    let values = spec_values(&module, constants)?;
    let freeze = ["--set-spec-const-default-value", values.as_str(), "--freeze-spec-const", "--fold-spec-const-op-composite"];
    let dce = spirv_opt(&words, &[&freeze[..], &["--eliminate-dead-branches", "--eliminate-dead-functions", "--eliminate-dead-code-aggressive"]].concat())?;
    let dce = dr::load_words(&dce).map_err(|e| anyhow!("{}: {e}", source.name))?;
    let functions = dce
        .functions
        .iter()
        .filter_map(|f| f.def.as_ref()?.result_id)
        .filter_map(|id| {
            dce.debug_names.iter().find_map(|i| match (&i.operands[..], i.class.opcode) {
                ([Operand::IdRef(t), Operand::LiteralString(name)], Op::Name) if *t == id => Some(name.split('(').next().unwrap_or(name).to_string()),
                _ => None,
            })
        })
        .collect();
    let optimised = spirv_opt(&words, &[&freeze[..], &["-O"]].concat())?;
    let optimised = dr::load_words(&optimised).map_err(|e| anyhow!("{}: {e}", source.name))?;
    let instructions = optimised.functions.iter().map(|f| f.blocks.iter().map(|b| b.instructions.len() + 1).sum::<usize>()).sum();
    Ok(Specialised { functions, instructions })
}

/// True when spirv-opt can be run.
pub fn available() -> bool {
    Command::new("spirv-opt").arg("--version").stdout(Stdio::null()).stderr(Stdio::null()).status().is_ok_and(|s| s.success())
}
