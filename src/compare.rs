//! One cost table across devices: each device's cost per BRDF evaluation of every model (lavapipe's measured
//! ns/eval from a `profile` report, callgrind's Ir/eval and ACO's cycles/eval from `inspect` reports), net of
//! the memory-only kernel, relative to ggx, with Spearman's rank correlation between every pair of devices.
//! `inspect` builds it from the devices it ran; `brdfprof compare` from saved JSON reports, refusing files
//! whose kernels differ (each report records a SHA-256 of every model's kernel: SPIR-V and the
//! specialisation constants that select the model).

use crate::export::markdown::{Table, sig};
use crate::model::BASELINE_LABEL;
use crate::profile::ProfileReport;
use crate::schema::HASH_NOTE;
use crate::schema::InspectReport;
use anyhow::{Result, anyhow, bail};
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// One device's (or one measure's) cost per evaluation of each kernel.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct CostColumn {
    /// Column name: "llvmpipe ns/eval", "callgrind Ir/eval", "navi21 cycles/eval".
    pub name: String,
    pub unit: String,
    /// Where the figures come from (device, driver, file).
    pub source: String,
    /// Model -> cost per evaluation.
    pub gross: BTreeMap<String, f64>,
    /// Model -> cost minus the memory-only kernel's.
    pub net: BTreeMap<String, f64>,
    /// Model -> 95% CI of the net cost, where measured.
    #[serde(default)]
    pub net_ci: BTreeMap<String, (f64, f64)>,
    /// A measured column's net ratios to the reference as its report gives them (the median over rounds of
    /// each round's ratio, `profile::Row::net_vs_reference`), a model missing where the ratio is unresolved;
    /// None for a modelled or counted column, whose ratio is that of its net figures.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub measured_ratios: Option<BTreeMap<String, f64>>,
    /// Model -> kernel hash.
    #[serde(default)]
    pub hashes: BTreeMap<String, String>,
    /// Lights per pixel of the workload.
    pub lights: u32,
}

/// Rank correlation of two columns over the models both have.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct PairCorrelation {
    pub a: String,
    pub b: String,
    pub models: usize,
    /// Spearman's rho of the net costs (None with fewer than 3 models in common).
    pub spearman_net: Option<f64>,
    /// Its percentile-bootstrap 95% CI (`stats::spearman_ci`; None below 4 models).
    #[serde(default)]
    pub spearman_ci: Option<(f64, f64)>,
    /// (model pairs the two order oppositely, pairs both order): the swaps behind rho.
    #[serde(default)]
    pub discordant: Option<(usize, usize)>,
}

impl PairCorrelation {
    /// The rank agreement of `a` and `b` over the models both have (the memory-only kernel left out).
    pub fn of(a: (&str, &BTreeMap<String, f64>), b: (&str, &BTreeMap<String, f64>), models: &[String]) -> Self {
        let common: Vec<&String> =
            models.iter().filter(|m| *m != BASELINE_LABEL && a.1.contains_key(*m) && b.1.contains_key(*m)).collect();
        let xs: Vec<f64> = common.iter().map(|m| a.1[*m]).collect();
        let ys: Vec<f64> = common.iter().map(|m| b.1[*m]).collect();
        let enough = common.len() >= 3;
        PairCorrelation {
            a: a.0.to_string(),
            b: b.0.to_string(),
            models: common.len(),
            spearman_net: enough.then(|| crate::stats::spearman(&xs, &ys)),
            spearman_ci: crate::stats::spearman_ci(&xs, &ys, 0.95),
            discordant: enough.then(|| crate::stats::discordant_pairs(&xs, &ys)),
        }
    }

    /// rho with its CI: `0.92 [0.85, 0.96]`; over too few models for a CI no rho is printed (a rank
    /// correlation of 3 models is one of 4 values, 1.00 by chance one time in six).
    pub fn rho_cell(&self) -> String {
        match (self.spearman_net, self.spearman_ci) {
            (Some(r), Some((lo, hi))) => format!("{r:.2} [{lo:.2}, {hi:.2}]"),
            _ => format!("- ({} models: too few for a CI)", self.models),
        }
    }

    pub fn discordant_cell(&self) -> String {
        self.discordant.map_or("-".into(), |(d, n)| format!("{d} of {n}"))
    }
}

/// Each kernel's SPIR-V instruction count after spirv-opt -O (`spirv-O/total`, the light loop unrolled as the
/// targets unroll it) net of the memory-only kernel's, from the first report that has them.
pub fn spirv_counts(reports: &[InspectReport]) -> BTreeMap<String, f64> {
    for r in reports {
        let total = |m: &str| r.rows.iter().find(|x| x.model == m).and_then(|x| x.stats.get("spirv-O/total").copied());
        let Some(base) = total(BASELINE_LABEL) else { continue };
        let counts: BTreeMap<String, f64> = r
            .rows
            .iter()
            .filter(|x| x.model != BASELINE_LABEL)
            .filter_map(|x| x.stats.get("spirv-O/total").map(|t| (x.model.clone(), t - base)))
            .collect();
        if !counts.is_empty() {
            return counts;
        }
    }
    BTreeMap::new()
}

/// How the rank tables' CIs are made.
pub const RHO_NOTE: &str = "CIs: percentile bootstrap over the models (4,000 draws with replacement, seed 2026); discordant pairs: model pairs the two order oppositely, of those both order (ties left out).";

/// The name the SPIR-V baseline goes by in tables.
pub const SPIRV_BASELINE: &str = "SPIR-V instructions (spirv-opt -O)";

#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct CostTable {
    /// Models in row order (the memory-only kernel last).
    pub models: Vec<String>,
    pub columns: Vec<CostColumn>,
    pub correlations: Vec<PairCorrelation>,
    /// Each column against the kernels' SPIR-V instruction count (`spirv_counts`): what a plain op count
    /// already predicts, the baseline a compiler's ranking is read against (empty without SPIR-V counts).
    #[serde(default)]
    pub spirv_baseline: Vec<PairCorrelation>,
    /// Models whose kernel is another's (the same SPIR-V hash), with that model: ranked once, as the other.
    #[serde(default)]
    pub same_kernel: Vec<(String, String)>,
}

/// `models` with each kernel once (the first model of each SPIR-V hash any column records), and the others
/// with the model whose kernel they are: two specs that compile to one kernel would count a tie twice.
fn distinct_kernels(columns: &[CostColumn], models: &[String]) -> (Vec<String>, Vec<(String, String)>) {
    let hash = |m: &String| columns.iter().find_map(|c| c.hashes.get(m).cloned());
    let (mut distinct, mut same): (Vec<String>, Vec<(String, String)>) = (Vec::new(), Vec::new());
    for m in models {
        match hash(m).and_then(|h| distinct.iter().find(|d| hash(d).as_ref() == Some(&h)).cloned()) {
            Some(first) => same.push((m.clone(), first)),
            None => distinct.push(m.clone()),
        }
    }
    (distinct, same)
}

fn hashes(report: &InspectReport) -> BTreeMap<String, String> {
    report.rows.iter().filter_map(|r| r.notes.get(HASH_NOTE).map(|h| (r.model.clone(), h.clone()))).collect()
}

fn device_name(report: &InspectReport) -> String {
    report.provenance["device"]["name"].as_str().unwrap_or("?").to_string()
}

/// The cost columns an inspect report gives: ACO's cycles/eval (RADV), callgrind's Ir/eval (lavapipe).
pub fn inspect_columns(report: &InspectReport, source: &str) -> Vec<CostColumn> {
    let mut out = Vec::new();
    let device = device_name(report);
    if let Some(cost) = report.cost.clone().or_else(|| crate::targets::cost_of(report)) {
        out.push(CostColumn {
            name: crate::targets::column_name(&cost),
            unit: format!("{} {} per evaluation ({})", cost.compiler, cost.unit, cost.model),
            source: format!("{source}{device}, {}", crate::targets::mesa_noop::driver_version(report)),
            gross: cost.rows.iter().map(|r| (r.model.clone(), r.cycles_per_eval)).collect(),
            net: cost.rows.iter().filter_map(|r| r.net_cycles_per_eval.map(|n| (r.model.clone(), n))).collect(),
            net_ci: BTreeMap::new(),
            measured_ratios: None,
            hashes: hashes(report),
            lights: report.lights,
        });
    }
    let gross: BTreeMap<String, f64> = report
        .rows
        .iter()
        .filter_map(|r| r.stats.get("callgrind/ir-per-eval").map(|v| (r.model.clone(), *v)))
        .collect();
    if !gross.is_empty() {
        out.push(CostColumn {
            name: "callgrind Ir/eval".into(),
            unit: "x86 instructions of lavapipe's JIT code per evaluation".into(),
            source: format!("{source}{device}"),
            gross,
            net: report
                .rows
                .iter()
                .filter_map(|r| r.stats.get("callgrind/net-ir-per-eval").map(|v| (r.model.clone(), *v)))
                .collect(),
            net_ci: BTreeMap::new(),
            measured_ratios: None,
            hashes: hashes(report),
            lights: report.lights,
        });
    }
    out
}

/// The cost columns of a `profile` report, read back typed: ns/eval per light count.
pub fn profile_columns(view: &ProfileReport, source: &str) -> Vec<CostColumn> {
    let device = Some(view.provenance.device.name.as_str()).filter(|n| !n.is_empty()).unwrap_or("?").to_string();
    let short = device.split([' ', '(']).next().unwrap_or("?").to_string();
    let mut lights: Vec<u32> = view.rows.iter().map(|r| r.lights).collect();
    lights.sort();
    lights.dedup();
    let several = lights.len() > 1;
    let mut out = Vec::new();
    for l in lights {
        let mut col = CostColumn {
            name: if several { format!("{short} ns/eval ({l} lights)") } else { format!("{short} ns/eval") },
            unit: "measured ns per evaluation (median over rounds)".into(),
            source: format!("{source}{device}"),
            gross: BTreeMap::new(),
            net: BTreeMap::new(),
            net_ci: BTreeMap::new(),
            measured_ratios: Some(BTreeMap::new()),
            hashes: view.kernel_sha256.clone(),
            lights: l,
        };
        for r in view.rows.iter().filter(|r| r.lights == l) {
            col.gross.insert(r.model.clone(), r.ns_per_eval.median);
            if let Some(n) = &r.net_ns_per_eval {
                col.net.insert(r.model.clone(), n.median);
                col.net_ci.insert(r.model.clone(), (n.lo, n.hi));
            }
            if let (Some(ratio), Some(map)) = (&r.net_vs_reference, col.measured_ratios.as_mut()) {
                map.insert(r.model.clone(), ratio.median);
            }
        }
        out.push(col);
    }
    out
}

/// Refuses columns whose kernels differ: a model whose hash is not the same in every column that has it, or
/// a column without hashes.
pub fn check_kernels(columns: &[CostColumn]) -> Result<()> {
    for c in columns {
        if c.hashes.is_empty() {
            bail!(
                "{} ({}): records no kernel hashes (written by an older brdfprof); its kernels cannot be matched with the others'. Measure it again",
                c.name,
                c.source
            );
        }
    }
    let mut seen: BTreeMap<&str, (&str, &CostColumn)> = BTreeMap::new();
    for c in columns {
        // Every model whose kernel differs from the first column that has it, against that column.
        let mut differ: BTreeMap<&str, Vec<String>> = BTreeMap::new();
        for (model, h) in &c.hashes {
            match seen.get(model.as_str()) {
                Some((h0, c0)) if *h0 != h.as_str() => {
                    differ.entry(c0.name.as_str()).or_default().push(format!(
                        "`{model}` ({} vs {})",
                        &h0[..12.min(h0.len())],
                        &h[..12.min(h.len())]
                    ));
                }
                Some(_) => {}
                None => {
                    seen.insert(model, (h, c));
                }
            }
        }
        if let Some((other, models)) = differ.into_iter().next() {
            let c0 = columns.iter().find(|x| x.name == other).expect("a column seen before");
            bail!(
                "the kernels differ: {} SPIR-V hashes in {} ({}) and {} ({}); compare reports of the same kernels",
                models.join(", "),
                c0.name,
                c0.source,
                c.name,
                c.source
            );
        }
    }
    Ok(())
}

/// The table of `columns`, with every pair's rank correlation.
pub fn build(columns: Vec<CostColumn>) -> CostTable {
    let mut models: Vec<String> = Vec::new();
    for c in &columns {
        for m in c.gross.keys() {
            if !models.contains(m) && m != BASELINE_LABEL {
                models.push(m.clone());
            }
        }
    }
    // Row order: the reference first, then by name as the first column orders them (cheapest net first).
    let first = columns.first().cloned();
    models.sort_by(|a, b| {
        let key = |m: &String| {
            (
                m != crate::brdf::spec::REFERENCE_MODEL,
                first.as_ref().and_then(|c| c.net.get(m).copied()).unwrap_or(f64::INFINITY),
            )
        };
        let (ka, kb) = (key(a), key(b));
        ka.0.cmp(&kb.0).then(ka.1.total_cmp(&kb.1)).then(a.cmp(b))
    });
    if columns.iter().any(|c| c.gross.contains_key(BASELINE_LABEL)) {
        models.push(BASELINE_LABEL.into());
    }
    let (distinct, same_kernel) = distinct_kernels(&columns, &models);
    let mut correlations = Vec::new();
    for i in 0..columns.len() {
        for j in i + 1..columns.len() {
            let (a, b) = (&columns[i], &columns[j]);
            correlations.push(PairCorrelation::of((&a.name, &a.net), (&b.name, &b.net), &distinct));
        }
    }
    CostTable { models, columns, correlations, spirv_baseline: Vec::new(), same_kernel }
}

impl CostTable {
    /// The table with every column's rank agreement with the SPIR-V counts (`spirv_counts`).
    pub fn with_spirv_baseline(mut self, counts: &BTreeMap<String, f64>) -> Self {
        if !counts.is_empty() {
            let distinct: Vec<String> =
                self.models.iter().filter(|m| !self.same_kernel.iter().any(|(s, _)| s == *m)).cloned().collect();
            self.spirv_baseline = self
                .columns
                .iter()
                .map(|c| PairCorrelation::of((SPIRV_BASELINE, counts), (&c.name, &c.net), &distinct))
                .collect();
        }
        self
    }

    /// Net cost relative to ggx's net cost in the same column: one definition everywhere (docs/measurement.md):
    /// a measured column's own per-round ratio (None where unresolved), else the ratio of the net figures.
    pub fn relative(&self, column: &CostColumn, model: &str) -> Option<f64> {
        if let Some(ratios) = &column.measured_ratios {
            return ratios.get(model).copied();
        }
        let g = column.net.get(crate::brdf::spec::REFERENCE_MODEL)?;
        column.net.get(model).map(|n| n / g).filter(|r| r.is_finite() && *g > 0.0)
    }

    /// The "net vs ggx" cell: the ratio, "unresolved" for a measured model without one, else "-".
    fn relative_cell(&self, column: &CostColumn, model: &str) -> String {
        let measured = column.measured_ratios.is_some();
        match self.relative(column, model) {
            Some(r) if r <= 0.0 && !measured => crate::schema::cost::HARNESS_BOUND.into(),
            Some(r) => format!("{r:.2}"),
            None if column.measured_ratios.is_some() && column.net.contains_key(model) => "unresolved".into(),
            None => "-".into(),
        }
    }

    pub fn markdown(&self) -> String {
        let mut headers = vec!["model".to_string()];
        for c in &self.columns {
            headers.push(c.name.clone());
            headers.push("net".into());
            headers.push("net vs ggx".into());
        }
        let mut t = Table::new(headers);
        for m in &self.models {
            let mut cells = vec![m.clone()];
            for c in &self.columns {
                cells.push(c.gross.get(m).map_or("-".into(), |v| sig(*v, 4)));
                cells.push(match (c.net.get(m), c.net_ci.get(m)) {
                    (Some(v), Some((lo, hi))) => format!("{} [{}, {}]", sig(*v, 3), sig(*lo, 3), sig(*hi, 3)),
                    (Some(v), None) => sig(*v, 4),
                    _ => "-".into(),
                });
                cells.push(self.relative_cell(c, m));
            }
            t.row(cells);
        }
        let mut out = format!("### Cost per BRDF evaluation across devices\n\n{}\n", t.markdown());
        out += "Sources: ";
        out += &self
            .columns
            .iter()
            .map(|c| format!("{}: {} ({} lights)", c.name, c.source, c.lights))
            .collect::<Vec<_>>()
            .join("; ");
        out += "\n\n";
        if !self.correlations.is_empty() {
            let mut t =
                Table::new(["device A", "device B", "models", "Spearman rho (net cost) [95% CI]", "discordant pairs"]);
            for p in &self.correlations {
                t.row([p.a.clone(), p.b.clone(), p.models.to_string(), p.rho_cell(), p.discordant_cell()]);
            }
            let same = match self.same_kernel.is_empty() {
                true => String::new(),
                false => format!(
                    " Ranked once, as the model whose kernel they are (the same SPIR-V): {}.",
                    self.same_kernel.iter().map(|(m, f)| format!("{m} (= {f})")).collect::<Vec<_>>().join(", ")
                ),
            };
            out += &format!("### Rank correlation between devices\n\n{}\n{RHO_NOTE}{same}\n\n", t.markdown());
        }
        if !self.spirv_baseline.is_empty() {
            let mut t =
                Table::new(["device", "models", "Spearman rho with the SPIR-V count [95% CI]", "discordant pairs"]);
            for p in &self.spirv_baseline {
                t.row([p.b.clone(), p.models.to_string(), p.rho_cell(), p.discordant_cell()]);
            }
            out += &format!(
                "### Against a plain SPIR-V instruction count\n\nEach device's net cost against the kernel's SPIR-V instructions after spirv-opt -O, net of the memory-only kernel's: what counting ops already predicts. A device pair agreeing no better than each agrees with this count says little about the compilers.\n\n{}\n",
                t.markdown()
            );
        }
        out
    }

    /// The headline picture: net cost relative to ggx as a heat-map table, models by rows, devices by columns
    /// grouped by vendor and compiler, each group saying whether its columns are measured, counted or modelled
    /// (`export::heat_table`).
    pub fn chart(&self, path: &Path) -> Result<()> {
        let models: Vec<&String> = self.models.iter().filter(|m| *m != BASELINE_LABEL).collect();
        let mut order: Vec<(usize, String, usize)> =
            self.columns.iter().enumerate().map(|(j, c)| (c.vendor().0, c.vendor().1, j)).collect();
        order.sort_by(|a, b| (a.0, &a.1).cmp(&(b.0, &b.1)).then(a.2.cmp(&b.2)));
        let mut groups: Vec<(String, Vec<String>)> = Vec::new();
        let mut picked = Vec::new();
        for (_, vendor, j) in &order {
            let c = &self.columns[*j];
            let short = c.name.strip_suffix(" cycles/eval").unwrap_or(&c.name).to_string();
            match groups.last_mut() {
                Some((g, cols)) if g == vendor => cols.push(short),
                _ => groups.push((vendor.clone(), vec![short])),
            }
            picked.push(*j);
        }
        // A group of one kind says it once; a mixed group (lavapipe's measured and counted) says it per column.
        let mut at = 0;
        for (g, cols) in groups.iter_mut() {
            let kinds: Vec<&str> = picked[at..at + cols.len()].iter().map(|&j| self.columns[j].kind()).collect();
            if kinds.iter().all(|k| *k == kinds[0]) {
                *g = format!("{g}: {}", kinds[0]);
            } else {
                cols.iter_mut().zip(&kinds).for_each(|(c, k)| *c = format!("{c}, {k}"));
            }
            at += cols.len();
        }
        // A modelled net at or below 0 is harness-bound, no ratio: left grey, never drawn as "cheapest".
        let cell = |j: usize, m: &str| {
            let c = &self.columns[j];
            self.relative(c, m).filter(|r| *r > 0.0 || c.measured_ratios.is_some())
        };
        let cells = models.iter().map(|m| picked.iter().map(|&j| cell(j, m)).collect()).collect();
        let table = crate::export::heat_table::HeatTable {
            title: "BRDF cost net of the memory-only kernel, relative to ggx in each column (grey: no figure, or harness-bound)".into(),
            groups,
            rows: models.iter().map(|m| m.to_string()).collect(),
            cells,
            scale_name: "net cost / ggx's".into(),
        };
        crate::export::heat_table::draw(path, &table)
    }
}

/// The columns of one saved JSON report: a `profile` report, an `inspect` report, an `inspect` report of
/// several devices, or a `check` baseline (its inspect part).
pub fn load_columns(path: &Path) -> Result<Vec<CostColumn>> {
    let text = String::from_utf8(crate::io::read_bounded(path, crate::io::MAX_REPORT_BYTES)?)
        .map_err(|_| anyhow!("{}: not UTF-8 text: not a brdfprof JSON report", path.display()))?;
    let value: serde_json::Value =
        serde_json::from_str(&text).map_err(|e| anyhow!("{}: not valid JSON ({e})", path.display()))?;
    let source = format!("{}: ", path.display());
    // A report of another command is named as what it is, with where its figures go instead.
    let kind = value.get("kind").and_then(|k| k.as_str()).unwrap_or_default();
    if ["diff", "stability"].contains(&kind) || value.get("grid_points").is_some() {
        let kind = if kind.is_empty() { "stability" } else { kind };
        bail!(
            "{}: a `{kind}` report, which holds no cost per evaluation to compare; give profile or inspect reports (or a check baseline); `brdfprof report` draws a `{kind}` report",
            path.display()
        );
    }
    let inspect_of = |v: &serde_json::Value| -> Result<InspectReport> {
        serde_json::from_value(v.clone())
            .map_err(|e| anyhow!("{}: not a brdfprof inspect report ({e})", path.display()))
    };
    let columns = if value.get("raw").is_some() && value.get("workload").is_some() {
        if value.get("kernel_sha256").is_none() {
            bail!(
                "{}: a profile report that records no kernel hashes (written by an older brdfprof); its kernels cannot be matched with the others'. Measure it again",
                path.display()
            );
        }
        let view: ProfileReport = serde_json::from_value(value)
            .map_err(|e| anyhow!("{}: not a brdfprof profile report ({e})", path.display()))?;
        profile_columns(&view, &source)
    } else if let Some(reports) = value.get("reports").and_then(|r| r.as_array()) {
        let mut out = Vec::new();
        for r in reports {
            out.extend(inspect_columns(&inspect_of(r)?, &source));
        }
        out
    } else if value.get("inspect").is_some() && value.get("environment").is_some() {
        inspect_columns(&inspect_of(&value["inspect"])?, &source)
    } else {
        inspect_columns(&inspect_of(&value)?, &source)
    };
    if columns.is_empty() {
        bail!(
            "{}: no cost per evaluation in it (a profile report, or an inspect report with ACO statistics or callgrind counts)",
            path.display()
        );
    }
    Ok(columns)
}

/// Refuses a report given twice (the same file by any path, or two files with the same content): a column
/// against itself correlates perfectly and says nothing.
fn refuse_repeats(files: &[PathBuf]) -> Result<()> {
    refuse_repeated_reports(files, "a report compared with itself correlates perfectly and says nothing")
}

/// Refuses a report given twice (by any path, or two files with the same content), `why` saying what the
/// repeat would do.
pub fn refuse_repeated_reports(files: &[PathBuf], why: &str) -> Result<()> {
    let mut seen: Vec<(&PathBuf, Vec<u8>)> = Vec::new();
    for f in files {
        let bytes = crate::io::read_bounded(f, crate::io::MAX_REPORT_BYTES)?;
        let digest = Sha256::digest(bytes).to_vec();
        if let Some((first, _)) = seen.iter().find(|(_, d)| *d == digest) {
            bail!("{} is the same report as {}: give each report once ({why})", f.display(), first.display());
        }
        seen.push((f, digest));
    }
    Ok(())
}

impl CostColumn {
    /// Measured (a timed column), counted (callgrind's instructions) or modelled (a compile-only target).
    pub fn kind(&self) -> &'static str {
        if self.unit.starts_with("measured") {
            "measured"
        } else if self.name.starts_with("callgrind") {
            "counted"
        } else {
            "modelled"
        }
    }

    /// The column's vendor and compiler, for grouping, with its rank in the headline picture's order (CPU,
    /// AMD, NVIDIA, Intel, Qualcomm, Arm, other); from the source's device name and the unit's compiler.
    pub fn vendor(&self) -> (usize, String) {
        let source = self.source.to_lowercase();
        let has = |words: &[&str]| words.iter().any(|w| source.contains(w));
        let compiler = self.unit.split_whitespace().next().unwrap_or("?");
        let (rank, vendor) = if has(&["llvmpipe", "lavapipe", "swiftshader"]) && self.kind() != "modelled" {
            return (0, "lavapipe".into());
        } else if has(&["radv", "amd"]) {
            (1, "AMD")
        } else if has(&["nvidia", "nouveau", "nvk"]) {
            (2, "NVIDIA")
        } else if has(&["intel", "anv"]) {
            (3, "Intel")
        } else if has(&["adreno", "turnip", "freedreno"]) {
            (4, "Qualcomm")
        } else if has(&["mali", "panvk", "panfrost"]) {
            (5, "Arm")
        } else {
            (6, "other")
        };
        (rank, format!("{vendor} ({compiler})"))
    }

    /// Refuses figures no measurement gives: a cost that is not finite or not above 0, a net cost that is not
    /// finite or above the gross one (the memory-only kernel cannot cost less than nothing), a CI that does
    /// not hold its median.
    pub fn check_figures(&self) -> Result<()> {
        let fail = |model: &str, why: String| {
            anyhow!(
                "{} ({}): `{model}`: {why}; not a figure a measurement gives (an edited or damaged report?)",
                self.name,
                self.source
            )
        };
        for (model, &g) in &self.gross {
            if !(g.is_finite() && g > 0.0) {
                return Err(fail(model, format!("cost {g}")));
            }
        }
        for (model, &n) in &self.net {
            let gross = self.gross.get(model).copied().unwrap_or(f64::INFINITY);
            if !n.is_finite() || n > gross {
                return Err(fail(model, format!("net cost {n} (gross {gross})")));
            }
            if let Some(&(lo, hi)) =
                self.net_ci.get(model).filter(|(lo, hi)| !(lo.is_finite() && hi.is_finite() && *lo <= n && n <= *hi))
            {
                return Err(fail(model, format!("net cost {n} outside its confidence interval [{lo}, {hi}]")));
            }
        }
        Ok(())
    }
}

/// `brdfprof compare FILE ...`: every file's columns, checked for the same kernels, in one table.
pub fn from_files(files: &[PathBuf]) -> Result<CostTable> {
    if files.is_empty() {
        bail!("compare needs at least one FILE.json (profile or inspect reports)");
    }
    refuse_repeats(files)?;
    let mut columns: Vec<CostColumn> = Vec::new();
    for f in files {
        for mut c in load_columns(f)? {
            c.check_figures()?;
            // Two files of the same device: keep both, told apart by their file.
            if columns.iter().any(|o| o.name == c.name) {
                c.name = format!(
                    "{} [{}]",
                    c.name,
                    f.file_name().map_or_else(|| f.display().to_string(), |n| n.to_string_lossy().into_owned())
                );
            }
            columns.push(c);
        }
    }
    check_kernels(&columns)?;
    Ok(build(columns))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The committed five-vendor table: the headline picture's groups come out in vendor order (IGC and brw two
    /// groups of Intel's), each of one kind but lavapipe's.
    #[test]
    fn the_headline_columns_group_by_vendor_and_say_how_each_was_obtained() {
        let text = std::fs::read_to_string("results/targets/inspect-thesis.json").unwrap();
        let json: serde_json::Value = serde_json::from_str(&text).unwrap();
        let columns: Vec<CostColumn> = serde_json::from_value(json["costs"]["columns"].clone()).unwrap();
        let groups: Vec<(usize, String, &str)> =
            columns.iter().map(|c| (c.vendor().0, c.vendor().1, c.kind())).collect();
        let mut ranks: Vec<usize> = groups.iter().map(|g| g.0).collect();
        ranks.dedup();
        assert_eq!(ranks, [0, 1, 2, 3, 4, 5], "lavapipe, AMD, NVIDIA, Intel, Qualcomm, Arm: {groups:?}");
        let kind = |name: &str| groups.iter().zip(&columns).find(|(_, c)| c.name.starts_with(name)).unwrap().0.2;
        assert_eq!(
            (kind("llvmpipe"), kind("callgrind"), kind("navi21"), kind("sm_89")),
            ("measured", "counted", "modelled", "modelled")
        );
        for name in ["AMD (ACO)", "Intel (IGC)", "Intel (brw)", "Qualcomm (ir3)", "Arm (Bifrost)"] {
            assert!(groups.iter().any(|g| g.1 == name), "no {name}: {groups:?}");
        }
    }
}
