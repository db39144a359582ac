//! Pairs of `.brdf` files that differ in one operation (tests/fixtures/brdf/pairs/: one sqrt more, one division
//! more, `pow(x, 5.0)` against four multiplies) on one AMD, NVIDIA and Intel target each: every vendor's cost
//! must move the way its compiler's code does. Code that only adds instructions never costs less; identical
//! instruction counts cost the same; a cost that moves moves with the work on the pipe (or the latency term)
//! that binds, and a branch weight or a translation artefact cannot reverse it.

use crate::compile_only::inspect_json;
use brdfprof::targets::cost::schedule::Schedule;
use brdfprof::targets::radv::families::FAMILIES as AMD;

const PAIRS: [(&str, &str); 3] = [("base", "plus-sqrt"), ("base", "plus-division"), ("mul5", "pow5")];

/// A row's statistics as the library reads them.
fn stats(row: &serde_json::Value) -> std::collections::BTreeMap<String, f64> {
    serde_json::from_value(row["stats"].clone()).unwrap()
}

/// Instructions per class as the vendor's compiler counts them (ACO's perfinfo classes, SASS and IGA classes).
fn classes(target: &str, row: &serde_json::Value) -> Vec<f64> {
    let s = stats(row);
    let get = |k: String| s.get(&k).copied().unwrap_or_else(|| panic!("{target} {}: no {k}", row["model"]));
    match target {
        "radv:navi21" => brdfprof::targets::radv::aco_perfinfo::Class::ALL
            .iter()
            .map(|c| get(format!("driver/Compute Shader/{}", brdfprof::targets::radv::aco_perfinfo::count_name(*c))))
            .collect(),
        "nvidia:sm_89" => {
            brdfprof::targets::nvidia::Class::ALL.iter().map(|c| get(format!("driver/SASS/{}", c.name()))).collect()
        }
        _ => brdfprof::targets::intel::Class::ALL.iter().map(|c| get(format!("driver/IGC/{}", c.name()))).collect(),
    }
}

/// The rule's terms of a row per evaluation (8 lights).
fn terms(target: &str, row: &serde_json::Value) -> Vec<(String, f64)> {
    let s = stats(row);
    let (schedule, lanes) = match target {
        "radv:navi21" => {
            (brdfprof::targets::radv::schedule(&s, AMD.iter().find(|f| f.family == "navi21").unwrap()).unwrap(), 64.0)
        }
        "nvidia:sm_89" => (Schedule::of(&s).unwrap(), 32.0),
        _ => (Schedule::of(&s).unwrap(), s["driver/IGC/SIMD Width"]),
    };
    schedule.scaled(1.0 / (lanes * 8.0)).terms()
}

#[test]
fn one_operation_more_moves_every_vendors_cost_the_way_its_code_does() {
    let dir = tempfile::tempdir().unwrap();
    let fixtures = crate::common::repo_root().join("tests/fixtures/brdf/pairs");
    let files = ["base", "plus-sqrt", "plus-division", "pow5", "mul5"]
        .map(|n| fixtures.join(format!("{n}.brdf")).to_str().unwrap().to_string());
    let mut extra = Vec::new();
    for f in &files {
        extra.extend(["--model", f.as_str()]);
    }
    let targets = ["radv:navi21", "nvidia:sm_89", "intel:gen12lp"];
    let all = inspect_json(dir.path(), "pairs", &targets, &extra, "ptxas statistics");
    let mut moved = 0;
    for (target, report) in targets.iter().zip(all["reports"].as_array().unwrap()) {
        let row = |m: &str| report["rows"].as_array().unwrap().iter().find(|r| r["model"] == m).unwrap().clone();
        let net = |m: &str| {
            report["cost"]["rows"].as_array().unwrap().iter().find(|r| r["model"] == m).unwrap()["net_cycles_per_eval"]
                .as_f64()
                .unwrap()
        };
        for (a, b) in PAIRS {
            let (ca, cb) = (classes(target, &row(a)), classes(target, &row(b)));
            let (ta, tb) = (terms(target, &row(a)), terms(target, &row(b)));
            let delta = net(b) - net(a);
            let what = format!("{target} {a} -> {b}: net {} -> {}, classes {ca:?} -> {cb:?}", net(a), net(b));
            if ca == cb && ta == tb {
                assert_eq!(delta, 0.0, "{what}: the same code, the same cost");
                continue;
            }
            if ca.iter().zip(&cb).all(|(x, y)| y >= x) {
                assert!(delta >= 0.0, "{what}: the code only adds instructions");
            }
            // The cost moves with the terms: up only where some term grew, down only where some shrank.
            let grew = ta.iter().zip(&tb).any(|(x, y)| y.1 > x.1);
            let shrank = ta.iter().zip(&tb).any(|(x, y)| y.1 < x.1);
            assert!((delta <= 0.0 || grew) && (delta >= 0.0 || shrank), "{what}: terms {ta:?} -> {tb:?}");
            moved += usize::from(delta != 0.0);
        }
        // The sqrt and the division each reach the compiler's code: one class of instructions (those that
        // compute them) grows by at least one per light, whatever the scheduler's waits do to another.
        for b in ["plus-sqrt", "plus-division"] {
            let added = classes(target, &row(b))
                .iter()
                .zip(classes(target, &row("base")))
                .map(|(y, x)| y - x)
                .fold(f64::NEG_INFINITY, f64::max);
            assert!(added >= 8.0, "{target} {b}: no class has 8 instructions more than base for 8 lights");
        }
    }
    assert!(moved >= 3, "the one-operation pairs moved only {moved} costs of 9");
}
