//! `brdfprof report` opened in a real browser: Debian's headless Chromium (installed by `make setup`) loads the
//! page from file://, and the test fails on any console message, reads the DOM back after the page's script
//! ran and checks the figures shown are the JSON's, and checks a screenshot is not blank.

use crate::common;
use std::path::{Path, PathBuf};
use std::process::Command;

/// The reports of a default profile, sweep, stability and `inspect --device radv:all`, as committed.
const INPUTS: [&str; 4] = [
    "results/profile-llvmpipe.json",
    "results/sweep-llvmpipe.json",
    "results/stability-llvmpipe.json",
    "results/radv/inspect-radv-all.json",
];

fn chromium() -> PathBuf {
    let found = ["/usr/bin/chromium", "/usr/bin/chromium-browser"].into_iter().map(PathBuf::from).find(|p| p.exists());
    found.expect(
        "Chromium is not installed: run `make setup` (Debian package chromium); the report is tested in a real browser",
    )
}

/// Runs headless Chromium on `page` with `extra` arguments; returns (stdout, the console lines of stderr).
fn headless(page: &Path, profile: &Path, extra: &[&str]) -> (String, Vec<String>) {
    let out = Command::new(chromium())
        .args([
            "--headless",
            "--no-sandbox",
            "--disable-gpu",
            "--no-first-run",
            "--enable-logging=stderr",
            "--v=0",
            "--virtual-time-budget=3000",
        ])
        .arg(format!("--user-data-dir={}", profile.display()))
        .args(extra)
        .arg(format!("file://{}", page.display()))
        .output()
        .expect("chromium runs");
    assert!(out.status.success(), "chromium failed: {}", String::from_utf8_lossy(&out.stderr));
    let console =
        String::from_utf8_lossy(&out.stderr).lines().filter(|l| l.contains("CONSOLE")).map(str::to_owned).collect();
    (String::from_utf8_lossy(&out.stdout).into_owned(), console)
}

/// The `data-v` of column `col` in the table row keyed `row`, as the browser's DOM holds it.
fn shown(dom: &str, row: &str, col: &str) -> f64 {
    let start = dom.find(&format!("<tr data-row=\"{row}\">")).unwrap_or_else(|| panic!("no row {row} in the DOM"));
    let tr = &dom[start..start + dom[start..].find("</tr>").unwrap()];
    let at = tr
        .find(&format!("data-col=\"{col}\" data-v=\""))
        .unwrap_or_else(|| panic!("no {col} figure in row {row}: {tr}"));
    let v = &tr[at + col.len() + 20..];
    v[..v.find('"').unwrap()].parse().unwrap()
}

/// The number in attribute `name` of the element that starts at `at`.
fn attr_at(dom: &str, at: usize, name: &str) -> Option<f64> {
    let tag = &dom[at..at + dom[at..].find('>').unwrap()];
    let v = &tag[tag.find(&format!(" {name}=\""))? + name.len() + 3..];
    v[..v.find('"').unwrap()].parse().ok()
}

/// What page.js measured in Chromium at 1400 px: no two text boxes of any chart, polar plot or heat map
/// overlap; the summary table fits the page; every heat map carries its colour scale and value axes.
fn readable_at_1400_px(dom: &str) {
    let svgs: Vec<usize> = dom.match_indices("<svg ").map(|(i, _)| i).collect();
    assert!(svgs.len() > 20, "{} pictures", svgs.len());
    for &i in &svgs {
        let overlaps = attr_at(dom, i, "data-overlaps").expect("page.js measured every picture");
        let tag = &dom[i..i + dom[i..].find('>').unwrap()];
        assert_eq!(overlaps, 0.0, "text boxes overlap in {tag}");
    }
    let labelled = svgs.iter().filter(|&&i| attr_at(dom, i, "data-texts").unwrap_or(0.0) > 0.0).count();
    assert_eq!(labelled, svgs.len(), "every picture has text (titles, axes or labels) that was measured");
    let page = attr_at(dom, dom.find("<body").unwrap(), "data-page-width").unwrap();
    let summary = dom.find("<section id=\"summary\"").unwrap();
    let table = summary + dom[summary..].find("<table").unwrap();
    let width = attr_at(dom, table, "data-width").unwrap();
    assert!(width <= page, "the summary table is {width} px wide on a {page} px page");
    let heat: Vec<&str> = dom
        .match_indices("<svg class=\"heatmap\"")
        .map(|(i, _)| &dom[i..i + dom[i..].find("</svg>").unwrap()])
        .collect();
    assert!(!heat.is_empty(), "the stability report's heat maps");
    for h in heat {
        assert!(
            h.contains("<linearGradient") && h.contains("bad values per cell") && h.contains(">roughness<"),
            "a heat map without its scale"
        );
    }
}

fn json(path: &str) -> serde_json::Value {
    serde_json::from_str(&std::fs::read_to_string(common::repo_root().join(path)).unwrap()).unwrap()
}

#[test]
fn a_report_of_profile_sweep_inspect_and_stability_opens_in_chromium_with_the_jsons_numbers() {
    let dir = tempfile::tempdir().unwrap();
    let page = dir.path().join("report.html");
    let mut args = vec!["report".to_string()];
    args.extend(INPUTS.iter().map(|p| common::repo_root().join(p).display().to_string()));
    args.extend(["--out".into(), page.display().to_string()]);
    common::run(&args.iter().map(String::as_str).collect::<Vec<_>>()).ok();
    let size = std::fs::metadata(&page).unwrap().len();
    assert!(size < 5 << 20, "the report is {size} bytes, over 5 MB");

    let (dom, console) = headless(&page, &dir.path().join("profile"), &["--dump-dom", "--window-size=1400,900"]);
    assert!(console.is_empty(), "console messages:\n{}", console.join("\n"));
    assert!(dom.contains("data-ready=\"1\""), "the page's script did not finish");
    assert!(!dom.contains("src=\"http") && !dom.contains("href=\"http"), "the page loads nothing from the network");
    readable_at_1400_px(&dom);

    let profile = json(INPUTS[0]);
    let rows = profile["rows"].as_array().unwrap();
    assert!(!rows.is_empty());
    for r in rows {
        let key = format!("profile0/{}/{}", r["lights"], r["model"].as_str().unwrap());
        assert_eq!(shown(&dom, &key, "ns"), r["ns_per_eval"]["median"].as_f64().unwrap(), "{key}");
    }
    let sweep = json(INPUTS[1]);
    for r in sweep["rows"].as_array().unwrap() {
        // Rows are keyed by the input's position among the report's inputs (the sweep is the second).
        let key = format!("sweep1/{}", r["label"].as_str().unwrap());
        assert_eq!(shown(&dom, &key, "ns"), r["ns_per_eval"]["median"].as_f64().unwrap(), "{key}");
        if let Some(rms) = r["accuracy"]["vs_exact"]["rms"].as_f64() {
            assert_eq!(shown(&dom, &key, "rms"), rms, "{key}");
        }
    }

    let shot = dir.path().join("shot.png");
    headless(
        &page,
        &dir.path().join("profile"),
        &[&format!("--screenshot={}", shot.display()), "--window-size=1280,900"],
    );
    let img = image::open(&shot).unwrap().to_rgb8();
    let colours: std::collections::HashSet<[u8; 3]> = img.pixels().map(|p| p.0).collect();
    assert!(colours.len() > 64, "the screenshot has {} colours: blank", colours.len());
}

/// The page a user opens after a profile, the default sweep, the default stability run and the 23-device
/// inspect behind README's headline table, in Chromium at 1400 x 900: at most 12 screens tall; the summary
/// first, ending within the first screen, with stability's verdict as its first figure column and the
/// failures in it; long sections folded; no table wider than its section without its first column in view;
/// no two text boxes of any picture overlapping (folded pictures measured open).
#[test]
fn the_four_report_is_taken_in_at_a_glance() {
    let dir = tempfile::tempdir().unwrap();
    let page = dir.path().join("report.html");
    let inputs = [INPUTS[0], INPUTS[1], INPUTS[2], "results/targets/inspect-thesis.json"];
    let mut args = vec!["report".to_string()];
    args.extend(inputs.iter().map(|p| common::repo_root().join(p).display().to_string()));
    args.extend(["--out".into(), page.display().to_string()]);
    let r = common::run(&args.iter().map(String::as_str).collect::<Vec<_>>());
    assert_eq!(r.code, Some(0), "{}", r.stderr);

    let (dom, console) = headless(&page, &dir.path().join("profile"), &["--dump-dom", "--window-size=1400,900"]);
    assert!(console.is_empty(), "console messages:\n{}", console.join("\n"));
    readable_at_1400_px(&dom);
    let body = dom.find("<body").unwrap();
    let height = attr_at(&dom, body, "data-page-height").expect("page.js measured the page");
    assert!(height <= 12.0 * 900.0, "the page is {height} px tall: {:.1} screens of 900", height / 900.0);
    let unsticky = attr_at(&dom, body, "data-wide-unsticky").expect("page.js measured the tables");
    assert_eq!(unsticky, 0.0, "wide tables whose first column scrolls away: {}", &dom[body..body + 400]);

    let first = dom.find("<section id=").unwrap();
    assert!(dom[first..].starts_with("<section id=\"summary\""), "the summary comes first");
    let bottom = attr_of(&dom, "<section id=\"summary\"", "data-bottom");
    assert!(bottom <= 900.0, "the summary ends at {bottom} px: below the first screen of 900");
    let summary = &dom[first..first + dom[first..].find("</section>").unwrap()];
    let headers: Vec<&str> = summary
        .match_indices("<th ")
        .map(|(i, _)| {
            let h = &summary[i..];
            let open = h.find('>').unwrap() + 1;
            &h[open..h.find("</th>").unwrap()]
        })
        .collect();
    assert_eq!(headers.get(1).copied(), Some("stability"), "stability's verdict first: {headers:?}");
    let shown_rows = &summary[..summary.find("<details").unwrap_or(summary.len())];
    assert!(shown_rows.contains("FAIL ("), "failing models on the first screen");
    for vendor in ["AMD", "NVIDIA", "Intel", "Qualcomm", "Arm"] {
        assert!(headers.iter().any(|h| h.starts_with(vendor)), "a column for {vendor}: {headers:?}");
    }
    let folds = dom.matches("<details class=\"fold\"").count();
    assert!(folds >= 6, "{folds} folded sections");
    // The failures grouped by cause, each cause naming how many specs fail so.
    assert!(dom.contains("The failures by cause") && dom.contains("data-row=\"cause2/0\""), "failures by cause");
    // The rank correlations as a matrix, uncertain ones greyed.
    assert!(dom.contains("<table class=\"matrix\""), "the rank correlation matrix");
}

/// A `brdfprof diff` result in the report (from `report d.json` and from `diff --html`): in Chromium, every
/// channel's max/RMS, every worst row's difference and every histogram count is the JSON's, and the picture is
/// there.
#[test]
fn a_diff_report_shows_the_jsons_numbers_in_chromium() {
    let dir = tempfile::tempdir().unwrap();
    let (d, from_diff, from_report) =
        (dir.path().join("d.json"), dir.path().join("diff.html"), dir.path().join("report.html"));
    let path = |p: &Path| p.display().to_string();
    let r = common::run(&[
        "diff",
        "--model",
        "ggx,name=base",
        "--model",
        "filament-high",
        "--samples",
        "2000",
        "--worst",
        "5",
        "--json",
        &path(&d),
        "--html",
        &path(&from_diff),
    ]);
    assert!(r.code == Some(0), "{}", r.stderr);
    common::run(&["report", &path(&d), "--out", &path(&from_report)]).ok();
    let j: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&d).unwrap()).unwrap();
    for (k, page) in [from_diff, from_report].iter().enumerate() {
        let (dom, console) = headless(page, &dir.path().join(format!("profile{k}")), &["--dump-dom"]);
        assert!(console.is_empty(), "console messages:\n{}", console.join("\n"));
        assert!(dom.contains("data-ready=\"1\""), "the page's script did not finish");
        assert!(
            dom.contains("B = <code>filament-high</code> against A = <code>base</code>"),
            "the models by their labels"
        );
        for c in j["difference"]["channels"].as_array().unwrap() {
            let key = format!("diff0/{}", c["channel"].as_str().unwrap());
            for col in ["max_rel", "rms_rel", "max_abs", "rms_abs"] {
                assert_eq!(shown(&dom, &key, col), c[col].as_f64().unwrap(), "{key} {col}");
            }
        }
        let worst = j["worst"].as_array().unwrap();
        assert_eq!(worst.len(), 5);
        for (w, row) in worst.iter().enumerate() {
            assert_eq!(shown(&dom, &format!("diff0/worst{w}"), "rel"), row["rel"].as_f64().unwrap(), "worst row {w}");
            assert_eq!(
                shown(&dom, &format!("diff0/worst{w}"), "index"),
                row["index"].as_f64().unwrap(),
                "worst row {w}"
            );
        }
        for (b, count) in j["histogram"]["counts"].as_array().unwrap().iter().enumerate() {
            assert_eq!(shown(&dom, &format!("diff0/bin{b}"), "rows"), count.as_f64().unwrap(), "bin {b}");
        }
        assert!(
            dom.contains("src=\"data:image/png;base64,")
                && dom.contains("alt=\"B = filament-high against A = base: lit spheres"),
            "the picture of B against A"
        );
    }
}

/// A diff whose `.brdf` model is gone since it ran is still drawn: its tables are the saved diff's, and the
/// picture says why it is not drawn (exit 0, a warning naming the file).
#[test]
fn a_report_of_a_diff_whose_brdf_file_is_gone_says_why_its_picture_is_missing() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let model = d.join("mine.brdf");
    std::fs::copy(common::repo_root().join("examples/brdf/ggx.brdf"), &model).unwrap();
    let spec = format!("{},roughness=@roughness,f0=@f0", model.display());
    common::run_in(d, &["diff", "--model", "ggx", "--model", &spec, "--samples", "200", "--json", "d.json"]).ok();
    std::fs::remove_file(&model).unwrap();
    let r = common::run_in(d, &["report", "d.json", "--out", "r.html"]).ok();
    assert!(r.stderr.contains("not drawn") && r.stderr.contains("mine.brdf"), "{}", r.stderr);
    let page = std::fs::read_to_string(d.join("r.html")).unwrap();
    assert!(page.contains("Picture not drawn: a model cannot be read now"), "the card says why");
    assert!(page.contains("diff0/r") && page.contains("mine.brdf"), "the saved tables are drawn");
}

/// Counts read from a saved stability report are summed without wrapping: two cells of u32::MAX bad values
/// make a caption of 8589934590, not 4294967294.
#[test]
fn a_stability_reports_huge_counts_do_not_wrap_in_the_heat_map_caption() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let mut st = json("results/stability-llvmpipe.json");
    // `bad_cells` as written: sparse [roughness index, NoV index, count] triples.
    let spec = st["specs"].as_array_mut().unwrap().iter_mut().find(|s| s["bad_cells"].is_array());
    spec.expect("a spec with a heat map")["bad_cells"] = serde_json::json!([[0, 0, u32::MAX], [1, 1, u32::MAX]]);
    std::fs::write(d.join("st.json"), st.to_string()).unwrap();
    common::run_in(d, &["report", "st.json", "--no-gpu", "--out", "r.html"]).ok();
    let page = std::fs::read_to_string(d.join("r.html")).unwrap();
    assert!(page.contains(&format!("{} bad values", 2 * u64::from(u32::MAX))), "the total, summed wide");
}

/// The console check can fail: a page that logs an error is caught.
#[test]
fn a_console_error_is_seen() {
    let dir = tempfile::tempdir().unwrap();
    let page = dir.path().join("bad.html");
    std::fs::write(
        &page,
        "<!doctype html><html><body><script>console.error('brdfprof-test-error');</script></body></html>",
    )
    .unwrap();
    let (_, console) = headless(&page, &dir.path().join("profile"), &["--dump-dom"]);
    assert!(console.iter().any(|l| l.contains("brdfprof-test-error")), "console lines: {console:?}");
}

/// The attribute `attr` of the element that starts with `open` in the DOM, as a number.
fn attr_of(dom: &str, open: &str, attr: &str) -> f64 {
    let start = dom.find(open).unwrap_or_else(|| panic!("no {open} in the DOM"));
    let tag = &dom[start..start + dom[start..].find('>').unwrap()];
    let at = tag.find(&format!("{attr}=\"")).unwrap_or_else(|| panic!("no {attr} on {tag}")) + attr.len() + 2;
    tag[at..at + tag[at..].find('"').unwrap()].parse().unwrap()
}

/// The page a team would show. A profile, a diff of four models against a reference and a stability
/// run with `--unguarded` (each guard variant a spec of its own): in Chromium at 1280x900 the summary (one row
/// per model) is the first section and fits the first screen, provenance is folded at the end, each model has
/// one card however many reports name it (guard variants none), the lobes of all models are overlaid, and
/// stability's cells read as the Markdown's.
#[test]
fn the_report_opens_on_a_one_screen_summary_with_one_card_per_model() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let path = |p: &Path| p.display().to_string();
    let engine = |name: &str| path(&common::repo_root().join("tests/fixtures/brdf/engine").join(name));
    let (set, page) = (d.join("set.json"), d.join("report.html"));
    let reference = "d=ggx,vis=smith-ggx-correlated,f=schlick";
    let r = common::run(&[
        "diff",
        "--reference",
        reference,
        "--model",
        "filament-high",
        "--model",
        "ggx",
        "--model",
        &engine("engine-ggx.brdf"),
        "--model",
        &engine("unclamped-ggx.brdf"),
        "--samples",
        "1000",
        "--json",
        &path(&set),
    ]);
    assert_eq!(r.code, Some(0), "{}", r.stderr);
    let st = common::run(&[
        "stability",
        "--unguarded",
        "--no-energy",
        "--model",
        "ggx",
        "--model",
        &engine("unclamped-ggx.brdf"),
        "--out",
        &path(d),
    ]);
    assert_eq!(st.code, Some(1), "the unclamped file fails: {}", st.stderr);
    let stability = common::device_file(d, "stability-", ".json");
    let profile = common::repo_root().join(INPUTS[0]);
    common::run(&["report", &path(&profile), &path(&set), &path(&stability), "--out", &path(&page)]).ok();

    let (dom, console) = headless(&page, &d.join("profile"), &["--dump-dom", "--window-size=1280,900"]);
    assert!(console.is_empty(), "console messages:\n{}", console.join("\n"));
    let first = dom.find("<section id=").unwrap();
    assert!(dom[first..].starts_with("<section id=\"summary\""), "the summary comes first");
    let bottom = attr_of(&dom, "<section id=\"summary\"", "data-bottom");
    assert!(bottom <= 900.0, "the summary ends at {bottom} px: below the first screen of 900");
    let provenance = dom.find("<section id=\"provenance\"").unwrap();
    assert!(
        dom[provenance..].contains("<details>") && provenance > dom.find("<section id=\"diff\"").unwrap(),
        "provenance folded, last"
    );

    let rows: Vec<&str> = dom
        .match_indices("<tr data-row=\"summary/")
        .map(|(i, _)| &dom[i + 22..i + 22 + dom[i + 22..].find('"').unwrap()])
        .collect();
    let mut unique = rows.clone();
    unique.sort();
    unique.dedup();
    assert_eq!(unique.len(), rows.len(), "a model named twice in the summary: {rows:?}");
    for model in ["ggx", "blinn", "filament-high", "engine-ggx", "unclamped-ggx"] {
        assert!(rows.contains(&model), "{model} has no summary row: {rows:?}");
    }
    let cards: Vec<&str> = dom
        .match_indices("<div class=\"model\" data-model=\"")
        .map(|(i, m)| &dom[i + m.len()..i + m.len() + dom[i + m.len()..].find('"').unwrap()])
        .collect();
    let mut distinct = cards.clone();
    distinct.sort();
    distinct.dedup();
    assert_eq!(distinct.len(), cards.len(), "one card per model: {cards:?}");
    assert!(cards.iter().all(|c| !c.contains("guards=")), "no card for a guard variant: {cards:?}");
    // Every summary row's model, and the reference the diff drew against.
    assert_eq!(cards.len(), rows.len() + 1, "cards {cards:?} for rows {rows:?}");
    assert!(cards.contains(&reference), "{cards:?}");
    assert!(dom.contains("data-model=\"overlay\"") && dom.contains("All models overlaid"), "the lobes overlaid");
    let summary = &dom[first..first + dom[first..].find("</section>").unwrap()];
    assert!(summary.contains("FAIL (") && summary.contains(">ok<"), "stability's verdict per model");
    assert!(dom.contains("(no twin)"), "the stability table's cells read as the Markdown's");
}
