//! `brdfprof eval`: f_s of one model for every row of a CSV file.

use super::{on_device, DeviceArgs, ModelArgs};
use anyhow::{bail, Result};
use brdfprof::model::brdf_file::{FileParam, FileParamKind};
use brdfprof::model::file_model::{Binding, FileModel, Input};
use brdfprof::model::Model;
use brdfprof::{io, kernels, messages};
use clap::Args;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

#[derive(Args)]
pub struct EvalArgs {
    #[command(flatten)]
    pub model: ModelArgs,
    /// CSV with columns nx,ny,nz,vx,vy,vz,lx,ly,lz,roughness,f0r,f0g,f0b (any order; others ignored). For a
    /// .brdf model: optional tx,ty,tz (the tangent X, made orthogonal to N; Y = N x X; without them X is
    /// Duff et al. 2017's basis), and a column named like a parameter (NAMEr,NAMEg,NAMEb for a colour) sets
    /// it per row.
    #[arg(long)]
    pub input: PathBuf,
    /// CSV written with columns r,g,b, one row per input row (written atomically).
    #[arg(long)]
    pub output: PathBuf,
    #[command(flatten)]
    pub device: DeviceArgs,
}

pub fn eval(args: &EvalArgs) -> Result<ExitCode> {
    io::check_output_path("--output", &args.output)?;
    let models = args.model.models(&[])?;
    let [model] = models.as_slice() else {
        bail!("eval takes exactly one --model");
    };
    let mut inputs = vec![("--input", args.input.as_path())];
    inputs.extend(model.file().map(|f| ("--model", std::path::Path::new(&f.path))));
    io::check_not_input("--output", &args.output, &inputs)?;
    let shown = model.name();
    let (model, input, rows) = read_input(model, &args.input, &args.model.params)?;
    let extras = kernels::EvalExtras { tangents: input.tangents.as_deref(), rows: &rows.values, row_floats: rows.floats };
    let (device, values) = if args.device.device.as_deref() == Some(OPENCL_DEVICE) {
        on_opencl(&model, &input.samples, &extras)?
    } else {
        let (gpu, values) = on_device(&args.device, |gpu, _| kernels::eval_with(gpu, &model, &input.samples, &extras, kernels::RunLimits::default()))?;
        (gpu.info.name.clone(), values)
    };
    io::write_output(&args.output, io::format_rgb_csv(&values).as_bytes())?;
    let bad = values.iter().filter(|v| v.iter().any(|x| !x.is_finite())).count();
    if bad > 0 {
        messages::warning(format!("{bad} of {} rows of {shown} are not finite (written as NaN or inf)", values.len()));
    }
    messages::progress(format!("{} rows of {shown} on {device} -> {}", values.len(), args.output.display()));
    Ok(ExitCode::SUCCESS)
}

/// `eval --device opencl`: the eval kernel's OpenCL C translation (the one Intel's compiler gets) run through
/// OpenCL, PoCL on this CPU unless BRDFPROF_OPENCL_DEVICE names another: a second execution of the same BRDF
/// source, independent of Vulkan, with the same CSV in and out.
pub const OPENCL_DEVICE: &str = "opencl";

fn on_opencl(model: &Model, samples: &[brdfprof::brdf::Sample], extras: &kernels::EvalExtras) -> Result<(String, Vec<[f32; 3]>)> {
    use brdfprof::translate::{opencl, prepare};
    let translation = prepare::eval_kernel(model, kernels::embedded())?;
    let kernel = opencl::ClKernel::build(&translation, false)?;
    let values = opencl::eval(&kernel, samples, extras)?;
    Ok((format!("{} (OpenCL)", kernel.device), values))
}

/// Parameters read per CSV row: `floats` values per row, rows one after another.
#[derive(Default)]
pub(super) struct RowValues {
    pub(super) values: Vec<f32>,
    pub(super) floats: usize,
}

/// The CSV's samples and tangents, and, for a `.brdf` model, the model with each parameter that has a column
/// named like it (NAME, or NAMEr,NAMEg,NAMEb for a colour) read per row, unless `--param` sets it.
pub(super) fn read_input(model: &Model, path: &Path, params: &[String]) -> Result<(Model, io::csv::EvalInput, RowValues)> {
    let Some(file) = model.file() else {
        let input = io::csv::read_eval_csv(path, &[])?;
        if input.tangents.is_some() {
            messages::note(format!("{}: columns tx,ty,tz are read by .brdf models only; {model} is isotropic", path.display()));
        }
        return Ok((model.clone(), input, RowValues::default()));
    };
    let columns: Vec<String> = file.file.params.iter().filter(|p| !geometry_column(file, p)).flat_map(|p| p.columns()).collect();
    let input = io::read_eval_csv_with(path, &columns.iter().map(String::as_str).collect::<Vec<_>>(), &relaxed_columns(file, &columns))?;
    // Every parameter not bound to an input is read per row, from its column(s) or repeating its value, so that
    // a row gives the same bits whether its value came from a column or from --param (a constant the
    // compiler would otherwise fold, rounding differently).
    let given = |name: &str| params.iter().any(|p| p.split_once('=').is_some_and(|(k, _)| k.trim() == name));
    let mut per_row: Vec<(&str, Vec<Vec<f32>>)> = Vec::new();
    let mut from_columns = Vec::new();
    for (p, binding) in file.file.params.iter().zip(&file.bindings) {
        let Binding::Value(value) = binding else { continue };
        let cols: Vec<(usize, &Vec<f32>)> = p.columns().iter().filter_map(|c| input.columns.iter().position(|(n, _)| n == c)).map(|k| (input.column_numbers[k], &input.columns[k].1)).collect();
        if !cols.is_empty() && cols.len() != p.columns().len() {
            bail!("{}: a colour parameter `{}` is set per row by all of {} or none", path.display(), p.name, p.columns().join(","));
        }
        let overridden = given(&p.name) || *value != p.default_value();
        if !cols.is_empty() && overridden {
            messages::note(format!("the value given for {} overrides the column(s) {} of {}", p.name, p.columns().join(","), path.display()));
        }
        let values = if !cols.is_empty() && !overridden {
            check_column(path, &input, p, cols[0])?;
            from_columns.push(p.name.as_str());
            cols.into_iter().map(|(_, v)| v.clone()).collect()
        } else {
            value.floats().into_iter().map(|x| vec![x; input.samples.len()]).collect()
        };
        per_row.push((p.name.as_str(), values));
    }
    let names: Vec<&str> = per_row.iter().map(|(n, _)| *n).collect();
    let (with_rows, floats) = file.with_rows(&names);
    let mut values = Vec::with_capacity(input.samples.len() * floats);
    for i in 0..input.samples.len() {
        for (_, cols) in &per_row {
            values.extend(cols.iter().map(|c| c[i]));
        }
    }
    if !from_columns.is_empty() {
        messages::progress(format!("{} set per row from {}", from_columns.join(", "), path.display()));
    }
    Ok((Model::File(std::sync::Arc::new(with_rows)), input, RowValues { values, floats }))
}

/// A parameter whose column would be one of the geometry's (nx..lz, tx..tz): not read per row (the column is
/// the vector's), with a note saying so.
fn geometry_column(file: &FileModel, p: &FileParam) -> bool {
    let geometry: Vec<&str> = io::SAMPLE_COLUMNS[..9].iter().chain(&io::TANGENT_COLUMNS).copied().collect();
    let clash: Vec<String> = p.columns().into_iter().filter(|c| geometry.contains(&c.as_str())).collect();
    if clash.is_empty() {
        return false;
    }
    messages::note(format!(
        "{}: parameter `{}` is not read per row: column(s) {} hold the geometry's vectors; set it with --param {}=VALUE",
        file.path,
        p.name,
        clash.join(","),
        p.name
    ));
    true
}

/// The sample columns (`roughness`, `f0r,f0g,f0b`) that are a parameter's own column and that no binding of
/// the model reads as an input: they need not be in [0, 1] (the parameter's range applies, as a warning).
fn relaxed_columns<'a>(file: &FileModel, columns: &'a [String]) -> Vec<&'a str> {
    let reads = |inputs: &[Input]| file.bindings.iter().any(|b| matches!(b, Binding::Input(i) if inputs.contains(i)));
    columns
        .iter()
        .map(String::as_str)
        .filter(|c| match *c {
            "roughness" => !reads(&[Input::Roughness, Input::Alpha]),
            "f0r" | "f0g" | "f0b" => !reads(&[Input::F0, Input::BaseColor]),
            _ => false,
        })
        .collect()
}

/// A parameter's column as the file declares the parameter: a bool's values 0 or 1 (else an error naming the
/// line and column), a float's within its slider range (else a warning: those are slider bounds).
fn check_column(path: &Path, input: &io::csv::EvalInput, p: &FileParam, (column, values): (usize, &Vec<f32>)) -> Result<()> {
    match p.kind {
        FileParamKind::Bool { .. } => {
            if let Some(i) = values.iter().position(|&x| x != 0.0 && x != 1.0) {
                bail!("{}:{}: column {column} `{}`: {} is not a bool (0 or 1), which parameter `{}` is", path.display(), input.lines[i], p.name, values[i], p.name);
            }
        }
        FileParamKind::Float { min, max, .. } => {
            let outside: Vec<usize> = (0..values.len()).filter(|&i| !(min..=max).contains(&f64::from(values[i]))).collect();
            if let Some(&i) = outside.first() {
                messages::warning(format!(
                    "{}: column {column} `{}`: {} of {} rows are outside the file's range [{min}, {max}] (BRDF Explorer's slider bounds), the first at line {} ({}); used as given",
                    path.display(),
                    p.name,
                    outside.len(),
                    values.len(),
                    input.lines[i],
                    values[i]
                ));
            }
        }
        FileParamKind::Color { .. } => {}
    }
    Ok(())
}
