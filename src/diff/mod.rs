//! `brdfprof diff`: two models evaluated on the device on the same inputs, and how far apart they are. B is
//! measured against A (the first model): the relative difference is `accuracy::rel_err(b, a)`,
//! |b - a| / max(|a|, 1e-3), the measure every accuracy figure of brdfprof uses. Where both models have f64
//! twins, the twins' difference on the same inputs is reported too: the formulas' own difference, without fp32
//! rounding. docs/diff.md documents the JSON report (`"kind": "diff"`).

pub mod picture;
pub mod signed;

use crate::accuracy::rel_err;
use crate::brdf::guards::unit;
use crate::brdf::{Sample, samples};
use crate::model::Model;
use serde::{Deserialize, Serialize};

/// The report's `kind`, and its shape's version (bumped when a field changes meaning or goes away).
pub const KIND: &str = "diff";
pub const SCHEMA: u32 = 1;
/// The kind of `diff --reference SPEC`'s report: every model against one reference's f64 values.
pub const SET_KIND: &str = "diff-set";

/// Histogram edges of the relative difference: [0, 1e-7), [1e-7, 1e-6), ..., [0.1, 1), [1, inf).
pub const HISTOGRAM_EDGES: [f64; 9] = [0.0, 1e-7, 1e-6, 1e-5, 1e-4, 1e-3, 1e-2, 1e-1, 1.0];

/// The largest input `diff` evaluates (both models' outputs and the statistics stay within a few GB).
pub const MAX_SAMPLES: usize = 20_000_000;

pub use crate::brdf::f0::F0Set;
pub use crate::brdf::samples::{DEFAULT_MIN_COS, SampleDomain};

/// The default inputs: `count` well-conditioned samples (`SampleDomain::default()`, F0 of real materials,
/// `F0Set::default()`), seeded.
pub fn default_samples(count: usize, seed: u64) -> Vec<Sample> {
    default_samples_in(count, seed, &SampleDomain::default(), F0Set::default())
}

/// `default_samples` within `domain` (`--roughness`, `--nov`, `--nol`, a file's domains), F0 from `f0`.
pub fn default_samples_in(count: usize, seed: u64, domain: &SampleDomain, f0: F0Set) -> Vec<Sample> {
    let (lo, hi) = domain.roughness;
    let mut s = if lo == hi {
        let mut s = samples::well_conditioned_in(count, seed, domain.nov, domain.nol, 0.0..1.0);
        s.iter_mut().for_each(|x| x.roughness = lo as f32);
        s
    } else {
        samples::well_conditioned_in(count, seed, domain.nov, domain.nol, lo..hi)
    };
    f0.apply(&mut s, seed);
    s
}

/// The words that say what the default inputs are.
pub fn default_samples_label(count: usize, seed: u64) -> String {
    default_samples_label_in(count, seed, &SampleDomain::default(), ["", "", ""], F0Set::default())
}

/// `default_samples_label` within `domain`, `why` saying where its roughness, NoV and NoL ranges come from.
pub fn default_samples_label_in(count: usize, seed: u64, domain: &SampleDomain, why: [&str; 3], f0: F0Set) -> String {
    let (r, v, l) = (domain.roughness, domain.nov, domain.nol);
    let cosines = if v == l && why[1] == why[2] {
        format!("NoV, NoL in [{}, {}]{}", v.0, v.1, why[1])
    } else {
        format!("NoV in [{}, {}]{}, NoL in [{}, {}]{}", v.0, v.1, why[1], l.0, l.1, why[2])
    };
    format!(
        "{count} well-conditioned samples (seed {seed}; {cosines}, roughness in [{}, {}]{}, {})",
        r.0,
        r.1,
        why[0],
        f0.describe()
    )
}

/// One model as the report names it.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Side {
    /// The label in tables and file names (`name=` or the shortest spec).
    pub name: String,
    /// The full form, with every parameter.
    pub canonical: String,
    /// What translated an HLSL or WGSL model into the kernels' GLSL, with versions.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub front_end: Option<String>,
}

impl Side {
    pub fn of(model: &Model) -> Self {
        Side {
            name: model.label(),
            canonical: model.canonical(),
            front_end: model.file().and_then(|f| f.file.front_end.clone()),
        }
    }

    /// A reference's side: its formula in f64 at the sampled roughness (`ModelSpec::eval_reference`: no
    /// roughness floor), not its kernel's values.
    pub fn reference(model: &Model) -> Self {
        Side { name: format!("{} (f64, no floor)", model.label()), canonical: model.canonical(), front_end: None }
    }
}

/// What `brdfprof diff --reference SPEC --model ... --json` writes: each model against the reference's f64
/// values on the same rows, one `DiffReport` each (A the reference), and one table over them.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct DiffSet {
    #[serde(skip_deserializing)]
    pub kind: &'static str,
    #[serde(skip_deserializing)]
    pub schema: u32,
    pub reference: Side,
    pub device: String,
    pub input: String,
    pub rows: usize,
    pub tolerance: Option<f64>,
    /// Every model within it (true without a tolerance).
    pub within_tolerance: bool,
    pub diffs: Vec<DiffReport>,
}

impl DiffSet {
    pub fn new(diffs: Vec<DiffReport>, tolerance: Option<f64>) -> Self {
        let first = diffs.first().expect("a model to compare");
        DiffSet {
            kind: SET_KIND,
            schema: SCHEMA,
            reference: first.a.clone(),
            device: first.device.clone(),
            input: first.input.clone(),
            rows: first.rows,
            tolerance,
            within_tolerance: diffs.iter().all(|d| d.within_tolerance),
            diffs,
        }
    }

    /// One table (a row per model: its largest and RMS relative difference over the channels, its
    /// non-finite values, its worst row), then each model's report.
    pub fn markdown(&self) -> String {
        use crate::export::markdown::Table;
        let mut out = format!(
            "# {} models against {}\n\n{} rows of {} on {}; relative: rel_err(model, reference) = |model - reference| / max(|reference|, {}).\n\n",
            self.diffs.len(),
            self.reference.name,
            self.rows,
            self.input,
            self.device,
            crate::accuracy::FLOOR
        );
        for d in self.diffs.iter().filter(|d| d.b.front_end.is_some()) {
            out += &format!("{}'s front end: {}.\n\n", d.b.name, d.b.front_end.as_deref().unwrap_or(""));
        }
        let mut t = Table::new([
            "model",
            "max rel",
            "RMS rel (worst channel)",
            "max abs",
            "best-fit scale",
            "B/A median",
            "rows within 1e-3",
            "non-finite (model / one side only)",
            "worst row",
            "verdict",
        ]);
        for d in &self.diffs {
            t.row(self.row(d));
        }
        out += &t.markdown();
        if let Some(tol) = self.tolerance {
            out += &format!(
                "\n--tolerance {tol}: {}.\n",
                if self.within_tolerance { "every model within it" } else { "NOT every model within it" }
            );
        }
        for d in &self.diffs {
            out += &format!("\n{}", d.markdown().replacen("# ", "## ", 1));
        }
        out
    }

    /// One model's row of the table.
    fn row(&self, d: &DiffReport) -> [String; 10] {
        use crate::export::markdown::sig;
        let rms = d.difference.channels.iter().map(|c| c.rms_rel).fold(0.0, f64::max);
        let within: usize =
            d.histogram.counts.iter().zip(&d.histogram.edges).filter(|(_, e)| **e < 1e-3).map(|(n, _)| n).sum();
        let nonfinite = d.difference.channels.iter().map(|c| c.b_nonfinite).sum::<usize>();
        let one_side = d.difference.channels.iter().map(|c| c.mismatched_nonfinite).sum::<usize>();
        let worst = d.worst.first().map_or("-".into(), |w| {
            let (n, v, l) = (unit(w.sample.n), unit(w.sample.v), unit(w.sample.l));
            format!(
                "{} ({}) at NoV {:.3}, NoL {:.3}, roughness {:.3}",
                sig(w.rel, 3),
                w.channel,
                n.dot(v),
                n.dot(l),
                w.sample.roughness
            )
        });
        let verdict = match self.tolerance {
            Some(_) if d.within_tolerance => "within",
            Some(_) => "ABOVE",
            None => "-",
        };
        [
            d.b.name.clone(),
            sig(d.difference.max_rel, 3),
            sig(rms, 3),
            sig(d.difference.max_abs, 3),
            d.signed.best_fit_scale.map_or("-".into(), |s| sig(s, 3)),
            d.signed.ratio_at(50.0).map_or("-".into(), |r| sig(r, 3)),
            format!("{within} of {}", d.rows),
            format!("{nonfinite} / {one_side}"),
            worst,
            verdict.to_string(),
        ]
    }
}

/// One channel's figures: |b - a| and rel_err(b, a), max and RMS over the rows whose values are both finite.
#[derive(Clone, Debug, Default, Serialize, Deserialize, PartialEq)]
pub struct ChannelStats {
    pub channel: String,
    #[serde(default = "crate::io::nan", deserialize_with = "crate::io::nan_if_null")]
    pub max_abs: f64,
    #[serde(default = "crate::io::nan", deserialize_with = "crate::io::nan_if_null")]
    pub rms_abs: f64,
    #[serde(default = "crate::io::nan", deserialize_with = "crate::io::nan_if_null")]
    pub max_rel: f64,
    #[serde(default = "crate::io::nan", deserialize_with = "crate::io::nan_if_null")]
    pub rms_rel: f64,
    /// Rows where A's value is NaN or Inf, where B's is, and where exactly one of them is (a difference no
    /// number measures: the statistics above leave those rows out, and `within_tolerance` fails on them).
    #[serde(skip_deserializing)]
    pub a_nonfinite: usize,
    #[serde(skip_deserializing)]
    pub b_nonfinite: usize,
    pub mismatched_nonfinite: usize,
    /// Rows where both are non-finite and not the same infinity (NaN on both sides): no difference measures
    /// them, so no tolerance can be claimed for them.
    #[serde(skip_deserializing)]
    pub unmeasured: usize,
}

/// A row where the models differ most (largest relative difference over its channels).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct WorstRow {
    /// 0-based index into the inputs.
    pub index: usize,
    /// The CSV line of the row, for `--input`.
    pub line: Option<usize>,
    pub sample: Sample,
    #[serde(deserialize_with = "nan_if_null_rgb")]
    pub a: [f32; 3],
    #[serde(deserialize_with = "nan_if_null_rgb")]
    pub b: [f32; 3],
    /// The channel with the largest relative difference, and that difference (infinite where one side is not
    /// finite).
    pub channel: String,
    #[serde(default = "crate::io::nan", deserialize_with = "crate::io::nan_if_null")]
    pub rel: f64,
    #[serde(skip_deserializing)]
    pub abs: f64,
}

/// Rows by their largest relative difference over the channels.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Histogram {
    /// Lower edges of the bins; the last bin is [last edge, inf).
    pub edges: Vec<f64>,
    pub counts: Vec<usize>,
    /// Rows whose three channels are equal in value (a subset of the first bin).
    pub identical: usize,
    /// Rows where one model gives a non-finite value and the other does not (in no bin).
    pub nonfinite: usize,
}

/// The statistics of B against A over a set of rows.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Difference {
    pub channels: Vec<ChannelStats>,
    /// Largest relative difference over every channel (infinite when a row is non-finite on one side only).
    #[serde(default = "crate::io::nan", deserialize_with = "crate::io::nan_if_null")]
    pub max_rel: f64,
    #[serde(skip_deserializing)]
    pub max_abs: f64,
}

/// What `brdfprof diff --json` writes (docs/diff.md), and what `report` reads back: what no reader shows is
/// skipped, and a figure written as null (NaN or Inf) reads as NaN (`io::finite`).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct DiffReport {
    #[serde(skip_deserializing)]
    pub kind: &'static str,
    #[serde(skip_deserializing)]
    pub schema: u32,
    pub a: Side,
    pub b: Side,
    pub device: String,
    /// What the inputs were: the CSV's path, or the default samples' description.
    pub input: String,
    pub rows: usize,
    /// "rel_err(b, a) = |b - a| / max(|a|, 1e-3)".
    pub relative_to: String,
    pub difference: Difference,
    /// The f64 twins' difference on the same inputs, where both models have twins.
    #[serde(skip_deserializing)]
    pub twins: Option<Difference>,
    pub worst: Vec<WorstRow>,
    pub histogram: Histogram,
    /// How B is wrong: B/A percentiles, the best-fit scale, the shares brighter and darker (`signed`).
    #[serde(default)]
    pub signed: signed::Signed,
    pub tolerance: Option<f64>,
    /// max_rel <= tolerance and no row finite on one side only (true without a tolerance).
    pub within_tolerance: bool,
}

pub const CHANNELS: [&str; 3] = ["r", "g", "b"];

/// A model's values as read back: a NaN or Inf, written as null, reads as NaN.
fn nan_if_null_rgb<'de, D: serde::Deserializer<'de>>(d: D) -> std::result::Result<[f32; 3], D::Error> {
    Ok(<[Option<f32>; 3]>::deserialize(d)?.map(|x| x.unwrap_or(f32::NAN)))
}

/// The relative difference of one value pair: rel_err(b, a), 0 for equal values (infinities included),
/// infinite when exactly one is finite, and None when both are non-finite and differ (no measure applies).
fn pair_rel(a: f64, b: f64) -> Option<f64> {
    if a == b {
        return Some(0.0);
    }
    match (a.is_finite(), b.is_finite()) {
        (true, true) => Some(rel_err(b, a)),
        (false, false) => None,
        _ => Some(f64::INFINITY),
    }
}

impl Difference {
    /// Values (rows times channels) no difference measures: NaN on both sides.
    pub fn unmeasured(&self) -> usize {
        self.channels.iter().map(|c| c.unmeasured).sum()
    }
}

/// B against A over every row and channel.
pub fn difference(a: &[[f64; 3]], b: &[[f64; 3]]) -> Difference {
    assert_eq!(a.len(), b.len(), "one value of each model per row");
    let channels: Vec<ChannelStats> = (0..3).map(|c| channel_stats(c, a, b)).collect();
    let worst = |f: fn(&ChannelStats) -> f64| channels.iter().map(f).fold(0.0, f64::max);
    let mismatched = channels.iter().any(|c| c.mismatched_nonfinite > 0);
    Difference {
        max_rel: if mismatched { f64::INFINITY } else { worst(|c| c.max_rel) },
        max_abs: worst(|c| c.max_abs),
        channels,
    }
}

fn channel_stats(c: usize, a: &[[f64; 3]], b: &[[f64; 3]]) -> ChannelStats {
    let mut s = ChannelStats { channel: CHANNELS[c].to_string(), ..Default::default() };
    let (mut sum_abs, mut sum_rel, mut n) = (0.0, 0.0, 0usize);
    for (x, y) in a.iter().zip(b).map(|(x, y)| (x[c], y[c])) {
        s.a_nonfinite += !x.is_finite() as usize;
        s.b_nonfinite += !y.is_finite() as usize;
        if x.is_finite() != y.is_finite() {
            s.mismatched_nonfinite += 1;
            continue;
        }
        if !x.is_finite() {
            s.unmeasured += (x != y) as usize;
            continue;
        }
        let (abs, rel) = ((y - x).abs(), rel_err(y, x));
        s.max_abs = s.max_abs.max(abs);
        s.max_rel = s.max_rel.max(rel);
        sum_abs += abs * abs;
        sum_rel += rel * rel;
        n += 1;
    }
    let n = n.max(1) as f64;
    (s.rms_abs, s.rms_rel) = ((sum_abs / n).sqrt(), (sum_rel / n).sqrt());
    s
}

/// The largest relative difference of a row over its channels, with the channel (None: no measure applies).
fn row_rel(a: [f64; 3], b: [f64; 3]) -> Option<(usize, f64)> {
    (0..3).filter_map(|c| pair_rel(a[c], b[c]).map(|r| (c, r))).max_by(|x, y| x.1.total_cmp(&y.1))
}

/// The histogram of rows by `row_rel`.
pub fn histogram(a: &[[f64; 3]], b: &[[f64; 3]]) -> Histogram {
    let mut h = Histogram {
        edges: HISTOGRAM_EDGES.to_vec(),
        counts: vec![0; HISTOGRAM_EDGES.len()],
        identical: 0,
        nonfinite: 0,
    };
    for (x, y) in a.iter().zip(b) {
        h.identical += (x == y) as usize;
        match row_rel(*x, *y) {
            Some((_, r)) if r.is_finite() => h.counts[HISTOGRAM_EDGES.iter().rposition(|&e| r >= e).unwrap_or(0)] += 1,
            _ => h.nonfinite += 1,
        }
    }
    h
}

/// The `count` rows with the largest `row_rel`, largest first (ties: the earlier row first).
pub fn worst_rows(
    samples: &[Sample],
    lines: Option<&[usize]>,
    a: &[[f32; 3]],
    b: &[[f32; 3]],
    count: usize,
) -> Vec<WorstRow> {
    let wide = |v: &[f32; 3]| v.map(f64::from);
    let mut ranked: Vec<(usize, usize, f64)> = (0..samples.len())
        .map(|i| row_rel(wide(&a[i]), wide(&b[i])).map_or((i, 0, f64::INFINITY), |(c, r)| (i, c, r)))
        .collect();
    ranked.sort_by(|x, y| y.2.total_cmp(&x.2).then(x.0.cmp(&y.0)));
    ranked
        .into_iter()
        .take(count)
        .map(|(i, c, rel)| WorstRow {
            index: i,
            line: lines.map(|l| l[i]),
            sample: samples[i],
            a: a[i],
            b: b[i],
            channel: CHANNELS[c].to_string(),
            rel,
            abs: (f64::from(b[i][c]) - f64::from(a[i][c])).abs(),
        })
        .collect()
}

/// The f64 twins of both models over `samples`, where both have one.
pub fn twin_values(a: &Model, b: &Model, samples: &[Sample]) -> Option<(Vec<[f64; 3]>, Vec<[f64; 3]>)> {
    let (ta, tb) = (a.twin()?, b.twin()?);
    Some((samples.iter().map(|s| ta.eval(s)).collect(), samples.iter().map(|s| tb.eval(s)).collect()))
}

/// The inputs and outputs a report is built from.
pub struct Evaluated<'a> {
    pub a: &'a Model,
    pub b: &'a Model,
    pub samples: &'a [Sample],
    pub lines: Option<&'a [usize]>,
    pub a_values: &'a [[f32; 3]],
    pub b_values: &'a [[f32; 3]],
    /// A's exact values, where A is a reference (`diff --reference`): the difference is taken against them
    /// (`a_values` are them rounded to f32, for the rows listed).
    pub a_exact: Option<&'a [[f64; 3]]>,
}

impl DiffReport {
    /// The report of `e` on `device`, `input` saying what the inputs were.
    pub fn build(e: &Evaluated, device: &str, input: &str, worst: usize, tolerance: Option<f64>) -> Self {
        let wide = |v: &[[f32; 3]]| v.iter().map(|x| x.map(f64::from)).collect::<Vec<_>>();
        let (a, b) = (e.a_exact.map_or_else(|| wide(e.a_values), <[_]>::to_vec), wide(e.b_values));
        let difference = difference(&a, &b);
        let within_tolerance = tolerance.is_none_or(|t| difference.max_rel <= t && difference.unmeasured() == 0);
        DiffReport {
            kind: KIND,
            schema: SCHEMA,
            a: if e.a_exact.is_some() { Side::reference(e.a) } else { Side::of(e.a) },
            b: Side::of(e.b),
            device: device.to_string(),
            input: input.to_string(),
            rows: e.samples.len(),
            relative_to: format!("rel_err(b, a) = |b - a| / max(|a|, {}): B against A", crate::accuracy::FLOOR),
            twins: twin_values(e.a, e.b, e.samples).map(|(ta, tb)| self::difference(&ta, &tb)),
            worst: worst_rows(e.samples, e.lines, e.a_values, e.b_values, worst),
            histogram: histogram(&a, &b),
            signed: signed::signed(&a, &b),
            difference,
            tolerance,
            within_tolerance,
        }
    }

    /// The report as Markdown: the channel table, the twins' figures, the histogram and the worst rows.
    pub fn markdown(&self) -> String {
        use crate::export::markdown::{Table, sig};
        let mut out = format!(
            "# {} against {}\n\n{} rows of {} on {}; relative: {}.\n\n",
            self.b.name, self.a.name, self.rows, self.input, self.device, self.relative_to
        );
        for side in [&self.a, &self.b] {
            if let Some(f) = &side.front_end {
                out += &format!("{}'s front end: {f}.\n\n", side.name);
            }
        }
        let mut t =
            Table::new(["channel", "max rel", "RMS rel", "max abs", "RMS abs", "non-finite (A / B / one side only)"]);
        for c in &self.difference.channels {
            t.row([
                c.channel.to_string(),
                sig(c.max_rel, 3),
                sig(c.rms_rel, 3),
                sig(c.max_abs, 3),
                sig(c.rms_abs, 3),
                format!("{} / {} / {}", c.a_nonfinite, c.b_nonfinite, c.mismatched_nonfinite),
            ]);
        }
        out += &t.markdown();
        if let Some(tw) = &self.twins {
            out += &format!(
                "\nf64 twins on the same rows (the formulas' own difference): max rel {}, max abs {}.\n",
                sig(tw.max_rel, 3),
                sig(tw.max_abs, 3)
            );
        }
        out += &self.signed.markdown();
        out += &self.histogram_markdown();
        out += &self.worst_markdown();
        if let Some(tol) = self.tolerance {
            let unmeasured = self.difference.unmeasured();
            out += &match (self.within_tolerance, unmeasured) {
                (true, _) => format!("\nWithin --tolerance {tol} (max rel {}).\n", sig(self.difference.max_rel, 3)),
                (false, 0) => format!("\nABOVE --tolerance {tol} (max rel {}).\n", sig(self.difference.max_rel, 3)),
                (false, n) => format!(
                    "\nNOT within --tolerance {tol}: {n} values are NaN on both sides, which no difference measures (max rel {} over the rest).\n",
                    sig(self.difference.max_rel, 3)
                ),
            };
        }
        out
    }

    fn histogram_markdown(&self) -> String {
        let h = &self.histogram;
        let mut t = crate::export::markdown::Table::new(["largest relative difference of a row", "rows", ""]);
        let most = h.counts.iter().copied().max().unwrap_or(0).max(1);
        for (i, &n) in h.counts.iter().enumerate() {
            let range = match h.edges.get(i + 1) {
                Some(hi) => format!("[{:e}, {:e})", h.edges[i], hi),
                None => format!(">= {:e}", h.edges[i]),
            };
            t.row([range, n.to_string(), "#".repeat((40 * n).div_ceil(most))]);
        }
        format!(
            "\n{} of {} rows identical; {} finite on one side only.\n\n{}",
            h.identical,
            self.rows,
            h.nonfinite,
            t.markdown()
        )
    }

    fn worst_markdown(&self) -> String {
        if self.worst.is_empty() {
            return String::new();
        }
        let mut t =
            crate::export::markdown::Table::new(["row", "n", "v", "l", "roughness", "f0", "A", "B", "rel (channel)"]);
        for w in &self.worst {
            let v3 = |v: [f32; 3]| format!("{} {} {}", v[0], v[1], v[2]);
            let s = &w.sample;
            let row = w.line.map_or(w.index.to_string(), |l| format!("line {l}"));
            t.row([
                row,
                v3(s.n),
                v3(s.v),
                v3(s.l),
                s.roughness.to_string(),
                v3(s.f0),
                v3(w.a),
                v3(w.b),
                format!("{} ({})", crate::export::markdown::sig(w.rel, 3), w.channel),
            ]);
        }
        format!("\nRows where they differ most:\n\n{}", t.markdown())
    }
}

/// The CSV of both outputs: the inputs, A's r,g,b and B's, one row per input row.
pub fn csv(samples: &[Sample], a: &[[f32; 3]], b: &[[f32; 3]]) -> String {
    let mut out = String::with_capacity(samples.len() * 160);
    out.push_str("nx,ny,nz,vx,vy,vz,lx,ly,lz,roughness,f0r,f0g,f0b,a_r,a_g,a_b,b_r,b_g,b_b\n");
    for ((s, x), y) in samples.iter().zip(a).zip(b) {
        let fields: Vec<String> =
            s.n.iter()
                .chain(&s.v)
                .chain(&s.l)
                .chain(std::iter::once(&s.roughness))
                .chain(&s.f0)
                .chain(x)
                .chain(y)
                .map(f32::to_string)
                .collect();
        out.push_str(&fields.join(","));
        out.push('\n');
    }
    out
}

/// The CSV of `diff --reference`: the inputs, the reference's r,g,b (its f64 values rounded to f32), then each
/// model's as m1_r,m1_g,m1_b, m2_r, ... in the order given.
pub fn csv_set(samples: &[Sample], reference: &[[f32; 3]], models: &[Vec<[f32; 3]>]) -> String {
    let mut out = String::with_capacity(samples.len() * (100 + 40 * models.len()));
    out.push_str("nx,ny,nz,vx,vy,vz,lx,ly,lz,roughness,f0r,f0g,f0b,ref_r,ref_g,ref_b");
    for i in 1..=models.len() {
        out.push_str(&format!(",m{i}_r,m{i}_g,m{i}_b"));
    }
    out.push('\n');
    for (k, s) in samples.iter().enumerate() {
        let values = std::iter::once(&reference[k]).chain(models.iter().map(|m| &m[k])).flatten();
        let fields: Vec<String> =
            s.n.iter()
                .chain(&s.v)
                .chain(&s.l)
                .chain(std::iter::once(&s.roughness))
                .chain(&s.f0)
                .chain(values)
                .map(f32::to_string)
                .collect();
        out.push_str(&fields.join(","));
        out.push('\n');
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn identical_values_differ_by_nothing_and_one_sided_infinities_fail() {
        let a = vec![[1.0, 0.0, f64::INFINITY], [0.5, 2.0, 3.0]];
        let d = difference(&a, &a);
        assert_eq!((d.max_rel, d.max_abs), (0.0, 0.0));
        assert_eq!(histogram(&a, &a).identical, 2);
        let mut b = a.clone();
        b[1][1] = f64::NAN;
        let d = difference(&a, &b);
        assert_eq!((d.max_rel, d.channels[1].mismatched_nonfinite), (f64::INFINITY, 1));
        assert_eq!(histogram(&a, &b).nonfinite, 1);
    }

    #[test]
    fn relative_difference_is_against_a_with_the_floor() {
        let d = difference(&[[2.0, 1e-6, 0.0]], &[[3.0, 2e-6, 0.0]]);
        assert_eq!(d.channels[0].max_rel, 0.5);
        assert!((d.channels[1].max_rel - 1e-3).abs() < 1e-12, "{}", d.channels[1].max_rel);
        assert_eq!(d.max_abs, 1.0);
        let h = histogram(&[[2.0, 1.0, 1.0]], &[[3.0, 1.0, 1.0]]);
        assert_eq!(h.counts[HISTOGRAM_EDGES.len() - 2], 1, "0.5 falls in [0.1, 1)");
    }
}
