//! `brdfprof check`: a shader-db-style comparison of this build's counts and timings with a saved baseline,
//! and a regression gate that a noisy CI machine can trust.
//!
//! - Deterministic counts (SPIR-V, naga, driver, callgrind) regress when they grow by more than a threshold
//!   (default 1%, `--threshold KEY=FRACTION` per statistic or per group).
//! - Timings (per-round cost ratios to a reference measured in the same rounds, see `timing`) regress only
//!   when the change is significant (Mann-Whitney U, alpha 0.05, at least 9 rounds on each side) and larger
//!   than a noise threshold (default 5%).
//! - SPIR-V and naga counts depend only on the shaders and the tools, so they are always compared. Driver
//!   statistics, callgrind counts and timings depend on the machine: each group is compared only when the
//!   environment it depends on (its fingerprint) is the same as the baseline's, or with `--force`;
//!   otherwise it is reported as "not comparable" with the reason and cannot fail the check.

mod baseline;
mod compare;
mod environment;
pub mod findings;
pub mod lines;
mod report;
mod thresholds;
pub mod timing;

pub use baseline::{Baseline, FORMAT, load};
pub use compare::{Change, Comparison, GroupStatus, ModelLines, TimingChange, compare};
pub use environment::{environment, host_cpu};
pub use thresholds::{
    ALPHA, DEFAULT_COUNT_THRESHOLD, DEFAULT_TIMING_THRESHOLD, GROUPS, MIN_TIMING_ROUNDS, TIMING_KEY, Thresholds,
    group_of, is_gated,
};

use crate::brdf::spec::THESIS_MODELS;
use crate::export::json;
use crate::gpu::Gpu;
use crate::inspect::InspectOptions;
use crate::inspect::callgrind::CallgrindOptions;
use crate::model::Model;
use crate::shaders::Shaders;
use anyhow::{Result, anyhow, bail};
use std::path::PathBuf;
use timing::TimingOptions;

/// Everything `check` measures.
pub struct CheckOptions {
    pub baseline: Option<PathBuf>,
    pub save: Option<PathBuf>,
    pub thresholds: Thresholds,
    pub force: bool,
    /// Models asked for on the command line (default: the baseline's, else the thesis models).
    pub models: Vec<Model>,
    /// Lights asked for (default: the baseline's, else 8).
    pub lights: Option<u32>,
    pub callgrind: Option<CallgrindOptions>,
    /// Timing run shape (`lights` is filled in); rounds 0 skips timing.
    pub timing: TimingOptions,
}

/// The result of `check`: the report text, the exit status (0 no regression, 1 regression, 2 could not
/// measure), the regressions as findings (SARIF, annotations) and what was measured on (target, compiler).
pub struct Outcome {
    pub text: String,
    pub exit: u8,
    pub findings: Vec<crate::export::sarif::Finding>,
    pub measured_on: (String, String),
}

/// The baseline's rows whose shader file is gone (renamed or deleted since it was saved), each as "`label`
/// (path)": not measured, named in the report, the other models compared.
fn missing_files(old: Option<&Baseline>) -> Vec<String> {
    let Some(b) = old else { return Vec::new() };
    b.inspect
        .rows
        .iter()
        .filter_map(|r| {
            let (path, _) = crate::model::file_model::split_path(r.spec.as_deref()?, std::path::Path::new(""))?;
            (!std::path::Path::new(path).exists()).then(|| {
                format!("`{}` ({})", crate::messages::escape_line(&r.model), crate::messages::escape_line(path))
            })
        })
        .collect()
}

/// The models and lights a check measures: those asked for, else the baseline's (but those whose file is
/// gone: `missing_files`), else the defaults.
fn plan(options: &CheckOptions, old: Option<&Baseline>) -> Result<(Vec<Model>, u32)> {
    let lights = match (options.lights, old) {
        (Some(l), Some(b)) if l != b.inspect.lights => {
            bail!(
                "--lights {l}: the baseline was measured with {} lights; a check compares like with like (save a new baseline instead)",
                b.inspect.lights
            )
        }
        (Some(l), _) => l,
        (None, Some(b)) => b.inspect.lights,
        (None, None) => 8,
    };
    if lights == 0 {
        bail!("--lights must be at least 1");
    }
    let specs = if !options.models.is_empty() {
        options.models.clone()
    } else if let Some(b) = old {
        b.inspect
            .rows
            .iter()
            .filter_map(|r| r.spec.as_deref())
            .filter(|s| {
                crate::model::file_model::split_path(s, std::path::Path::new(""))
                    .is_none_or(|(path, _)| std::path::Path::new(path).exists())
            })
            .map(|s| Model::parse(s).map_err(|e| anyhow!("{s}: {e}")))
            .collect::<Result<_>>()?
    } else {
        THESIS_MODELS.iter().map(|m| Model::parse(m)).collect::<Result<_>>()?
    };
    Ok((specs, lights))
}

/// Measures this build: every count, then the timing run.
pub fn measure(
    gpu: &Gpu,
    shaders: &Shaders,
    models: Vec<Model>,
    lights: u32,
    options: &CheckOptions,
) -> Result<Baseline> {
    crate::messages::progress(format!(
        "check: counting instructions ({} models + baseline kernel{})",
        models.len(),
        if options.callgrind.is_some() { ", callgrind" } else { "" }
    ));
    let inspect = crate::inspect::run(
        gpu,
        shaders,
        &InspectOptions { models: models.clone(), lights, callgrind: options.callgrind.clone() },
    )?;
    let timing = if options.timing.rounds > 0 {
        crate::messages::progress(format!("check: timing {} rounds", options.timing.rounds));
        Some(timing::run(gpu, shaders, &models, &TimingOptions { lights, ..options.timing.clone() })?)
    } else {
        None
    };
    let environment = environment(&inspect, timing.as_ref());
    Ok(Baseline { format: FORMAT.into(), inspect, timing, environment })
}

/// Runs `check`: loads the baseline (before opening the device, so a bad file fails at once), measures,
/// compares, saves.
pub fn run(options: &CheckOptions, shaders: &Shaders, open: impl FnOnce() -> Result<Gpu>) -> Result<Outcome> {
    run_measured(options, |specs, lights| {
        let gpu = open()?;
        let new = measure(&gpu, shaders, specs, lights, options)?;
        gpu.check_validation()?;
        Ok(new)
    })
}

/// `run` on a compile-only target (`--device radv:FAMILY`, `nvidia:FAMILY`): its compiler's statistics
/// (`targets`), no timing and no callgrind (nothing executes). `verify_on`: the Vulkan device a target's
/// translation is checked against first.
pub fn run_target(
    options: &CheckOptions,
    shaders: &Shaders,
    target: crate::targets::Target,
    validate: bool,
    verify_on: Option<&Gpu>,
) -> Result<Outcome> {
    run_measured(options, |specs, lights| {
        crate::messages::progress(format!(
            "check: compiling for {} ({} models + baseline kernel)",
            target.name(),
            specs.len()
        ));
        let request = crate::targets::Request {
            models: &specs,
            lights,
            shaders,
            validate,
            isa_dir: None,
            precise: false,
            verify_on,
            // Kept in the baseline so that a regression names the source lines whose cost rose.
            lines: crate::targets::names_lines(&target),
        };
        let run = crate::targets::compile_all(&[target], &request)?.pop().expect("one run per target");
        let mut inspect = run.report;
        if let Some(note) = run.note {
            crate::messages::note(note);
        }
        for group in ["callgrind/", "timing/"] {
            inspect
                .section_notes
                .insert(group.into(), format!("not applicable: {} compiles only, nothing executes", target.name()));
        }
        let environment = environment(&inspect, None);
        Ok(Baseline { format: FORMAT.into(), inspect, timing: None, environment })
    })
}

/// Loads the baseline, measures with `measure(models, lights)`, compares, saves.
fn run_measured(options: &CheckOptions, measure: impl FnOnce(Vec<Model>, u32) -> Result<Baseline>) -> Result<Outcome> {
    if options.baseline.is_none() && options.save.is_none() {
        bail!("check needs --baseline FILE (and/or --save-baseline FILE to write one)");
    }
    let old = options.baseline.as_deref().map(load).transpose()?;
    let (specs, lights) = plan(options, old.as_ref())?;
    let models = specs.clone();
    let new = measure(specs, lights)?;
    let measured_on = findings::measured_on(&new);
    let mut outcome = match (&old, &options.baseline) {
        (Some(old), Some(path)) => {
            let cmp = compare(old, &new, &options.thresholds, options.force);
            let findings = findings::findings(&cmp, &new);
            Outcome { text: cmp.report(path, &new), exit: cmp.exit_code(), findings, measured_on }
        }
        _ => Outcome {
            text: format!("{}\n\n{}", new.inspect.summary(), new.inspect.markdown()),
            exit: 0,
            findings: Vec::new(),
            measured_on,
        },
    };
    let missing = missing_files(old.as_ref());
    if !missing.is_empty() {
        crate::messages::warning(format!(
            "check: the baseline names shader files that are gone, not compared: {}; save a new baseline (--save-baseline) to drop them",
            missing.join(", ")
        ));
        outcome.text += &format!(
            "\n\n## Shader files the baseline names that are gone\n\nRenamed or deleted since the baseline was saved, so not measured (the other models are compared); `--save-baseline` writes a baseline without them.\n\n{}\n",
            missing.iter().map(|m| format!("- {m}")).collect::<Vec<_>>().join("\n")
        );
    }
    // A model that failed on the target (its translation's check, its compile) has no figures to gate: the
    // others are compared, and the check fails naming it, never passing over it.
    let failed = findings::failed(&new, &models);
    if !failed.is_empty() {
        outcome.text += &format!(
            "\n\n## Models with no figures\n\n{}\n",
            failed.iter().map(|f| format!("- {}", f.message)).collect::<Vec<_>>().join("\n")
        );
        outcome.exit = outcome.exit.max(1);
        outcome.findings.extend(failed);
    }
    if let Some(path) = &options.save {
        json::write_report(path, json::Kind::Baseline, &baseline::with_paths_relative_to(&new, path))?;
        crate::messages::progress(format!("check: baseline saved to {}", path.display()));
    }
    Ok(outcome)
}

#[cfg(test)]
mod tests {
    use super::timing::TimingRun;
    use super::*;
    use crate::export::json;
    use crate::schema::{InspectReport, Row};
    use std::collections::BTreeMap;
    use std::path::Path;

    fn row(model: &str, stats: &[(&str, f64)]) -> Row {
        Row {
            model: model.into(),
            spec: (model != "baseline").then(|| Model::parse(model).unwrap().canonical()),
            stats: stats.iter().map(|(k, v)| (k.to_string(), *v)).collect(),
            notes: BTreeMap::new(),
        }
    }

    fn baseline(rows: Vec<Row>, timing: Option<TimingRun>, host: &str) -> Baseline {
        let columns = rows
            .iter()
            .flat_map(|r| r.stats.keys().cloned())
            .collect::<std::collections::BTreeSet<_>>()
            .into_iter()
            .collect();
        let inspect = InspectReport {
            provenance: serde_json::json!({"device": {"name": "llvmpipe (LLVM 15.0.6, 256 bits)"}}),
            kernels: "embedded spv/".into(),
            lights: 8,
            tools: BTreeMap::new(),
            columns,
            rows,
            section_notes: BTreeMap::new(),
            callgrind: None,
            callgrind_setup: BTreeMap::new(),
            vs_profile: None,
            cost: None,
            lines: Vec::new(),
            loop_trips: Vec::new(),
        };
        let mut environment = BTreeMap::new();
        for g in ["callgrind", "timing"] {
            environment.insert(g.to_string(), [("host-cpu".to_string(), host.to_string())].into());
        }
        Baseline { format: FORMAT.into(), inspect, timing, environment }
    }

    fn timing(ratios: &[(&str, Vec<f64>)]) -> TimingRun {
        TimingRun {
            reference: "test".into(),
            width: 8,
            height: 8,
            lights: 8,
            rounds: ratios[0].1.len(),
            reps: 1,
            ratios: ratios.iter().map(|(m, r)| (m.to_string(), r.clone())).collect(),
            round_ns: BTreeMap::new(),
            ns_per_eval: BTreeMap::new(),
        }
    }

    /// 15 ratios around `centre`, spread +-1%.
    fn around(centre: f64) -> Vec<f64> {
        (0..15).map(|i| centre * (1.0 + 0.01 * ((i * 7 % 15) as f64 / 7.0 - 1.0))).collect()
    }

    #[test]
    fn thresholds_prefer_the_key_then_the_group_then_the_default() {
        let t = Thresholds::parse(&["spirv=0.1".into(), "spirv/total=0.02".into(), "timing=0.2".into()]).unwrap();
        assert_eq!(t.get("spirv/total"), 0.02);
        assert_eq!(t.get("spirv/glsl.Pow"), 0.1);
        assert_eq!(t.get("callgrind/ir-per-eval"), DEFAULT_COUNT_THRESHOLD);
        assert_eq!(t.get(TIMING_KEY), 0.2);
        assert_eq!(Thresholds::default().get(TIMING_KEY), DEFAULT_TIMING_THRESHOLD);
        assert!(
            Thresholds::parse(&["bogus/x=0.1".into()]).unwrap_err().to_string().contains("unknown statistic `bogus/x`")
        );
        assert!(Thresholds::parse(&["spirv=abc".into()]).unwrap_err().to_string().contains("not a number"));
        assert!(Thresholds::parse(&["spirv=-1".into()]).is_err());
        assert!(Thresholds::parse(&["spirv".into()]).is_err());
    }

    #[test]
    fn counts_regress_beyond_their_threshold_only() {
        let old = baseline(
            vec![row("ggx", &[("spirv/total", 100.0), ("spirv/functions", 10.0), ("spirv/glsl.Exp", 1.0)])],
            None,
            "cpu",
        );
        let new = baseline(
            vec![row("ggx", &[("spirv/total", 100.9), ("spirv/functions", 20.0), ("spirv/glsl.Pow", 1.0)])],
            None,
            "cpu",
        );
        let cmp = compare(&old, &new, &Thresholds::default(), false);
        let regressions = cmp.regressions();
        // +0.9% total is within 1%; functions are reported only; Pow appeared (+inf); Exp went away (helped).
        assert_eq!(regressions.len(), 1, "{regressions:?}");
        assert!(regressions[0].starts_with("ggx spirv/glsl.Pow: 0 -> 1"), "{regressions:?}");
        assert_eq!(cmp.exit_code(), 1);
        let report = cmp.report(Path::new("b.json"), &new);
        assert!(report.contains("## Helped (1)") && report.contains("ggx spirv/glsl.Exp: 1 -> 0"), "{report}");
        let loose = compare(&old, &new, &Thresholds::parse(&["spirv/glsl.Pow=1e300".into()]).unwrap(), false);
        assert_eq!(loose.exit_code(), 1, "+inf exceeds any finite threshold");
        assert_eq!(compare(&old, &old, &Thresholds::default(), false).exit_code(), 0);
    }

    #[test]
    fn machine_dependent_groups_compare_only_in_the_same_environment() {
        let old = baseline(
            vec![row("ggx", &[("spirv/total", 100.0), ("callgrind/ir-per-eval", 60.0)])],
            Some(timing(&[("ggx", around(1.0))])),
            "cpu A",
        );
        let mut new = baseline(
            vec![row("ggx", &[("spirv/total", 100.0), ("callgrind/ir-per-eval", 70.0)])],
            Some(timing(&[("ggx", around(1.5))])),
            "cpu B",
        );
        let cmp = compare(&old, &new, &Thresholds::default(), false);
        assert_eq!(cmp.exit_code(), 0, "{:?}", cmp.regressions());
        let status = |c: &Comparison, g: &str| c.groups.iter().find(|(n, _)| n == g).unwrap().1.clone();
        assert!(
            matches!(status(&cmp, "callgrind"), GroupStatus::NotComparable(d) if d.contains("host-cpu: baseline `cpu A`, now `cpu B`"))
        );
        assert!(matches!(status(&cmp, "timing"), GroupStatus::NotComparable(_)));
        assert!(matches!(status(&cmp, "spirv"), GroupStatus::Compared));
        // Forced, or in the same environment, both regress.
        assert_eq!(compare(&old, &new, &Thresholds::default(), true).regressions().len(), 2);
        new.environment = old.environment.clone();
        let same = compare(&old, &new, &Thresholds::default(), false);
        assert_eq!(same.regressions().len(), 2, "{:?}", same.regressions());
        assert_eq!(same.exit_code(), 1);
    }

    #[test]
    fn timings_need_significance_and_size() {
        let old = baseline(vec![row("ggx", &[])], Some(timing(&[("ggx", around(1.0)), ("blinn", around(1.2))])), "cpu");
        // ggx +10% (significant, beyond 5%): regression; blinn +2% (significant, within 5%): not.
        let new = baseline(
            vec![row("ggx", &[])],
            Some(timing(&[("ggx", around(1.1)), ("blinn", around(1.2 * 1.02))])),
            "cpu",
        );
        let cmp = compare(&old, &new, &Thresholds::default(), false);
        let by = |m: &str| cmp.timing.iter().find(|t| t.model == m).unwrap().clone();
        assert!(by("ggx").is_regression() && by("ggx").p.unwrap() < 1e-3);
        assert!(by("blinn").significant() && !by("blinn").is_regression());
        assert_eq!(cmp.exit_code(), 1);
        // Fewer than 9 rounds: no test, no verdict.
        let short = |c: f64| timing(&[("ggx", around(c)[..8].to_vec())]);
        let cmp = compare(
            &baseline(vec![row("ggx", &[])], Some(short(1.0)), "cpu"),
            &baseline(vec![row("ggx", &[])], Some(short(2.0)), "cpu"),
            &Thresholds::default(),
            false,
        );
        assert_eq!((cmp.timing[0].p, cmp.exit_code()), (None, 0));
    }

    #[test]
    fn a_failed_callgrind_run_is_could_not_measure() {
        let old = baseline(vec![row("ggx", &[("callgrind/ir-per-eval", 60.0)])], None, "cpu");
        let mut new = baseline(vec![row("ggx", &[])], None, "cpu");
        new.inspect.section_notes.insert("callgrind/".into(), "could not measure: valgrind crashed".into());
        let cmp = compare(&old, &new, &Thresholds::default(), false);
        assert_eq!(cmp.exit_code(), 2);
        assert!(
            cmp.report(Path::new("b.json"), &new)
                .contains("COULD NOT MEASURE: callgrind: could not measure: valgrind crashed")
        );
        // On another machine the figures would not have been compared anyway: no failure.
        let elsewhere = baseline(vec![row("ggx", &[])], None, "another cpu");
        let mut new_elsewhere = elsewhere.clone();
        new_elsewhere.inspect.section_notes = new.inspect.section_notes.clone();
        assert_eq!(compare(&old, &new_elsewhere, &Thresholds::default(), false).exit_code(), 0);
        // Skipped on purpose: not compared, no failure.
        new.inspect.section_notes.insert("callgrind/".into(), "not measured (--no-callgrind)".into());
        assert_eq!(compare(&old, &new, &Thresholds::default(), false).exit_code(), 0);
    }

    #[test]
    fn bad_baselines_are_refused_with_the_reason() {
        let dir = tempfile::tempdir().unwrap();
        let missing = dir.path().join("missing.json");
        assert!(load(&missing).unwrap_err().to_string().contains("cannot read it"));
        let write = |name: &str, text: &str| {
            let p = dir.path().join(name);
            std::fs::write(&p, text).unwrap();
            p
        };
        let e = load(&write("trunc.json", "{\"format\": \"brdfprof-check")).unwrap_err().to_string();
        assert!(e.contains("corrupt, not valid JSON"), "{e}");
        let e = load(&write("other.json", "{\"rows\": []}")).unwrap_err().to_string();
        assert!(e.contains("not a brdfprof check baseline"), "{e}");
        let e = load(&write("old.json", "{\"format\": \"brdfprof-check-baseline/0\"}")).unwrap_err().to_string();
        assert!(e.contains("format `brdfprof-check-baseline/0`"), "{e}");
        let good = baseline(vec![row("ggx", &[("spirv/total", 1.0)])], None, "cpu");
        let p = dir.path().join("good.json");
        json::write_json(&p, &good).unwrap();
        assert_eq!(load(&p).unwrap().inspect.rows, good.inspect.rows);
        let e = load(&write(
            "bad.json",
            &std::fs::read_to_string(&p).unwrap().replace("\"spirv/total\": 1.0", "\"spirv/total\": \"x\""),
        ))
        .unwrap_err()
        .to_string();
        assert!(e.contains("corrupt") && e.contains("bad.json"), "{e}");
    }

    #[test]
    fn impossible_figures_are_refused_naming_the_statistic_and_value() {
        let committed = Path::new(env!("CARGO_MANIFEST_DIR")).join("results/baseline-llvmpipe.json");
        let good: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&committed).unwrap()).unwrap();
        let dir = tempfile::tempdir().unwrap();
        let refused = |edit: &dyn Fn(&mut serde_json::Value)| {
            let mut v = good.clone();
            edit(&mut v);
            let p = dir.path().join("b.json");
            std::fs::write(&p, serde_json::to_string(&v).unwrap()).unwrap();
            load(&p).err().map(|e| e.to_string()).unwrap_or_else(|| "accepted".into())
        };
        assert_eq!(refused(&|_| {}), "accepted");
        let stat = |key: &'static str, x: f64| {
            move |v: &mut serde_json::Value| v["inspect"]["rows"][0]["stats"][key] = x.into()
        };
        let e = refused(&stat("spirv/total", -1.0));
        assert!(
            e.contains("b.json: corrupt (row `ggx`: statistic spirv/total is -1; a count cannot be negative)"),
            "{e}"
        );
        // Per-line cycles are counts too (they set each line's share of a regression).
        let e = refused(&|v: &mut serde_json::Value| {
            v["inspect"]["lines"] = serde_json::json!([{"model": "ggx", "binding_pipe": "FMA", "unattributed": 0, "instructions": 1,
                "lines": [{"file": "m.brdf", "line": 3, "instructions": 1, "pipes": {"FMA": -4.0}, "binding": -4.0, "schedule": 0.0}]}]);
        });
        assert!(e.contains("m.brdf:3 has -4 cycles on FMA"), "{e}");
        // A row naming a shader file that is gone is no corruption: the file is named as missing when checked.
        let gone = |v: &mut serde_json::Value| v["inspect"]["rows"][0]["spec"] = "gone/missing.brdf".into();
        assert_eq!(refused(&gone), "accepted");
        let e = refused(&stat("callgrind/ir-per-eval", -67.5));
        assert!(e.contains("statistic callgrind/ir-per-eval is -67.5; a count cannot be negative"), "{e}");
        let e = refused(&stat("naga/expressions", 1.5));
        assert!(e.contains("statistic naga/expressions is 1.5; an instruction count is a whole number"), "{e}");
        assert_eq!(refused(&stat("callgrind/net-ir-per-eval", -1.0)), "accepted", "a net count may be negative");
        let e = refused(&|v| v["inspect"]["lights"] = 0.into());
        assert!(e.contains("inspect.lights is 0"), "{e}");
        let e = refused(&|v| v["inspect"]["lights"] = (-1).into());
        assert!(e.contains("corrupt") && e.contains("-1"), "{e}");
        let e = refused(&|v| v["inspect"]["callgrind"]["evaluations"] = 0.into());
        assert!(e.contains("callgrind.evaluations is 0"), "{e}");
        let e = refused(&|v| v["timing"]["reps"] = 0.into());
        assert!(e.contains("timing.reps is 0"), "{e}");
        let e = refused(&|v| v["timing"]["lights"] = 3.into());
        assert!(e.contains("timing.lights is 3 but inspect.lights is 8"), "{e}");
        let e = refused(&|v| v["timing"]["ratios"]["ggx"][2] = (-0.5).into());
        assert!(e.contains("timing.ratios of `ggx`: -0.5 is not a positive number"), "{e}");
        let e = refused(&|v| v["timing"]["rounds"] = 16.into());
        assert!(e.contains("15 values for 16 rounds"), "{e}");
        let e = refused(&|v| v["timing"]["ratios"]["phong"] = v["timing"]["ratios"]["ggx"].clone());
        assert!(e.contains("timing.ratios: `phong` is not a row of the baseline"), "{e}");
        let e = refused(&|v| v["timing"]["ns_per_eval"]["ggx"] = 0.into());
        assert!(e.contains("timing.ns_per_eval of `ggx`: 0 is not a positive number"), "{e}");
    }
}
