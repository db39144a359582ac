//! Reading SPIR-V, below every command that does (inspect counts it, translate and the compile-only targets
//! start from it, scenes specialise it). Instruction counts of a kernel specialised for one model: spirv-opt sets and freezes the
//! specialisation constants and removes the branches and functions the model does not run (so the counts are
//! those of that model alone), optionally followed by the full `spirv-opt -O`. rspirv parses the result and
//! every instruction inside a function body is counted by class.

pub mod loops;

use crate::gpu::SpecConstants;
use anyhow::{Result, anyhow, bail};
use rspirv::dr::{Module, Operand};
use rspirv::spirv::{Decoration, GlslStd450Op, Op};
use std::collections::BTreeMap;

/// spirv-opt passes that keep only the code a frozen specialisation runs, without optimising it further.
pub const SPECIALISE_PASSES: [&str; 5] = [
    "--freeze-spec-const",
    "--fold-spec-const-op-composite",
    "--eliminate-dead-branches",
    "--eliminate-dead-code-aggressive",
    "--eliminate-dead-functions",
];

/// The class an instruction is counted in.
pub fn class_of(op: Op) -> &'static str {
    use Op::*;
    match op {
        FAdd | FSub | FMul | FDiv | FRem | FMod | FNegate | VectorTimesScalar | MatrixTimesScalar
        | VectorTimesMatrix | MatrixTimesVector | MatrixTimesMatrix | OuterProduct | Dot | Transpose => "float-arith",
        IAdd | ISub | IMul | SDiv | UDiv | SRem | SMod | UMod | SNegate | ShiftLeftLogical | ShiftRightLogical
        | ShiftRightArithmetic | BitwiseAnd | BitwiseOr | BitwiseXor | Not | IAddCarry | ISubBorrow | UMulExtended
        | SMulExtended | BitFieldInsert | BitFieldSExtract | BitFieldUExtract | BitReverse | BitCount => "int-arith",
        ExtInst => "ext",
        FConvert | ConvertFToU | ConvertFToS | ConvertSToF | ConvertUToF | UConvert | SConvert | Bitcast
        | QuantizeToF16 | SatConvertSToU | SatConvertUToS => "conversion",
        Load
        | Store
        | AccessChain
        | InBoundsAccessChain
        | PtrAccessChain
        | InBoundsPtrAccessChain
        | CopyMemory
        | CopyMemorySized
        | Variable
        | ArrayLength
        | AtomicLoad
        | AtomicStore => "memory",
        CompositeConstruct | CompositeExtract | CompositeInsert | VectorShuffle | VectorExtractDynamic
        | VectorInsertDynamic | CopyObject | CopyLogical => "composite",
        Branch | BranchConditional | Switch | Phi | LoopMerge | SelectionMerge | Return | ReturnValue | Kill
        | TerminateInvocation | Unreachable | FunctionCall => "control",
        FOrdEqual
        | FUnordEqual
        | FOrdNotEqual
        | FUnordNotEqual
        | FOrdLessThan
        | FUnordLessThan
        | FOrdGreaterThan
        | FUnordGreaterThan
        | FOrdLessThanEqual
        | FUnordLessThanEqual
        | FOrdGreaterThanEqual
        | FUnordGreaterThanEqual
        | IEqual
        | INotEqual
        | SLessThan
        | SLessThanEqual
        | SGreaterThan
        | SGreaterThanEqual
        | ULessThan
        | ULessThanEqual
        | UGreaterThan
        | UGreaterThanEqual
        | LogicalAnd
        | LogicalOr
        | LogicalNot
        | LogicalEqual
        | LogicalNotEqual
        | Select
        | Any
        | All
        | IsNan
        | IsInf
        | IsFinite
        | IsNormal
        | SignBitSet => "compare-logic",
        _ => "other",
    }
}

/// The classes, in report order (extended instructions are counted by name instead of as one class).
pub const CLASSES: [&str; 8] =
    ["float-arith", "int-arith", "conversion", "memory", "composite", "control", "compare-logic", "other"];

/// Counts of one module: instructions inside function bodies (OpLabel, OpFunction, OpFunctionParameter and
/// OpFunctionEnd excluded), per class, and GLSL.std.450 extended instructions per name.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Counts {
    pub total: u64,
    pub functions: u64,
    pub classes: BTreeMap<&'static str, u64>,
    /// GLSL.std.450 instruction name (as the spec spells it: Pow, InverseSqrt, FMix, ...) -> count.
    pub glsl: BTreeMap<String, u64>,
}

impl Counts {
    /// `prefix/total`, `prefix/functions`, `prefix/<class>`, `prefix/glsl.<Name>`: the statistic keys.
    pub fn stats(&self, prefix: &str) -> Vec<(String, f64)> {
        let mut out = vec![
            (format!("{prefix}/total"), self.total as f64),
            (format!("{prefix}/functions"), self.functions as f64),
        ];
        out.extend(CLASSES.iter().map(|c| (format!("{prefix}/{c}"), *self.classes.get(c).unwrap_or(&0) as f64)));
        out.extend(self.glsl.iter().map(|(name, n)| (format!("{prefix}/glsl.{name}"), *n as f64)));
        out
    }
}

/// The result ids of OpExtInstImport "GLSL.std.450".
fn glsl_std_450_sets(module: &Module) -> Vec<u32> {
    module
        .ext_inst_imports
        .iter()
        .filter(|i| matches!(i.operands.first(), Some(Operand::LiteralString(s)) if s == "GLSL.std.450"))
        .filter_map(|i| i.result_id)
        .collect()
}

/// Counts the instructions of `words` by class.
pub fn count(words: &[u32]) -> Result<Counts> {
    let module = rspirv::dr::load_words(words).map_err(|e| anyhow!("rspirv cannot parse the module: {e}"))?;
    let glsl_sets = glsl_std_450_sets(&module);
    let mut counts = Counts { functions: module.functions.len() as u64, ..Default::default() };
    for inst in module.functions.iter().flat_map(|f| &f.blocks).flat_map(|b| &b.instructions) {
        counts.total += 1;
        let class = class_of(inst.class.opcode);
        if class != "ext" {
            *counts.classes.entry(class).or_default() += 1;
            continue;
        }
        let glsl = match inst.operands.as_slice() {
            [Operand::IdRef(set), Operand::LiteralExtInstInteger(n), ..] if glsl_sets.contains(set) => {
                GlslStd450Op::from_u32(*n)
            }
            _ => None,
        };
        match glsl {
            Some(op) => *counts.glsl.entry(format!("{op:?}")).or_default() += 1,
            None => *counts.classes.entry("other").or_default() += 1,
        }
    }
    Ok(counts)
}

/// `--set-spec-const-default-value` text for `constants`, each value written in the type its OpSpecConstant
/// has in `words` (ids the module does not declare are left out: spirv-opt would reject them).
pub fn spec_default_values(words: &[u32], constants: &SpecConstants) -> Result<String> {
    let module = rspirv::dr::load_words(words).map_err(|e| anyhow!("rspirv cannot parse the module: {e}"))?;
    let target_of_spec_id: BTreeMap<u32, u32> = module
        .annotations
        .iter()
        .filter(|a| a.class.opcode == Op::Decorate)
        .filter_map(|a| match a.operands.as_slice() {
            [Operand::IdRef(target), Operand::Decoration(Decoration::SpecId), Operand::LiteralBit32(id)] => {
                Some((*id, *target))
            }
            _ => None,
        })
        .collect();
    let types: BTreeMap<u32, &rspirv::dr::Instruction> =
        module.types_global_values.iter().filter_map(|i| i.result_id.map(|id| (id, i))).collect();
    let mut items = Vec::new();
    for (id, bytes) in constants.values() {
        let Some(constant) = target_of_spec_id.get(&id).and_then(|t| types.get(t)) else { continue };
        let ty = constant.result_type.and_then(|t| types.get(&t)).map(|t| t.class.opcode);
        let text = match ty {
            Some(Op::TypeFloat) => format!("{:?}", f32::from_ne_bytes(bytes)),
            Some(Op::TypeInt) => i32::from_ne_bytes(bytes).to_string(),
            other => bail!(
                "specialisation constant {id} has type {other:?}; brdfprof only sets 32-bit int and float constants"
            ),
        };
        items.push(format!("{id}:{text}"));
    }
    Ok(items.join(" "))
}

/// spirv-opt's output for `args` on `words`, kept for the process and in the disk cache: every vendor's report
/// specialises and optimises the same kernels, and the translation's checks specialise them again (125 runs
/// for the 33 compile-only targets' warm reports before, 2.7 s of a 4.3 s run on a 2-core VM). The key is the
/// module's bytes, the arguments and spirv-opt's version.
pub fn spirv_opt(words: &[u32], args: &[String]) -> Result<Vec<u32>> {
    use std::sync::{Mutex, OnceLock};
    static SEEN: OnceLock<Mutex<std::collections::HashMap<crate::cache::Key, Vec<u32>>>> = OnceLock::new();
    let bytes: &[u8] = bytemuck::cast_slice(words);
    let key = crate::cache::KeyBuilder::new("spirv-opt")
        .part("spirv-opt", spirv_opt_version().unwrap_or_default())
        .part("args", args.join("\n"))
        .part("module", bytes)
        .finish();
    let seen = SEEN.get_or_init(Default::default);
    if let Some(out) = seen.lock().unwrap_or_else(|e| e.into_inner()).get(&key) {
        return Ok(out.clone());
    }
    let valid = |b: &[u8]| {
        if b.len() % 4 == 0 && b.get(..4) == Some(&0x0723_0203u32.to_le_bytes()[..]) {
            Ok(())
        } else {
            Err(anyhow!("not a SPIR-V module"))
        }
    };
    let store = crate::cache::Store::open_default();
    let out = crate::cache::get_or_build(store.as_ref(), "spirv_opt", &key, "spirv-opt's output", valid, || {
        Ok(bytemuck::cast_slice(&run_spirv_opt(words, args)?).to_vec())
    })?;
    let out: Vec<u32> = out.chunks_exact(4).map(|c| u32::from_le_bytes(c.try_into().unwrap())).collect();
    seen.lock().unwrap_or_else(|e| e.into_inner()).insert(key, out.clone());
    Ok(out)
}

/// Runs spirv-opt with `args` on `words` (through stdin and stdout), under the compile limit.
fn run_spirv_opt(words: &[u32], args: &[String]) -> Result<Vec<u32>> {
    let mut cmd = crate::cleanup::command("spirv-opt");
    crate::launch::bound_memory(&mut cmd)?;
    cmd.args(args).args(["-", "-o", "-"]);
    let bytes: Vec<u8> = words.iter().flat_map(|w| w.to_le_bytes()).collect();
    let shown = if args.len() > 3 { format!("{} ...", args[..3].join(" ")) } else { args.join(" ") };
    let out = match crate::launch::output_with_input(&mut cmd, bytes, &format!("spirv-opt {shown}")) {
        Ok(out) => out,
        Err(e) if e.downcast_ref::<std::io::Error>().is_some() => {
            bail!("cannot run spirv-opt ({e}): install spirv-tools, or run `make setup`")
        }
        Err(e) => return Err(e),
    };
    if !out.status.success() {
        bail!("spirv-opt {} failed: {}", args.join(" "), String::from_utf8_lossy(&out.stderr).trim());
    }
    if out.stdout.len() % 4 != 0 {
        bail!(
            "spirv-opt wrote {} bytes, not whole SPIR-V words: {}",
            out.stdout.len(),
            String::from_utf8_lossy(&out.stdout[..out.stdout.len().min(300)])
        );
    }
    Ok(out.stdout.chunks_exact(4).map(|c| u32::from_le_bytes(c.try_into().unwrap())).collect())
}

/// The module with its specialisation constants set and frozen, and only the code they select kept.
pub fn specialise(words: &[u32], constants: &SpecConstants) -> Result<Vec<u32>> {
    let values = spec_default_values(words, constants)?;
    // A module none of whose constants is set (a .brdf model's eval kernel) keeps its defaults.
    let mut args =
        if values.is_empty() { Vec::new() } else { vec!["--set-spec-const-default-value".to_string(), values] };
    args.extend(SPECIALISE_PASSES.iter().map(|s| s.to_string()));
    spirv_opt(words, &args)
}

/// `spirv-opt -O` of a (specialised) module.
pub fn optimise(words: &[u32]) -> Result<Vec<u32>> {
    spirv_opt(words, &["-O".to_string()])
}

/// `spirv-opt --version`'s first line, e.g. "SPIRV-Tools v2023.1 ...".
pub fn spirv_opt_version() -> Option<String> {
    static V: std::sync::OnceLock<Option<String>> = std::sync::OnceLock::new();
    V.get_or_init(|| crate::shaders::first_line_of(crate::cleanup::command("spirv-opt").arg("--version"))).clone()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn classes() {
        assert_eq!(class_of(Op::FMul), "float-arith");
        assert_eq!(class_of(Op::Dot), "float-arith");
        assert_eq!(class_of(Op::FConvert), "conversion");
        assert_eq!(class_of(Op::AccessChain), "memory");
        assert_eq!(class_of(Op::Phi), "control");
        assert_eq!(class_of(Op::FOrdLessThan), "compare-logic");
    }
}
