//! `brdfprof sweep` on a small set: writes its Markdown, JSON and PNG; its ranks and Pareto flags follow from
//! its own figures; the exact combination (GGX, exact correlated Smith, exact dielectric) has no approximation
//! error beyond fp32 rounding while the Schlick/joint-approx preset has some.

use crate::common;
use serde_json::Value;

#[test]
fn small_sweep_is_consistent() {
    let dir = tempfile::tempdir().unwrap();
    let models = ["ggx", "cook-torrance", "d=ggx,vis=smith-ggx-correlated,f=dielectric", "ggx,precision=f16"];
    let mut cmd = common::brdfprof();
    cmd.args(["sweep", "--validate", "--size", "128x128", "--budget", "4", "--min-rounds", "9", "--out"]).arg(dir.path());
    for m in models {
        cmd.args(["--model", m]);
    }
    let out = cmd.output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{stderr}");
    assert!(!stderr.contains("validation ["), "{stderr}");
    let stem = common::device_file(dir.path(), "sweep-", ".md").with_extension("");
    let md = std::fs::read_to_string(stem.with_extension("md")).unwrap();
    assert!(md.contains("| rank") && md.contains("Pareto"));
    let png = image::open(stem.with_extension("png")).unwrap();
    assert_eq!((png.width(), png.height()), (2400, 1600));
    let report: Value = serde_json::from_str(&std::fs::read_to_string(stem.with_extension("json")).unwrap()).unwrap();
    let rows = report["rows"].as_array().unwrap();
    assert_eq!(rows.len(), models.len());
    let get = |r: &Value, k: &str| r["cost_vs_fastest"][k].as_f64().unwrap();
    let rms = |r: &Value| r["accuracy"]["vs_exact"]["rms"].as_f64().unwrap();
    for (i, r) in rows.iter().enumerate() {
        let below = rows.iter().filter(|o| get(o, "hi") < get(r, "lo")).count();
        assert_eq!(r["rank"].as_u64().unwrap() as usize, 1 + below, "rank of {}", r["spec"]);
        let dominated = rows.iter().any(|o| {
            let (c, e, c2, e2) = (get(r, "median"), rms(r), get(o, "median"), rms(o));
            c2 <= c && e2 <= e && (c2 < c || e2 < e)
        });
        assert_eq!(r["pareto"].as_bool().unwrap(), !dominated, "Pareto flag of {}", r["spec"]);
        let tied = rows.iter().enumerate().any(|(j, o)| j != i && get(o, "lo") <= get(r, "hi") && get(r, "lo") <= get(o, "hi"));
        assert_eq!(r["tied"].as_bool().unwrap(), tied);
        if i > 0 {
            let prev = &rows[i - 1];
            let key = |r: &Value| (r["rank"].as_u64().unwrap(), get(r, "median"));
            assert!(key(prev).0 < key(r).0 || key(prev).0 == key(r).0 && key(prev).1 <= key(r).1, "rows sorted by rank, then cost");
        }
    }
    let row = |name: &str| rows.iter().find(|r| r["spec"] == name).unwrap();
    let exact = row("d=ggx,vis=smith-ggx-correlated,f=dielectric");
    assert!(rms(exact) < 1e-5, "the exact combination's error is rounding only: {}", rms(exact));
    assert!(rms(row("ggx")) > 100.0 * rms(exact), "Schlick and the joint approximation cost accuracy");
    assert!(row("ggx,precision=f16")["accuracy"]["numerical"]["max"].as_f64().unwrap() > 1e-3, "fp16 rounding shows");
}
