//! The translation does no more transcendental work than the SPIR-V: for every preset, each
//! example `.brdf` file and every default sweep spec, the profiling kernel's transcendental instructions
//! (exp, log, reciprocal, reciprocal square root, square root, sine, cosine) are counted in ACO's navi21
//! disassembly (`inspect --isa`, the SPIR-V as RADV compiles it), in ptxas' sm_89 SASS (MUFU) and in IGC's
//! gen12lp ISA (math) of the kernel's C translation, and must agree but where a compiler's own lowering
//! explains the difference, each such case listed in `EXCEPTIONS` with the mechanism and checked to apply.

use crate::common;
use brdfprof::kernels;
use brdfprof::model::Model;
use brdfprof::targets::{intel, nvidia};
use brdfprof::translate::{Dialect, prepare};
use std::collections::BTreeMap;
use std::path::Path;

/// The transcendental functions compared.
const OPS: [&str; 7] = ["exp", "log", "rcp", "rsqrt", "sqrt", "sin", "cos"];

type Counts = BTreeMap<&'static str, f64>;

/// ACO's listing: `v_exp_f32_e32`, `v_log_f16`, ... (`v_rcp_iflag_f32`, integer division's reciprocal, counts
/// as rcp).
fn aco_counts(listing: &str) -> Counts {
    let mut c = Counts::new();
    for word in listing.split(|ch: char| !(ch.is_ascii_alphanumeric() || ch == '_')) {
        let Some(rest) = word.strip_prefix("v_") else { continue };
        let Some(at) = ["_f16", "_f32"].iter().filter_map(|t| rest.find(t)).min() else { continue };
        let op = match &rest[..at] {
            "exp" => "exp",
            "log" => "log",
            "rcp" | "rcp_iflag" => "rcp",
            "rsq" => "rsqrt",
            "sqrt" => "sqrt",
            "sin" => "sin",
            "cos" => "cos",
            _ => continue,
        };
        *c.entry(op).or_default() += 1.0;
    }
    c
}

/// ptxas' SASS: MUFU.EX2, LG2, RCP, RSQ, SQRT, SIN, COS (MUFU.RCP64H and friends are fp64's and not counted).
fn sass_counts(listing: &str) -> Counts {
    let mut c = Counts::new();
    for (_, rest) in listing.match_indices("MUFU.").map(|(i, _)| ((), &listing[i + 5..])) {
        let name: String = rest.chars().take_while(|ch| ch.is_ascii_alphanumeric()).collect();
        let op = match name.as_str() {
            "EX2" => "exp",
            "LG2" => "log",
            "RCP" => "rcp",
            "RSQ" => "rsqrt",
            "SQRT" => "sqrt",
            "SIN" => "sin",
            "COS" => "cos",
            _ => continue,
        };
        *c.entry(op).or_default() += 1.0;
    }
    c
}

/// IGC's IGA listing, per lane: each `math.F (N|Mk)` counts N / (the kernel's SIMD width), so a SIMD32 kernel's
/// two SIMD16 halves count once. `math.pow` is an exp and a log, `math.fdiv` a reciprocal; integer division
/// (`math.iqot` and `math.irem` of one division) is one reciprocal, as ACO and ptxas lower it.
fn igc_counts(listing: &str) -> Counts {
    let mut lanes: BTreeMap<String, f64> = BTreeMap::new();
    let mut simd = 1.0f64;
    for line in listing.lines() {
        let Some(at) = line.find("math.") else { continue };
        let mut words = line[at + 5..].split_whitespace();
        let (Some(f), Some(exec)) = (words.next(), words.next()) else { continue };
        let Some((n, m)) = exec.trim_start_matches('(').trim_end_matches(')').split_once("|M") else { continue };
        let (n, m): (f64, f64) = (n.parse().unwrap_or(0.0), m.parse().unwrap_or(0.0));
        simd = simd.max(n + m);
        *lanes.entry(f.to_string()).or_default() += n;
    }
    let per = |f: &str| lanes.get(f).copied().unwrap_or(0.0) / simd;
    let mut c = Counts::new();
    c.insert("exp", per("exp") + per("pow"));
    c.insert("log", per("log") + per("pow"));
    c.insert("rcp", per("inv") + per("fdiv") + per("iqot").max(per("irem")));
    for (op, f) in [("rsqrt", "rsqt"), ("sqrt", "sqt"), ("sin", "sin"), ("cos", "cos")] {
        c.insert(op, per(f));
    }
    c
}

/// A listed difference: which kernels (a substring of the canonical spec), on which compiler, which function,
/// by how much (the compiler's count minus ACO's, exactly), and why.
struct Exception {
    kernels: &'static str,
    compiler: &'static str,
    op: &'static str,
    more: f64,
    why: &'static str,
}

const EXCEPTIONS: &[Exception] = &[Exception {
    kernels: "f=f82",
    compiler: "sm_89",
    op: "rcp",
    more: 6.0,
    why: "F82-tint's fit (b and the tint, per channel) is arithmetic on the metal's n and k, constants after specialisation: ACO and IGC fold its divisions at compile time; NVRTC with -use_fast_math leaves the approximate divisions unfolded (the SASS MOVs the immediates and takes MUFU.RCP of them), once per kernel, not per light",
}];
/// Every preset, example file and default sweep spec once: (what `--model` takes, the model).
fn models() -> Vec<(String, Model)> {
    let mut specs: Vec<String> = crate::compile_only::every_preset_and_example();
    specs.extend(brdfprof::sweep::default_specs().into_iter().map(|s| Model::spec(s).canonical()));
    let mut out: Vec<(String, Model)> = Vec::new();
    for s in specs {
        let m = Model::parse(&s).unwrap();
        if !out.iter().any(|(_, o)| o.canonical() == m.canonical()) {
            out.push((s, m));
        }
    }
    out
}

/// ACO's listing of every model's profiling kernel on navi21, by label (`inspect --isa`).
fn aco_listings(dir: &Path, models: &[(String, Model)]) -> BTreeMap<String, String> {
    let isa = dir.join("isa");
    let mut args: Vec<String> = [
        "inspect",
        "--no-callgrind",
        "--device",
        "radv:navi21",
        "--isa",
        isa.to_str().unwrap(),
        "--json",
        dir.join("aco.json").to_str().unwrap(),
    ]
    .map(String::from)
    .to_vec();
    for (spec, _) in models {
        args.extend(["--model".to_string(), spec.clone()]);
    }
    let refs: Vec<&str> = args.iter().map(String::as_str).collect();
    common::run_in(dir, &refs).ok();
    let labels = models.iter().map(|(_, m)| m.label()).chain([brdfprof::model::BASELINE_LABEL.to_string()]);
    labels
        .map(|l| {
            (
                l.clone(),
                std::fs::read_to_string(
                    isa.join("navi21").join(format!("{}.assembly.txt", brdfprof::targets::file_slug(&l))),
                )
                .unwrap_or_default(),
            )
        })
        .collect()
}

#[test]
fn every_kernel_does_the_same_transcendental_work_on_amd_nvidia_and_intel() {
    let dir = tempfile::tempdir().unwrap();
    let models = models();
    let aco = aco_listings(dir.path(), &models);
    let sm_89 = nvidia::FAMILIES.iter().find(|f| f.name == "sm_89").unwrap();
    let gen12lp = intel::FAMILIES.iter().find(|f| f.name == "gen12lp").unwrap();
    let mut table = Vec::new();
    let mut unexplained = Vec::new();
    let mut used = vec![0usize; EXCEPTIONS.len()];
    let mut all: Vec<(String, Option<&Model>)> = models.iter().map(|(_, m)| (m.label(), Some(m))).collect();
    all.push((brdfprof::model::BASELINE_LABEL.to_string(), None));
    for (label, m) in all {
        let name = m.map_or_else(|| label.clone(), Model::canonical);
        let t = prepare::shade_kernel(m, 8, kernels::embedded()).unwrap_or_else(|e| panic!("{name}: {e:#}"));
        assert!(!aco[&label].is_empty(), "{name}: no ACO listing");
        let a = aco_counts(&aco[&label]);
        let n = sass_counts(&nvidia::compile(&t.source(Dialect::Cuda), sm_89, false).unwrap().listing);
        let i = match intel::compile(&t.source(Dialect::OpenCl), gen12lp, false) {
            Ok(b) => Some(igc_counts(&b.listing)),
            Err(e) if format!("{e:#}").contains("fp64") => None,
            Err(e) => panic!("{name}: {e:#}"),
        };
        let count = |c: &Counts, op: &str| c.get(op).copied().unwrap_or(0.0);
        let row: Vec<String> = OPS
            .iter()
            .map(|op| {
                format!(
                    "{op} {}/{}/{}",
                    count(&a, op),
                    count(&n, op),
                    i.as_ref().map_or("-".into(), |i| count(i, op).to_string())
                )
            })
            .collect();
        table.push(format!("{name:60} {}", row.join("  ")));
        for op in OPS {
            for (compiler, c) in [("sm_89", Some(&n)), ("gen12lp", i.as_ref())] {
                let Some(c) = c else { continue };
                let more = count(c, op) - count(&a, op);
                if more == 0.0 {
                    continue;
                }
                match EXCEPTIONS
                    .iter()
                    .position(|x| x.compiler == compiler && x.op == op && name.contains(x.kernels) && x.more == more)
                {
                    Some(k) => used[k] += 1,
                    None => {
                        unexplained.push(format!("{name}: {op} navi21 {}, {compiler} {}", count(&a, op), count(c, op)))
                    }
                }
            }
        }
    }
    // The comparison can fail: burley's kernel prepared without flattening (SSA form and unrolling only)
    // computes the GTR normaliser once per light on sm_89, where ACO computes it once.
    let plain = prepare::shade_kernel_as(
        Some(&Model::parse("burley").unwrap()),
        8,
        kernels::embedded(),
        prepare::Preparation::Plain,
    )
    .unwrap();
    let unflattened = sass_counts(&nvidia::compile(&plain.source(Dialect::Cuda), sm_89, false).unwrap().listing);
    let aco_burley = aco_counts(&aco["burley"]);
    println!(
        "burley unflattened on sm_89: {} EX2, {} RCP; navi21: {} v_exp, {} v_rcp",
        unflattened["exp"], unflattened["rcp"], aco_burley["exp"], aco_burley["rcp"]
    );
    assert!(unflattened["exp"] > aco_burley["exp"] && unflattened["rcp"] > aco_burley["rcp"]);
    println!("navi21/sm_89/gen12lp per kernel (8 lights):\n{}", table.join("\n"));
    assert!(
        unexplained.is_empty(),
        "{} transcendental counts differ with no listed reason:\n{}",
        unexplained.len(),
        unexplained.join("\n")
    );
    for (x, n) in EXCEPTIONS.iter().zip(&used) {
        assert!(
            *n > 0,
            "the exception for {} {} on {} ({}) no longer applies: remove it",
            x.kernels,
            x.op,
            x.compiler,
            x.why
        );
    }
}
