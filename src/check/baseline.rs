//! The baseline file: every count, the timing ratios and the environment they were measured in.

use crate::check::timing::TimingRun;
use crate::model::Model;
use crate::schema::InspectReport;
use crate::schema::callgrind::CallgrindRun;
use anyhow::{Context, Result, anyhow, bail};
use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The `format` field of a baseline file.
pub const FORMAT: &str = "brdfprof-check-baseline/1";

/// A saved run: every count, the timing ratios and the environment they were measured in.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Baseline {
    pub format: String,
    pub inspect: InspectReport,
    pub timing: Option<TimingRun>,
    /// Group -> what its figures depend on (key -> value); compared before the group's figures are.
    pub environment: BTreeMap<String, BTreeMap<String, String>>,
}

impl Baseline {
    /// What the run was measured on: the compile-only target (`nvidia:sm_89`) or the device, and the compiler.
    pub fn measured_on(&self) -> (String, String) {
        let device = self.inspect.provenance["device"]["name"].as_str().unwrap_or("?").to_string();
        match &self.inspect.cost {
            Some(c) => (c.target.clone().unwrap_or(device), c.compiler.clone()),
            None => (device, self.inspect.tools.iter().map(|(k, v)| format!("{k} {v}")).collect::<Vec<_>>().join(", ")),
        }
    }
}

/// Reads and checks a baseline file; every error names the file and what is wrong with it.
pub fn load(path: &Path) -> Result<Baseline> {
    let name = path.display();
    let text = String::from_utf8(
        crate::io::read_bounded(path, crate::io::MAX_REPORT_BYTES)
            .with_context(|| format!("baseline {name}: cannot read it"))?,
    )
    .map_err(|_| anyhow::anyhow!("baseline {name}: not UTF-8 text: not a brdfprof baseline"))?;
    let value: serde_json::Value =
        serde_json::from_str(&text).map_err(|e| anyhow!("baseline {name}: corrupt, not valid JSON ({e})"))?;
    match value.get("format").and_then(|f| f.as_str()) {
        Some(FORMAT) => {}
        Some(other) => bail!(
            "baseline {name}: format `{other}`, this brdfprof reads `{FORMAT}`; save a new one with --save-baseline"
        ),
        None => bail!("baseline {name}: not a brdfprof check baseline (no `format` field; expected `{FORMAT}`)"),
    }
    let mut baseline: Baseline =
        serde_json::from_value(value).map_err(|e| anyhow!("baseline {name}: corrupt ({e})"))?;
    validate(&baseline).map_err(|e| anyhow!("baseline {name}: corrupt ({e})"))?;
    let dir = path.parent().unwrap_or(Path::new(""));
    map_file_paths(&mut baseline, |p| {
        let beside = dir.join(p);
        (Path::new(p).is_relative() && beside.is_file()).then(|| normal(&beside).display().to_string())
    });
    Ok(baseline)
}

/// `b` as a baseline file at `path` holds it: each shader file's path relative to the baseline's own folder
/// (where the file exists), so that `check` run from another folder, or the repository checked out elsewhere,
/// finds it (`load` resolves them back; a baseline saved before keeps paths relative to where it was saved,
/// which `load` leaves as they are where the baseline's folder does not hold them).
pub fn with_paths_relative_to(b: &Baseline, path: &Path) -> Baseline {
    let mut out = b.clone();
    let dir = std::path::absolute(path.parent().unwrap_or(Path::new(""))).unwrap_or_default();
    map_file_paths(&mut out, |p| {
        let file = std::path::absolute(p).ok().filter(|f| f.is_file())?;
        Some(relative(&normal(&dir), &normal(&file)).display().to_string())
    });
    out
}

/// Applies `f` to the path of each row's spec that names a shader file, replacing it where `f` answers.
fn map_file_paths(b: &mut Baseline, f: impl Fn(&str) -> Option<String>) {
    for row in &mut b.inspect.rows {
        let Some(spec) = row.spec.clone() else { continue };
        let Some((p, _)) = crate::model::file_model::split_path(&spec, Path::new("")) else { continue };
        let Some(at) = spec.find(p) else { continue };
        if let Some(new) = f(p) {
            row.spec = Some(format!("{}{new}{}", &spec[..at], &spec[at + p.len()..]));
        }
    }
}

/// `p` with `.` dropped and `..` taken back where it can be (no file system access).
fn normal(p: &Path) -> PathBuf {
    let mut out = PathBuf::new();
    for c in p.components() {
        match c {
            std::path::Component::CurDir => {}
            std::path::Component::ParentDir
                if matches!(out.components().next_back(), Some(std::path::Component::Normal(_))) =>
            {
                out.pop();
            }
            other => out.push(other),
        }
    }
    out
}

/// `to` relative to the folder `from` (both absolute and normal).
fn relative(from: &Path, to: &Path) -> PathBuf {
    let (a, b): (Vec<_>, Vec<_>) = (from.components().collect(), to.components().collect());
    let common = a.iter().zip(&b).take_while(|(x, y)| x == y).count();
    let mut out = PathBuf::new();
    for _ in common..a.len() {
        out.push("..");
    }
    for c in &b[common..] {
        out.push(c);
    }
    out
}

/// What serde cannot check: models that parse, statistics a measurement can give (finite; counts whole and
/// not negative), a workload that can be run, and timing figures for known models, one per round. Errors name
/// the statistic or field and its value.
fn validate(b: &Baseline) -> Result<()> {
    if b.inspect.lights == 0 {
        bail!("inspect.lights is 0; a kernel shades at least one light");
    }
    if b.inspect.rows.is_empty() {
        bail!("no rows");
    }
    for (i, row) in b.inspect.rows.iter().enumerate() {
        if b.inspect.rows[..i].iter().any(|r| r.model == row.model) {
            bail!("row `{}` appears twice", row.model);
        }
        // A shader file's spec is read when the file is measured again: a file renamed or deleted since is named
        // as missing then (`missing_files`), which is no fault of the baseline.
        if let Some(s) = row.spec.as_deref().filter(|s| !crate::model::file_model::names_a_file(s)) {
            Model::parse(s).map_err(|e| anyhow!("row `{}`: spec `{s}`: {e}", row.model))?;
        }
        for (k, v) in &row.stats {
            check_statistic(k, *v).map_err(|why| anyhow!("row `{}`: statistic {k} is {v}; {why}", row.model))?;
        }
    }
    for k in &b.inspect.lines {
        for l in &k.lines {
            if let Some((pipe, v)) = l.pipes.iter().find(|(_, v)| !(v.is_finite() && **v >= 0.0)) {
                bail!(
                    "lines of `{}`: {}:{} has {v} cycles on {pipe}; a line's cycles are finite and not negative",
                    k.model,
                    l.file,
                    l.line
                );
            }
        }
    }
    if let Some(cg) = &b.inspect.callgrind {
        validate_callgrind(cg)?;
    }
    if let Some(t) = &b.timing {
        validate_timing(b, t)?;
    }
    Ok(())
}

/// Why a statistic's value cannot come from a measurement, or Ok.
fn check_statistic(key: &str, v: f64) -> Result<(), &'static str> {
    // Net callgrind counts are differences, and drivers report values verbatim (`driver/<executable>/<name>`).
    let signed = key == "callgrind/net-ir-per-eval" || key.strip_prefix("driver/").is_some_and(|k| k.contains('/'));
    let whole = ["spirv/", "spirv-O/", "naga/"].iter().any(|p| key.starts_with(p));
    if !v.is_finite() {
        Err("statistics are finite")
    } else if v < 0.0 && !signed {
        Err("a count cannot be negative")
    } else if whole && v.fract() != 0.0 {
        Err("an instruction count is a whole number")
    } else {
        Ok(())
    }
}

fn validate_callgrind(cg: &CallgrindRun) -> Result<()> {
    if cg.evaluations == 0 {
        bail!("callgrind.evaluations is 0; the measured dispatch evaluates at least once");
    }
    for (i, k) in cg.kernels.iter().enumerate() {
        if k.jit_ir == 0 {
            bail!("callgrind kernel `{}`: jit_ir is 0; a kernel executes instructions", k.label);
        }
        if cg.kernels[..i].iter().any(|o| o.label == k.label) {
            bail!("callgrind kernel `{}` appears twice", k.label);
        }
    }
    Ok(())
}

fn validate_timing(b: &Baseline, t: &TimingRun) -> Result<()> {
    for (field, v) in [
        ("width", t.width as usize),
        ("height", t.height as usize),
        ("lights", t.lights as usize),
        ("rounds", t.rounds),
        ("reps", t.reps),
    ] {
        if v == 0 {
            bail!("timing.{field} is 0; a timing run has at least 1");
        }
    }
    if t.lights != b.inspect.lights {
        bail!("timing.lights is {} but inspect.lights is {}; both come from one run", t.lights, b.inspect.lights);
    }
    let per_round = |what: &str, model: &str, values: &[f64]| -> Result<()> {
        if values.len() != t.rounds {
            bail!("timing.{what} of `{model}`: {} values for {} rounds", values.len(), t.rounds);
        }
        if let Some(v) = values.iter().find(|v| !(v.is_finite() && **v > 0.0)) {
            bail!("timing.{what} of `{model}`: {v} is not a positive number");
        }
        Ok(())
    };
    for (model, ratios) in &t.ratios {
        if b.inspect.row(model).is_none() {
            bail!("timing.ratios: `{model}` is not a row of the baseline");
        }
        per_round("ratios", model, ratios)?;
    }
    for (kernel, ns) in &t.round_ns {
        per_round("round_ns", kernel, ns)?;
    }
    if let Some((kernel, v)) = t.ns_per_eval.iter().find(|(_, v)| !(v.is_finite() && **v > 0.0)) {
        bail!("timing.ns_per_eval of `{kernel}`: {v} is not a positive number");
    }
    Ok(())
}
