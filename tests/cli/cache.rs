//! The kernel cache cannot lie: its key covers every file glslang includes (an edited glsl/ copy is not
//! served stale SPIR-V), and an entry whose bytes changed in any way is detected, discarded, recompiled and
//! replaced with a warning naming it, so that a result is the same as without the cache. `brdfprof cache
//! show|clear` lists and removes brdfprof's entries only.

use crate::common::{self, Run, brdfprof};
use brdfprof::brdf::samples;
use rand::{Rng, SeedableRng};
use std::path::{Path, PathBuf};

fn example(name: &str) -> String {
    common::repo_root().join("examples/brdf").join(format!("{name}.brdf")).display().to_string()
}

fn write_csv(path: &Path, n: usize) {
    let mut text = String::from("nx,ny,nz,vx,vy,vz,lx,ly,lz,roughness,f0r,f0g,f0b\n");
    for s in samples::well_conditioned(n, 21, 0.05, 0.2..1.0) {
        let [n, v, l, f] = [s.n, s.v, s.l, s.f0];
        text += &format!(
            "{},{},{},{},{},{},{},{},{},{},{},{},{}\n",
            n[0], n[1], n[2], v[0], v[1], v[2], l[0], l[1], l[2], s.roughness, f[0], f[1], f[2]
        );
    }
    std::fs::write(path, text).unwrap();
}

/// `brdfprof ARGS` in `dir` with the disk cache at `cache` ("" turns it off).
fn run_cached(dir: &Path, cache: &str, args: &[&str]) -> Run {
    let out = brdfprof().args(args).env("BRDFPROF_CACHE_DIR", cache).current_dir(dir).output().unwrap();
    Run {
        code: out.status.code(),
        stdout: String::from_utf8_lossy(&out.stdout).into_owned(),
        stderr: String::from_utf8_lossy(&out.stderr).into_owned(),
    }
}

fn entries(cache: &Path) -> Vec<PathBuf> {
    let mut e: Vec<PathBuf> = std::fs::read_dir(cache).unwrap().map(|e| e.unwrap().path()).collect();
    e.sort();
    e
}

/// A baseline from a copy of glsl/, then a `pow` added to the file model's return in the copy's brdf.glsl.
/// With the cache on, the gate must see the edit, not exit 0 on a cache hit.
#[test]
fn an_edited_include_is_not_served_from_the_cache() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let cache = d.join("cache");
    let glsl = d.join("glsl");
    brdfprof::shaders::write_glsl_tree(&glsl).unwrap();
    let model = format!("{},roughness=@roughness,f0=@f0", example("ggx"));
    let check = |extra: &[&str]| {
        run_cached(
            d,
            cache.to_str().unwrap(),
            &[&["check", "--glsl", "glsl", "--model", &model, "--no-callgrind", "--rounds", "0"], extra].concat(),
        )
    };
    check(&["--save-baseline", "b.json"]).ok();
    let brdf = glsl.join("brdf.glsl");
    let source = std::fs::read_to_string(&brdf).unwrap();
    let call = "return BRDF_FILE_FUNCTION(L, V, N, X, cross(N, X));";
    assert!(source.contains(call), "brdf.glsl returns the file's BRDF as `{call}`");
    std::fs::write(
        &brdf,
        source.replace(call, "return BRDF_FILE_FUNCTION(L, V, N, X, cross(N, X)) * pow(max(dot(N, L), 1e-4), 1e-7);"),
    )
    .unwrap();
    let r = check(&["--baseline", "b.json"]);
    assert_eq!(r.code, Some(1), "the edit is a regression with the cache on\n{}\n{}", r.stdout, r.stderr);
    assert!(r.stdout.contains("glsl.Pow") && r.stdout.contains("REGRESSION"), "{}", r.stdout);
}

/// The float 3.14159 of the file's PI changed to 6.283 in the cached SPIR-V (which halved every value, exit
/// 0): detected, recompiled, the same rows as without the cache, and the entry replaced.
#[test]
fn a_changed_float_in_an_entry_is_detected_and_replaced() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    write_csv(&d.join("in.csv"), 50);
    let cache = d.join("cache");
    let ggx = example("ggx");
    let eval =
        |cache: &str, out: &str| run_cached(d, cache, &["eval", "--model", &ggx, "--input", "in.csv", "--output", out]);
    eval("", "reference.csv").ok();
    eval(cache.to_str().unwrap(), "first.csv").ok();
    let all = entries(&cache);
    let [entry] = all.as_slice() else { panic!("one entry: {all:?}") };
    let mut bytes = std::fs::read(&entry).unwrap();
    let pi = std::f32::consts::PI.to_le_bytes();
    let at = bytes.windows(4).position(|w| w == pi).expect("the file's PI is a constant of the SPIR-V");
    bytes[at..at + 4].copy_from_slice(&6.283f32.to_le_bytes());
    std::fs::write(&entry, &bytes).unwrap();
    let r = eval(cache.to_str().unwrap(), "after.csv").ok();
    assert!(
        r.stderr.contains(&format!("warning: the cache entry {} ", entry.display())) && r.stderr.contains("damaged"),
        "{}",
        r.stderr
    );
    let reference = std::fs::read_to_string(d.join("reference.csv")).unwrap();
    assert_eq!(std::fs::read_to_string(d.join("after.csv")).unwrap(), reference, "the same rows as without the cache");
    assert_eq!(std::fs::read_to_string(d.join("first.csv")).unwrap(), reference);
    assert_ne!(std::fs::read(&entry).unwrap(), bytes, "the entry is replaced");
    let r = eval(cache.to_str().unwrap(), "again.csv").ok();
    assert!(!r.stderr.contains("damaged"), "the replaced entry verifies: {}", r.stderr);
    // An entry that is no longer SPIR-V at all (it failed every later run, and segfaulted under validation).
    std::fs::write(&entry, b"\x03\x02\x23\x07 not SPIR-V any more").unwrap();
    let r = run_cached(
        d,
        cache.to_str().unwrap(),
        &["eval", "--model", &ggx, "--input", "in.csv", "--output", "garbage.csv", "--validate"],
    )
    .ok();
    assert!(r.stderr.contains(&entry.display().to_string()), "{}", r.stderr);
    assert_eq!(std::fs::read_to_string(d.join("garbage.csv")).unwrap(), reference);
}

/// Fuzz: random damage to an entry (bit flips, bytes replaced, cut short, grown, another entry's bytes) never
/// changes a result silently: every run gives the cache-off rows, and a changed entry is reported.
#[test]
fn random_damage_to_entries_never_changes_a_result() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    write_csv(&d.join("in.csv"), 20);
    let cache = d.join("cache");
    let (ggx, blinn) = (example("ggx"), example("blinn"));
    let eval = |model: &str, cache: &str, out: &str| {
        run_cached(d, cache, &["eval", "--model", model, "--input", "in.csv", "--output", out]).ok()
    };
    eval(&ggx, "", "reference.csv");
    let reference = std::fs::read_to_string(d.join("reference.csv")).unwrap();
    eval(&blinn, cache.to_str().unwrap(), "blinn.csv");
    let other = std::fs::read(&entries(&cache)[0]).unwrap();
    eval(&ggx, cache.to_str().unwrap(), "ggx.csv");
    let entry = entries(&cache).into_iter().find(|e| std::fs::read(e).unwrap() != other).unwrap();
    let mut rng = rand_pcg::Pcg64::seed_from_u64(2021);
    for round in 0..8 {
        let mut bytes = std::fs::read(&entry).unwrap();
        let what = match round % 4 {
            0 => {
                let i = rng.random_range(0..bytes.len());
                bytes[i] ^= 1 << rng.random_range(0..8);
                format!("bit flip at {i}")
            }
            1 => {
                let n = rng.random_range(1..bytes.len());
                bytes.truncate(n);
                format!("cut to {n} bytes")
            }
            2 => {
                for _ in 0..4 {
                    let i = rng.random_range(0..bytes.len());
                    bytes[i] = bytes[i].wrapping_add(rng.random_range(1..=255));
                }
                "4 bytes changed".to_string()
            }
            _ => {
                bytes = other.clone();
                "the other model's entry copied over it".to_string()
            }
        };
        std::fs::write(&entry, &bytes).unwrap();
        let r = eval(&ggx, cache.to_str().unwrap(), "out.csv");
        assert_eq!(
            std::fs::read_to_string(d.join("out.csv")).unwrap(),
            reference,
            "round {round} ({what}): a different result"
        );
        assert!(r.stderr.contains("damaged"), "round {round} ({what}): not reported\n{}", r.stderr);
    }
}

#[test]
fn cache_show_and_clear_touch_only_brdfprofs_entries() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    write_csv(&d.join("in.csv"), 4);
    let cache = d.join("cache");
    let c = cache.to_str().unwrap();
    run_cached(d, c, &["eval", "--model", &example("ggx"), "--input", "in.csv", "--output", "out.csv"]).ok();
    std::fs::write(cache.join("notes.txt"), "the user's own file").unwrap();
    let size = std::fs::metadata(&entries(&cache)[0]).unwrap().len();
    let show = run_cached(d, c, &["cache", "show"]).ok();
    assert!(show.stdout.contains(&format!("directory: {c} (BRDFPROF_CACHE_DIR)")), "{}", show.stdout);
    assert!(
        show.stdout.contains("entries: 1 (spv: 1)") && show.stdout.contains(&format!("total size: {size} bytes")),
        "{}",
        show.stdout
    );
    let clear = run_cached(d, c, &["cache", "clear"]).ok();
    assert!(clear.stdout.contains(&format!("removed 1 cache entry ({size} bytes)")), "{}", clear.stdout);
    assert_eq!(entries(&cache), [cache.join("notes.txt")], "only brdfprof's entry went");
    assert!(run_cached(d, c, &["cache", "show"]).ok().stdout.contains("entries: 0"));
    assert!(run_cached(d, "", &["cache", "show"]).ok().stdout.contains("the disk cache is off"));
}

/// `cache show` reads an entry's header and streams its payload through the checksum: a 3 GB sparse file
/// named like an entry (its header claiming all 3 GB, or 1 MB) is listed as damaged under a 512 MB address
/// space limit, which reading it whole would exceed six times over.
#[test]
fn cache_show_reads_a_huge_sparse_entry_in_bounded_memory() {
    let dir = tempfile::tempdir().unwrap();
    let cache = dir.path().join("cache");
    std::fs::create_dir(&cache).unwrap();
    let size: u64 = 3 << 30;
    for (name, claimed) in [("a", size - 200), ("b", 1 << 20)] {
        let key = format!("{:064}", 0).replacen('0', name, 1);
        let header = format!("brdfprof-cache 1\nkind: spv\nkey: {key}\nlength: {claimed}\nsha256: {:064}\n\n", 0);
        let file = std::fs::File::create(cache.join(format!("{key}.spv"))).unwrap();
        std::os::unix::fs::FileExt::write_all_at(&file, header.as_bytes(), 0).unwrap();
        file.set_len(size).unwrap();
    }
    let started = std::time::Instant::now();
    let out = std::process::Command::new("sh")
        .args(["-c", "ulimit -v 524288 && exec \"$0\" cache show", env!("CARGO_BIN_EXE_brdfprof")])
        .env("BRDFPROF_CACHE_DIR", &cache)
        .output()
        .unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(0), "{stdout}{}", String::from_utf8_lossy(&out.stderr));
    assert!(stdout.contains("entries: 2 (spv: 2)"), "{stdout}");
    assert!(stdout.contains("more than any entry holds"), "the 3 GB claim is refused from the header: {stdout}");
    assert!(stdout.contains("where the header says 1048576"), "the 1 MB claim is read 1 MB + 1 byte far: {stdout}");
    assert!(started.elapsed().as_secs() < 20, "headers and at most a bounded payload read");
}
