//! `brdfprof eval` end to end: a CSV round trip checked against the f64 twins, and bad input giving a clear
//! error, exit status 2 and no output file.

use crate::common;
use brdfprof::brdf::{ModelSpec, THESIS_MODELS, samples};
use std::path::Path;

fn write_csv(path: &Path, s: &[brdfprof::brdf::Sample]) {
    // Columns shuffled and an extra one, as users' files come.
    let mut text = String::from("id,lz,ly,lx,roughness,f0b,f0g,f0r,nz,ny,nx,vz,vy,vx\n");
    for (i, s) in s.iter().enumerate() {
        text += &format!(
            "{i},{},{},{},{},{},{},{},{},{},{},{},{},{}\n",
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
    std::fs::write(path, text).unwrap();
}

#[test]
fn eval_round_trips_a_csv_for_every_thesis_model() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("in.csv");
    let samples = samples::well_conditioned(5_000, 11, 0.05, 0.2..1.0);
    write_csv(&input, &samples);
    for model in THESIS_MODELS {
        let output = dir.path().join(format!("{model}.csv"));
        let run = common::brdfprof()
            .args(["eval", "--validate", "--model", model, "--input"])
            .arg(&input)
            .arg("--output")
            .arg(&output)
            .output()
            .unwrap();
        assert!(run.status.success(), "{model}: {}", String::from_utf8_lossy(&run.stderr));
        assert!(
            !String::from_utf8_lossy(&run.stderr).contains("validation"),
            "{}",
            String::from_utf8_lossy(&run.stderr)
        );
        let text = std::fs::read_to_string(&output).unwrap();
        let mut lines = text.lines();
        assert_eq!(lines.next(), Some("r,g,b"));
        let spec = ModelSpec::parse(model).unwrap();
        let mut rows = 0;
        for (line, s) in lines.zip(&samples) {
            let got: Vec<f64> = line.split(',').map(|x| x.parse().unwrap()).collect();
            let want = spec.eval(s);
            for c in 0..3 {
                assert!(common::rel_err(got[c], want[c]) <= 1e-3, "{model} row {rows}: {} vs {}", got[c], want[c]);
            }
            rows += 1;
        }
        assert_eq!(rows, samples.len());
    }
}

#[test]
fn back_facing_rows_give_zero() {
    let dir = tempfile::tempdir().unwrap();
    let (input, output) = (dir.path().join("in.csv"), dir.path().join("out.csv"));
    std::fs::write(
        &input,
        "nx,ny,nz,vx,vy,vz,lx,ly,lz,roughness,f0r,f0g,f0b\n0,0,1,0,0.6,0.8,0,0,-1,0.5,0.04,0.04,0.04\n0,0,1,0,0,-1,0.6,0,0.8,0.5,0.04,0.04,0.04\n0,0,2,0,1.2,1.6,0.3,0,0.4,0.5,0.04,0.04,0.04\n",
    )
    .unwrap();
    let run = common::brdfprof()
        .args(["eval", "--validate", "--model", "ggx", "--input"])
        .arg(&input)
        .arg("--output")
        .arg(&output)
        .output()
        .unwrap();
    assert!(run.status.success());
    let text = std::fs::read_to_string(&output).unwrap();
    let rows: Vec<&str> = text.lines().skip(1).collect();
    assert_eq!(rows[..2], ["0,0,0", "0,0,0"], "NoL <= 0 and NoV <= 0 give 0");
    assert!(
        rows[2].split(',').all(|x| x.parse::<f64>().unwrap() > 0.0),
        "unnormalised vectors are normalised: {}",
        rows[2]
    );
}

#[test]
fn bad_input_fails_clearly_with_exit_2_and_no_output() {
    let dir = tempfile::tempdir().unwrap();
    let good_header = "nx,ny,nz,vx,vy,vz,lx,ly,lz,roughness,f0r,f0g,f0b";
    let good_row = "0,0,1,0,0.6,0.8,0.6,0,0.8,0.5,0.04,0.04,0.04";
    let cases: Vec<(&str, String, Vec<&str>, &str)> = vec![
        (
            "missing column",
            format!("nx,ny,nz,vx,vy,vz,lx,ly,roughness,f0r,f0g,f0b\n0,0,1,0,0.6,0.8,0.6,0,0.5,0.04,0.04,0.04\n"),
            vec!["--model", "ggx"],
            "in.csv:1: header lacks column(s) lz",
        ),
        (
            "non-number",
            format!("{good_header}\n{good_row}\n0,0,1,0,0.6,zero,0.6,0,0.8,0.5,0.04,0.04,0.04\n"),
            vec!["--model", "ggx"],
            "in.csv:3: column 6 `vz`: `zero` is not a number",
        ),
        ("empty file", String::new(), vec!["--model", "ggx"], "in.csv: empty file"),
        ("unknown model", format!("{good_header}\n{good_row}\n"), vec!["--model", "phong"], "unknown model `phong`"),
        (
            "unknown device",
            format!("{good_header}\n{good_row}\n"),
            vec!["--model", "ggx", "--device", "no-such-gpu"],
            "no device whose name contains `no-such-gpu`",
        ),
        (
            "device index",
            format!("{good_header}\n{good_row}\n"),
            vec!["--model", "ggx", "--device", "99"],
            "no device with index 99",
        ),
        (
            "NaN",
            format!("{good_header}\n{good_row}\nnan,0,1,0,0.6,0.8,0.6,0,0.8,0.5,0.04,0.04,0.04\n"),
            vec!["--model", "ggx"],
            "in.csv:3: column 1 `nx`: `nan` is not finite",
        ),
        (
            "zero vector",
            format!("{good_header}\n0,0,1,0,0,0,0.6,0,0.8,0.5,0.04,0.04,0.04\n"),
            vec!["--model", "ggx"],
            "in.csv:2: columns vx,vy,vz: zero-length vector",
        ),
        (
            "bad gamma",
            format!("{good_header}\n{good_row}\n"),
            vec!["--model", "burley", "--param", "gamma=abc"],
            "gamma `abc` is not a number",
        ),
    ];
    for (what, content, args, expected) in cases {
        let input = dir.path().join("in.csv");
        let output = dir.path().join("out.csv");
        std::fs::write(&input, content).unwrap();
        let run = common::brdfprof()
            .args(["eval", "--validate"])
            .args(&args)
            .arg("--input")
            .arg(&input)
            .arg("--output")
            .arg(&output)
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&run.stderr);
        assert_eq!(run.status.code(), Some(2), "{what}: exit status; stderr: {stderr}");
        assert!(stderr.contains(expected), "{what}: expected `{expected}` in: {stderr}");
        assert!(!output.exists(), "{what}: an output file was written");
    }
    let missing = common::brdfprof()
        .args(["eval", "--validate", "--model", "ggx", "--input", "/nonexistent/in.csv", "--output"])
        .arg(dir.path().join("o.csv"))
        .output()
        .unwrap();
    assert_eq!(missing.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&missing.stderr).contains("cannot read /nonexistent/in.csv"));
}

/// `eval --device opencl` runs the OpenCL C translation on PoCL: the same CSV out as on Vulkan, within 1e-5
/// relative (1e-3 floor) for every thesis model, each example `.brdf` and a constant lookup table (read in place
/// from __constant memory), so a user can diff two independent executions of one BRDF source.
#[test]
fn eval_on_opencl_agrees_with_vulkan_for_the_thesis_models_the_example_files_and_a_table() {
    let dir = tempfile::tempdir().unwrap();
    let input = dir.path().join("in.csv");
    write_csv(&input, &samples::well_conditioned(5_000, 13, 0.05, 0.2..1.0));
    let mut models: Vec<String> = THESIS_MODELS.iter().map(|m| m.to_string()).collect();
    let examples = common::repo_root().join("examples/brdf");
    let mut files: Vec<String> = std::fs::read_dir(&examples)
        .unwrap()
        .map(|e| e.unwrap().path().display().to_string())
        .filter(|p| p.ends_with(".brdf"))
        .collect();
    files.sort();
    assert!(!files.is_empty());
    models.extend(files);
    models.push(common::repo_root().join("tests/fixtures/brdf/table/lookup-64.brdf").display().to_string());
    let read = |p: &Path| -> Vec<f64> {
        std::fs::read_to_string(p)
            .unwrap()
            .lines()
            .skip(1)
            .flat_map(|l| l.split(',').map(|x| x.parse::<f64>().unwrap()).collect::<Vec<_>>())
            .collect()
    };
    for model in &models {
        let (vk, cl) = (dir.path().join("vk.csv"), dir.path().join("cl.csv"));
        common::run(&["eval", "--model", model, "--input", input.to_str().unwrap(), "--output", vk.to_str().unwrap()])
            .ok();
        let run = common::run(&[
            "eval",
            "--device",
            "opencl",
            "--model",
            model,
            "--input",
            input.to_str().unwrap(),
            "--output",
            cl.to_str().unwrap(),
        ])
        .ok();
        assert!(run.stderr.contains("(OpenCL)"), "{}", run.stderr);
        let (a, b) = (read(&vk), read(&cl));
        assert_eq!(a.len(), 15_000, "{model}");
        assert_eq!(a.len(), b.len(), "{model}");
        let worst = a.iter().zip(&b).map(|(x, y)| (x - y).abs() / x.abs().max(1e-3)).fold(0.0, f64::max);
        assert!(worst <= 1e-5, "{model}: OpenCL against Vulkan {worst:.2e}");
    }
}
