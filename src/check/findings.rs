//! A comparison's regressions as findings (`export::sarif::Finding`): one per regressed model, located at the
//! lines of the model's own file whose cost rose most (at the file where no line is known), for SARIF and
//! GitHub's annotations.

use super::baseline::Baseline;
use super::compare::Comparison;
use super::report::LINES_SHOWN;
use super::thresholds::TIMING_KEY;
use crate::export::markdown::sig;
use crate::export::sarif::{Finding, Place, Rule};
use crate::model::Model;
use serde_json::json;

pub const COUNT_RULE: Rule = Rule {
    id: "brdfprof/count-regression",
    name: "Shader cost regression",
    short: "A model's instruction counts or modelled cycles grew past the check's threshold.",
    full: "brdfprof check compared the model's kernel with the saved baseline: its modelled cycles per evaluation on a compile-only target (the cost group, default threshold 2%) or a gated statistic (SPIR-V, driver or compiler statistics, callgrind) grew by more than its threshold (--threshold). The locations are the source lines whose cost on the kernel's binding pipe rose most.",
    help: "The model's shader costs more than the baseline recorded. Look at the lines named (their cost on the kernel's binding pipe rose most) and at the report's 'Modelled cycles per evaluation' table. If the change is intended, save a new baseline: `brdfprof check --baseline B --save-baseline B` (docs/gate.md).",
};

pub const TIMING_RULE: Rule = Rule {
    id: "brdfprof/timing-regression",
    name: "Shader timing regression",
    short: "A model's measured cost relative to the reference model rose significantly past the threshold.",
    full: "brdfprof check timed the model interleaved with the reference model: its per-round cost ratio rose past the noise threshold with a significant Mann-Whitney U test (alpha 0.05).",
    help: "The model's measured cost relative to the reference rose. Rerun to rule out a noisy machine (the test already accounts for the rounds' spread); if the change is intended, save a new baseline with --save-baseline (docs/gate.md).",
};

pub const FAILED_RULE: Rule = Rule {
    id: "brdfprof/model-failed",
    name: "Model not measured",
    short: "A model failed on the check's target, so the check has no figures for it.",
    full: "brdfprof check could not measure the model on the target: its translation failed its check against the Vulkan device, or the vendor's compiler refused it. The other models were measured and compared; the check fails until this one is measured again.",
    help: "The message gives the compiler's or the translation check's reason. Fix the shader (or report a brdfprof defect where the reason says so); the check passes again once the model is measured.",
};

/// Statistics a finding's message names (the largest relative changes).
const MESSAGE_CHANGES: usize = 3;

/// Every rule a finding may name, in SARIF's `rules` order.
pub const RULES: [&Rule; 3] = [&COUNT_RULE, &TIMING_RULE, &FAILED_RULE];

/// What `new` was measured on (`Baseline::measured_on`).
pub fn measured_on(new: &Baseline) -> (String, String) {
    new.measured_on()
}

/// One finding per model that failed on the target of `new` (its cost section's `failed`), at its file where
/// it is one of `models`.
pub fn failed(new: &Baseline, models: &[Model]) -> Vec<Finding> {
    let (target, compiler) = measured_on(new);
    let Some(cost) = &new.inspect.cost else { return Vec::new() };
    cost.failed
        .iter()
        .map(|(model, why)| {
            let file = models.iter().find(|m| m.label() == *model).and_then(|m| m.file().map(|f| f.path.clone()));
            Finding {
                rule: &FAILED_RULE,
                message: format!("{model} on {target}: failed, so no figures: {why}"),
                places: file
                    .into_iter()
                    .map(|f| Place { file: f, line: None, text: String::new(), note: String::new() })
                    .collect(),
                identity: format!("{target}\n{model}\nfailed"),
                properties: json!({ "model": model, "target": target, "compiler": compiler, "failed": why }),
            }
        })
        .collect()
}

/// The model file behind row `model` of `new`, where it is one.
fn model_file(new: &Baseline, model: &str) -> Option<String> {
    let spec = new.inspect.row(model)?.spec.as_deref()?;
    Model::parse(spec).ok()?.file().map(|f| f.path.clone())
}

/// One finding per regressed model, the largest relative change first.
pub fn findings(cmp: &Comparison, new: &Baseline) -> Vec<Finding> {
    let (target, compiler) = measured_on(new);
    let mut models: Vec<String> = Vec::new();
    let regressions = cmp.changes.iter().filter(|c| c.is_regression()).map(|c| &c.model);
    for model in regressions.chain(cmp.timing.iter().filter(|t| t.is_regression()).map(|t| &t.model)) {
        if !models.contains(model) {
            models.push(model.clone());
        }
    }
    models.sort_by(|a, b| cmp.size(b).total_cmp(&cmp.size(a)).then(a.cmp(b)));
    models.iter().map(|model| finding(cmp, new, model, &target, &compiler)).collect()
}

fn finding(cmp: &Comparison, new: &Baseline, model: &str, target: &str, compiler: &str) -> Finding {
    let mut regressed: Vec<_> = cmp.changes.iter().filter(|c| c.model == model && c.is_regression()).collect();
    regressed.sort_by(|a, b| b.rel.total_cmp(&a.rel));
    let counts: Vec<String> = regressed
        .iter()
        .map(|c| format!("{} {} -> {} ({:+.1}%)", c.key, sig(c.old, 4), sig(c.new, 4), 100.0 * c.rel))
        .collect();
    let timing: Vec<String> = cmp
        .timing
        .iter()
        .filter(|t| t.model == model && t.is_regression())
        .map(|t| {
            format!("{TIMING_KEY} {} -> {} ({:+.1}%)", sig(t.old_median, 4), sig(t.new_median, 4), 100.0 * t.change)
        })
        .collect();
    let rule = if counts.is_empty() { &TIMING_RULE } else { &COUNT_RULE };
    let file = model_file(new, model);
    let lines = cmp.lines.iter().find(|m| m.model == model);
    // The model's own lines: glsl/'s are brdfprof's, not in the user's repository.
    let places: Vec<Place> = lines
        .map(|m| super::lines::risen(&m.changes, usize::MAX))
        .unwrap_or_default()
        .into_iter()
        .filter(|c| file.as_deref().is_some_and(|f| same_file(f, &c.file)))
        .take(LINES_SHOWN)
        .map(|c| Place {
            file: c.file.clone(),
            line: Some(c.line),
            text: c.text.clone(),
            note: format!(
                "+{} {} cycles per wave ({} -> {}), {:.0}% of the rise",
                sig(c.rise(), 3),
                lines.map_or("", |m| m.pipe.as_str()),
                sig(c.before, 3),
                sig(c.after, 3),
                100.0 * c.share
            ),
        })
        .collect();
    let places = match (places.is_empty(), &file) {
        (true, Some(f)) => vec![Place { file: f.clone(), line: None, text: String::new(), note: String::new() }],
        _ => places,
    };
    let at = places
        .first()
        .and_then(|p| p.line.map(|l| format!("; the line whose cost rose most: {}:{l} ({})", p.file, p.note)));
    // The message names the largest changes; the properties hold all of them.
    let all: Vec<&String> = timing.iter().chain(&counts).collect();
    let shown = all.iter().take(MESSAGE_CHANGES).map(|s| s.as_str()).collect::<Vec<_>>().join(", ");
    let more = all.len().saturating_sub(MESSAGE_CHANGES);
    let more = if more > 0 { format!(" and {more} more statistic(s)") } else { String::new() };
    Finding {
        rule,
        message: format!("{model} on {target}: {shown}{more}{}", at.unwrap_or_default()),
        places,
        identity: format!("{target}\n{model}"),
        properties: json!({ "model": model, "target": target, "compiler": compiler, "regressions": counts.iter().chain(&timing).collect::<Vec<_>>() }),
    }
}

/// Whether a line's file (as per-line cost names it: relative to the working directory where below it) is
/// the model file `model` (as the user gave it).
fn same_file(model: &str, line_file: &str) -> bool {
    let canon = |p: &str| std::fs::canonicalize(p).ok();
    model == line_file || canon(model).is_some_and(|m| Some(m) == canon(line_file))
}
