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
    cmd.args(["sweep", "--validate", "--size", "128x128", "--budget", "4", "--min-rounds", "9", "--out"])
        .arg(dir.path());
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
        let tied = rows
            .iter()
            .enumerate()
            .any(|(j, o)| j != i && get(o, "lo") <= get(r, "hi") && get(r, "lo") <= get(o, "hi"));
        assert_eq!(r["tied"].as_bool().unwrap(), tied);
        if i > 0 {
            let prev = &rows[i - 1];
            let key = |r: &Value| (r["rank"].as_u64().unwrap(), get(r, "median"));
            assert!(
                key(prev).0 < key(r).0 || key(prev).0 == key(r).0 && key(prev).1 <= key(r).1,
                "rows sorted by rank, then cost"
            );
        }
    }
    let row = |name: &str| rows.iter().find(|r| r["spec"] == name).unwrap();
    let exact = row("d=ggx,vis=smith-ggx-correlated,f=dielectric");
    assert!(rms(exact) < 1e-5, "the exact combination's error is rounding only: {}", rms(exact));
    assert!(rms(row("ggx")) > 100.0 * rms(exact), "Schlick and the joint approximation cost accuracy");
    assert!(row("ggx,precision=f16")["accuracy"]["numerical"]["max"].as_f64().unwrap() > 1e-3, "fp16 rounding shows");
}

/// A file that is NaN below roughness 0.25 and below N.V 0.4: finite on a sample set within its domain only.
fn cut_file(domain: &str) -> String {
    format!(
        "analytic\n::begin parameters\nfloat roughness 0 1 0.5\n::end parameters\n::begin brdfprof\nbind roughness=@roughness\n{domain}::end brdfprof\n\
         ::begin shader\nvec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y) {{ return vec3(0.1 * sqrt(roughness - 0.25) * sqrt(dot(N, V) - 0.4)); }}\n::end shader\n"
    )
}

fn sweep_json(dir: &std::path::Path, extra: &[&str]) -> Value {
    let out = dir.join(format!("out{}", std::fs::read_dir(dir).unwrap().count()));
    let mut cmd = common::brdfprof();
    cmd.current_dir(dir)
        // Accuracy is what these sweeps check: three timed rounds, not the budget's worth.
        .args(["sweep", "--validate", "--size", "16x16", "--budget", "20", "--min-rounds", "3", "--max-rounds", "3"])
        .arg("--out")
        .arg(&out)
        .args(extra);
    let r = cmd.output().unwrap();
    assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
    serde_json::from_str(&std::fs::read_to_string(common::device_file(&out, "sweep-", ".json")).unwrap()).unwrap()
}

#[test]
fn sweep_samples_its_domain_and_measures_every_model_against_a_chosen_reference() {
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("cut.brdf"), cut_file("")).unwrap();
    std::fs::write(dir.path().join("cut-declared.brdf"), cut_file("domain roughness 0.3 1\ndomain nov 0.5 1\n"))
        .unwrap();
    let correlated = "d=ggx,vis=smith-ggx-correlated,f=schlick";
    let models = ["--model", "cut.brdf", "--model", "ggx", "--model", correlated];
    let row = |s: &Value, name: &str| {
        s["rows"].as_array().unwrap().iter().find(|r| r["spec"].as_str().unwrap().starts_with(name)).unwrap().clone()
    };
    let nonfinite = |r: &Value| r["accuracy"]["vs_exact"]["nonfinite"].as_u64().unwrap();
    let rms = |r: &Value| r["accuracy"]["vs_exact"]["rms"].as_f64().unwrap();

    let plain = sweep_json(dir.path(), &models);
    assert!(nonfinite(&row(&plain, "cut")) > 0, "the default set reaches below the file's cut");
    assert!(row(&plain, "ggx")["accuracy"]["reference"].is_null(), "a spec against its own exact model by default");
    assert!(
        rms(&row(&plain, correlated)) > 1e-3,
        "the physical Fresnel counts Schlick's error: {}",
        rms(&row(&plain, correlated))
    );

    let mut args = models.to_vec();
    args.extend(["--roughness", "0.3..1", "--nov", "0.5..1", "--reference", correlated, "--exact-fresnel", "own"]);
    let chosen = sweep_json(dir.path(), &args);
    assert_eq!(nonfinite(&row(&chosen, "cut")), 0, "every sample within --roughness and --nov");
    assert!(
        chosen["sample_set"].as_str().unwrap().contains("roughness [0.3, 1], NoV [0.5, 1]"),
        "{}",
        chosen["sample_set"]
    );
    for r in chosen["rows"].as_array().unwrap() {
        assert_eq!(r["accuracy"]["reference"], correlated, "--reference applies to every model: {}", r["spec"]);
    }
    assert!(
        rms(&row(&chosen, correlated)) < 1e-5,
        "against itself with its own Fresnel only rounding is left: {}",
        rms(&row(&chosen, correlated))
    );
    assert!(rms(&row(&chosen, "ggx")) > 1e-3, "ggx's joint visibility approximation still shows");
    assert!(chosen["against"].as_str().unwrap().contains("own Fresnel"), "{}", chosen["against"]);

    let declared = sweep_json(dir.path(), &["--model", "cut-declared.brdf", "--model", "ggx"]);
    assert_eq!(nonfinite(&row(&declared, "cut-declared")), 0, "the file's declared domain bounds the set");
    assert!(declared["sample_set"].as_str().unwrap().contains("declared domain"), "{}", declared["sample_set"]);
    let mut crossed = vec!["--model", "cut-declared.brdf", "--model", "ggx", "--roughness", "0.2..0.3"];
    crossed.extend(["--nov", "0.5..1"]);
    assert!(
        nonfinite(&row(&sweep_json(dir.path(), &crossed), "cut-declared")) > 0,
        "--roughness overrides the declaration"
    );
}
