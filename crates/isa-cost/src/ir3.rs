//! ir3's statistics (Mesa's Adreno compiler, through Turnip's pipeline-executable statistics) under the one
//! rule: its instruction categories as pipes, its SS and SY stall estimates added to one wave's latency.

use crate::driver_stat;
use crate::schedule::Schedule;

type Stats = std::collections::BTreeMap<String, f64>;

/// ir3's instruction categories by pipe (`instrs_per_cat`, statistics "catN instructions").
pub const PIPES: [(&str, &[u8]); 5] =
    [("ALU", &[1, 2, 3]), ("SFU", &[4]), ("texture", &[5]), ("load/store", &[6]), ("control", &[0, 7])];

/// The rule's figures of one wave of `fibres` (its subgroup size), and its fibres.
pub fn schedule_of(stats: &Stats, fibres: f64) -> Option<(Schedule, f64)> {
    let stat = |name: &str| driver_stat(stats, name);
    let instructions = stat("Instruction Count")?;
    let nops = stat("NOPs Count").unwrap_or(0.0);
    let cat = |k: &u8| stat(&format!("cat{k} instructions"));
    // ir3 older than its per-category statistics: no pipes to price.
    (0..8).try_for_each(|k| cat(&k).map(|_| ()))?;
    let passes = fibres / 64.0;
    let pipes = PIPES
        .iter()
        .map(|(name, cats)| {
            let issued: f64 = cats.iter().filter_map(cat).sum::<f64>() - if cats.contains(&0) { nops } else { 0.0 };
            let per_issue = if *name == "ALU" { passes.max(1.0) } else { 1.0 };
            (name.to_string(), issued.max(0.0) * per_issue)
        })
        .collect();
    let stalls =
        stat("Estimated cycles stalled on SS").unwrap_or(0.0) + stat("Estimated cycles stalled on SY").unwrap_or(0.0);
    let schedule = Schedule { pipes, latency: Some(instructions + stalls), resident_waves: stat("Max Waves Per Core") };
    Some((schedule, fibres))
}
