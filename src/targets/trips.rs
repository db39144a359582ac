//! A BRDF's own loops priced at their trip count. Where a compiler keeps a loop whose trip count it cannot know
//! (`FileModel::uncounted_loops`), every rule would count its body once, and a compiler that unrolls it with a
//! remainder (ptxas) keeps several copies of which one runs. So the model is compiled twice more with every loop
//! at a fixed count of header passes (`loop-passes=`: 2 and 3 per entry, a pass counter in place of its exit
//! tests, `spirv::loops`), which every compiler unrolls, and each term of the rule (each pipe, the schedule
//! latency) is extrapolated linearly in loop-header passes per evaluation from those two compiles to the
//! model's own passes, counted by its eval kernel's translation on the host (`translate::verify::loop_passes`).
//! What that leaves out: the kept loop's own counter, compare and branch per pass (the unrolled code has none);
//! the resident waves are the kernel's as compiled, loop kept.

use super::Run;
use crate::model::Model;
use crate::schema::{FixedPasses, LoopTrips};
use crate::shaders::Shaders;

/// The loop-header passes per entry of the two compiles a model's loops are extrapolated from.
pub const FIXED_PASSES: [u32; 2] = [2, 3];

/// One model with loops brdfprof cannot count: its passes per evaluation and its compiles at fixed passes.
pub struct Trips {
    pub model: Model,
    /// Each such loop's `file:line`, escaped.
    pub at: Vec<String>,
    /// Loop-header passes per evaluation, or why they were not counted.
    pub passes: Result<f64, String>,
    /// The model at each of `FIXED_PASSES` (its label its own) with its passes per evaluation, or why they
    /// could not be made (None where the model's passes were not counted).
    pub fixed: Option<Result<Vec<(u32, Model, f64)>, String>>,
}

impl Trips {
    /// The models of `models` whose loops brdfprof cannot count, each measured and with its fixed-pass twins.
    pub fn of(models: &[Model], shaders: &Shaders) -> Vec<Trips> {
        let mut labels: Vec<String> = models.iter().map(Model::label).collect();
        models
            .iter()
            .filter_map(|m| {
                // A model whose loops are already at fixed passes has its trip count.
                let f = m.file().filter(|f| f.loop_passes.is_none())?;
                let at = loop_lines(f);
                if at.is_empty() {
                    return None;
                }
                let counted = |m: &Model| crate::translate::verify::loop_passes(m, shaders);
                let passes = counted(m).map_err(|e| crate::messages::escape_line(&format!("{e:#}")));
                let loops = f.file.loops.len();
                let fixed = passes.is_ok().then(|| {
                    if loops > 1 {
                        // The host counts every loop's passes in one sum and a twin sets every loop alike: one
                        // slope cannot price loops of different counts, nor a loop inside another.
                        return Err(format!("the file has {loops} loops, and one count of passes prices one loop"));
                    }
                    FIXED_PASSES
                        .iter()
                        .map(|&n| {
                            let twin = fixed_twin(f, n, &mut labels);
                            twin.kernel(crate::model::KernelKind::Shade, shaders)?;
                            Ok((n, twin.clone(), counted(&twin)?))
                        })
                        .collect::<anyhow::Result<Vec<_>>>()
                        .map_err(|e| crate::messages::escape_line(&format!("{e:#}")))
                });
                Some(Trips { model: m.clone(), at, passes, fixed })
            })
            .collect()
    }

    /// The models to compile beside the requested ones.
    pub fn twins(trips: &[Trips]) -> Vec<Model> {
        trips.iter().filter_map(|t| t.fixed.as_ref()?.as_ref().ok()).flatten().map(|(_, m, _)| m.clone()).collect()
    }

    /// The driver note of one run's cost table: each model, its loops' lines, its passes and whether it is
    /// priced at them there (`attached`: the models `attach` priced so on this target).
    pub fn note(trips: &[Trips], attached: &[String]) -> Option<String> {
        let named: Vec<String> = trips
            .iter()
            .map(|t| {
                let label = crate::messages::escape_line(&t.model.label());
                let at = t.at.join(", ");
                match (&t.passes, &t.fixed) {
                    (Ok(p), Some(Ok(_))) if attached.contains(&t.model.label()) => {
                        format!("{label} ({at}) with {p:.1} loop-header passes per evaluation, priced at them")
                    }
                    (Ok(p), Some(Ok(_))) => format!("{label} ({at}) with {p:.1} loop-header passes per evaluation, each loop's body counted once (its compiles at fixed passes were not both priced on this target)"),
                    (Ok(p), Some(Err(e))) => format!("{label} ({at}) with {p:.1} loop-header passes per evaluation, each loop's body counted once ({e})"),
                    (Ok(p), None) => format!("{label} ({at}) with {p:.1} loop-header passes per evaluation, each loop's body counted once"),
                    (Err(e), _) => format!("{label} ({at}), each loop's body counted once (passes not counted: {e})"),
                }
            })
            .collect();
        (!named.is_empty()).then(|| {
            format!(
                "Loops brdfprof cannot count from the source: {}. Passes are counted on the translation check's samples; a model priced at them is compiled again with its loops at {} and {} passes per entry (every compiler unrolls those), and each term of the rule is extrapolated linearly in passes per evaluation from those two compiles; the loop's own counter and branch are left out (docs/measured.md, \"A BRDF's own loops\").",
                named.join("; "),
                FIXED_PASSES[0],
                FIXED_PASSES[1]
            )
        })
    }

    /// Moves the fixed-pass twins' rows (and lines) of a run's report into its `loop_trips` and prices the
    /// run's rows again with them; a twin the target left out or failed is no model of the user's, so its
    /// entries go from the table's lists (its model is then priced with its loops' body once).
    pub fn attach(trips: &[Trips], run: &mut Run) -> Vec<String> {
        let report = &mut run.report;
        let twins: Vec<Model> = Trips::twins(trips);
        let is_twin = |m: &str| twins.iter().any(|t| t.label() == m || t.name() == m);
        let mut attached = Vec::new();
        for t in trips {
            let (Ok(passes), Some(Ok(fixed))) = (&t.passes, &t.fixed) else { continue };
            let rows: Vec<FixedPasses> = fixed
                .iter()
                .filter_map(|(n, twin, p)| {
                    let row =
                        report.rows.iter().position(|r| r.model == twin.label()).map(|k| report.rows.remove(k))?;
                    Some(FixedPasses { loop_passes: *n, passes: *p, stats: row.stats })
                })
                .collect();
            if rows.len() == fixed.len() {
                report.loop_trips.push(LoopTrips { model: t.model.label(), passes: *passes, fixed: rows });
                attached.push(t.model.label());
            }
        }
        report.rows.retain(|r| !is_twin(&r.model));
        report.lines.retain(|l| !is_twin(&l.model));
        if let Some(mut cost) = report.cost.take() {
            if !attached.is_empty()
                && let Some(priced) = super::cost_of(report)
            {
                cost.rows = priced.rows;
            }
            cost.rows.retain(|r| !is_twin(&r.model));
            cost.absent.retain(|(m, _)| !is_twin(m));
            cost.failed.retain(|(m, _)| !is_twin(m));
            report.cost = Some(cost);
        }
        attached
    }
}

/// Whether `model` is a fixed-pass twin `Trips::of` made (a user's `loop-passes=` model is not).
pub fn is_twin(model: &Model) -> bool {
    model.file().is_some_and(|f| f.loop_passes.is_some() && f.label.as_deref().is_some_and(|l| l.contains(TWIN_MARK)))
}

/// What a twin's label carries after its model's: `.loop-passes=`.
const TWIN_MARK: &str = ".loop-passes=";

/// The note of a cost table that counts each loop's body once (a scene's kernels): the models with loops
/// brdfprof cannot count, and each such loop's line.
pub fn counted_once_note(models: &[Model]) -> Option<String> {
    let named: Vec<String> = models
        .iter()
        .filter_map(|m| {
            let at = loop_lines(m.file()?);
            (!at.is_empty()).then(|| format!("{} ({})", crate::messages::escape_line(&m.label()), at.join(", ")))
        })
        .collect();
    (!named.is_empty()).then(|| {
        format!(
            "Loops brdfprof cannot count from the source: {}. A scene kernel counts each loop's body once, whatever its trip count, and a light loop around it is kept rolled, one light's work per pass (`inspect --model` prices a model's loops at their passes: docs/measured.md, \"A BRDF's own loops\").",
            named.join("; ")
        )
    })
}

/// The `file:line` of each loop of `f` brdfprof cannot count, escaped.
fn loop_lines(f: &crate::model::file_model::FileModel) -> Vec<String> {
    f.uncounted_loops()
        .map(|l| format!("{}:{}", crate::messages::escape_line(l.file.as_deref().unwrap_or(&f.path)), l.line))
        .collect()
}

/// `f`'s model with its loops at `passes` per entry, labelled `<label>.loop-passes=N` (shortened and made a
/// valid label, unique among `labels`).
fn fixed_twin(f: &crate::model::file_model::FileModel, passes: u32, labels: &mut Vec<String>) -> Model {
    let stem: String = Model::File(std::sync::Arc::new(f.clone()))
        .label()
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() || "-_.+".contains(c) { c } else { '_' })
        .take(40)
        .collect();
    let stem = stem.trim_start_matches(['-', '.']);
    let base = format!("{}{TWIN_MARK}{passes}", if stem.is_empty() { "model" } else { stem });
    let label = (0..)
        .map(|k| if k == 0 { base.clone() } else { format!("{base}.{k}") })
        .find(|l| !labels.contains(l))
        .expect("a free label");
    labels.push(label.clone());
    let twin = crate::model::file_model::FileModel { loop_passes: Some(passes), label: Some(label), ..f.clone() };
    Model::File(std::sync::Arc::new(twin))
}
