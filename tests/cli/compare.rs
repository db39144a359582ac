//! `brdfprof compare`: saved profile and inspect reports merged into one cost table, JSON and PNG; reports of
//! different kernels are refused by their SPIR-V hashes.

use crate::common::run_in;
use std::path::Path;

fn json(path: &Path) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

#[test]
fn compare_merges_profile_and_inspect_reports_and_refuses_other_kernels() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    run_in(
        d,
        &["inspect", "--no-callgrind", "--device", "radv:navi21", "--json", "navi21.json", "--markdown", "navi21.md"],
    )
    .ok();
    run_in(
        d,
        &[
            "inspect",
            "--no-callgrind",
            "--device",
            "radv:vega10",
            "--device",
            "radv:gfx1100",
            "--json",
            "two.json",
            "--markdown",
            "two.md",
        ],
    )
    .ok();
    run_in(d, &["profile", "--size", "32x32", "--min-rounds", "2", "--max-rounds", "2", "--json", "profile.json"]).ok();
    let out = run_in(
        d,
        &[
            "compare",
            "profile.json",
            "navi21.json",
            "two.json",
            "--json",
            "c.json",
            "--markdown",
            "c.md",
            "--chart",
            "c.png",
        ],
    )
    .ok();
    assert!(out.stdout.contains("Rank correlation between devices"), "{}", out.stdout);
    let table = json(&d.join("c.json"));
    let names: Vec<&str> = table["columns"].as_array().unwrap().iter().map(|c| c["name"].as_str().unwrap()).collect();
    assert_eq!(names.len(), 4, "{names:?}");
    assert!(
        names[0].ends_with("ns/eval")
            && names[1..] == ["navi21 cycles/eval", "vega10 cycles/eval", "gfx1100 cycles/eval"],
        "{names:?}"
    );
    assert_eq!(table["correlations"].as_array().unwrap().len(), 6);
    assert_eq!(table["models"].as_array().unwrap().len(), 5, "four thesis models and the memory-only kernel");
    for c in table["columns"].as_array().unwrap() {
        for m in ["ggx", "blinn", "cook-torrance", "burley"] {
            assert!(c["net"][m].as_f64().is_some(), "{} has no net cost of {m}", c["name"]);
        }
    }
    assert_eq!(&std::fs::read(d.join("c.png")).unwrap()[..8], b"\x89PNG\r\n\x1a\n");

    // The same models from other kernels (a copy of glsl/ with D_Ggx changed): refused, naming the model.
    let glsl = d.join("glsl");
    brdfprof::shaders::write_glsl_tree(&glsl).unwrap();
    let brdf = glsl.join("brdf.glsl");
    let source = std::fs::read_to_string(&brdf).unwrap();
    let at = source.find("real D_Ggx(").unwrap();
    let ret = at + source[at..].find("return ").unwrap() + "return ".len();
    std::fs::write(&brdf, format!("{}real(1.0001) * {}", &source[..ret], &source[ret..])).unwrap();
    run_in(
        d,
        &[
            "inspect",
            "--no-callgrind",
            "--device",
            "radv:navi21",
            "--glsl",
            "glsl",
            "--model",
            "ggx",
            "--json",
            "edited.json",
            "--markdown",
            "edited.md",
        ],
    )
    .ok();
    run_in(d, &["compare", "navi21.json", "edited.json", "--json", "x.json", "--markdown", "x.md", "--chart", "x.png"])
        .fails(2, "the kernels differ: ");
    assert!(run_in(d, &["compare", "navi21.json", "edited.json"]).stderr.contains("`ggx` ("));
    // A profile report without kernel hashes (an older brdfprof's), and a file that is no report.
    let mut old = json(&d.join("profile.json"));
    old.as_object_mut().unwrap().remove("kernel_sha256");
    std::fs::write(d.join("old.json"), old.to_string()).unwrap();
    run_in(d, &["compare", "old.json", "navi21.json", "--json", "x.json", "--markdown", "x.md", "--chart", "x.png"])
        .fails(2, "old.json: a profile report that records no kernel hashes");
    std::fs::write(d.join("junk.json"), "{\"rows\": 3}").unwrap();
    run_in(d, &["compare", "junk.json", "--json", "x.json", "--markdown", "x.md", "--chart", "x.png"])
        .fails(2, "junk.json: not a brdfprof inspect report");
    assert!(!d.join("x.json").exists() && !d.join("x.png").exists());
    // The same report twice (by name, or a copy) correlates perfectly with itself: refused.
    run_in(
        d,
        &["compare", "navi21.json", "./navi21.json", "--json", "x.json", "--markdown", "x.md", "--chart", "x.png"],
    )
    .fails(2, "./navi21.json is the same report as navi21.json");
    std::fs::copy(d.join("profile.json"), d.join("copy.json")).unwrap();
    run_in(d, &["compare", "profile.json", "copy.json", "--json", "x.json", "--markdown", "x.md", "--chart", "x.png"])
        .fails(2, "copy.json is the same report as profile.json");
    // Figures no measurement gives: a negative cost, a net cost above the gross one.
    let mut edited = json(&d.join("profile.json"));
    edited["rows"][0]["ns_per_eval"]["median"] = serde_json::json!(-1.0);
    std::fs::write(d.join("negative.json"), edited.to_string()).unwrap();
    run_in(
        d,
        &["compare", "negative.json", "navi21.json", "--json", "x.json", "--markdown", "x.md", "--chart", "x.png"],
    )
    .fails(2, "cost -1; not a figure a measurement gives");
    let mut edited = json(&d.join("navi21.json"));
    let gross = edited["cost"]["rows"][0]["cycles_per_eval"].as_f64().unwrap();
    edited["cost"]["rows"][0]["net_cycles_per_eval"] = serde_json::json!(gross * 2.0);
    std::fs::write(d.join("net.json"), edited.to_string()).unwrap();
    run_in(d, &["compare", "profile.json", "net.json", "--json", "x.json", "--markdown", "x.md", "--chart", "x.png"])
        .fails(2, "not a figure a measurement gives");
    // An output that is one of the reports is refused.
    run_in(
        d,
        &["compare", "profile.json", "navi21.json", "--json", "profile.json", "--markdown", "x.md", "--chart", "x.png"],
    )
    .fails(2, "--json profile.json: is the same file as FILE profile.json");
    assert!(!d.join("x.json").exists() && !d.join("x.png").exists());
}
