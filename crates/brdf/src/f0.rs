//! Where sampled F0 comes from: real materials by default, so that a model's error is measured on
//! reflectances materials have (a Schlick error at F0 = 0.0004, which no material has, is not a finding), or
//! a uniform box when asked.
//!
//! The materials: dielectrics from their refractive index n, F0 = ((n - 1) / (n + 1))^2 (Fresnel at normal
//! incidence), and metals' linear RGB F0 from Real-Time Rendering, 4th ed., Table 9.2 (Hoffman's measured values).

use super::Sample;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

/// Dielectrics: name and refractive index.
pub const DIELECTRICS: [(&str, f64); 5] =
    [("water", 1.333), ("skin", 1.4), ("glass", 1.5), ("sapphire", 1.77), ("diamond", 2.42)];

/// Metals: name and linear RGB F0 (Real-Time Rendering, 4th ed., Table 9.2).
pub const METALS: [(&str, [f64; 3]); 8] = [
    ("titanium", [0.542, 0.497, 0.449]),
    ("chromium", [0.549, 0.556, 0.554]),
    ("iron", [0.562, 0.565, 0.578]),
    ("nickel", [0.660, 0.609, 0.526]),
    ("copper", [0.955, 0.638, 0.538]),
    ("gold", [1.000, 0.782, 0.344]),
    ("aluminium", [0.913, 0.922, 0.924]),
    ("silver", [0.972, 0.960, 0.915]),
];

/// A dielectric's F0 from its refractive index.
pub fn dielectric_f0(ior: f64) -> f64 {
    ((ior - 1.0) / (ior + 1.0)).powi(2)
}

/// Every material of the set, as (name, F0).
pub fn materials() -> Vec<(&'static str, [f64; 3])> {
    DIELECTRICS.iter().map(|&(n, ior)| (n, [dielectric_f0(ior); 3])).chain(METALS).collect()
}

/// How samples draw F0.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum F0Set {
    /// One material of `materials()` per sample, each equally likely.
    Materials,
    /// Uniform in [lo, hi] per channel.
    Uniform([(f64, f64); 3]),
}

impl Default for F0Set {
    fn default() -> Self {
        F0Set::Materials
    }
}

/// A bound as a label writes it: as typed for ordinary values, in exponent form for the tiny (1e-300 would
/// otherwise run to 300 digits).
fn num(x: f64) -> String {
    if x == 0.0 || x >= 1e-4 { format!("{x}") } else { format!("{x:e}") }
}

impl F0Set {
    /// `materials`, `uniform` ([0, 1]^3), `MIN..MAX` (every channel) or `R0..R1,G0..G1,B0..B1`, within [0, 1].
    pub fn parse(text: &str) -> Result<F0Set, String> {
        let range = |t: &str| -> Result<(f64, f64), String> {
            let (lo, hi) = t.split_once("..").ok_or(format!("`{t}`: expected MIN..MAX"))?;
            let number = |s: &str| s.trim().parse::<f64>().ok().filter(|x| (0.0..=1.0).contains(x));
            match (number(lo), number(hi)) {
                (Some(lo), Some(hi)) if lo <= hi => Ok((lo, hi)),
                (Some(lo), Some(hi)) => Err(format!("`{t}`: MIN {lo} is above MAX {hi}")),
                _ => Err(format!("`{t}`: MIN and MAX are numbers within [0, 1]")),
            }
        };
        match text.trim() {
            "materials" => Ok(F0Set::Materials),
            "uniform" => Ok(F0Set::Uniform([(0.0, 1.0); 3])),
            t => match t.split(',').collect::<Vec<_>>().as_slice() {
                [one] => Ok(F0Set::Uniform([range(one)?; 3])),
                [r, g, b] => Ok(F0Set::Uniform([range(r)?, range(g)?, range(b)?])),
                _ => Err(format!("`{t}`: give materials, uniform, MIN..MAX or R0..R1,G0..G1,B0..B1")),
            },
        }
    }

    /// What the set is, for an input label.
    pub fn describe(&self) -> String {
        match self {
            F0Set::Materials => format!(
                "F0 of {} real materials, one per sample ({} dielectrics from their refractive index, {} metals of Real-Time Rendering 4th ed. Table 9.2)",
                DIELECTRICS.len() + METALS.len(),
                DIELECTRICS.len(),
                METALS.len()
            ),
            F0Set::Uniform([r, g, b]) if r == g && g == b => format!("F0 in [{}, {}]^3", num(r.0), num(r.1)),
            F0Set::Uniform([r, g, b]) => format!(
                "F0 in [{}, {}] x [{}, {}] x [{}, {}]",
                num(r.0),
                num(r.1),
                num(g.0),
                num(g.1),
                num(b.0),
                num(b.1)
            ),
        }
    }

    /// Sets each sample's F0 from this set, drawn from its own stream of `seed` (the other columns stay).
    pub fn apply(&self, samples: &mut [Sample], seed: u64) {
        let mut rng = Pcg64::seed_from_u64(seed ^ 0xf0f0_f0f0);
        let all = materials();
        for s in samples {
            let f0 = match self {
                F0Set::Materials => all[rng.random_range(0..all.len())].1,
                F0Set::Uniform(r) => r.map(|(lo, hi)| if lo == hi { lo } else { rng.random_range(lo..=hi) }),
            };
            s.f0 = f0.map(|x| x as f32);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_tiny_bound_is_written_short() {
        let d = F0Set::parse("1e-400..1e-300").unwrap().describe();
        assert!(d.len() < 40, "{d}");
        assert_eq!(F0Set::parse("0.02..0.05").unwrap().describe(), "F0 in [0.02, 0.05]^3");
    }

    #[test]
    fn sets_parse_and_keep_every_f0_within_them() {
        let mut s = crate::samples::well_conditioned(2000, 5, 0.05, 0.0..1.0);
        F0Set::parse("0.02..0.08").unwrap().apply(&mut s, 5);
        assert!(s.iter().all(|x| x.f0.iter().all(|&c| (0.02..=0.08).contains(&c))));
        F0Set::Materials.apply(&mut s, 5);
        let all = materials();
        assert!(s.iter().all(|x| all.iter().any(|(_, f)| f.map(|c| c as f32) == x.f0)));
        assert!((dielectric_f0(1.5) - 0.04).abs() < 1e-12, "glass");
        assert_eq!(F0Set::parse("uniform"), Ok(F0Set::Uniform([(0.0, 1.0); 3])));
        assert!(F0Set::parse("0.2..0.1").is_err() && F0Set::parse("0..2").is_err() && F0Set::parse("x").is_err());
        let per = F0Set::parse("0.9..1,0.5..0.6,0..0.1").unwrap();
        assert_eq!(per, F0Set::Uniform([(0.9, 1.0), (0.5, 0.6), (0.0, 0.1)]));
    }
}
