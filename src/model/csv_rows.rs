//! An eval CSV bound to a model: the samples and tangents, the material columns the model reads (and only
//! those required), and for a `.brdf` model each parameter with a column named like it read per row.

use super::Model;
use super::brdf_file::{FileParam, FileParamKind};
use super::file_model::{Binding, FileModel, Input};
use crate::io::{self, Columns, EvalInput};
use crate::messages;
use anyhow::{Result, bail};
use std::path::Path;

/// Parameters read per CSV row: `floats` values per row, rows one after another.
#[derive(Default)]
pub struct RowValues {
    pub values: Vec<f32>,
    pub floats: usize,
}

/// The CSV's samples and tangents, and, for a `.brdf` model, the model with each parameter that has a column
/// named like it (NAME, or NAMEr,NAMEg,NAMEb for a colour) read per row, unless `--param` sets it.
pub fn read_rows(model: &Model, path: &Path, params: &[String]) -> Result<(Model, EvalInput, RowValues)> {
    let unread = model.unread_columns();
    let Some(file) = model.file() else {
        let input = io::read_eval_csv_with(path, &Columns { unread: &unread, ..Columns::default() })?;
        if input.tangents.is_some() {
            messages::note(format!(
                "{}: columns tx,ty,tz are read by .brdf models only; {model} is isotropic",
                path.display()
            ));
        }
        return Ok((model.clone(), input, RowValues::default()));
    };
    let columns: Vec<String> =
        file.file.params.iter().filter(|p| !geometry_column(file, p)).flat_map(|p| p.columns()).collect();
    let optional: Vec<&str> = columns.iter().map(String::as_str).collect();
    let relaxed = relaxed_columns(file, &columns);
    let input = io::read_eval_csv_with(path, &Columns { optional: &optional, relaxed: &relaxed, unread: &unread })?;
    // Every parameter not bound to an input is read per row, from its column(s) or repeating its value, so that
    // a row gives the same bits whether its value came from a column or from --param (a constant the
    // compiler would otherwise fold, rounding differently).
    let given = |name: &str| params.iter().any(|p| p.split_once('=').is_some_and(|(k, _)| k.trim() == name));
    let mut per_row: Vec<(&str, Vec<Vec<f32>>)> = Vec::new();
    let mut from_columns = Vec::new();
    for (p, binding) in file.file.params.iter().zip(&file.bindings) {
        let Binding::Value(value) = binding else { continue };
        let cols: Vec<(usize, &Vec<f32>)> = p
            .columns()
            .iter()
            .filter_map(|c| input.columns.iter().position(|(n, _)| n == c))
            .map(|k| (input.column_numbers[k], &input.columns[k].1))
            .collect();
        if !cols.is_empty() && cols.len() != p.columns().len() {
            bail!(
                "{}: a colour parameter `{}` is set per row by all of {} or none",
                path.display(),
                p.name,
                p.columns().join(",")
            );
        }
        let overridden = given(&p.name) || *value != p.default_value();
        if !cols.is_empty() && overridden {
            messages::note(format!(
                "the value given for {} overrides the column(s) {} of {}",
                p.name,
                p.columns().join(","),
                path.display()
            ));
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
fn check_column(path: &Path, input: &EvalInput, p: &FileParam, (column, values): (usize, &Vec<f32>)) -> Result<()> {
    match p.kind {
        FileParamKind::Bool { .. } => {
            if let Some(i) = values.iter().position(|&x| x != 0.0 && x != 1.0) {
                bail!(
                    "{}:{}: column {column} `{}`: {} is not a bool (0 or 1), which parameter `{}` is",
                    path.display(),
                    input.lines[i],
                    p.name,
                    values[i],
                    p.name
                );
            }
        }
        FileParamKind::Float { min, max, .. } => {
            let outside: Vec<usize> =
                (0..values.len()).filter(|&i| !(min..=max).contains(&f64::from(values[i]))).collect();
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
