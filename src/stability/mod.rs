//! `brdfprof stability`: do the kernels stay finite, non-negative and close to their f64 limits where things
//! break? Every spec runs the catalogue of hard cases and the dense grid on the GPU; results are checked
//! against the f64 twin within a tolerance that respects the input's conditioning; jumps the f64 model does not
//! have are reported as discontinuities; reciprocity and energy (directional albedo with F = 1) complete it.

pub mod catalogue;
mod check;
pub mod energy;
pub mod failures;
pub mod grid;

pub use check::{Checks, Expected, check_model};

use crate::accuracy::FLOOR;
use crate::brdf::guards::{GuardSet, SWITCHES, unit};
use crate::brdf::spec::with_each_param_sample;
use crate::brdf::{D, F, ModelSpec, Precision, Sample, Vis, samples};
use crate::gpu::Gpu;

use crate::model::Model;
use anyhow::Result;
use catalogue::{Expect, HardCase};
use indicatif::ProgressBar;
use rand::{Rng, SeedableRng};

use serde::{Deserialize, Deserializer, Serialize};

/// Every D with every Vis (Schlick Fresnel), and every Fresnel term on the reference preset (with each metal
/// where it reads one), in fp32 and fp16: every spec the term library offers up to the choice of Fresnel.
pub fn default_specs() -> Vec<ModelSpec> {
    let mut specs = Vec::new();
    for precision in Precision::ALL {
        for &d in D::ALL {
            for &vis in Vis::ALL {
                specs.push(ModelSpec { precision, ..ModelSpec::new(d, vis, F::Schlick) });
            }
        }
        let reference = ModelSpec { precision, ..ModelSpec::reference() };
        for &f in F::ALL {
            for s in with_each_param_sample(ModelSpec { f, ..reference }) {
                if !specs.contains(&s) {
                    specs.push(s);
                }
            }
        }
    }
    specs
}

/// Absolute rounding of a unit vector's components in the kernel's arithmetic (normalising costs about an ulp
/// of 1 on top of the component's own half ulp): 2^-23 in fp32, 2^-11 in fp16.
fn unit_epsilon(p: Precision) -> f64 {
    match p {
        Precision::F32 => 2f64.powi(-23),
        Precision::F16 => 2f64.powi(-11),
    }
}

/// Relative tolerance of a well-conditioned result.
fn base_tolerance(p: Precision) -> f64 {
    match p {
        Precision::F32 => 1e-3,
        Precision::F16 => 2e-2,
    }
}

/// How far the expected f64 result moves when the kernel's unit vectors carry the rounding of its arithmetic:
/// the largest change over 8 random perturbations of every unit-vector component by +-epsilon (absolute; not
/// renormalised, as the kernel adds V + L without renormalising them) and of roughness and F0 by +-epsilon
/// (relative). Where the half vector is ill-conditioned (V near -L, |V + L| small), a lobe is razor-thin or a
/// cosine is near 0 (the exact formula's 1/NoV), this is what any implementation at that precision can promise.
fn sensitivity(expected: &Expected, s: &Sample, channel: usize, epsilon: f64, seed: u64) -> f64 {
    let (n, v, l) = (unit(s.n), unit(s.v), unit(s.l));
    let (r, f0) = (f64::from(s.roughness), s.f0.map(f64::from));
    let Some(base) = expected.at_unit(n, v, l, r, f0) else { return 0.0 };
    let base = base[channel];
    let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
    let mut sign = || if rng.random::<bool>() { 1.0 } else { -1.0 };
    (0..8)
        .map(|_| {
            let mut shift = |u: glam::DVec3| u + glam::DVec3::new(epsilon * sign(), epsilon * sign(), epsilon * sign());
            let (pn, pv, pl) = (shift(n), shift(v), shift(l));
            let pr = r * (1.0 + epsilon * sign());
            let pf = f0.map(|x| x * (1.0 + epsilon * sign()));
            expected.at_unit(pn, pv, pl, pr, pf).map_or(0.0, |e| (e[channel] - base).abs())
        })
        .fold(0.0, f64::max)
}

/// The tolerance for one value: the base tolerance of the model's precision, or four times what the rounding
/// of the kernel's unit vectors alone moves the expected f64 result, whichever is larger.
pub fn tolerance(expected: &Expected, s: &Sample, channel: usize, value: f64, seed: u64) -> f64 {
    let base = base_tolerance(expected.precision) * value.abs().max(FLOOR);
    base.max(4.0 * sensitivity(expected, s, channel, unit_epsilon(expected.precision), seed))
}

/// A stability report is read back (`report`, `--html`) as these same types: what no reader shows is skipped,
/// a figure written as null (NaN or Inf) reads as NaN (`io::finite`), and what an older report lacks takes the
/// default it stood for then.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct CaseResult {
    pub case: String,
    /// The input as a reader checks it (`failures::describe`; empty in a report written before it).
    #[serde(default)]
    pub inputs: String,
    #[serde(skip_deserializing)]
    pub expected: Option<[f64; 3]>,
    #[serde(skip_deserializing)]
    pub got: [f32; 3],
    /// Largest |got - expected| / tolerance over the channels (NaN/Inf count as infinite).
    #[serde(default = "crate::io::nan", deserialize_with = "crate::io::nan_if_null")]
    pub deviation: f64,
    #[serde(skip_deserializing)]
    pub ok: bool,
}

/// A hard case at the model's declared domain's own bounds (`catalogue::at_domain_bounds`), with what its
/// precision loses there against the formula's exact value, said even within tolerance.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct BoundCase {
    pub case: String,
    pub inputs: String,
    /// The channel furthest from the exact value (relatively).
    #[serde(default = "crate::io::nan", deserialize_with = "crate::io::nan_if_null")]
    pub got: f64,
    pub exact: Option<f64>,
    /// got / exact - 1, signed (negative: low).
    pub loss: Option<f64>,
    #[serde(default = "crate::io::nan", deserialize_with = "crate::io::nan_if_null")]
    pub deviation: f64,
    pub ok: bool,
}

#[derive(Clone, Debug, Default, Serialize, Deserialize)]
#[serde(default)]
pub struct Worst {
    /// |got - expected| in units of the tolerance.
    #[serde(default = "crate::io::nan", deserialize_with = "crate::io::nan_if_null")]
    pub deviation: f64,
    #[serde(skip_deserializing)]
    pub got: f32,
    #[serde(skip_deserializing)]
    pub expected: f64,
    pub input: String,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct SpecStability {
    /// What tables and charts call it (`Model::label`; empty in a report written before labels).
    #[serde(default)]
    pub label: String,
    /// The text that parses back to the model (`Model::name`).
    pub spec: String,
    pub precision: String,
    /// Whether the model has an f64 twin.
    #[serde(default)]
    pub has_twin: bool,
    /// What its results were checked against: `twin`, `reference `SPEC`` (`--reference`, for a model
    /// without a twin), or None: then nothing is out of tolerance (there is nothing to be within) and jumps
    /// are not counted (every step of a finely sampled lobe would be one), only NaN, Inf and negative values.
    pub expected_from: Option<String>,
    /// The input ranges checked (roughness, NoV, NoL), where any was given or declared, and the valid hard
    /// cases and grid points outside them (not counted).
    #[serde(skip_deserializing)]
    pub domain: Option<String>,
    #[serde(skip_deserializing)]
    pub cases_outside_domain: usize,
    #[serde(skip_deserializing)]
    pub grid_outside_domain: usize,
    /// On valid inputs (catalogue and grid).
    pub nan: usize,
    pub inf: usize,
    pub negative: usize,
    /// Non-finite or negative results from invalid inputs (NaN/Inf in), reported, not failing.
    #[serde(default)]
    pub invalid_input_poisoned: usize,
    /// Hard cases run, and the results of those out of tolerance (or poisoned, for invalid input).
    pub cases_run: usize,
    pub cases_out_of_tolerance: Vec<CaseResult>,
    /// Largest deviation per hard case, in catalogue order (for the per-case summary).
    #[serde(skip)]
    pub case_deviation: Vec<f64>,
    /// Valid hard cases with no value to check against, each with why (`NoValue`): the reference's D is
    /// singular there, or its exact value is beyond fp32's range.
    #[serde(default)]
    pub cases_without_value: Vec<String>,
    /// Grid points in the domain likewise.
    #[serde(default)]
    pub grid_without_value: usize,
    /// Grid points out of tolerance.
    pub grid_out_of_tolerance: usize,
    #[serde(default = "no_worst")]
    pub worst: Worst,
    /// Whether jumps were looked for (with an expectation to tell the model's own steps from breaks; reports
    /// written before it counted them always).
    #[serde(default = "always", deserialize_with = "true_if_null")]
    pub jumps_checked: bool,
    /// Steps in f_s NoL along NoV, NoL or roughness that the f64 model does not take, at values out of tolerance.
    #[serde(default)]
    pub discontinuities: usize,
    #[serde(skip_deserializing)]
    pub discontinuity_examples: Vec<String>,
    /// Steps the f64 model takes too, between lit points (the formula's and its guards' own).
    #[serde(default)]
    pub model_jumps: usize,
    /// max |f(v, l) - f(l, v)| / max(|f|, 1e-3) over the reciprocity samples whose values are finite (None
    /// when none is).
    pub reciprocity: Option<f64>,
    /// Reciprocity values (sample pairs x channels) left out because either side is NaN or Inf.
    #[serde(skip_deserializing)]
    pub reciprocity_nonfinite: usize,
    /// Bad values (NaN, Inf, negative) per (NoV, roughness) grid cell, [roughness][NoV], where any; written
    /// as `cell_triples`.
    #[serde(serialize_with = "sparse_cells", skip_deserializing)]
    pub bad_cells: Option<Vec<Vec<u32>>>,
    /// `bad_cells` as read back: the triples as written (None in a measured report). Kept sparse because the
    /// grid the report was measured on need not be this build's, and the page draws from the triples.
    #[serde(rename = "bad_cells", skip_serializing)]
    pub bad_cell_triples: Option<Vec<[u32; 3]>>,
    /// Every failing valid input: hard cases by name, grid points counted (the first listed), each with its
    /// input values and the input guards that remove it (empty in a report written before they were listed).
    #[serde(default)]
    pub failures: failures::Failures,
    /// The cases at the declared domain's bounds (empty without a domain).
    #[serde(default)]
    pub at_domain_bounds: Vec<BoundCase>,
    pub energy: Option<energy::Energy>,
}

/// Bad cells as [roughness index, NoV index, count] triples of the non-empty cells, row by row.
fn cell_triples(cells: &[Vec<u32>]) -> Vec<[u32; 3]> {
    cells
        .iter()
        .enumerate()
        .flat_map(|(r, row)| {
            row.iter().enumerate().filter(|(_, n)| **n > 0).map(move |(v, n)| [r as u32, v as u32, *n])
        })
        .collect()
}

fn sparse_cells<S: serde::Serializer>(cells: &Option<Vec<Vec<u32>>>, s: S) -> Result<S::Ok, S::Error> {
    cells.as_deref().map(cell_triples).serialize(s)
}

/// What a report without a worst deviation reads as: none known.
fn no_worst() -> Worst {
    Worst { deviation: f64::NAN, ..Worst::default() }
}

fn always() -> bool {
    true
}

fn true_if_null<'de, D: Deserializer<'de>>(d: D) -> Result<bool, D::Error> {
    Ok(Option::<bool>::deserialize(d)?.unwrap_or(true))
}

impl SpecStability {
    /// NaN, Inf or a negative value on a valid input.
    pub fn fails(&self) -> bool {
        self.nan + self.inf + self.negative > 0
    }

    /// The bad values per (roughness, NoV) grid cell, as measured or as read back from a report's triples.
    pub fn dense_bad_cells(&self) -> Option<Vec<Vec<u32>>> {
        if let Some(c) = &self.bad_cells {
            return Some(c.clone());
        }
        let triples = self.bad_cell_triples.as_ref().filter(|t| !t.is_empty())?;
        let mut cells = vec![vec![0u32; grid::COSINES.len()]; grid::ROUGHNESS.len()];
        for &[r, v, n] in triples {
            if let Some(c) = cells.get_mut(r as usize).and_then(|row| row.get_mut(v as usize)) {
                *c = n;
            }
        }
        Some(cells)
    }

    /// What to call it: its label, or its spec in a report written before labels.
    pub fn label(&self) -> &str {
        if self.label.is_empty() { &self.spec } else { &self.label }
    }

    /// Whether its values were checked against expected ones (a twin or a reference).
    pub fn checked(&self) -> bool {
        self.has_twin || self.expected_from.is_some()
    }
}

#[derive(Clone, Debug)]
pub struct StabilityOptions {
    pub models: Vec<Model>,
    pub energy: bool,
    /// Expected values for the models without an f64 twin (`--reference`).
    pub reference: Option<ModelSpec>,
    /// The roughness, NoV and NoL ranges checked (`--roughness`, `--nov`, `--nol`); else each file's declared
    /// domain, else all.
    pub roughness: Option<(f64, f64)>,
    pub nov: Option<(f64, f64)>,
    pub nol: Option<(f64, f64)>,
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct StabilityReport {
    pub provenance: crate::export::json::Provenance,
    pub specs: Vec<SpecStability>,
    pub grid_points: usize,
    pub cases: Vec<HardCase>,
    /// What each guard saves, where a spec ran with and without some of its guards (`with_guard_variants`).
    #[serde(skip_deserializing)]
    pub guard_savings: Vec<GuardSaving>,
}

/// A spec run without some of its guards against the same spec with all of them: what they save.
#[derive(Clone, Debug, Serialize)]
pub struct GuardSaving {
    /// The guarded spec's name.
    pub spec: String,
    /// The guards taken off, as the spec key writes them (`off`, `off:sin2h`).
    pub off: String,
    /// NaN, Inf and negative results on valid inputs without them (the guarded spec has none where it passes).
    pub nan: usize,
    pub inf: usize,
    pub negative: usize,
    /// Grid points out of tolerance without them, beyond the guarded spec's.
    pub grid_out_of_tolerance: usize,
    /// The hard cases out of tolerance without them and within it with them.
    pub cases: Vec<String>,
}

/// `models`, each built-in spec that keeps all its guards followed by the same spec with all of them off, with
/// each one off alone (`guards=off:NAME`: what that guard saves that the others do not) and with each one on
/// alone (what it saves by itself): the runs `guard_savings` reads.
pub fn with_guard_variants(models: Vec<Model>) -> Vec<Model> {
    let mut out = Vec::new();
    for m in models {
        let variants: Vec<Model> = match m.twin().filter(|s| s.guards == GuardSet::ALL) {
            Some(s) => std::iter::once(GuardSet::NONE)
                .chain(SWITCHES.iter().map(|g| GuardSet(GuardSet::ALL.0 & !g.bit)))
                .chain(SWITCHES.iter().map(|g| GuardSet(g.bit)))
                .map(|guards| Model::spec(ModelSpec { guards, ..*s }))
                .collect(),
            None => Vec::new(),
        };
        out.push(m);
        out.extend(variants);
    }
    let mut seen = Vec::new();
    out.retain(|m| {
        if seen.contains(m) {
            false
        } else {
            seen.push(m.clone());
            true
        }
    });
    out
}

/// A guard set as a reader says it: `none`, `all but NAME`, `only NAME`, or the spec key's form.
fn describe_guards(text: &str) -> String {
    let Ok(set) = GuardSet::parse(text) else { return text.to_string() };
    let on: Vec<&str> = SWITCHES.iter().filter(|g| set.0 & g.bit != 0).map(|g| g.name).collect();
    let off: Vec<&str> = SWITCHES.iter().filter(|g| set.0 & g.bit == 0).map(|g| g.name).collect();
    match (on.as_slice(), off.as_slice()) {
        ([], _) => "none (`off`)".into(),
        ([only], _) => format!("only {only}"),
        (_, [one]) => format!("all but {one}"),
        _ => format!("`{text}`"),
    }
}

/// For each spec run with all its guards and also with some off, what those guards save (`GuardSaving`).
fn guard_savings(models: &[Model], specs: &[SpecStability], cases: &[HardCase]) -> Vec<GuardSaving> {
    let mut out = Vec::new();
    for (i, guarded) in models.iter().enumerate() {
        let Some(g) = guarded.twin().filter(|s| s.guards == GuardSet::ALL) else { continue };
        for (j, without) in models.iter().enumerate() {
            let Some(w) = without
                .twin()
                .filter(|w| w.guards != GuardSet::ALL && ModelSpec { guards: GuardSet::ALL, ..**w } == *g)
            else {
                continue;
            };
            let saved =
                (0..cases.len()).filter(|&k| specs[j].case_deviation[k] > 1.0 && specs[i].case_deviation[k] <= 1.0);
            out.push(GuardSaving {
                spec: specs[i].spec.clone(),
                off: w.guards.text(),
                nan: specs[j].nan,
                inf: specs[j].inf,
                negative: specs[j].negative,
                grid_out_of_tolerance: specs[j].grid_out_of_tolerance.saturating_sub(specs[i].grid_out_of_tolerance),
                cases: saved.map(|k| cases[k].name.clone()).collect(),
            });
        }
    }
    out
}

impl StabilityReport {
    pub fn failing(&self) -> Vec<&SpecStability> {
        self.specs.iter().filter(|s| s.fails()).collect()
    }

    /// Writes stability-<device>.md and .json, the furnace and albedo charts and the failures' heat map under
    /// `out`; returns their paths.
    pub fn write(&self, out: &std::path::Path, device: &str) -> Result<Vec<std::path::PathBuf>> {
        let stem = out.join(format!("stability-{device}"));
        let mut written = vec![stem.with_extension("md"), stem.with_extension("json")];
        crate::export::json::write_report_compact(&written[1], crate::export::json::Kind::Stability, self)?;
        crate::io::write_markdown(&written[0], &self.markdown())?;
        let entries = self.energy_entries();
        if !entries.is_empty() {
            let furnace = out.join(format!("furnace-{device}.png"));
            let albedo = out.join(format!("albedo-{device}.png"));
            energy::furnace_png(&furnace, &entries)?;
            energy::albedo_chart(&albedo, &entries)?;
            written.extend([furnace, albedo]);
        }
        let heat = out.join(format!("stability-{device}-failures.png"));
        if self.heatmaps(&heat)? {
            written.push(heat);
        }
        Ok(written)
    }
}

pub fn run(gpu: &Gpu, options: &StabilityOptions, progress: &ProgressBar) -> Result<StabilityReport> {
    let cases = catalogue::hard_cases();
    let grid = grid::samples();
    let reciprocity = samples::well_conditioned(20_000, 4, 1e-3, 0.0..1.0);
    let mut specs = Vec::new();
    progress.set_length(options.models.len() as u64);
    for (i, model) in options.models.iter().enumerate() {
        progress.set_position(i as u64);
        progress.set_message(model.name());
        model.check_support(&gpu.info)?;
        // A file's own reference and domains where the command line gives none.
        let declared = model.declared_reference();
        let (nov, nol) = model.cosine_domains();
        let checks = Checks {
            reference: options.reference.as_ref().or(declared.as_ref()),
            roughness: options.roughness.or(model.roughness_domain()),
            nov: options.nov.or(nov),
            nol: options.nol.or(nol),
            f_nol: model.file().is_some_and(|f| f.returns_f_nol()),
        };
        if let Some(why) = checks.leaves_nothing(&cases, &grid) {
            anyhow::bail!("{}: {why}", model.label());
        }
        specs.push(check_model(gpu, model, &checks, &cases, &grid, &reciprocity)?);
    }
    if options.energy {
        energy::attach(gpu, &options.models, &mut specs, progress)?;
    }
    let guard_savings = guard_savings(&options.models, &specs, &cases);
    Ok(StabilityReport {
        provenance: crate::export::json::Provenance::new(&gpu.info),
        specs,
        grid_points: grid.len(),
        cases,
        guard_savings,
    })
}

/// The "cases out of tolerance" cell, as the Markdown and the HTML page both write it: without a twin or
/// reference a case is counted only for a NaN, Inf or negative value (or a poisoned invalid input).
pub fn cases_cell(out: usize, run: usize, checked: bool) -> String {
    if checked { format!("{out}/{run}") } else { format!("{out}/{run} (no twin)") }
}

/// The jumps cell, as the Markdown and the HTML page both write it.
pub fn jumps_cell(n: usize, checked: bool) -> String {
    if checked { n.to_string() } else { "- (no reference)".into() }
}

/// A stability run's spec with some of brdfprof's guards off (`--unguarded`): a variant, not a model.
pub fn is_guard_variant(spec: &str) -> bool {
    Model::parse(spec).ok().and_then(|m| m.twin().map(|s| s.guards != GuardSet::ALL)).unwrap_or(false)
}

/// The failures picture's colour key under its title: grey for none, then yellow to red up to each panel's
/// own most.
fn draw_heat_key(
    top: &plotters::drawing::DrawingArea<plotters::prelude::BitMapBackend, plotters::coord::Shift>,
) -> Result<()> {
    use crate::export::text::{self, Style};
    use plotters::prelude::*;
    let err = |e: &dyn std::fmt::Display| anyhow::anyhow!("heat map: {e}");
    let ink = |size: u32, bold: bool| Style { size, bold, colour: BLACK, vertical: false };
    // The key: grey for none, then yellow to red up to each panel's own most.
    let (kx, ky, kw) = (10, 42, 260);
    top.draw(&Rectangle::new([(kx, ky), (kx + 22, ky + 14)], heat_colour(0, 1.0).filled())).map_err(|e| err(&e))?;
    text::draw(&top, "none", (kx + 26, ky - 1), ink(13, false))?;
    let gx = kx + 70;
    for i in 0..kw {
        let n = 1 + (i as usize * 999) / (kw as usize - 1);
        let c = heat_colour(n, 1000.0);
        top.draw(&Rectangle::new([(gx + i, ky), (gx + i + 1, ky + 14)], c.filled())).map_err(|e| err(&e))?;
    }
    text::draw(&top, "one bad value", (gx, ky + 16), ink(12, false))?;
    let most = "the most in that panel";
    text::draw(&top, most, (gx + kw - text::measure(most, 12, false).0, ky + 16), ink(12, false))?;
    text::draw(&top, "bad values per cell (linear in each panel)", (gx + kw + 16, ky - 1), ink(13, false))?;
    Ok(())
}

/// One failing spec's panel: its caption (`fit_caption`) over its grid of bad values per cell.
fn draw_heat_panel(
    area: &plotters::drawing::DrawingArea<plotters::prelude::BitMapBackend, plotters::coord::Shift>,
    label: &str,
    cells: &[Vec<u32>],
    (pw, caption): (u32, u32),
) -> Result<()> {
    use crate::export::text::{self, Style};
    use plotters::prelude::*;
    let err = |e: &dyn std::fmt::Display| anyhow::anyhow!("heat map: {e}");
    let ink = |size: u32, bold: bool| Style { size, bold, colour: BLACK, vertical: false };
    let max = cells.iter().flatten().copied().max().unwrap_or(1).max(1) as f64;
    let (label_area, plot) = area.split_vertically(caption);
    let (lines, size) = fit_caption(label, pw as i32 - 12);
    for (k, line) in lines.iter().enumerate() {
        let w = text::measure(line, size, false).0;
        text::draw(&label_area, line, ((pw as i32 - w) / 2, 2 + k as i32 * (size as i32 + 2)), ink(size, false))?;
    }
    let mut chart = ChartBuilder::on(&plot)
        .margin(6)
        .x_label_area_size(28)
        .y_label_area_size(36)
        .build_cartesian_2d(0..grid::COSINES.len(), 0..grid::ROUGHNESS.len())
        .map_err(|e| err(&e))?;
    chart
        .configure_mesh()
        .disable_mesh()
        .x_desc("NoV")
        .y_desc("roughness")
        .x_labels(8)
        .y_labels(8)
        .x_label_formatter(&|i| axis_value(grid::COSINES.get(*i).copied()))
        .y_label_formatter(&|i| axis_value(grid::ROUGHNESS.get(*i).map(|&r| f64::from(r))))
        .label_style((crate::export::png::FONT, 10))
        .draw()
        .map_err(|e| err(&e))?;
    chart
        .draw_series(cells.iter().enumerate().flat_map(|(r, row)| {
            row.iter()
                .enumerate()
                .map(move |(v, &n)| Rectangle::new([(v, r), (v + 1, r + 1)], heat_colour(n as usize, max).filled()))
        }))
        .map_err(|e| err(&e))?;
    Ok(())
}

/// A heat-map cell's colour: light grey for none, then yellow to red by `n / most`.
fn heat_colour(n: usize, most: f64) -> plotters::style::RGBColor {
    use plotters::style::RGBColor;
    if n == 0 {
        return RGBColor(235, 235, 235);
    }
    let t = (n as f64 / most).clamp(0.0, 1.0);
    RGBColor(255, (200.0 * (1.0 - t)) as u8, (60.0 * (1.0 - t)) as u8)
}

/// A panel's caption in at most two lines no wider than `width`: the largest size from 13 px down to 9 that
/// fits, the spec split at the comma nearest its middle; past that, shortened in the middle with an ellipsis.
fn fit_caption(label: &str, width: i32) -> (Vec<String>, u32) {
    use crate::export::text::measure;
    let fits = |t: &str, z: u32| measure(t, z, false).0 <= width;
    let halves = || {
        let commas: Vec<usize> = label.match_indices(',').map(|(i, _)| i).collect();
        let mid = label.len() / 2;
        commas
            .into_iter()
            .min_by_key(|&i| i.abs_diff(mid))
            .map(|i| (label[..=i].to_string(), label[i + 1..].to_string()))
    };
    for z in (9..=13).rev() {
        if fits(label, z) {
            return (vec![label.to_string()], z);
        }
        if let Some((a, b)) = halves().filter(|(a, b)| fits(a, z) && fits(b, z)) {
            return (vec![a, b], z);
        }
    }
    let chars: Vec<char> = label.chars().collect();
    let mut keep = chars.len();
    while keep > 4 {
        keep -= 1;
        let t: String =
            chars[..keep / 2].iter().chain(['\u{2026}'].iter()).chain(&chars[chars.len() - keep / 2..]).collect();
        if fits(&t, 9) {
            return (vec![t], 9);
        }
    }
    (vec![label.to_string()], 9)
}

/// A heat-map cell's value on its axis (the grid's spacing is not even: each cell is labelled with its value).
fn axis_value(x: Option<f64>) -> String {
    match x {
        Some(x) if x == 0.0 || (1e-2..=1.0).contains(&x) => format!("{}", (x * 1e4).round() / 1e4),
        Some(x) => format!("{x:.0e}"),
        None => String::new(),
    }
}

/// A signed relative difference as a reader says it: "20% low", "3.1e-05 high", "exact".
pub fn loss_text(x: f64) -> String {
    let side = if x < 0.0 { "low" } else { "high" };
    match x.abs() {
        0.0 => "exact".into(),
        a if a >= 1e-3 => format!("{}% {side}", crate::export::markdown::sig(100.0 * a, 3)),
        a => format!("{a:.1e} {side}"),
    }
}

/// The worst deviation as a table cell: in tolerances, or what the value was when it is not a number.
fn worst_cell(w: &Worst) -> String {
    if w.got.is_nan() {
        "NaN result".into()
    } else if w.got.is_infinite() {
        "Inf result".into()
    } else {
        format!("{:.2e}", w.deviation)
    }
}

/// The max E, hemispherical albedo and E-vs-CPU cells, NaN/Inf cells counted (never a gain, never "inf").
fn energy_cells(e: &energy::Energy) -> (String, String, String) {
    use crate::export::markdown::sig;
    let nonfinite =
        if e.nonfinite > 0 { format!(" ({} of {} cells NaN/Inf)", e.nonfinite, e.cells()) } else { String::new() };
    let max_e = match e.max_e {
        Some(m) => {
            format!("{}{} (±{:.0e}){nonfinite}", sig(m, 3), if e.gains_energy { " gain" } else { "" }, e.error_bound)
        }
        None => format!("-{nonfinite}"),
    };
    let hemi = if e.hemispherical_at_r1.is_finite() { sig(e.hemispherical_at_r1, 3) } else { "- (NaN/Inf)".into() };
    let cpu_nonfinite =
        if e.cpu_check_nonfinite > 0 { format!(" ({} NaN/Inf)", e.cpu_check_nonfinite) } else { String::new() };
    (max_e, hemi, format!("{}{cpu_nonfinite}", e.cpu_check.map_or("- (no twin)".into(), |c| format!("{c:.1e}"))))
}

/// Reciprocity as a table cell, with the values it had to leave out.
fn reciprocity_cell(s: &SpecStability) -> String {
    let left_out =
        if s.reciprocity_nonfinite > 0 { format!(" ({} NaN/Inf)", s.reciprocity_nonfinite) } else { String::new() };
    match s.reciprocity {
        Some(r) => format!("{r:.1e}{left_out}"),
        None => format!("-{left_out}"),
    }
}

impl StabilityReport {
    pub fn markdown(&self) -> String {
        use crate::export::markdown::Table;
        let mut out = format!(
            "# brdfprof stability\n\n{} ({}), {} specs; {} hard cases and {} grid points each.\n\n\
             NaN/Inf/neg: results on valid inputs (a spec with any fails, and the command exits 1). Out of tolerance: cases and \
             grid points whose result is further from the expected value (a built-in spec's f64 twin, which applies the same guards; \
             a model without one: its reference's formula exactly at the same inputs, with no roughness or cosine floor, where \
             an input with no exact value (roughness 0) or one beyond fp32's range is said, not judged) than max(base, 4 x what rounding the inputs at the kernel's precision alone moves the f64 result), base = 1e-3 (fp32) \
             or 2e-2 (fp16) relative; worst: that distance in tolerances. Jumps: steps in f_s NoL along NoV, NoL or roughness \
             that the f64 model does not take. Reciprocity: max |f(v,l) - f(l,v)| / max(|f|, 1e-3) over finite pairs (NaN/Inf \
             values are counted, never taken for agreement). E: directional albedo with F = 1 (max over the finite cells of \
             NoV in [0.02, 1], r in [0.1, 1]; error bound of the integration; NaN/Inf cells counted); hemi r=1: the hemispherical albedo \
             at r = 1, so 1 - hemi is the energy single scattering loses; E vs CPU: max |E_gpu - E_cpu| / max(1, E_cpu) against \
             the CPU's f64 integration of the same formula at r = 0.1, 0.5, 1. A `.brdf` model has no f64 twin: its NaN, Inf \
             and negative counts (each tied to its hard case or grid point below, with the input guards that remove it), \
             invalid-input cases, reciprocity and E (its own Fresnel, given F0 = 1) are measured; tolerances and jumps only \
             against a `--reference` spec's f64 values, E vs CPU not at all. A domain (`--roughness`, `--nov`, `--nol`, a \
             file's `domain` lines) leaves the valid cases and grid points outside it uncounted.\n\n",
            self.provenance.device.name,
            self.provenance.device.driver_info,
            self.specs.len(),
            self.cases.len(),
            self.grid_points
        );
        if !self.provenance.front_ends.is_empty() {
            out +=
                &format!("{}\n\n", crate::export::markdown::front_ends_line(&self.provenance.front_ends).trim_start());
        }
        let mut t = Table::new([
            "spec",
            "NaN",
            "Inf",
            "neg",
            "cases out of tol.",
            "grid out of tol.",
            "worst (x tol.)",
            "jumps",
            "reciprocity",
            "max E",
            "hemi r=1",
            "E vs CPU",
            "verdict",
        ]);
        for s in &self.specs {
            let (max_e, hemi, cpu) = s.energy.as_ref().map_or(("-".into(), "-".into(), "-".into()), energy_cells);
            t.row([
                s.label.clone(),
                s.nan.to_string(),
                s.inf.to_string(),
                s.negative.to_string(),
                cases_cell(s.cases_out_of_tolerance.len(), s.cases_run, s.expected_from.is_some()),
                if s.expected_from.is_some() { s.grid_out_of_tolerance.to_string() } else { "-".into() },
                if s.expected_from.is_some() { worst_cell(&s.worst) } else { "-".into() },
                jumps_cell(s.discontinuities, s.jumps_checked),
                reciprocity_cell(s),
                max_e,
                hemi,
                cpu,
                if s.fails() { "FAIL".into() } else { "ok".into() },
            ]);
        }
        out += &t.markdown();
        out += &self.expectations_markdown();
        out += &self.out_of_tolerance_markdown();
        out += &self.bounds_markdown();
        out += &self.cases_markdown();
        out += &self.guard_savings_markdown();
        out += &self.failing_markdown();
        out
    }

    /// Where each spec checked against a reference or twin is out of tolerance: its worst value and every
    /// hard case out of tolerance, each with its inputs, what it got and what was expected.
    fn out_of_tolerance_markdown(&self) -> String {
        let mut out = String::new();
        for s in self.specs.iter().filter(|s| s.checked()) {
            let cases: Vec<&CaseResult> = s.cases_out_of_tolerance.iter().filter(|c| c.expected.is_some()).collect();
            if cases.is_empty() && s.grid_out_of_tolerance == 0 {
                continue;
            }
            out += &format!(
                "- `{}`: {} hard cases and {} grid points out of tolerance; the worst, {} x tolerance, at {}: got {}, expected {}\n",
                crate::export::escape_line(s.label()),
                cases.len(),
                s.grid_out_of_tolerance,
                worst_cell(&s.worst),
                s.worst.input,
                crate::export::markdown::sig(f64::from(s.worst.got), 4),
                crate::export::markdown::sig(s.worst.expected, 4)
            );
            for c in cases {
                let worst = (0..3)
                    .max_by(|&a, &b| {
                        let e = c.expected.unwrap_or_default();
                        (f64::from(c.got[a]) - e[a]).abs().total_cmp(&(f64::from(c.got[b]) - e[b]).abs())
                    })
                    .unwrap_or(0);
                out += &format!(
                    "  - `{}` at {}: got {}, expected {} ({:.2e} x tolerance)\n",
                    c.case,
                    c.inputs,
                    crate::export::markdown::sig(f64::from(c.got[worst]), 4),
                    crate::export::markdown::sig(c.expected.unwrap_or_default()[worst], 4),
                    c.deviation
                );
            }
        }
        if out.is_empty() {
            return out;
        }
        format!(
            "\n## Out of tolerance: where\n\nEach spec's worst value and every hard case out of tolerance, with its inputs (the channel furthest from the expected value).\n\n{out}"
        )
    }

    /// The cases at each declared domain's bounds, with what the precision loses there against the formula's
    /// exact value, within tolerance or not.
    fn bounds_markdown(&self) -> String {
        use crate::export::markdown::{Table, sig};
        let mut t = Table::new(["spec", "case", "inputs", "got", "exact", "loss", "x tol.", "verdict"]);
        let mut any = false;
        for s in &self.specs {
            for b in &s.at_domain_bounds {
                any = true;
                t.row([
                    crate::export::escape_line(s.label()),
                    b.case.clone(),
                    b.inputs.clone(),
                    sig(b.got, 4),
                    b.exact.map_or("-".into(), |e| sig(e, 4)),
                    b.loss.map_or("-".into(), loss_text),
                    if b.deviation.is_finite() { format!("{:.2e}", b.deviation) } else { "-".into() },
                    if b.ok { "within".into() } else { "out of tolerance".into() },
                ]);
            }
        }
        if !any {
            return String::new();
        }
        format!(
            "\n## At the domain's bounds\n\nEach declared domain's own ends (roughness minimum and maximum: the peak N = H, the peak at grazing, off the peak; the NoV and NoL minimum), which the catalogue's fixed values may miss: the result against the formula's exact value there (no floor), and what the kernel's precision loses, said even within tolerance.\n\n{}",
            t.markdown()
        )
    }

    /// The hard-case table: how many specs each case puts out of tolerance, and the worst.
    fn cases_markdown(&self) -> String {
        use crate::export::markdown::Table;
        let mut out = String::from(
            "\n## Hard cases\n\nSpecs out of tolerance per case (fp32 / fp16; without a twin or reference: with a NaN, Inf or negative value), with the worst one.\n\n",
        );
        let mut c = Table::new(["case", "expected", "fp32 out", "fp16 out", "worst spec (x tol.)"]);
        for (i, case) in self.cases.iter().enumerate() {
            let count = |p: &str| self.specs.iter().filter(|s| s.precision == p && s.case_deviation[i] > 1.0).count();
            let worst = self
                .specs
                .iter()
                .max_by(|a, b| a.case_deviation[i].total_cmp(&b.case_deviation[i]))
                .filter(|s| s.case_deviation[i] > 1.0);
            c.row([
                case.name.clone(),
                match case.expect {
                    Expect::Twin => "f64 limit (twin)".into(),
                    Expect::FiniteNonNegative => "finite >= 0 (invalid input)".into(),
                },
                count("f32").to_string(),
                count("f16").to_string(),
                worst.map_or("-".into(), |s| format!("{} ({:.1e})", s.label, s.case_deviation[i])),
            ]);
        }
        out += &c.markdown();
        out
    }

    /// Where each failing spec fails, and the guards that remove each failure.
    fn failing_markdown(&self) -> String {
        let mut out = String::new();
        let failing = self.failing();
        if !failing.is_empty() {
            let guards: Vec<String> =
                crate::brdf::guards::INPUT_GUARDS.iter().map(|g| format!("`{}` ({})", g.name, g.does)).collect();
            out += &format!(
                "\n## Failing specs: where they fail\n\nEvery valid hard case with a NaN, Inf or negative result, the grid points with one (the first {} listed), \
                 and which of brdfprof's guards, applied to the inputs as an engine's caller could, removes each: {}; `{}`: all of them at once.\n\n",
                failures::GRID_EXAMPLES,
                guards.join("; "),
                failures::ALL_GUARDS
            );
            for s in failing {
                let worst = if s.expected_from.is_some() && s.worst.deviation.is_finite() {
                    format!("; worst deviation {:.2e} x tolerance at {}", s.worst.deviation, s.worst.input)
                } else {
                    String::new()
                };
                out += &s
                    .failures
                    .markdown(&s.label, &format!("{} NaN, {} Inf, {} negative{worst}", s.nan, s.inf, s.negative));
            }
        }
        out
    }

    /// What the models without a twin were checked against, and the roughness domains, where any.
    fn expectations_markdown(&self) -> String {
        let mut lines = Vec::new();
        for s in &self.specs {
            let against = match (&s.expected_from, s.has_twin) {
                (Some(e), false) => Some(format!("checked against the {e}, in f64")),
                _ => None,
            };
            let domain = s.domain.as_ref().map(|d| {
                format!(
                    "{d}: {} valid hard cases and {} grid points outside it not counted",
                    s.cases_outside_domain, s.grid_outside_domain
                )
            });
            let without = (!s.cases_without_value.is_empty() || s.grid_without_value > 0).then(|| {
                format!(
                    "nothing to check the value against (NaN and negative values still count) at {} grid points and {}",
                    s.grid_without_value,
                    if s.cases_without_value.is_empty() {
                        "no hard case".to_string()
                    } else {
                        s.cases_without_value.join("; ")
                    }
                )
            });
            let said: Vec<String> = against.into_iter().chain(domain).chain(without).collect();
            if !said.is_empty() {
                lines.push(format!("- `{}`: {}\n", crate::export::escape_line(&s.label), said.join("; ")));
            }
        }
        if lines.is_empty() { String::new() } else { format!("\n{}", lines.concat()) }
    }

    /// The "what each guard saves" section, where specs ran without some of their guards.
    fn guard_savings_markdown(&self) -> String {
        if self.guard_savings.is_empty() {
            return String::new();
        }
        let mut t = crate::export::markdown::Table::new([
            "spec",
            "guards",
            "NaN",
            "Inf",
            "neg",
            "grid out of tol. (more)",
            "hard cases out of tolerance only without them",
        ]);
        for g in &self.guard_savings {
            let cases = if g.cases.is_empty() { "-".to_string() } else { g.cases.join("; ") };
            t.row([
                g.spec.clone(),
                describe_guards(&g.off),
                g.nan.to_string(),
                g.inf.to_string(),
                g.negative.to_string(),
                g.grid_out_of_tolerance.to_string(),
                cases,
            ]);
        }
        format!(
            "\n## What each guard saves\n\nEach spec with all its guards against the same spec with all of them off (`off`), with each one off alone (`off:NAME`: what only that guard saves) and with each one on alone (`off:` all the others: what it saves by itself) (docs/guards.md): the results on valid inputs without them, and the hard cases they keep within tolerance.\n\n{}",
            t.markdown()
        )
    }

    /// A heat map per failing spec over (NoV, roughness): bad values per grid cell, one panel each, under a
    /// title that counts what the Markdown counts and a colour key.
    pub fn heatmaps(&self, path: &std::path::Path) -> Result<bool> {
        use crate::export::text::{self, Style};
        use plotters::prelude::*;
        let all = self.failing();
        // Every failing spec whose grid failed gets a panel (one that failed only in hard cases has no map, and
        // where none did there is no picture).
        let grids: Vec<(&SpecStability, Vec<Vec<u32>>)> =
            all.iter().filter_map(|s| s.dense_bad_cells().map(|c| (*s, c))).collect();
        let failing: Vec<&SpecStability> = grids.iter().map(|(s, _)| *s).collect();
        if failing.is_empty() {
            return Ok(false);
        }
        let only_cases = all.len() - failing.len();
        let title = format!(
            "{} failing specs (NaN, Inf or negative on valid inputs): a panel for each of the {} that fail on the (NoV, roughness) grid{}",
            all.len(),
            failing.len(),
            if only_cases > 0 { format!("; {only_cases} fail only in hard cases") } else { String::new() }
        );
        let columns = 6usize.min(failing.len());
        let rows = failing.len().div_ceil(columns);
        let (pw, ph, head, caption) = (300u32, 250u32, 76u32, 34u32);
        let width = pw * columns as u32;
        let ink = |size: u32, bold: bool| Style { size, bold, colour: BLACK, vertical: false };
        crate::export::png::render(path, width, ph * rows as u32 + head, |root| {
            let (top, body) = root.split_vertically(head);
            let size = (10..=20).rev().find(|&z| text::measure(&title, z, false).0 <= width as i32 - 20).unwrap_or(10);
            text::draw(&top, &title, (10, 6), ink(size, false))?;
            draw_heat_key(&top)?;
            for (area, (s, cells)) in body.split_evenly((rows, columns)).iter().zip(&grids) {
                draw_heat_panel(area, &s.label, cells, (pw, caption))?;
            }
            Ok(())
        })?;
        Ok(true)
    }

    /// (label, energy) of the specs to draw, one per D/Vis/precision: all of them when at most 24, else the
    /// presets' (the JSON and Markdown hold every spec's figures).
    pub fn energy_entries(&self) -> Vec<(String, &energy::Energy)> {
        let mut seen = Vec::new();
        let mut entries = Vec::new();
        let mut files = Vec::new();
        for s in self.specs.iter().filter(|s| s.energy.is_some()) {
            let Ok(spec) = ModelSpec::parse(&s.spec) else {
                // A .brdf model: always drawn, under its own name.
                files.push((s.label.clone(), s.energy.as_ref().unwrap()));
                continue;
            };
            let white = energy::white(&spec);
            if !seen.contains(&white) {
                seen.push(white);
                let label = format!(
                    "{}/{}{}",
                    spec.d.name(),
                    spec.vis.name(),
                    if spec.precision == Precision::F16 { " f16" } else { "" }
                );
                entries.push((label, white, s.energy.as_ref().unwrap()));
            }
        }
        if entries.len() > 24 {
            let presets: Vec<ModelSpec> = crate::brdf::PRESETS
                .iter()
                .flat_map(|p| {
                    let s = ModelSpec::preset(p.name).unwrap();
                    Precision::ALL.map(|precision| energy::white(&ModelSpec { precision, ..s }))
                })
                .collect();
            entries.retain(|(_, w, _)| presets.contains(w));
        }
        entries.into_iter().map(|(label, _, e)| (label, e)).chain(files).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The committed failures picture, drawn from the committed JSON (`BLESS=1` writes it back to
    /// results/): one panel per spec that fails on the grid, read back from the report's sparse cells.
    #[test]
    fn the_committed_failures_picture_draws_from_its_json() {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
        let text = std::fs::read_to_string(root.join("results/stability-llvmpipe.json")).unwrap();
        let report: StabilityReport = serde_json::from_str(&text).unwrap();
        let grids = report.failing().iter().filter(|s| s.dense_bad_cells().is_some()).count();
        assert!(grids > 0 && grids <= report.failing().len());
        let dir = tempfile::tempdir().unwrap();
        let out = crate::export::png::blessed_or_scratch("stability-llvmpipe-failures.png", dir.path());
        assert!(report.heatmaps(&out).unwrap());
        let img = image::open(&out).unwrap();
        assert_eq!(img.height(), 250 * grids.div_ceil(6) as u32 + 76, "a row of six panels per six specs");
    }

    /// A long spec's caption fits its panel: in one line, or two split at a comma, or shortened.
    #[test]
    fn captions_fit_their_panel() {
        use crate::export::text::measure;
        for label in
            ["ggx", "d=ggx,vis=smith-ggx-joint-approx,f=conductor,metal=aluminium,precision=f16", &"x".repeat(200)]
        {
            let (lines, size) = fit_caption(label, 288);
            assert!(lines.len() <= 2 && (9..=13).contains(&size), "{label}: {lines:?}");
            assert!(lines.iter().all(|l| measure(l, size, false).0 <= 288), "{label}: {lines:?} at {size}");
        }
        assert_eq!(fit_caption("ggx", 288), (vec!["ggx".to_string()], 13));
    }
}
