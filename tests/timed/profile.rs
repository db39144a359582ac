//! `brdfprof profile` with its defaults, twice, under the validation layer: each run finishes within two
//! minutes, every model's cost relative to ggx has a 95% CI narrower than +-10% of the ratio, and models
//! whose CIs do not overlap come in the same order in both runs. (Its own test binary, so that no other
//! test competes for the two cores while it measures.)

use crate::common;
use serde_json::Value;
use std::time::{Duration, Instant};

struct Run {
    /// (model, median, lo, hi) of the ratio to ggx.
    ratios: Vec<(String, f64, f64, f64)>,
}

fn profile(json: &std::path::Path) -> (Run, Duration) {
    let start = Instant::now();
    let out = common::brdfprof().args(["profile", "--validate", "--json"]).arg(json).output().unwrap();
    let elapsed = start.elapsed();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "profile failed: {stderr}");
    assert!(!stderr.contains("validation ["), "validation messages: {stderr}");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("| model") && stdout.contains("vs ggx"), "no table on stdout: {stdout}");
    let report: Value = serde_json::from_str(&std::fs::read_to_string(json).unwrap()).unwrap();
    let rows = report["rows"].as_array().unwrap();
    let labels = report["labels"].as_array().unwrap();
    let rounds = report["rounds"].as_u64().unwrap() as usize;
    let reps = report["reps_per_round"].as_u64().unwrap() as usize;
    // The raw data holds every repetition of every variant.
    let ns = report["raw"]["ns"].as_array().unwrap();
    assert_eq!(ns.len(), labels.len());
    for series in ns {
        assert_eq!(series.as_array().unwrap().len(), rounds);
        assert!(series.as_array().unwrap().iter().all(|r| r.as_array().unwrap().len() == reps));
    }
    assert!(report["provenance"]["device"]["name"].is_string());
    assert_eq!(report["workload"]["width"], 960);
    assert_eq!(report["workload"]["height"], 540);
    assert_eq!(report["workload"]["gbuffer"], "packed");
    assert!(report["provenance"]["cpu"]["family"].is_string() && report["provenance"]["cpu"]["features"].is_array());
    // Every model row says how much of its time the memory-only kernel takes.
    for r in rows.iter().filter(|r| !r["spec"].is_null()) {
        let share = r["harness_share"]["median"].as_f64().unwrap();
        assert!(share > 0.0 && share < 1.0, "harness share {share}");
    }
    let ratios = rows
        .iter()
        .filter(|r| !r["spec"].is_null())
        .map(|r| {
            let v = &r["vs_reference"];
            (
                r["model"].as_str().unwrap().to_string(),
                v["median"].as_f64().unwrap(),
                v["lo"].as_f64().unwrap(),
                v["hi"].as_f64().unwrap(),
            )
        })
        .collect();
    (Run { ratios }, elapsed)
}

#[test]
fn default_profile_is_fast_resolved_and_repeatable() {
    let _serial = crate::serial();
    let dir = tempfile::tempdir().unwrap();
    let (a, ta) = profile(&dir.path().join("a.json"));
    let (b, tb) = profile(&dir.path().join("b.json"));
    for (run, t) in [(&a, ta), (&b, tb)] {
        assert!(t < Duration::from_secs(120), "profile took {t:?}");
        for (model, median, lo, hi) in &run.ratios {
            assert!(brdfprof::brdf::THESIS_MODELS.contains(&model.as_str()));
            assert!((hi - lo) / 2.0 < 0.10 * median, "{model}: ratio {median} CI [{lo}, {hi}] is wider than +-10%");
        }
    }
    for (i, x) in a.ratios.iter().enumerate() {
        for y in &a.ratios[i + 1..] {
            let other = |name: &str| b.ratios.iter().find(|r| r.0 == name).unwrap().clone();
            let (bx, by) = (other(&x.0), other(&y.0));
            let separated_a = x.3 < y.2 || y.3 < x.2;
            let separated_b = bx.3 < by.2 || by.3 < bx.2;
            // Only a ranking both runs resolve must agree: two models within a few percent (blinn and burley
            // on lavapipe, 1.49-1.56x) resolve in one run and overlap in the next, and their point estimates
            // may then cross without either run being wrong.
            if separated_a && separated_b {
                assert_eq!(
                    x.1 < y.1,
                    bx.1 < by.1,
                    "{} and {} swapped order between runs: {x:?} {y:?} vs {bx:?} {by:?}",
                    x.0,
                    y.0
                );
            }
        }
    }
}

/// The protocol times every instance of a variant each round and keeps the faster: a variant whose second
/// instance does the work twice shows an instance spread near 2, and its times are the single-work instance's.
#[test]
fn protocol_keeps_the_faster_instance_and_reports_the_spread() {
    let _serial = crate::serial();
    use brdfprof::measure::gbuffer;
    use brdfprof::measure::protocol::{self, ProtocolOptions, Timed};
    use brdfprof::measure::workload::{Variant, Workload};

    struct Uneven<'g>(Variant<'g>);
    impl Timed for Uneven<'_> {
        fn instances(&self) -> usize {
            2
        }
        fn record(&self, cmd: &brdfprof::gpu::Commands, instance: usize) {
            for _ in 0..=instance {
                self.0.record(cmd, 0);
            }
        }
    }

    let gpu = common::gpu();
    let work = Workload::upload(
        &gpu,
        &gbuffer::synthetic(256, 256, gbuffer::GBufferFormat::Packed),
        &gbuffer::lights(8),
        None,
    )
    .unwrap();
    let ggx = brdfprof::model::Model::reference();
    let variants = [Uneven(Variant::new(&gpu, &work, Some(&ggx), brdfprof::kernels::embedded(), 1).unwrap())];
    let options = ProtocolOptions {
        min_rounds: 9,
        max_rounds: 9,
        reps: 3,
        budget: std::time::Duration::from_secs(60),
        started: std::time::Instant::now(),
        seed: 3,
    };
    let raw = protocol::measure(&gpu, &variants, &options, |_| false, |_| {}).unwrap();
    let spread = raw.instance_spread(0);
    assert!(spread > 1.5 && spread < 2.6, "twice the work should be about twice the time: {spread}");
    for (round, kept) in raw.ns[0].iter().enumerate() {
        let medians = &raw.instance_ns[0][round];
        assert_eq!(
            brdfprof::stats::median(kept),
            medians[0].min(medians[1]),
            "round {round} keeps the faster instance"
        );
    }
    common::assert_no_validation_messages(&gpu);
}

/// An engine's function returning f_s N.L (tests/fixtures/brdf/engine/engine-ggx.brdf, `returns f_nol`) costs
/// what the same maths written as BRDF Explorer's BRDF returning f_s costs: the net cost ratios' 95% CIs of
/// the two, interleaved in one run on lavapipe, overlap, or their medians are within 10% (no glue is timed:
/// brdfprof divides by N.L on the host).
#[test]
fn an_engine_entry_costs_what_its_twin_returning_f_costs() {
    let _serial = crate::serial();
    let dir = tempfile::tempdir().unwrap();
    let json = dir.path().join("p.json");
    let engine = common::repo_root().join("tests/fixtures/brdf/engine");
    let out = common::brdfprof()
        .args(["profile", "--validate", "--size", "512x512", "--json", json.to_str().unwrap(), "--model"])
        .arg(engine.join("engine-ggx.brdf"))
        .arg("--model")
        .arg(engine.join("engine-ggx-f.brdf"))
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success() && !stderr.contains("validation ["), "{stderr}");
    let report: Value = serde_json::from_str(&std::fs::read_to_string(json).unwrap()).unwrap();
    let ci = |name: &str| {
        let row = report["rows"]
            .as_array()
            .unwrap()
            .iter()
            .find(|r| r["model"] == name)
            .unwrap_or_else(|| panic!("no row {name}"));
        let r = &row["net_vs_reference"];
        (r["lo"].as_f64().unwrap(), r["median"].as_f64().unwrap(), r["hi"].as_f64().unwrap())
    };
    let (a, b) = (ci("engine-ggx"), ci("engine-ggx-f"));
    // The CIs overlap, or the medians are within 10% of each other: the two are the same products associated
    // differently (the engine form measured 2-6% cheaper here, 6% on a loaded machine), and a glue division
    // costs more (it moved Godot's function by 13-15% of ggx).
    let overlap = a.0 <= b.2 && b.0 <= a.2;
    assert!(
        overlap || (a.1 / b.1 - 1.0).abs() <= 0.10,
        "net cost vs ggx: engine form {a:?}, f form {b:?}: the CIs do not overlap and the medians differ by more than 10%"
    );
}
