//! Robust statistics for noisy timings: medians with distribution-free confidence intervals (order statistics
//! of the binomial), and the Mann-Whitney U test. No normality is assumed anywhere.

use serde::Serialize;

/// A median with its confidence interval.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, serde::Deserialize)]
pub struct Estimate {
    pub median: f64,
    pub lo: f64,
    pub hi: f64,
    /// Coverage actually achieved by the order statistics (>= the level asked for, or lower when n is too
    /// small for it, in which case lo/hi are the sample extremes).
    pub coverage: f64,
    pub n: usize,
}

impl Estimate {
    /// Half-width of the interval relative to the median.
    pub fn rel_half_width(&self) -> f64 {
        (self.hi - self.lo) / 2.0 / self.median.abs()
    }
    pub fn overlaps(&self, other: &Estimate) -> bool {
        self.lo <= other.hi && other.lo <= self.hi
    }
}

pub fn median(xs: &[f64]) -> f64 {
    let mut v: Vec<f64> = xs.to_vec();
    v.sort_by(f64::total_cmp);
    let n = v.len();
    assert!(n > 0, "median of nothing");
    if n % 2 == 1 { v[n / 2] } else { 0.5 * (v[n / 2 - 1] + v[n / 2]) }
}

/// ln C(n, k)
fn ln_choose(n: usize, k: usize) -> f64 {
    (1..=k).map(|i| ((n - k + i) as f64).ln() - (i as f64).ln()).sum()
}

/// P(X <= k) for X ~ Binomial(n, 1/2).
pub fn binomial_half_cdf(n: usize, k: usize) -> f64 {
    (0..=k.min(n)).map(|i| (ln_choose(n, i) - n as f64 * std::f64::consts::LN_2).exp()).sum::<f64>().min(1.0)
}

/// Median and its distribution-free confidence interval at `level` (e.g. 0.95): the order statistics
/// x_(j) and x_(n+1-j) with the largest j such that P(Bin(n, 1/2) < j) <= (1 - level)/2.
pub fn median_ci(xs: &[f64], level: f64) -> Estimate {
    let mut v: Vec<f64> = xs.to_vec();
    v.sort_by(f64::total_cmp);
    let n = v.len();
    assert!(n > 0, "median of nothing");
    let tail = (1.0 - level) / 2.0;
    // j is 1-based; P(X <= j-1) is the probability that the median lies below x_(j).
    let mut j = 0;
    while j + 1 <= n / 2 && binomial_half_cdf(n, j) <= tail {
        j += 1;
    }
    let (lo, hi, coverage) = if j == 0 {
        (v[0], v[n - 1], 1.0 - 2.0 * binomial_half_cdf(n, 0))
    } else {
        (v[j - 1], v[n - j], 1.0 - 2.0 * binomial_half_cdf(n, j - 1))
    };
    Estimate { median: median(&v), lo, hi, coverage, n }
}

/// Two-sided Mann-Whitney U test (normal approximation with tie correction, fine for n >= 8 each):
/// the p-value for "a and b come from the same distribution".
pub fn mann_whitney_p(a: &[f64], b: &[f64]) -> f64 {
    let (n1, n2) = (a.len() as f64, b.len() as f64);
    let mut all: Vec<(f64, usize)> = a.iter().map(|&x| (x, 0)).chain(b.iter().map(|&x| (x, 1))).collect();
    all.sort_by(|x, y| x.0.total_cmp(&y.0));
    let mut ranks = vec![0.0; all.len()];
    let mut tie_term = 0.0;
    let mut i = 0;
    while i < all.len() {
        let mut j = i;
        while j + 1 < all.len() && all[j + 1].0 == all[i].0 {
            j += 1;
        }
        let rank = (i + j) as f64 / 2.0 + 1.0;
        ranks[i..=j].iter_mut().for_each(|r| *r = rank);
        let t = (j - i + 1) as f64;
        tie_term += t * t * t - t;
        i = j + 1;
    }
    let r1: f64 = all.iter().zip(&ranks).filter(|((_, g), _)| *g == 0).map(|(_, r)| r).sum();
    let u = r1 - n1 * (n1 + 1.0) / 2.0;
    let n = n1 + n2;
    let sigma = (n1 * n2 / 12.0 * ((n + 1.0) - tie_term / (n * (n - 1.0)))).sqrt();
    if sigma == 0.0 {
        return 1.0;
    }
    let z = (u - n1 * n2 / 2.0).abs() / sigma;
    libm::erfc(z / std::f64::consts::SQRT_2)
}

/// Pairs that `x` and `y` order oppositely, and the pairs both order (a tie on either side is left out):
/// Kendall's discordant pairs, the swaps behind a rank correlation.
pub fn discordant_pairs(x: &[f64], y: &[f64]) -> (usize, usize) {
    let (mut discordant, mut ordered) = (0, 0);
    for i in 0..x.len() {
        for j in i + 1..x.len() {
            if x[i] == x[j] || y[i] == y[j] {
                continue;
            }
            ordered += 1;
            if (x[i] < x[j]) != (y[i] < y[j]) {
                discordant += 1;
            }
        }
    }
    (discordant, ordered)
}

/// Bootstrap draws behind `spearman_ci`, and their seed (fixed, so that a table is reproducible).
pub const BOOTSTRAP_RESAMPLES: usize = 4000;
pub const BOOTSTRAP_SEED: u64 = 2026;

/// Percentile-bootstrap CI at `level` of Spearman's rho: `BOOTSTRAP_RESAMPLES` draws of the n pairs with
/// replacement; a draw whose ranks are all tied on one side has no rho and is left out. None below 4 pairs.
pub fn spearman_ci(x: &[f64], y: &[f64], level: f64) -> Option<(f64, f64)> {
    use rand::{Rng, SeedableRng};
    let n = x.len();
    if n < 4 {
        return None;
    }
    let mut rng = rand_pcg::Pcg64::seed_from_u64(BOOTSTRAP_SEED);
    let mut rhos: Vec<f64> = (0..BOOTSTRAP_RESAMPLES)
        .filter_map(|_| {
            let idx: Vec<usize> = (0..n).map(|_| rng.random_range(0..n)).collect();
            let (a, b): (Vec<f64>, Vec<f64>) = idx.iter().map(|&i| (x[i], y[i])).unzip();
            Some(spearman(&a, &b)).filter(|r| r.is_finite())
        })
        .collect();
    if rhos.is_empty() {
        return None;
    }
    rhos.sort_by(f64::total_cmp);
    let tail = (1.0 - level) / 2.0;
    let m = rhos.len();
    let lo = rhos[((tail * m as f64).floor() as usize).min(m - 1)];
    let hi = rhos[(((1.0 - tail) * m as f64).ceil() as usize).clamp(1, m) - 1];
    Some((lo, hi))
}

/// Spearman's rank correlation.
pub fn spearman(x: &[f64], y: &[f64]) -> f64 {
    fn ranks(v: &[f64]) -> Vec<f64> {
        let mut idx: Vec<usize> = (0..v.len()).collect();
        idx.sort_by(|&a, &b| v[a].total_cmp(&v[b]));
        let mut r = vec![0.0; v.len()];
        let mut i = 0;
        while i < idx.len() {
            let mut j = i;
            while j + 1 < idx.len() && v[idx[j + 1]] == v[idx[i]] {
                j += 1;
            }
            for &k in &idx[i..=j] {
                r[k] = (i + j) as f64 / 2.0 + 1.0;
            }
            i = j + 1;
        }
        r
    }
    let (rx, ry) = (ranks(x), ranks(y));
    let n = x.len() as f64;
    let (mx, my) = (rx.iter().sum::<f64>() / n, ry.iter().sum::<f64>() / n);
    let cov: f64 = rx.iter().zip(&ry).map(|(a, b)| (a - mx) * (b - my)).sum();
    let vx: f64 = rx.iter().map(|a| (a - mx) * (a - mx)).sum();
    let vy: f64 = ry.iter().map(|b| (b - my) * (b - my)).sum();
    cov / (vx * vy).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn median_ci_matches_binomial_tables() {
        // n = 20: the 95% distribution-free interval for the median is (x_(6), x_(15)), coverage 0.9586.
        let xs: Vec<f64> = (1..=20).map(f64::from).collect();
        let e = median_ci(&xs, 0.95);
        assert_eq!((e.lo, e.hi, e.median), (6.0, 15.0, 10.5));
        assert!((e.coverage - 0.9586).abs() < 1e-4, "{}", e.coverage);
        // n = 5 cannot reach 95%: the extremes, with the coverage they give (1 - 2/32).
        let e = median_ci(&[3.0, 1.0, 2.0, 5.0, 4.0], 0.95);
        assert_eq!((e.lo, e.hi), (1.0, 5.0));
        assert!((e.coverage - 0.9375).abs() < 1e-12);
    }

    #[test]
    fn mann_whitney_separates_shifted_samples() {
        let a: Vec<f64> = (0..12).map(|i| 10.0 + i as f64 * 0.1).collect();
        let b: Vec<f64> = (0..12).map(|i| 11.5 + i as f64 * 0.1).collect();
        assert!(mann_whitney_p(&a, &b) < 1e-3);
        let c: Vec<f64> = (0..12).map(|i| 10.05 + i as f64 * 0.1).collect();
        assert!(mann_whitney_p(&a, &c) > 0.5);
    }

    #[test]
    fn discordant_pairs_count_the_swaps() {
        assert_eq!(discordant_pairs(&[1.0, 2.0, 3.0, 4.0], &[10.0, 20.0, 30.0, 40.0]), (0, 6));
        // One swap of neighbours: one discordant pair; a tie leaves its pairs out.
        assert_eq!(discordant_pairs(&[1.0, 2.0, 3.0, 4.0], &[10.0, 30.0, 20.0, 40.0]), (1, 6));
        assert_eq!(discordant_pairs(&[1.0, 2.0, 3.0], &[5.0, 5.0, 6.0]), (0, 2));
    }

    #[test]
    fn spearman_ci_covers_the_estimate_and_narrows_with_more_models() {
        let x: Vec<f64> = (0..60).map(f64::from).collect();
        // A noisy monotone relation (a fixed pseudo-random wobble).
        let y: Vec<f64> = x.iter().map(|v| v + 15.0 * ((v * 12.9898).sin() * 43758.5453).fract()).collect();
        let rho = spearman(&x, &y);
        let (lo, hi) = spearman_ci(&x, &y, 0.95).unwrap();
        assert!(lo <= rho && rho <= hi && hi <= 1.0 && lo > 0.5, "{lo} {rho} {hi}");
        let (lo6, hi6) = spearman_ci(&x[..6], &y[..6], 0.95).unwrap();
        assert!(hi6 - lo6 > hi - lo, "six models: [{lo6}, {hi6}] against sixty: [{lo}, {hi}]");
        assert_eq!(spearman_ci(&x[..3], &y[..3], 0.95), None);
    }

    #[test]
    fn spearman_of_monotone_is_one() {
        assert!((spearman(&[1.0, 2.0, 3.0, 4.0], &[10.0, 20.0, 25.0, 100.0]) - 1.0).abs() < 1e-12);
        assert!((spearman(&[1.0, 2.0, 3.0, 4.0], &[4.0, 3.0, 2.0, 1.0]) + 1.0).abs() < 1e-12);
    }
}
