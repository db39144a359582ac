//! Fuzzed inputs (seeded, so every run tries the same ones): random bytes and mutations of a valid eval CSV,
//! scene file and check baseline (byte flips, insertions, deletions, truncations, duplicated lines, numbers
//! replaced by huge, negative, NaN and infinite ones). In process, no parser may panic and every error must
//! name its input; end to end, every command must exit 0, 1 or 2 (never by a signal, nor hang), say why on
//! stderr when it fails, and write no output when it exits 2.

use crate::common::{self, brdfprof};
use brdfprof::brdf::samples;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;
use std::os::unix::process::ExitStatusExt;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path, PathBuf};
use std::process::Stdio;
use std::time::{Duration, Instant};

const SEED: u64 = 0x00b2_dfb2_0f00;
/// In-process cases per input kind (plus as many random byte strings).
const MUTANTS: usize = 1000;
const END_TO_END: usize = 10;

/// Numbers a mutation puts in place of one in the file.
const NUMBERS: [&str; 14] = [
    "1e39",
    "-1",
    "NaN",
    "nan",
    "inf",
    "-inf",
    "+inf",
    "1e308",
    "-1e308",
    "99999999999999999999",
    "4294967296",
    "-0",
    "1e-45",
    "0",
];
/// Bytes that mean something to one of the formats, or to none.
const SPECIAL: [u8; 14] = [b',', b'"', b'\n', b'\r', 0, 0xff, 0xc3, b'{', b'}', b'[', b']', b':', b'-', b'\\'];

fn eval_csv() -> Vec<u8> {
    let mut text = String::from("id,lz,ly,lx,roughness,f0b,f0g,f0r,nz,ny,nx,vz,vy,vx,tx,ty,tz\n");
    for (i, s) in samples::well_conditioned(12, 5, 0.05, 0.2..1.0).iter().enumerate() {
        text += &format!(
            "{i},{},{},{},{},{},{},{},{},{},{},{},{},{},1,0,0\n",
            s.l[2],
            s.l[1],
            s.l[0],
            s.roughness,
            s.f0[2],
            s.f0[1],
            s.f0[0],
            s.n[2],
            s.n[1],
            s.n[0],
            s.v[2],
            s.v[1],
            s.v[0]
        );
    }
    text.into_bytes()
}

fn scene_file() -> Vec<u8> {
    let text = std::fs::read_to_string(common::repo_root().join("scenes/sphere-grid.json")).unwrap();
    text.replace("[800, 350]", "[48, 24]").into_bytes()
}

fn baseline_file() -> Vec<u8> {
    std::fs::read(common::repo_root().join("results/baseline-llvmpipe.json")).unwrap()
}

/// Byte ranges of the numbers in `bytes` (a digit run with its sign, point and exponent).
fn numbers(bytes: &[u8]) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    let mut i = 0;
    while i < bytes.len() {
        if bytes[i].is_ascii_digit() {
            let start = if i > 0 && bytes[i - 1] == b'-' { i - 1 } else { i };
            let mut end = i;
            while end < bytes.len()
                && (bytes[end].is_ascii_digit() || matches!(bytes[end], b'.' | b'e' | b'E' | b'+' | b'-'))
            {
                end += 1;
            }
            out.push((start, end));
            i = end;
        } else {
            i += 1;
        }
    }
    out
}

/// One to three random mutations of `good`.
fn mutate(rng: &mut Pcg64, good: &[u8]) -> Vec<u8> {
    let mut b = good.to_vec();
    for _ in 0..rng.random_range(1..=3) {
        let at = |rng: &mut Pcg64, b: &Vec<u8>| rng.random_range(0..=b.len());
        match rng.random_range(0..7) {
            0 if !b.is_empty() => {
                let i = rng.random_range(0..b.len());
                b[i] ^= 1 << rng.random_range(0..8);
            }
            1 => {
                let byte =
                    if rng.random_bool(0.5) { SPECIAL[rng.random_range(0..SPECIAL.len())] } else { rng.random() };
                let i = at(rng, &b);
                b.insert(i, byte);
            }
            2 if !b.is_empty() => {
                let i = rng.random_range(0..b.len());
                let n = rng.random_range(1..=16.min(b.len() - i));
                b.drain(i..i + n);
            }
            3 => {
                let i = at(rng, &b);
                b.truncate(i);
            }
            4 => {
                let lines: Vec<&[u8]> = b.split(|&c| c == b'\n').collect();
                let k = rng.random_range(0..lines.len());
                let mut out = Vec::new();
                for (j, l) in lines.iter().enumerate() {
                    let copies = if j == k { 2 } else { 1 };
                    for _ in 0..copies {
                        out.extend_from_slice(l);
                        out.push(b'\n');
                    }
                }
                out.pop();
                b = out;
            }
            _ => {
                let spans = numbers(&b);
                if !spans.is_empty() {
                    let (s, e) = spans[rng.random_range(0..spans.len())];
                    let with = NUMBERS[rng.random_range(0..NUMBERS.len())];
                    b.splice(s..e, with.bytes());
                }
            }
        }
    }
    b
}

fn random_bytes(rng: &mut Pcg64) -> Vec<u8> {
    let n = rng.random_range(0..256);
    (0..n)
        .map(|_| if rng.random_bool(0.3) { SPECIAL[rng.random_range(0..SPECIAL.len())] } else { rng.random() })
        .collect()
}

/// Runs `parse` on `input`; it must not panic, and an error must name `name`.
fn survives(kind: &str, input: &[u8], name: &str, parse: impl FnOnce() -> anyhow::Result<()>) {
    match catch_unwind(AssertUnwindSafe(parse)) {
        Ok(Ok(())) => {}
        Ok(Err(e)) => {
            let msg = format!("{e:#}");
            assert!(
                !msg.trim().is_empty() && msg.contains(name),
                "{kind}: error `{msg}` does not name {name}; input: {:?}",
                String::from_utf8_lossy(input)
            );
        }
        Err(_) => panic!("{kind}: the parser panicked on {:?}", String::from_utf8_lossy(input)),
    }
}

#[test]
fn parsers_survive_random_and_mutated_input() {
    let mut rng = Pcg64::seed_from_u64(SEED);
    let dir = tempfile::tempdir().unwrap();
    let baseline_path = dir.path().join("fuzz-baseline.json");
    let baseline_name = baseline_path.display().to_string();
    let (csv, scene, baseline) = (eval_csv(), scene_file(), baseline_file());
    // The unmutated inputs are valid: mutants start from something every parser accepts.
    assert!(brdfprof::io::parse_samples_csv(&csv, "good.csv").is_ok());
    assert!(
        brdfprof::scene::Scene::parse(
            std::str::from_utf8(&scene).unwrap(),
            "good.json",
            PathBuf::new(),
            PathBuf::from("good.json")
        )
        .is_ok()
    );
    std::fs::write(&baseline_path, &baseline).unwrap();
    assert!(brdfprof::check::load(&baseline_path).is_ok());
    let (mut accepted, mut total) = ([0usize; 3], 0);
    for i in 0..2 * MUTANTS {
        let pick = |rng: &mut Pcg64, good: &[u8]| if i % 2 == 0 { mutate(rng, good) } else { random_bytes(rng) };
        let input = pick(&mut rng, &csv);
        survives("eval CSV", &input, "fuzz.csv", || {
            brdfprof::io::parse_eval_csv(&input, "fuzz.csv", &["id"]).map(|_| accepted[0] += 1)
        });
        let input = pick(&mut rng, &scene);
        survives("scene", &input, "fuzz.json", || {
            let text = String::from_utf8_lossy(&input);
            brdfprof::scene::Scene::parse(&text, "fuzz.json", PathBuf::new(), PathBuf::from("fuzz.json"))
                .map(|_| accepted[1] += 1)
        });
        let input = pick(&mut rng, &baseline);
        std::fs::write(&baseline_path, &input).unwrap();
        survives("baseline", &input, &baseline_name, || {
            brdfprof::check::load(&baseline_path).map(|_| accepted[2] += 1)
        });
        total += 1;
    }
    println!("accepted of {total} each: eval CSV {}, scene {}, baseline {}", accepted[0], accepted[1], accepted[2]);
}

/// What one end-to-end run did.
struct Outcome {
    code: i32,
    stderr: String,
}

/// Runs brdfprof with `args` in `dir`, killing it (and failing) after 60 s; it must exit 0, 1 or 2.
fn run_bounded(dir: &Path, args: &[&str], input: &[u8]) -> Outcome {
    let stderr_path = dir.join("stderr.txt");
    let mut child = brdfprof()
        .args(args)
        .current_dir(dir)
        .stdout(Stdio::null())
        .stderr(std::fs::File::create(&stderr_path).unwrap())
        .spawn()
        .unwrap();
    let start = Instant::now();
    let status = loop {
        if let Some(s) = child.try_wait().unwrap() {
            break s;
        }
        if start.elapsed() > Duration::from_secs(60) {
            child.kill().unwrap();
            child.wait().unwrap();
            panic!("{args:?} ran over 60 s on {:?}", String::from_utf8_lossy(input));
        }
        std::thread::sleep(Duration::from_millis(10));
    };
    let stderr = std::fs::read_to_string(&stderr_path).unwrap_or_default();
    std::fs::remove_file(&stderr_path).unwrap();
    assert!(
        status.signal().is_none(),
        "{args:?} died of signal {:?}; stderr: {stderr}; input: {:?}",
        status.signal(),
        String::from_utf8_lossy(input)
    );
    let code = status.code().unwrap();
    assert!(matches!(code, 0..=2), "{args:?} exited {code}; stderr: {stderr}");
    if code != 0 {
        assert!(stderr.contains("brdfprof: "), "{args:?} exited {code} without saying why; stderr: {stderr:?}");
    }
    Outcome { code, stderr }
}

#[test]
fn commands_survive_mutated_files() {
    let mut rng = Pcg64::seed_from_u64(SEED ^ 1);
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let (csv, scene, baseline) = (eval_csv(), scene_file(), baseline_file());
    let mut codes = Vec::new();
    for _ in 0..END_TO_END {
        let input = mutate(&mut rng, &scene);
        std::fs::write(d.join("fuzz.json"), &input).unwrap();
        codes.push(("scene", run_bounded(d, &["scene", "fuzz.json"], &input).code));

        let input = mutate(&mut rng, &csv);
        std::fs::write(d.join("fuzz.csv"), &input).unwrap();
        let out = d.join("out.csv");
        let run = run_bounded(d, &["eval", "--model", "ggx", "--input", "fuzz.csv", "--output", "out.csv"], &input);
        assert_eq!(
            out.exists(),
            run.code == 0,
            "eval exit {} with output {}: {}",
            run.code,
            if out.exists() { "written" } else { "missing" },
            run.stderr
        );
        if run.code == 2 {
            assert!(run.stderr.contains("fuzz.csv"), "{}", run.stderr);
        }
        let _ = std::fs::remove_file(&out);
        codes.push(("eval", run.code));

        let input = mutate(&mut rng, &baseline);
        std::fs::write(d.join("fuzz-baseline.json"), &input).unwrap();
        codes.push((
            "check",
            run_bounded(d, &["check", "--baseline", "fuzz-baseline.json", "--rounds", "0", "--no-callgrind"], &input)
                .code,
        ));
    }
    let mut left: Vec<String> =
        std::fs::read_dir(d).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    left.sort();
    assert_eq!(left, ["fuzz-baseline.json", "fuzz.csv", "fuzz.json"], "the commands wrote only their named outputs");
    println!("exit codes: {codes:?}");
}
