//! The writer tested as naga tests its back ends: SPIR-V in, C text out. Each `fixtures/NAME.comp` (the
//! source, for the reader and for build.sh) has its SPIR-V as the writer receives it (`NAME.spv`, after the
//! inlining passes; `NAME.plain.spv`, every function kept) and the expected text of each translation beside
//! it: `NAME.out` (the inlined module), `NAME.flat.out` (after `flatten`), `NAME.plain.out`, or `NAME.err`
//! where the writer must refuse the module. `BLESS=1` rewrites the expected files; review their diff.

use brdfprof_spirv_c::{Dialect, TexelFormat, TranslateOptions, Translation, flatten::flatten, translate};
use std::path::{Path, PathBuf};

fn fixtures() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures")
}

fn words(path: &Path) -> Vec<u32> {
    let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    assert_eq!(bytes.len() % 4, 0, "{}: not whole SPIR-V words", path.display());
    bytes.chunks_exact(4).map(|w| u32::from_le_bytes([w[0], w[1], w[2], w[3]])).collect()
}

/// The options a fixture asks for in its source: `// texel-format SET BINDING FORMAT` for each sampled texel
/// buffer (SPIR-V gives no format for those; the Vulkan view does).
fn options(comp: &str) -> TranslateOptions {
    let mut options = TranslateOptions::default();
    for line in comp.lines().filter_map(|l| l.strip_prefix("// texel-format ")) {
        let f: Vec<&str> = line.split_whitespace().collect();
        let format = match f[2] {
            "rgba32ui" => TexelFormat::Rgba32ui,
            "rgba32f" => TexelFormat::Rgba32f,
            "r32ui" => TexelFormat::R32ui,
            "r32f" => TexelFormat::R32f,
            other => panic!("texel-format {other}: not one the fixtures use"),
        };
        options.texel_formats.insert((f[0].parse().unwrap(), f[1].parse().unwrap()), format);
    }
    options
}

/// Everything a translation hands its users, as one text: the interface, the body, each dialect's entry.
fn render(t: &Translation) -> String {
    let mut out = format!("// local size {:?}, {:?}\n// ---- bindings ----\n", t.local_size, t.features);
    for b in &t.bindings {
        out += &format!("// {:?} {:?} {}\n", b.slot, b.kind, b.field);
    }
    out += "// ---- body ----\n";
    out += t.body();
    for d in [Dialect::Cuda, Dialect::OpenCl, Dialect::Host] {
        out += &format!("// ---- {} entry ----\n{}", d.name(), t.entry_wrapper(d));
    }
    out
}

/// `got` against the expected file (or written there under BLESS=1); the mismatch names the file and its
/// first differing line.
fn expect(path: &Path, got: &str, mismatches: &mut Vec<String>) {
    if std::env::var_os("BLESS").is_some() {
        std::fs::write(path, got).unwrap();
        return;
    }
    let want = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e} (BLESS=1 writes it)", path.display()));
    if want != got {
        let line = want
            .lines()
            .zip(got.lines())
            .position(|(a, b)| a != b)
            .unwrap_or_else(|| want.lines().count().min(got.lines().count()));
        mismatches.push(format!(
            "{}: differs from line {} on: expected {:?}, got {:?}",
            path.display(),
            line + 1,
            want.lines().nth(line),
            got.lines().nth(line)
        ));
    }
}

fn outcome(result: Result<Translation, brdfprof_spirv_c::TranslateError>) -> (&'static str, String) {
    match result {
        Ok(t) => ("out", render(&t)),
        Err(e) => ("err", format!("{e}\n")),
    }
}

#[test]
fn each_fixture_translates_to_its_expected_text() {
    let dir = fixtures();
    let mut names: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| e.unwrap().file_name().to_str()?.strip_suffix(".comp").map(String::from))
        .collect();
    names.sort();
    assert!(names.len() >= 4, "fixtures missing from {}", dir.display());
    let mut mismatches = Vec::new();
    for name in &names {
        let options = options(&std::fs::read_to_string(dir.join(format!("{name}.comp"))).unwrap());
        let inlined = words(&dir.join(format!("{name}.spv")));
        let plain = words(&dir.join(format!("{name}.plain.spv")));
        let flat = flatten(&inlined).map_err(|e| format!("{name}: flatten: {e:#}"));
        let runs = [("", translate(&inlined, &options)), (".plain", translate(&plain, &options))];
        for (suffix, result) in runs {
            let (ext, text) = outcome(result);
            expect(&dir.join(format!("{name}{suffix}.{ext}")), &text, &mut mismatches);
        }
        match flat {
            Ok(words) => {
                let (ext, text) = outcome(translate(&words, &options));
                expect(&dir.join(format!("{name}.flat.{ext}")), &text, &mut mismatches);
            }
            Err(e) => expect(&dir.join(format!("{name}.flat.err")), &format!("{e}\n"), &mut mismatches),
        }
    }
    assert!(
        mismatches.is_empty(),
        "translations that changed (BLESS=1 rewrites them; review the diff):\n{}",
        mismatches.join("\n")
    );
}

/// The expected files are only those a fixture produces, so that a renamed or removed fixture leaves no
/// stale expectation behind.
#[test]
fn every_expected_file_belongs_to_a_fixture() {
    let dir = fixtures();
    for e in std::fs::read_dir(&dir).unwrap() {
        let file = e.unwrap().file_name().to_string_lossy().to_string();
        let Some(stem) = [".out", ".err", ".spv"].iter().find_map(|x| file.strip_suffix(x)) else { continue };
        let name = stem.trim_end_matches(".plain").trim_end_matches(".flat");
        assert!(dir.join(format!("{name}.comp")).exists(), "{file}: no {name}.comp beside it");
    }
}

/// A fixture that is refused says so in every preparation, and one that translates does in every one.
#[test]
fn refusal_does_not_depend_on_the_preparation() {
    let dir = fixtures();
    for e in std::fs::read_dir(&dir).unwrap() {
        let file = e.unwrap().file_name().to_string_lossy().to_string();
        if let Some(name) = file.strip_suffix(".comp") {
            let kinds: Vec<bool> =
                ["", ".plain", ".flat"].iter().map(|s| dir.join(format!("{name}{s}.err")).exists()).collect();
            assert!(kinds.iter().all(|k| *k == kinds[0]), "{name}: refused in some preparations only: {kinds:?}");
        }
    }
}
