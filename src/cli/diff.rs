//! `brdfprof diff --model A --model B`: both models on the same inputs, B measured against A; or
//! `brdfprof diff --reference SPEC --model ... --model ...`: every model against one reference's f64 values.

use super::args::{DeviceArgs, HtmlArg, ModelArgs, cosine_range, reference_spec, roughness_range};
use super::on_device;
use anyhow::{Result, bail};
use brdfprof::brdf::ModelSpec;
use brdfprof::brdf::Sample;
use brdfprof::diff::{self, DiffReport, DiffSet, Evaluated};
use brdfprof::model::Model;
use brdfprof::model::csv_rows::{RowValues, read_rows};
use brdfprof::{export::json, io, kernels};
use clap::Args;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

#[derive(Args)]
pub struct DiffArgs {
    /// The two models, A then B (B is measured against A); specs or model files (.brdf, .hlsl, .ush, .wgsl,
    /// ...), as for `eval`. With
    /// --reference, any number of models, each measured against the reference.
    #[command(flatten)]
    pub model: ModelArgs,
    /// Measure every --model against this built-in spec's exact f64 values (e.g. `ggx`, or
    /// `d=ggx,vis=smith-ggx-correlated,f=schlick`), in one table.
    #[arg(long, value_parser = reference_spec)]
    pub reference: Option<ModelSpec>,
    /// CSV of inputs, as for `eval` (columns nx,ny,nz,vx,vy,vz,lx,ly,lz,roughness,f0r,f0g,f0b). Default: seeded
    /// well-conditioned samples (--samples, --seed).
    #[arg(long)]
    pub input: Option<PathBuf>,
    /// Number of default samples (NoV, NoL in [0.05, 1], roughness in [0, 1], F0 as --f0 says).
    #[arg(long, default_value_t = 10_000, conflicts_with = "input")]
    pub samples: usize,
    #[arg(long, default_value_t = 19, conflicts_with = "input")]
    pub seed: u64,
    /// Perceptual roughness range of the default samples, MIN..MAX within [0, 1] (default: [0, 1], or the
    /// range every `.brdf` model's `domain roughness` admits).
    #[arg(long, value_parser = roughness_range, conflicts_with = "input")]
    pub roughness: Option<(f64, f64)>,
    /// N.V range of the default samples, MIN..MAX within [0, 1] (default: [0.05, 1], or within it the range
    /// every `.brdf` model's `domain nov` admits).
    #[arg(long, value_parser = cosine_range, conflicts_with = "input")]
    pub nov: Option<(f64, f64)>,
    /// N.L range of the default samples, as --nov (`domain nol`).
    #[arg(long, value_parser = cosine_range, conflicts_with = "input")]
    pub nol: Option<(f64, f64)>,
    /// F0 of the default samples: `materials` (default: 13 real materials, one per sample, dielectrics from
    /// their refractive index and metals of Real-Time Rendering 4th ed. Table 9.2; docs/diff.md), `uniform`
    /// ([0, 1]^3), MIN..MAX (every channel) or R0..R1,G0..G1,B0..B1.
    #[arg(long, value_parser = diff::F0Set::parse, default_value = "materials", conflicts_with = "input")]
    pub f0: diff::F0Set,
    /// Rows listed where the models differ most.
    #[arg(long, default_value_t = 10)]
    pub worst: usize,
    /// Exit 1 when the largest relative difference |B - A| / max(|A|, 1e-3) over every channel exceeds this,
    /// or a value is finite on one side only.
    #[arg(long, value_parser = tolerance)]
    pub tolerance: Option<f64>,
    /// CSV of the inputs with both outputs: nx..f0b, a_r,a_g,a_b, b_r,b_g,b_b.
    #[arg(long)]
    pub csv: Option<PathBuf>,
    /// JSON report (`"kind": "diff"`, docs/diff.md).
    #[arg(long)]
    pub json: Option<PathBuf>,
    /// PNG: lit spheres of A and B, the relative difference of B against A, and both models' lobes.
    #[arg(long, conflicts_with = "reference")]
    pub png: Option<PathBuf>,
    #[command(flatten)]
    pub html: HtmlArg,
    #[command(flatten)]
    pub device: DeviceArgs,
}

/// The default samples' ranges (`--roughness`, `--nov`, `--nol`, else the models' declared domains within the
/// defaults), and the words saying where each comes from.
fn domain_of(args: &DiffArgs, models: &[&Model]) -> Result<(diff::SampleDomain, [String; 3])> {
    super::sample_domain([args.roughness, args.nov, args.nol], diff::SampleDomain::default(), models)
}

/// `--tolerance`: a finite number, 0 or more.
fn tolerance(text: &str) -> Result<f64, String> {
    match text.trim().parse::<f64>() {
        Ok(t) if t.is_finite() && t >= 0.0 => Ok(t),
        _ => Err(format!("`{text}`: give a relative difference, a finite number 0 or more (e.g. 1e-3)")),
    }
}

/// The outputs asked for, each checked writable, none an input, no two the same path.
fn outputs(args: &DiffArgs, models: &[Model]) -> Result<Vec<(&'static str, PathBuf)>> {
    let asked = [
        ("--csv", args.csv.as_deref()),
        ("--json", args.json.as_deref()),
        ("--png", args.png.as_deref()),
        ("--html", args.html.html.as_deref()),
    ];
    let mut inputs: Vec<(&str, &Path)> = args.input.iter().map(|p| ("--input", p.as_path())).collect();
    inputs.extend(super::model_inputs(models));
    super::checked_outputs(&asked, &inputs)
}

impl super::Run for DiffArgs {
    fn run(&self) -> Result<ExitCode> {
        diff(self)
    }
}

pub fn diff(args: &DiffArgs) -> Result<ExitCode> {
    let models = args.model.models(&[])?;
    if let Some(reference) = &args.reference {
        if models.is_empty() {
            bail!("diff --reference needs at least one --model to measure against it");
        }
        return diff_set(args, &Model::spec(*reference), &models);
    }
    // One file alone is measured against the reference it names (`reference SPEC`).
    if let [only] = models.as_slice() {
        if let Some(reference) = only.declared_reference() {
            return diff_set(args, &Model::spec(reference), &models);
        }
    }
    let [a, b] = models.as_slice() else {
        bail!(
            "diff takes exactly two --model (A, then B measured against A), or any number with --reference SPEC (or one `.brdf` file naming its `reference`); got {}",
            models.len()
        );
    };
    if args.input.is_none() && !(1..=diff::MAX_SAMPLES).contains(&args.samples) {
        bail!("--samples {}: give 1 to {}", args.samples, diff::MAX_SAMPLES);
    }
    let outs = outputs(args, &models)?;
    let inputs = Inputs::read(args, &models)?;
    let (gpu, values) = on_device(&args.device, |gpu, progress| {
        progress.set_message(format!("{} and {} on {} rows", a.label(), b.label(), inputs.samples.len()));
        let values = inputs.eval_all(gpu)?;
        if let Some((_, path)) = outs.iter().find(|(f, _)| *f == "--png") {
            progress.set_message("picture");
            diff::picture::write(gpu, path, &inputs.models[0].0, &inputs.models[1].0)?;
        }
        Ok(values)
    })?;
    let (va, vb) = (&values[0], &values[1]);
    let evaluated = Evaluated {
        a,
        b,
        samples: &inputs.samples,
        lines: inputs.lines.as_deref(),
        a_values: va,
        b_values: vb,
        a_exact: None,
    };
    let result = DiffReport::build(&evaluated, &gpu.info.name, &inputs.label, args.worst, args.tolerance);
    for (flag, path) in &outs {
        match *flag {
            "--csv" => io::write_output(path, diff::csv(&inputs.samples, va, vb).as_bytes())?,
            "--json" => json::write_json(path, &result)?,
            _ => {}
        }
    }
    // The page reads the result back through its JSON view, as `brdfprof report` reads a saved one.
    let label = args.json.clone().unwrap_or_else(|| PathBuf::from("diff.json"));
    args.html.write(&[super::just_measured(&label, &result)?], Some(&gpu))?;
    out!("{}", result.markdown());
    if !outs.is_empty() {
        outln!("\n{}", super::written(&outs.iter().map(|(_, p)| p.clone()).collect::<Vec<_>>()));
    }
    Ok(if result.within_tolerance { ExitCode::SUCCESS } else { ExitCode::from(1) })
}

/// `diff --reference`: every model on the same rows against the reference's f64 twin (no kernel of its own).
fn diff_set(args: &DiffArgs, reference: &Model, models: &[Model]) -> Result<ExitCode> {
    if args.png.is_some() {
        bail!(
            "--png draws two models side by side; a diff against a reference (--reference, or a file's `reference`) has none: give a second --model for it"
        );
    }
    if args.input.is_none() && !(1..=diff::MAX_SAMPLES).contains(&args.samples) {
        bail!("--samples {}: give 1 to {}", args.samples, diff::MAX_SAMPLES);
    }
    let twin = reference.twin().expect("a reference is a built-in spec");
    let outs = outputs(args, models)?;
    let mut inputs = Inputs::read(args, models)?;
    inputs.drop_singular_rows();
    if inputs.samples.is_empty() {
        bail!(
            "diff --reference: every row has roughness 0, where the reference's D is singular; no row is left to compare"
        );
    }
    let (gpu, values) = on_device(&args.device, |gpu, progress| {
        progress.set_message(format!("{} models on {} rows", models.len(), inputs.samples.len()));
        inputs.eval_all(gpu)
    })?;
    let exact: Vec<[f64; 3]> =
        inputs.samples.iter().map(|s| twin.eval_reference(s).expect("singular rows dropped")).collect();
    let rounded: Vec<[f32; 3]> = exact.iter().map(|v| v.map(|x| x as f32)).collect();
    let diffs: Vec<DiffReport> = models
        .iter()
        .zip(&values)
        .map(|(m, v)| {
            let e = Evaluated {
                a: reference,
                b: m,
                samples: &inputs.samples,
                lines: inputs.lines.as_deref(),
                a_values: &rounded,
                b_values: v,
                a_exact: Some(&exact),
            };
            DiffReport::build(&e, &gpu.info.name, &inputs.label, args.worst, args.tolerance)
        })
        .collect();
    let result = DiffSet::new(diffs, args.tolerance);
    for (flag, path) in &outs {
        match *flag {
            "--csv" => io::write_output(path, diff::csv_set(&inputs.samples, &rounded, &values).as_bytes())?,
            "--json" => json::write_json(path, &result)?,
            _ => {}
        }
    }
    let label = args.json.clone().unwrap_or_else(|| PathBuf::from("diff.json"));
    args.html.write(&[super::just_measured(&label, &result)?], Some(&gpu))?;
    out!("{}", result.markdown());
    if !outs.is_empty() {
        outln!("\n{}", super::written(&outs.iter().map(|(_, p)| p.clone()).collect::<Vec<_>>()));
    }
    Ok(if result.within_tolerance { ExitCode::SUCCESS } else { ExitCode::from(1) })
}

/// The rows every model is evaluated on, and each model with its per-row parameters (a `.brdf` file's
/// columns, as `eval` reads them).
struct Inputs {
    samples: Vec<Sample>,
    tangents: Option<Vec<[f32; 3]>>,
    lines: Option<Vec<usize>>,
    label: String,
    models: Vec<(Model, RowValues)>,
}

impl Inputs {
    /// Leaves out the rows where a reference has no value (roughness 0: its D is a Dirac delta), counting them
    /// in the label and on stderr.
    fn drop_singular_rows(&mut self) {
        let keep: Vec<bool> = self.samples.iter().map(|s| s.roughness > 0.0).collect();
        let dropped = keep.iter().filter(|k| !**k).count();
        if dropped == 0 {
            return;
        }
        fn kept<T: Copy>(rows: &[T], keep: &[bool], per_row: usize) -> Vec<T> {
            rows.chunks(per_row.max(1)).zip(keep).filter(|(_, k)| **k).flat_map(|(r, _)| r.iter().copied()).collect()
        }
        self.samples = kept(&self.samples, &keep, 1);
        self.lines = self.lines.as_ref().map(|l| kept(l, &keep, 1));
        self.tangents = self.tangents.as_ref().map(|t| kept(t, &keep, 1));
        for (_, row) in &mut self.models {
            if !row.values.is_empty() {
                row.values = kept(&row.values, &keep, row.floats);
            }
        }
        let why = format!("{dropped} rows with roughness 0 left out (the reference's D is singular there)");
        brdfprof::messages::note(format!("diff: {why}"));
        self.label += &format!("; {why}");
    }

    fn read(args: &DiffArgs, models: &[Model]) -> Result<Self> {
        let Some(path) = &args.input else {
            let (domain, why) = domain_of(args, &models.iter().collect::<Vec<_>>())?;
            return Ok(Inputs {
                samples: diff::default_samples_in(args.samples, args.seed, &domain, args.f0),
                tangents: None,
                lines: None,
                label: diff::default_samples_label_in(
                    args.samples,
                    args.seed,
                    &domain,
                    why.each_ref().map(String::as_str),
                    args.f0,
                ),
                models: models.iter().map(|m| (m.clone(), RowValues::default())).collect(),
            });
        };
        let mut read = Vec::new();
        let mut rows = None;
        for m in models {
            let (model, input, values) = read_rows(m, path, &args.model.params)?;
            if input.samples.is_empty() {
                bail!(
                    "--input {}: the file has a header but no rows: there is nothing to compare (as --samples 0 is refused)",
                    path.display()
                );
            }
            rows.get_or_insert(input);
            read.push((model, values));
        }
        let input = rows.expect("at least one model");
        Ok(Inputs {
            samples: input.samples,
            tangents: input.tangents,
            lines: Some(input.lines),
            label: path.display().to_string(),
            models: read,
        })
    }

    /// Every model's values on the rows, in order.
    fn eval_all(&self, gpu: &brdfprof::gpu::Gpu) -> Result<Vec<Vec<[f32; 3]>>> {
        self.models
            .iter()
            .map(|(m, rows)| {
                let extras = kernels::EvalExtras {
                    tangents: self.tangents.as_deref(),
                    rows: &rows.values,
                    row_floats: rows.floats,
                };
                kernels::eval_with(gpu, m, &self.samples, &extras, kernels::RunLimits::default())
            })
            .collect()
    }
}
