//! How B is wrong, not only how far: over every channel value where both models are finite, the percentiles
//! of B/A (where |A| is above the relative floor, `accuracy::FLOOR`), the least-squares scale s that best maps
//! A onto B (B ~ s A), and the shares of values where B is brighter or darker than A by more than that floor
//! in relative terms. A model 4x too bright reads s = 4 and a median B/A of 4 where an unsigned error says
//! only "3 too far".

use crate::export::markdown::sig;
use serde::{Deserialize, Serialize};

/// The percentiles of B/A given.
pub const PERCENTILES: [f64; 7] = [1.0, 5.0, 25.0, 50.0, 75.0, 95.0, 99.0];

/// The signed comparison of B against A.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Signed {
    /// Channel values with both sides finite.
    pub values: usize,
    /// Of those, the ones with |A| above the floor, over which B/A is taken.
    pub ratio_values: usize,
    /// (percentile, B/A) for `PERCENTILES`; empty where no value has |A| above the floor.
    pub ratio_percentiles: Vec<(f64, f64)>,
    /// sum(A B) / sum(A^2): the s minimising sum (B - s A)^2; None where A is 0 everywhere.
    pub best_fit_scale: Option<f64>,
    /// Shares of `values` where (B - A) / max(|A|, floor) is above the floor (brighter) or below minus it (darker).
    pub brighter: f64,
    pub darker: f64,
}

/// The value at percentile `p` of sorted `v` (nearest rank).
fn percentile(v: &[f64], p: f64) -> f64 {
    let k = ((p / 100.0) * v.len() as f64).ceil().max(1.0) as usize;
    v[k.min(v.len()) - 1]
}

/// The signed comparison of `b` against `a`, row by row and channel by channel.
pub fn signed(a: &[[f64; 3]], b: &[[f64; 3]]) -> Signed {
    let floor = crate::accuracy::FLOOR;
    let pairs: Vec<(f64, f64)> = a
        .iter()
        .zip(b)
        .flat_map(|(x, y)| x.iter().copied().zip(y.iter().copied()))
        .filter(|(x, y)| x.is_finite() && y.is_finite())
        .collect();
    let mut ratios: Vec<f64> = pairs.iter().filter(|(x, _)| x.abs() > floor).map(|(x, y)| y / x).collect();
    ratios.sort_by(f64::total_cmp);
    let (ab, aa) = pairs.iter().fold((0.0, 0.0), |(ab, aa), (x, y)| (ab + x * y, aa + x * x));
    let share = |pred: &dyn Fn(f64) -> bool| {
        let n = pairs.iter().filter(|(x, y)| pred((y - x) / x.abs().max(floor))).count();
        if pairs.is_empty() { 0.0 } else { n as f64 / pairs.len() as f64 }
    };
    Signed {
        values: pairs.len(),
        ratio_values: ratios.len(),
        ratio_percentiles: if ratios.is_empty() {
            Vec::new()
        } else {
            PERCENTILES.iter().map(|&p| (p, percentile(&ratios, p))).collect()
        },
        best_fit_scale: (aa > 0.0).then(|| ab / aa),
        brighter: share(&|r| r > floor),
        darker: share(&|r| r < -floor),
    }
}

impl Signed {
    /// B/A at percentile `p`, where computed.
    pub fn ratio_at(&self, p: f64) -> Option<f64> {
        self.ratio_percentiles.iter().find(|(q, _)| *q == p).map(|(_, r)| *r)
    }

    /// One paragraph of Markdown.
    pub fn markdown(&self) -> String {
        let scale = self.best_fit_scale.map_or("- (A is 0 everywhere)".into(), |s| sig(s, 4));
        let ratios = if self.ratio_percentiles.is_empty() {
            "no value of A above the floor".to_string()
        } else {
            self.ratio_percentiles.iter().map(|(p, r)| format!("p{p} {}", sig(*r, 3))).collect::<Vec<_>>().join(", ")
        };
        format!(
            "\nSigned, B against A over {} channel values: best-fit scale B ~ s A with s = {scale}; B/A percentiles ({} values with |A| > {}): {ratios}; B brighter than A on {:.1}% of values, darker on {:.1}% (by more than {} relative).\n",
            self.values,
            self.ratio_values,
            crate::accuracy::FLOOR,
            100.0 * self.brighter,
            100.0 * self.darker,
            crate::accuracy::FLOOR
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_model_four_times_too_bright_reads_four() {
        let a: Vec<[f64; 3]> = (1..=100).map(|i| [i as f64 * 0.01, 0.5, 2.0]).collect();
        let b: Vec<[f64; 3]> = a.iter().map(|x| x.map(|v| 4.0 * v)).collect();
        let s = signed(&a, &b);
        assert!((s.best_fit_scale.unwrap() - 4.0).abs() < 1e-12);
        assert!(s.ratio_percentiles.iter().all(|(_, r)| (r - 4.0).abs() < 1e-12));
        assert_eq!((s.brighter, s.darker, s.values), (1.0, 0.0, 300));
        let half = signed(&b, &a);
        assert!((half.best_fit_scale.unwrap() - 0.25).abs() < 1e-12 && half.darker == 1.0);
    }

    #[test]
    fn non_finite_values_and_a_below_the_floor_are_left_out_of_the_ratios() {
        let a = [[0.0, f64::NAN, 1.0], [1e-5, 2.0, 1.0]];
        let b = [[1.0, 1.0, 1.0], [1e-5, 3.0, 0.5]];
        let s = signed(&a, &b);
        assert_eq!((s.values, s.ratio_values), (5, 3));
        assert_eq!(s.ratio_at(50.0), Some(1.0));
        assert_eq!(s.ratio_at(1.0), Some(0.5));
        assert_eq!(s.ratio_at(99.0), Some(1.5));
    }
}
