//! The one rule every AMD, NVIDIA and Intel compile-only target's cycles/eval follows, over figures each
//! vendor's module takes from its compiler's own output (`targets::radv`, `nvidia`, `intel`):
//!
//! - **pipes**: the cycles one wave (warp, hardware thread) keeps each execution pipe busy, every instruction
//!   of the listing counted once (both sides of a branch: no vendor's branch weights, so that vendors differ
//!   only where their compilers' code does); a BRDF's own loop of unknown trip count is priced at the passes
//!   its eval kernel counts, extrapolated from two compiles with it at fixed passes (`Schedule::extrapolated`;
//!   the application's `targets::trips`);
//! - **schedule latency**: the cycles one wave takes alone, by the compiler's own schedule (ACO's per-instruction
//!   clocks, ptxas' stall counts and scoreboard waits, IGC's instruction order over its latency table);
//! - **resident waves**: how many waves the register allocation lets the unit hold, which hide that latency.
//!
//! cycles per wave = max(busiest pipe, schedule latency / resident waves): the unit is busy for as long as its
//! busiest pipe needs, unless too few waves are resident to cover one wave's latency. This is ACO's own
//! Inverse Throughput rule (`aco_statistics.cpp`: max of the resources' usage and latency over waves),
//! applied alike to every vendor. A net figure (what a BRDF adds to the memory-only kernel) is the difference
//! of the two bounds, so it is never above the gross difference; the term that binds the kernel is named, and
//! each term's own difference is kept as a breakdown (`added_terms`). A largest added term would not do: where
//! the BRDF's registers lower occupancy, the latency term grows more than the bound does (navi21's ggx: +31%).
//! Each vendor states its unit (SIMD, SM or EU cycles) and what a wave is; the statistics keep their names in
//! every report (`PIPE_PREFIX`, `LATENCY`, `RESIDENT_WAVES`), so `compare` and the gate read them back.

use std::collections::BTreeMap;

/// Statistic name prefix of a pipe's busy cycles per wave (`Pipe: FMA`).
pub const PIPE_PREFIX: &str = "Pipe: ";
/// Statistic: one wave's cycles alone by the compiler's schedule.
pub const LATENCY: &str = "Schedule Latency";
/// Statistic: waves resident per unit, from the registers.
pub const RESIDENT_WAVES: &str = "Resident Waves";
/// The name of the latency term where it binds.
pub const LATENCY_TERM: &str = "latency / resident waves";

/// The rule, one line, as every report states it.
pub const RULE: &str = "cycles per wave = max(busiest pipe, schedule latency / resident waves), every instruction counted once (a BRDF's loops of unknown trip count: at their counted passes, from two compiles at fixed passes); net = kernel's cycles - memory-only kernel's (each term's difference beside it)";

/// One kernel's figures under the rule.
#[derive(Clone, Debug, PartialEq)]
pub struct Schedule {
    /// (pipe, busy cycles per wave), by name.
    pub pipes: Vec<(String, f64)>,
    pub latency: Option<f64>,
    pub resident_waves: Option<f64>,
}

impl Schedule {
    /// The figures a report row holds (`driver/<executable>/Pipe: ...`, ...), None without any pipe.
    pub fn of(stats: &BTreeMap<String, f64>) -> Option<Schedule> {
        let mut s = Schedule { pipes: Vec::new(), latency: None, resident_waves: None };
        // `driver/<executable>/<name>`: the compiler's statistics (a compute pipeline has one executable).
        for (k, v) in stats {
            let Some((_, name)) = k.strip_prefix("driver/").and_then(|rest| rest.split_once('/')) else { continue };
            match name {
                LATENCY => s.latency = Some(*v),
                RESIDENT_WAVES => s.resident_waves = Some(*v),
                _ => {
                    if let Some(pipe) = name.strip_prefix(PIPE_PREFIX) {
                        s.pipes.push((pipe.to_string(), *v));
                    }
                }
            }
        }
        (!s.pipes.is_empty()).then_some(s)
    }

    /// Every figure in another unit: pipes and latency times `factor` (per evaluation: 1 / (lanes x lights)).
    pub fn scaled(&self, factor: f64) -> Schedule {
        Schedule {
            pipes: self.pipes.iter().map(|(n, v)| (n.clone(), v * factor)).collect(),
            latency: self.latency.map(|l| l * factor),
            resident_waves: self.resident_waves,
        }
    }

    /// The figures at `passes` on the line through `(pa, a)` and `(pb, b)` (`pa != pb`), each pipe and the
    /// latency on its own, none below zero: a kernel whose loops run `passes` header passes, from two compiles
    /// of it with its loops at fixed passes (the application's `targets::trips`). The resident waves are given.
    pub fn extrapolated(
        (pa, a): (f64, &Schedule),
        (pb, b): (f64, &Schedule),
        passes: f64,
        resident_waves: Option<f64>,
    ) -> Schedule {
        let at = |x: f64, y: f64| (x + (passes - pa) / (pb - pa) * (y - x)).max(0.0);
        let of = |s: &Schedule, name: &str| s.pipes.iter().find(|(n, _)| n == name).map_or(0.0, |p| p.1);
        let mut pipes: Vec<(String, f64)> = Vec::new();
        for (n, _) in a.pipes.iter().chain(&b.pipes) {
            if !pipes.iter().any(|(p, _)| p == n) {
                pipes.push((n.clone(), at(of(a, n), of(b, n))));
            }
        }
        let latency = match (a.latency, b.latency) {
            (Some(x), Some(y)) => Some(at(x, y)),
            _ => None,
        };
        Schedule { pipes, latency, resident_waves }
    }

    /// Latency over resident waves, where both are known.
    pub fn hidden_latency(&self) -> Option<f64> {
        match (self.latency, self.resident_waves) {
            (Some(l), Some(w)) if w > 0.0 => Some(l / w),
            _ => None,
        }
    }

    /// Every term of the rule: the pipes, then the latency term.
    pub fn terms(&self) -> Vec<(String, f64)> {
        let mut t = self.pipes.clone();
        if let Some(h) = self.hidden_latency() {
            t.push((LATENCY_TERM.to_string(), h));
        }
        t
    }

    /// The busiest pipe and its cycles.
    pub fn throughput(&self) -> (String, f64) {
        largest(self.pipes.iter().cloned())
    }

    /// Cycles per wave and the term that binds.
    pub fn cycles(&self) -> (String, f64) {
        largest(self.terms().into_iter())
    }

    /// What this kernel adds to `base` (the memory-only kernel): the term binding this kernel, and the
    /// difference of the two kernels' cycles.
    pub fn net(&self, base: &Schedule) -> (String, f64) {
        let (name, mine) = self.cycles();
        (name, mine - base.cycles().1)
    }

    /// Each term's difference from `base`'s (a pipe the memory-only kernel does not use is 0 there).
    pub fn added_terms(&self, base: &Schedule) -> Vec<(String, f64)> {
        let base_terms = base.terms();
        self.terms()
            .into_iter()
            .map(|(name, v)| {
                let b = base_terms.iter().find(|(b, _)| *b == name).map_or(0.0, |t| t.1);
                (name, v - b)
            })
            .collect()
    }
}

/// The largest value of `terms` with its name (the first on a tie); ("-", 0) for none.
fn largest(terms: impl Iterator<Item = (String, f64)>) -> (String, f64) {
    terms.fold(("-".to_string(), f64::NEG_INFINITY), |best, t| if t.1 > best.1 { t } else { best })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn stats(pairs: &[(&str, f64)]) -> BTreeMap<String, f64> {
        pairs.iter().map(|(k, v)| (format!("driver/X/{k}"), *v)).collect()
    }

    #[test]
    fn the_busiest_pipe_binds_unless_latency_is_not_hidden() {
        let s = Schedule::of(&stats(&[
            ("Pipe: FMA", 100.0),
            ("Pipe: MUFU", 40.0),
            (LATENCY, 800.0),
            (RESIDENT_WAVES, 16.0),
        ]))
        .unwrap();
        assert_eq!(s.throughput(), ("FMA".to_string(), 100.0));
        assert_eq!(s.cycles(), ("FMA".to_string(), 100.0));
        let few = Schedule { resident_waves: Some(4.0), ..s.clone() };
        assert_eq!(few.cycles(), (LATENCY_TERM.to_string(), 200.0));
        assert_eq!(Schedule::of(&stats(&[(LATENCY, 1.0)])), None);
    }

    #[test]
    fn a_loop_at_its_passes_is_on_the_line_through_two_fixed_counts() {
        let s = |fma: f64, lat: f64, waves: f64| Schedule {
            pipes: vec![("FMA".into(), fma), ("SFU".into(), 2.0)],
            latency: Some(lat),
            resident_waves: Some(waves),
        };
        // 2 passes: 10 FMA cycles, 3 passes: 14; 17 passes adds 15 more bodies of 4.
        let at = Schedule::extrapolated((2.0, &s(10.0, 100.0, 8.0)), (3.0, &s(14.0, 116.0, 6.0)), 17.0, Some(5.0));
        assert_eq!(at.pipes, [("FMA".to_string(), 70.0), ("SFU".to_string(), 2.0)]);
        assert_eq!((at.latency, at.resident_waves), (Some(340.0), Some(5.0)));
        // A term that fell between the two compiles stops at zero.
        let down = Schedule::extrapolated((2.0, &s(10.0, 100.0, 8.0)), (3.0, &s(9.0, 90.0, 8.0)), 40.0, None);
        assert_eq!((down.pipes[0].1, down.latency), (0.0, Some(0.0)));
    }

    #[test]
    fn net_is_the_difference_of_the_bounds_never_above_it() {
        let s = |fma: f64, mufu: f64, lat: f64, waves: f64| Schedule {
            pipes: vec![("FMA".into(), fma), ("MUFU".into(), mufu)],
            latency: Some(lat),
            resident_waves: Some(waves),
        };
        // The base binds on latency (50), the kernel on MUFU (70): it adds 20, though MUFU alone grew by 70.
        let (kernel, base) = (s(60.0, 70.0, 400.0, 10.0), s(10.0, 0.0, 500.0, 10.0));
        assert_eq!(kernel.net(&base), ("MUFU".to_string(), 20.0));
        assert_eq!(
            kernel.added_terms(&base),
            [("FMA".to_string(), 50.0), ("MUFU".to_string(), 70.0), (LATENCY_TERM.to_string(), -10.0)]
        );
        // Registers halve the waves: the latency term doubles (40 -> 80) while the bound grows by 30.
        let (kernel, base) = (s(70.0, 0.0, 800.0, 10.0), s(50.0, 0.0, 400.0, 10.0));
        let fewer = Schedule { resident_waves: Some(5.0), ..kernel };
        let (name, net) = fewer.net(&base);
        assert_eq!((name.as_str(), net), (LATENCY_TERM, 160.0 - 50.0));
        assert!(fewer.added_terms(&base).iter().any(|(n, v)| n == LATENCY_TERM && *v == 120.0));
        assert!(net <= fewer.cycles().1 - base.cycles().1);
    }
}
