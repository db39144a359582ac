//! The measured-reference suite: every check of `targets::cost::measured::CHECKS` rerun on its family, the
//! modelled ratio of the suite's own kernel pair (tests/fixtures/brdf/measured/) against the published
//! measurement. It fails naming the family, the pair and the source when the rule leaves a measurement's
//! tolerance (unless the difference is a named, documented one), when a named difference has come within
//! tolerance (its note is then false), or when the rule's figure has left the one recorded beside the check.

use crate::compile_only::inspect_json;
use brdfprof::targets::cost::measured::{CHECKS, Check, Figure, own_estimate};
use std::collections::{BTreeMap, BTreeSet};

/// Throughput pairs are read at 8 lights (the light loop unrolled, as a shading pass runs it); latency chains
/// at 1 light (one chain per wave, as the latency microbenchmarks run it).
const THROUGHPUT_LIGHTS: u32 = 8;
const LATENCY_LIGHTS: u32 = 1;

/// The kernels one check needs: (target, lights, kernel file stem).
fn kernels(c: &Check) -> Vec<(&'static str, u32, String)> {
    match &c.figure {
        Figure::Throughput { a, b, b_target } => {
            let bt = b_target.unwrap_or(c.target);
            ["t8", "t16"]
                .iter()
                .flat_map(|s| {
                    [(c.target, THROUGHPUT_LIGHTS, format!("{a}-{s}")), (bt, THROUGHPUT_LIGHTS, format!("{b}-{s}"))]
                })
                .collect()
        }
        Figure::Latency { kind, .. } => {
            ["c32", "c96"].iter().map(|s| (c.target, LATENCY_LIGHTS, format!("{kind}-{s}"))).collect()
        }
    }
}

/// (target, lights, model) -> the cost row's JSON.
type Rows = BTreeMap<(String, u32, String), serde_json::Value>;

fn price(dir: &std::path::Path) -> Rows {
    let mut wanted: BTreeMap<(&str, u32), BTreeSet<String>> = BTreeMap::new();
    for c in CHECKS {
        for (t, lights, k) in kernels(c) {
            wanted.entry((t, lights)).or_default().insert(k);
        }
    }
    let folder = crate::common::repo_root().join("tests/fixtures/brdf/measured");
    let mut rows = Rows::new();
    for ((target, lights), models) in &wanted {
        let files: Vec<String> =
            models.iter().map(|m| folder.join(format!("{m}.brdf")).display().to_string()).collect();
        let lights_text = lights.to_string();
        let mut extra = vec!["--lights", lights_text.as_str()];
        for f in &files {
            extra.extend(["--model", f.as_str()]);
        }
        let name = format!("measured-{}-{lights}", target.replace(':', "-"));
        let report = inspect_json(dir, &name, &[target], &extra, "statistics");
        // One device: the report itself; several: `reports`.
        let reports = report["reports"].as_array().cloned().unwrap_or_else(|| vec![report.clone()]);
        for r in &reports {
            let cost = &r["cost"];
            assert_eq!(cost["target"].as_str(), Some(*target), "{target}: a report without its cost table: {r}");
            for row in cost["rows"].as_array().unwrap() {
                let model = row["model"].as_str().unwrap().to_string();
                rows.insert((target.to_string(), *lights, model), row.clone());
            }
        }
    }
    rows
}

/// The check's pair read through `value` (a row's figure: target, lights, model): the slopes' ratio of a
/// throughput pair (64 operations apart), the cycles per link of a latency chain.
fn pair(c: &Check, value: impl Fn(&str, u32, &str) -> f64) -> f64 {
    match &c.figure {
        Figure::Throughput { a, b, b_target } => {
            let bt = b_target.unwrap_or(c.target);
            let slope = |t: &str, k: &str| {
                value(t, THROUGHPUT_LIGHTS, &format!("{k}-t16")) - value(t, THROUGHPUT_LIGHTS, &format!("{k}-t8"))
            };
            let (slope_a, slope_b) = (slope(c.target, a), slope(bt, b));
            assert!(slope_b > 0.0, "{bt} {b}: 64 more operations cost {slope_b}");
            slope_a / slope_b
        }
        Figure::Latency { kind, .. } => {
            let at = |m: String| value(c.target, LATENCY_LIGHTS, &m);
            (at(format!("{kind}-c96")) - at(format!("{kind}-c32"))) / 64.0
        }
    }
}

/// Statistic `stat` of a priced row.
fn stat<'a>(rows: &'a Rows, stat: &'a str) -> impl Fn(&str, u32, &str) -> f64 + 'a {
    move |t, lights, m| {
        rows.get(&(t.to_string(), lights, m.to_string()))
            .and_then(|r| r["stats"][stat].as_f64())
            .unwrap_or_else(|| panic!("{t} {m} at {lights} lights: no statistic {stat}"))
    }
}

/// The check's modelled figure from the priced rows: net cycles/eval for a throughput pair, the check's
/// statistic for a latency chain.
fn modelled(c: &Check, rows: &Rows) -> f64 {
    match &c.figure {
        Figure::Throughput { .. } => pair(c, |t, lights, m| {
            rows.get(&(t.to_string(), lights, m.to_string()))
                .and_then(|r| r["net_cycles_per_eval"].as_f64())
                .unwrap_or_else(|| panic!("{t} {m}: no net cycles/eval at {lights} lights"))
        }),
        Figure::Latency { stat: s, .. } => pair(c, stat(rows, s)),
    }
}

/// The check's pair read through the compiler's own estimate `s` (`OWN_ESTIMATES`).
fn own(c: &Check, rows: &Rows, s: &str) -> f64 {
    pair(c, stat(rows, s))
}

#[test]
fn the_cost_rule_holds_against_published_measurements_or_names_the_difference() {
    let dir = tempfile::tempdir().unwrap();
    let rows = price(dir.path());
    let mut failures = Vec::new();
    let mut table = Vec::new();
    for c in CHECKS {
        let m = modelled(c, &rows);
        let pair = match &c.figure {
            Figure::Throughput { a, b, b_target } => {
                format!("{a}-t16/t8 over {b}-t16/t8{}", b_target.map_or(String::new(), |t| format!(" on {t}")))
            }
            Figure::Latency { kind, stat } => format!("{kind}-c96 less {kind}-c32, {stat}"),
        };
        let error = m / c.measured - 1.0;
        table.push(format!(
            "{} {} [{}]: modelled {m:.3} measured {:.3} ({:+.1}%){}",
            c.source,
            c.target,
            pair,
            c.measured,
            100.0 * error,
            if c.known.is_some() { " known" } else { "" }
        ));
        let named = format!(
            "{} ({}, {pair}; {}): modelled {m:.3} against measured {:.3}",
            c.target, c.what, c.source, c.measured
        );
        match (c.within(m), c.known) {
            (false, None) => {
                failures.push(format!("{named}: {:+.1}%, beyond {:.0}%", 100.0 * error, 100.0 * c.tolerance))
            }
            (true, Some(_)) => {
                failures.push(format!("{named}: within tolerance now; its known difference in measured.rs is false"))
            }
            _ => {}
        }
        if let Some((stat, what)) = own_estimate(c.target) {
            let o = own(c, &rows, stat);
            table.push(format!("    {what}: {o:.3} ({:+.1}%)", 100.0 * (o / c.measured - 1.0)));
            match c.own {
                Some(recorded) if (o / recorded - 1.0).abs() <= 0.01 => {}
                _ => {
                    failures.push(format!("{named}: {what} gives {o:.3}; measured.rs records {:?} (update it)", c.own))
                }
            }
        }
        if !(m / c.modelled - 1.0).abs().le(&0.01) {
            failures.push(format!("{named}: src/targets/cost/measured.rs records {} (update it)", c.modelled));
        }
    }
    eprintln!("{}", table.join("\n"));
    assert!(failures.is_empty(), "the cost rule against published measurements:\n{}", failures.join("\n"));
}
