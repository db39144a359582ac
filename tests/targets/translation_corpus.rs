//! Every BRDF Explorer-style file of tests/fixtures/brdf/corpus/ (in two halves, two tests) gets NVIDIA
//! (sm_89) and Intel (gen12lp) costs from `inspect`, its translation judged against its own f64 evaluation: the
//! Vulkan kernel on the test device and the fp32 translation within the Vulkan precision bound of every value the
//! rules bound, and most values bound (a check that judged nothing would pass anything).

use crate::common;
use crate::compile_only;

/// Each kernel's figures from a row's `translation` note (`Agreement::summary`): (kernel, Vulkan's worst, the
/// translation's worst, values unbounded, values).
fn judged(note: &str) -> Vec<(&'static str, f64, f64, usize, usize)> {
    let mut out = Vec::new();
    for kernel in ["eval", "shade"] {
        let Some(at) = note.find(&format!("{kernel}: Vulkan at ")) else { continue };
        let part = &note[at..];
        let after = |what: &str| part.split(what).nth(1).unwrap_or("");
        let number = |what: &str| after(what).split(' ').next().and_then(|x| x.parse::<f64>().ok()).unwrap_or(f64::NAN);
        let counts: Vec<usize> = after("; ")
            .split(" values unbounded")
            .next()
            .unwrap_or("")
            .split(" of ")
            .filter_map(|x| x.trim().parse().ok())
            .collect();
        out.push((
            kernel,
            number("Vulkan at "),
            number("fp32 translation at "),
            counts.first().copied().unwrap_or(usize::MAX),
            counts.get(1).copied().unwrap_or(0),
        ));
    }
    out
}

/// The corpus files of one half (by their index in name order, so that both halves mix short and long files):
/// the two halves are two tests, whose translation checks (one model after another) then run side by side.
fn corpus_half(half: usize) -> Vec<String> {
    let corpus = common::repo_root().join("tests/fixtures/brdf/corpus");
    let mut files: Vec<String> = std::fs::read_dir(&corpus)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "brdf"))
        .map(|p| p.display().to_string())
        .collect();
    files.sort();
    assert_eq!(files.len(), 40);
    files.into_iter().enumerate().filter(|(i, _)| i % 2 == half).map(|(_, f)| f).collect()
}

#[test]
fn every_corpus_file_of_the_first_half_is_priced_on_sm_89_and_gen12lp_against_its_f64_evaluation() {
    priced_against_f64(&corpus_half(0));
}

#[test]
fn every_corpus_file_of_the_second_half_is_priced_on_sm_89_and_gen12lp_against_its_f64_evaluation() {
    priced_against_f64(&corpus_half(1));
}

fn priced_against_f64(files: &[String]) {
    let dir = tempfile::tempdir().unwrap();
    let mut extra: Vec<&str> = Vec::new();
    for f in files {
        extra.extend(["--model", f.as_str()]);
    }
    let report =
        compile_only::inspect_json(dir.path(), "corpus", &["nvidia:sm_89", "intel:gen12lp"], &extra, "IGC statistics");
    let reports = report["reports"].as_array().unwrap();
    assert_eq!(reports.len(), 2);
    for r in reports {
        let target = r["provenance"]["target"].as_str().unwrap();
        let costs = r["cost"]["rows"].as_array().unwrap();
        let priced: Vec<&str> = costs.iter().map(|c| c["model"].as_str().unwrap()).collect();
        // The report states the harness share: the memory-only kernel's share of each kernel's cost.
        let harness = r["section_notes"]["harness"].as_str().unwrap_or_default();
        assert!(harness.starts_with("Harness share on"), "{target}: {harness}");
        for f in files {
            let stem = std::path::Path::new(f).file_stem().unwrap().to_str().unwrap();
            assert!(priced.contains(&stem), "{target}: {stem} has no cost ({priced:?})");
            assert!(harness.contains(&format!("{stem} ")), "{target}: {stem} has no harness share: {harness}");
        }
        assert!(priced.contains(&"baseline"), "{target}: the memory-only kernel");
        assert!(costs.iter().all(|c| c["cycles_per_eval"].as_f64().unwrap() > 0.0), "{target}");
        for row in r["rows"].as_array().unwrap() {
            let note = row["notes"]["translation"]
                .as_str()
                .unwrap_or_else(|| panic!("{target} {}: no translation check", row["model"]));
            let kernels = judged(note);
            assert_eq!(kernels.len(), if row["model"] == "baseline" { 1 } else { 2 }, "{note}");
            for (kernel, vulkan, translation, unbounded, values) in kernels {
                assert!(vulkan <= 1.0 && translation <= 1.0, "{target} {} {kernel}: {note}", row["model"]);
                assert!(
                    values > 0 && 2 * unbounded < values,
                    "{target} {} {kernel}: {unbounded} of {values} values unbounded",
                    row["model"]
                );
            }
        }
    }
}
