//! The shader-db-style report of a comparison.

use super::baseline::Baseline;
use super::compare::{Change, Comparison, GroupStatus, rel_change};
use super::thresholds::{ALPHA, MIN_TIMING_ROUNDS, TIMING_KEY};
use crate::export::markdown::{self, Table};
use crate::schema::format_value;
use std::path::Path;

/// Lines shown per regressed model.
pub const LINES_SHOWN: usize = 5;

fn percent(rel: f64) -> String {
    if rel.is_infinite() {
        return if rel > 0.0 { "+inf".into() } else { "-inf".into() };
    }
    format!("{:+.2}%", rel * 100.0)
}

impl Comparison {
    pub fn regressions(&self) -> Vec<String> {
        let counts = self.changes.iter().filter(|c| c.is_regression()).map(|c| {
            format!(
                "{} {}: {} -> {} ({}, threshold {})",
                c.model,
                c.key,
                format_value(c.old),
                format_value(c.new),
                percent(c.rel),
                percent(c.threshold)
            )
        });
        let timing = self.timing.iter().filter(|t| t.is_regression()).map(|t| {
            format!(
                "{} {TIMING_KEY}: {} -> {} ({}, p = {}, threshold {})",
                t.model,
                markdown::sig(t.old_median, 4),
                markdown::sig(t.new_median, 4),
                percent(t.change),
                markdown::sig(t.p.unwrap_or(1.0), 2),
                percent(t.threshold)
            )
        });
        counts.chain(timing).collect()
    }

    /// Groups that should have been measured and were not.
    pub fn not_measured(&self) -> Vec<String> {
        self.groups
            .iter()
            .filter_map(|(g, s)| if let GroupStatus::NotMeasured(why) = s { Some(format!("{g}: {why}")) } else { None })
            .collect()
    }

    /// 1 on any regression, else 2 when a group could not be measured, else 0.
    pub fn exit_code(&self) -> u8 {
        if !self.regressions().is_empty() {
            1
        } else if !self.not_measured().is_empty() {
            2
        } else {
            0
        }
    }

    /// The shader-db-style report.
    pub fn report(&self, baseline_path: &Path, new: &Baseline) -> String {
        let mut out = format!("# brdfprof check against {}\n\n", baseline_path.display());
        out += &self.verdict_head();
        out += &format!("{}\n\n", new.inspect.summary());
        out += &self.cost_section();
        out += &self.groups_section();
        out += &self.changes_section();
        out += &self.helped_hurt_section();
        out += &self.totals_section();
        out += &self.timing_section();
        out += &self.lines_section();
        for note in self.notes.iter().chain(
            self.only_old
                .iter()
                .map(|m| format!("{m}: in the baseline only, not measured now"))
                .collect::<Vec<_>>()
                .iter(),
        ) {
            out += &format!("Note: {note}\n");
        }
        for m in &self.only_new {
            out += &format!("Note: {m}: no baseline figures (new model)\n");
        }
        out += &self.verdict_section();
        out
    }

    /// The verdict in the report's first lines, so that a reader (or a step summary cut at its limit) sees it
    /// first: regressed or not, how many models, the worst one with its modelled cycles per evaluation.
    pub fn verdict_head(&self) -> String {
        let mut models: Vec<&str> =
            self.changes.iter().filter(|c| c.is_regression()).map(|c| c.model.as_str()).collect();
        models.extend(self.timing.iter().filter(|t| t.is_regression()).map(|t| t.model.as_str()));
        models.sort();
        models.dedup();
        let missing = self.not_measured();
        if models.is_empty() {
            let verdict = if missing.is_empty() { "no regression" } else { "COULD NOT MEASURE" };
            return format!("**Verdict: {verdict}** ({} models compared)\n\n", self.models().len());
        }
        let worst = *models.iter().max_by(|a, b| self.size(a).total_cmp(&self.size(b))).expect("a regressed model");
        let cost = self.changes.iter().find(|c| c.model == worst && c.key == super::thresholds::COST_KEYS[0]);
        let detail = match cost {
            Some(c) => format!(
                "cycles per evaluation {} -> {} ({})",
                markdown::sig(c.old, 4),
                markdown::sig(c.new, 4),
                percent(c.rel)
            ),
            None => self
                .regressions()
                .into_iter()
                .find(|r| r.starts_with(&format!("{worst} ")))
                .map_or_else(String::new, |r| r[worst.len() + 1..].to_string()),
        };
        format!(
            "**Verdict: REGRESSED**: {} of {} models; the worst, `{worst}`: {detail}\n\n",
            models.len(),
            self.models().len()
        )
    }

    /// Each model's modelled cycles per evaluation before and after (a compile-only target's one rule, gross and
    /// net of the memory-only kernel): the figure the cost tables headline, gated by the `cost` group.
    fn cost_section(&self) -> String {
        let [gross, net] = super::thresholds::COST_KEYS;
        let of = |m: &str, k: &str| self.changes.iter().find(|c| c.model == m && c.key == k);
        let models: Vec<&str> = self.models().into_iter().filter(|m| of(m, gross).is_some()).collect();
        if models.is_empty() {
            return String::new();
        }
        let mut t = Table::new(["model", "cycles/eval", "change", "net cycles/eval", "change", "verdict"]);
        for m in &models {
            let g = of(m, gross).expect("filtered");
            let n = of(m, net);
            let verdict = if g.is_regression() || n.is_some_and(Change::is_regression) { "REGRESSION" } else { "-" };
            t.row([
                m.to_string(),
                format!("{} -> {}", markdown::sig(g.old, 4), markdown::sig(g.new, 4)),
                percent(g.rel),
                n.map_or("-".into(), |n| format!("{} -> {}", markdown::sig(n.old, 4), markdown::sig(n.new, 4))),
                n.map_or("-".into(), |n| if n.gated { percent(n.rel) } else { "harness-bound".into() }),
                verdict.into(),
            ]);
        }
        format!(
            "## Modelled cycles per evaluation\n\nEach model's cycles per BRDF evaluation under the target's one cost rule, before -> after, gated at {} by default (`--threshold cost=FRACTION`); instruction counts follow as secondary findings.\n\n{}\n",
            percent(super::thresholds::DEFAULT_COST_THRESHOLD).trim_start_matches('+'),
            t.markdown()
        )
    }

    fn groups_section(&self) -> String {
        let mut t = Table::new(["group", "status"]);
        for (g, s) in &self.groups {
            let text = match s {
                GroupStatus::Compared => "compared".to_string(),
                GroupStatus::Forced(d) => format!("compared (--force) although the environment differs: {d}"),
                GroupStatus::NotComparable(d) => format!("not comparable: {d} (--force compares anyway)"),
                GroupStatus::Absent(why) => format!("not compared: {why}"),
                GroupStatus::NotMeasured(why) => format!("NOT MEASURED: {why}"),
            };
            t.row([g.clone(), text]);
        }
        format!("## Statistic groups\n\n{}\n", t.markdown())
    }

    fn changes_section(&self) -> String {
        let changed: Vec<&Change> = self.changes.iter().filter(|c| c.old != c.new).collect();
        let out = format!(
            "## Changes\n\n{} statistics compared over {} models, {} changed.\n\n",
            self.changes.len(),
            self.models().len(),
            changed.len()
        );
        if changed.is_empty() {
            return out;
        }
        let mut t = Table::new(["model", "statistic", "old", "new", "change", "threshold", "verdict"]);
        for c in changed {
            let verdict = if c.is_regression() {
                "REGRESSION"
            } else if !c.gated {
                "reported only"
            } else if c.new > c.old {
                "hurt, within threshold"
            } else {
                "helped"
            };
            t.row([
                c.model.clone(),
                c.key.clone(),
                format_value(c.old),
                format_value(c.new),
                percent(c.rel),
                percent(c.threshold),
                verdict.into(),
            ]);
        }
        out + &t.markdown() + "\n"
    }

    fn models(&self) -> Vec<&str> {
        let mut m: Vec<&str> = self.changes.iter().map(|c| c.model.as_str()).collect();
        m.dedup();
        m
    }

    fn helped_hurt_section(&self) -> String {
        let mut hurt: Vec<&Change> = self.changes.iter().filter(|c| c.new > c.old).collect();
        let mut helped: Vec<&Change> = self.changes.iter().filter(|c| c.new < c.old).collect();
        hurt.sort_by(|a, b| b.rel.total_cmp(&a.rel));
        helped.sort_by(|a, b| a.rel.total_cmp(&b.rel));
        let line = |c: &&Change| {
            format!(
                "- {} {}: {} -> {} ({})\n",
                c.model,
                c.key,
                format_value(c.old),
                format_value(c.new),
                percent(c.rel)
            )
        };
        let list = |cs: &[&Change]| if cs.is_empty() { "(none)\n".to_string() } else { cs.iter().map(line).collect() };
        format!(
            "## Hurt ({}), largest change first\n\n{}\n## Helped ({}), largest change first\n\n{}\n",
            hurt.len(),
            list(&hurt),
            helped.len(),
            list(&helped)
        )
    }

    /// Totals of every statistic that changed somewhere (and of the headline totals), over all models and
    /// over the models where it changed.
    fn totals_section(&self) -> String {
        const HEADLINES: [&str; 3] = ["spirv/total", "spirv-O/total", "callgrind/ir-per-eval"];
        let mut keys: Vec<&str> = Vec::new();
        for c in &self.changes {
            if (c.old != c.new || HEADLINES.contains(&c.key.as_str())) && !keys.contains(&c.key.as_str()) {
                keys.push(&c.key);
            }
        }
        let mut all = Table::new(["statistic", "models", "old", "new", "change"]);
        let mut affected = Table::new(["statistic", "models", "old", "new", "change"]);
        for key in keys {
            let of_key: Vec<&Change> = self.changes.iter().filter(|c| c.key == key).collect();
            let sum = |cs: &[&Change]| (cs.iter().map(|c| c.old).sum::<f64>(), cs.iter().map(|c| c.new).sum::<f64>());
            let (o, n) = sum(&of_key);
            all.row([
                key.to_string(),
                of_key.len().to_string(),
                format_value(o),
                format_value(n),
                percent(rel_change(o, n)),
            ]);
            let changed: Vec<&Change> = of_key.iter().copied().filter(|c| c.old != c.new).collect();
            if !changed.is_empty() {
                let (o, n) = sum(&changed);
                affected.row([
                    key.to_string(),
                    changed.len().to_string(),
                    format_value(o),
                    format_value(n),
                    percent(rel_change(o, n)),
                ]);
            }
        }
        let mut out = format!("## Totals over all models\n\n{}\n", all.markdown());
        if !affected.rows.is_empty() {
            out += &format!("## Totals over affected models\n\n{}\n", affected.markdown());
        }
        out
    }

    fn timing_section(&self) -> String {
        if self.timing.is_empty() {
            return String::new();
        }
        let mut t =
            Table::new(["model", "old median [rounds]", "new median [rounds]", "change", "p", "threshold", "verdict"]);
        for c in &self.timing {
            t.row([
                c.model.clone(),
                format!("{} [{}]", markdown::sig(c.old_median, 4), c.n_old),
                format!("{} [{}]", markdown::sig(c.new_median, 4), c.n_new),
                percent(c.change),
                c.p.map_or("-".into(), |p| markdown::sig(p, 2)),
                percent(c.threshold),
                c.verdict().into(),
            ]);
        }
        format!(
            "## Timing: cost / reference, per round (Mann-Whitney U, alpha {ALPHA}, at least {MIN_TIMING_ROUNDS} rounds a side)\n\nReference: {}.\n\n{}\n",
            self.timing_reference,
            t.markdown()
        )
    }

    /// Each regressed model's lines whose cost rose most (`LINES_SHOWN`).
    fn lines_section(&self) -> String {
        let mut out = String::new();
        for m in &self.lines {
            let risen = super::lines::risen(&m.changes, LINES_SHOWN);
            if risen.is_empty() {
                continue;
            }
            let mut t = Table::new(["file:line", "before", "after", "change", "share of the rise", "source"]);
            for c in risen {
                t.row([
                    format!("{}:{}", c.file, c.line),
                    markdown::sig(c.before, 4),
                    markdown::sig(c.after, 4),
                    format!("+{}", markdown::sig(c.rise(), 4)),
                    format!("{:.0}%", 100.0 * c.share),
                    format!("`{}`", c.text.replace('|', "\\|").replace('`', "'")),
                ]);
            }
            out += &format!(
                "## {}: the lines whose cost rose most ({} cycles per wave; lines matched by their text, so an edit above a line does not move it)\n\n{}\n",
                m.model,
                m.pipe,
                t.markdown()
            );
        }
        out
    }

    fn verdict_section(&self) -> String {
        let regressions = self.regressions();
        let missing = self.not_measured();
        let mut out = String::from("\n## Verdict\n\n");
        if !regressions.is_empty() {
            out += &format!("REGRESSION: {} statistic(s) beyond threshold:\n", regressions.len());
            out += &regressions.iter().map(|r| format!("- {r}\n")).collect::<String>();
        }
        if !missing.is_empty() {
            out += &format!("COULD NOT MEASURE: {}\n", missing.join("; "));
        }
        if regressions.is_empty() && missing.is_empty() {
            out += "no regression\n";
        }
        out
    }
}
