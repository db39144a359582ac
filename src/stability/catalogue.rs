//! The named catalogue of hard cases. Each is built with N = +z, so the cosines the kernel computes are exact in
//! fp32 and the case means exactly what its name says. Expected values: the f64 twin of the spec (which
//! applies the same guards, so it is the limit the tool defines), 0 where no light arrives, and for invalid
//! input (NaN, Inf) any finite non-negative value: the kernel must not pass the poison on.

use crate::brdf::Sample;
use crate::brdf::terms::{PARAMS, Param, ParamKind, ParamValue};
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum Expect {
    /// The f64 twin's value (0 where it masks the light).
    Twin,
    /// Invalid input: any finite value >= 0.
    FiniteNonNegative,
}

/// Read back from stability reports by name only (the rest takes its default).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct HardCase {
    pub name: String,
    #[serde(skip_deserializing)]
    pub sample: Sample,
    /// Parameter values for this case (applied to the specs whose terms read them; the spec's own otherwise).
    #[serde(skip)]
    pub overrides: Vec<(Param, ParamValue)>,
    #[serde(skip_deserializing, default = "unread_expect")]
    pub expect: Expect,
}

/// What a read-back hard case expects (no reader asks).
fn unread_expect() -> Expect {
    Expect::Twin
}

/// Unit vector at cosine `cos` to +z and azimuth `phi`, in f32.
fn dir(cos: f64, phi: f64) -> [f32; 3] {
    let sin = (1.0 - cos * cos).max(0.0).sqrt();
    [(sin * phi.cos()) as f32, (sin * phi.sin()) as f32, cos as f32]
}

const N: [f32; 3] = [0.0, 0.0, 1.0];
const F0: [f32; 3] = [0.04, 0.5, 0.95];

fn sample(nov: f64, nol: f64, phi: f64, roughness: f32) -> Sample {
    Sample { n: N, v: dir(nov, 0.0), l: dir(nol, phi), roughness, f0: F0 }
}

/// V and L mirrored about N (so H = N exactly) at cosine `cos`.
fn mirror(cos: f64, roughness: f32) -> Sample {
    sample(cos, cos, PI, roughness)
}

/// `1 - 1e-6` rather than `0.999999` in case names.
fn hard_label(x: f64) -> String {
    let near = x.round();
    match x - near {
        d if d == 0.0 => format!("{near}"),
        d if d < 0.0 => format!("{near} - {:.0e}", -d),
        d => format!("{near} + {d:.0e}"),
    }
}

pub fn hard_cases() -> Vec<HardCase> {
    let mut cases = Vec::new();
    let mut add = |name: &str, sample: Sample, over: Option<(Param, f64)>, expect: Expect| {
        let overrides = over.map(|(p, x)| (p, ParamValue::Number(x))).into_iter().collect();
        cases.push(HardCase { name: name.to_string(), sample, overrides, expect });
    };
    use Expect::*;
    for (label, c) in [("0", 0.0), ("1e-7", 1e-7), ("1e-4", 1e-4), ("-1e-4 (just below)", -1e-4)] {
        add(&format!("grazing view, NoV = {label}"), sample(c, 0.7, PI / 3.0, 0.5), None, Twin);
        add(&format!("grazing light, NoL = {label}"), sample(0.7, c, PI / 3.0, 0.5), None, Twin);
        add(&format!("grazing view and light, NoV = NoL = {label}"), sample(c, c, PI / 3.0, 0.5), None, Twin);
    }
    add("back-facing light, NoL = -0.5", sample(0.7, -0.5, PI / 3.0, 0.5), None, Twin);
    let v = dir(0.6, 0.0);
    add("L = -V (no half vector)", Sample { l: v.map(|x| -x), ..sample(0.6, 0.6, 0.0, 0.5) }, None, Twin);
    add("L = V", sample(0.6, 0.6, 0.0, 0.5), None, Twin);
    add("N = H exactly", mirror(0.6, 0.5), None, Twin);
    add("N = H at grazing, NoV = NoL = 1e-4", mirror(1e-4, 0.5), None, Twin);
    for (label, r) in
        [("0", 0.0f32), ("1e-4", 1e-4), ("1e-2", 1e-2), ("fp16 smallest normal 6.1e-5", 6.103_515_6e-5), ("1", 1.0)]
    {
        add(&format!("roughness {label}, N = H"), mirror(0.6, r), None, Twin);
        add(&format!("roughness {label}, off the peak"), sample(0.6, 0.8, PI / 2.0, r), None, Twin);
    }
    // Every number parameter at its hard values (limit forms, range ends), where the normaliser of a
    // parameterised D is 0/0 (a2 = 1), next to it, at the peak of the narrowest lobe, and off it.
    for def in &PARAMS {
        let ParamKind::Number { .. } = def.kind else { continue };
        for &g in def.hard_values {
            let label = format!("{} {}", def.name, hard_label(g));
            let over = Some((def.param, g));
            add(&format!("{label}, a2 = 1 (0/0)"), mirror(0.6, 1.0), over, Twin);
            add(&format!("{label}, a2 = 1, off the peak"), sample(0.3, 0.9, PI / 2.0, 1.0), over, Twin);
            add(&format!("{label}, a2 near 1 (r = 0.99)"), sample(0.5, 0.7, PI / 4.0, 0.99), over, Twin);
            add(&format!("{label}, roughness 0, N = H"), mirror(0.6, 0.0), over, Twin);
            add(&format!("{label}, roughness 0, off the peak"), sample(0.6, 0.8, PI / 2.0, 0.0), over, Twin);
        }
    }
    // Blinn-Phong's exponent m = 2/a2 - 2 is largest at the roughness floor: pow(NoH, m) just off the peak.
    add("Blinn exponent at the smallest roughness, NoH just below 1", sample(0.6, 0.6001, PI, 0.0), None, Twin);
    // Beckmann's exp((NoH^2-1)/(a2 NoH^2)) underflows far from the peak at low roughness.
    add("Beckmann exp underflow, low roughness far off the peak", sample(0.95, 0.2, PI / 2.0, 0.05), None, Twin);
    add("denormal normal (0, 0, 1e-40)", Sample { n: [0.0, 0.0, 1e-40], ..mirror(0.6, 0.5) }, None, Twin);
    add("denormal view vector", Sample { v: [1e-40, 0.0, 1e-40], ..mirror(0.6, 0.5) }, None, Twin);
    add("zero normal", Sample { n: [0.0; 3], ..mirror(0.6, 0.5) }, None, Twin);
    add("zero view vector", Sample { v: [0.0; 3], ..mirror(0.6, 0.5) }, None, Twin);
    add("zero light vector", Sample { l: [0.0; 3], ..mirror(0.6, 0.5) }, None, Twin);
    for (label, scale) in [("0.5", 0.5f32), ("2", 2.0), ("1e-30", 1e-30), ("1e30", 1e30)] {
        let s = sample(0.6, 0.8, PI / 2.0, 0.5);
        add(
            &format!("vectors of length {label}"),
            Sample { n: s.n.map(|x| x * scale), v: s.v.map(|x| x * scale), l: s.l.map(|x| x * scale), ..s },
            None,
            Twin,
        );
    }
    add("F0 = 0", Sample { f0: [0.0; 3], ..sample(0.6, 0.8, PI / 2.0, 0.5) }, None, Twin);
    add("F0 = 1", Sample { f0: [1.0; 3], ..sample(0.6, 0.8, PI / 2.0, 0.5) }, None, Twin);
    add("F0 = 1 at grazing VoH", Sample { f0: [1.0; 3], ..sample(0.1, 0.1, 0.0, 0.5) }, None, Twin);
    add("roughness 1.5 (above 1, clamped)", sample(0.6, 0.8, PI / 2.0, 1.5), None, Twin);
    let base = sample(0.6, 0.8, PI / 2.0, 0.5);
    add("NaN in the normal", Sample { n: [f32::NAN, 0.0, 1.0], ..base }, None, FiniteNonNegative);
    add("Inf in the view vector", Sample { v: [0.0, f32::INFINITY, 1.0], ..base }, None, FiniteNonNegative);
    add("-Inf in the light vector", Sample { l: [f32::NEG_INFINITY, 0.0, 1.0], ..base }, None, FiniteNonNegative);
    add("NaN roughness", Sample { roughness: f32::NAN, ..base }, None, FiniteNonNegative);
    add("NaN F0", Sample { f0: [f32::NAN, 0.5, 0.5], ..base }, None, FiniteNonNegative);
    cases
}

/// The f32 nearest `x` on the inside of a bound (`up`: at or above it), so that the case is within the domain.
fn inside(x: f64, up: bool) -> f32 {
    let y = x as f32;
    match (f64::from(y) < x, f64::from(y) > x, up) {
        (true, _, true) => y.next_up(),
        (_, true, false) => y.next_down(),
        _ => y,
    }
}

/// Hard cases at a domain's own bounds, which the catalogue's fixed values may all miss: at the roughness
/// minimum and maximum the peak (N = H), the peak at grazing (the smallest cosines the domain allows, else
/// 1e-4) and off the peak; at the N.V and N.L minimum a grazing view and a grazing light. Named with the bound.
pub fn at_domain_bounds(checks: &super::Checks) -> Vec<HardCase> {
    let mut cases = Vec::new();
    let mut add = |name: String, sample: Sample| {
        if !cases.iter().any(|c: &HardCase| c.sample == sample) {
            cases.push(HardCase { name, sample, overrides: Vec::new(), expect: Expect::Twin });
        }
    };
    let lowest = |range: Option<(f64, f64)>| range.map(|(lo, _)| lo).filter(|lo| *lo > 0.0);
    let grazing = [lowest(checks.nov), lowest(checks.nol)]
        .into_iter()
        .flatten()
        .fold(None, |m: Option<f64>, x| Some(m.map_or(x, |m| m.max(x))))
        .unwrap_or(1e-4);
    let (r_lo, r_hi) = checks.roughness.unwrap_or((0.0, 1.0));
    let middle = inside(0.5f64.clamp(r_lo, r_hi), true);
    if let Some((lo, hi)) = checks.roughness {
        for (end, bound, r) in [("minimum", lo, inside(lo, true)), ("maximum", hi, inside(hi, false))] {
            let at = format!("at the domain's roughness {end} {bound}");
            add(format!("{at}, N = H"), mirror(0.6, r));
            add(format!("{at}, N = H at grazing, NoV = NoL = {grazing:e}"), mirror(grazing, r));
            add(format!("{at}, off the peak"), sample(0.6, 0.8, PI / 2.0, r));
        }
    }
    if let Some(lo) = lowest(checks.nov) {
        add(format!("at the domain's NoV minimum {lo}"), sample(lo, 0.7, PI / 3.0, middle));
    }
    if let Some(lo) = lowest(checks.nol) {
        add(format!("at the domain's NoL minimum {lo}"), sample(0.7, lo, PI / 3.0, middle));
    }
    cases
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn catalogue_names_are_unique_and_cover_the_issue() {
        let cases = hard_cases();
        let mut names: Vec<&str> = cases.iter().map(|c| c.name.as_str()).collect();
        names.sort();
        let n = names.len();
        names.dedup();
        assert_eq!(n, names.len());
        for needle in [
            "NoV = 0",
            "NoV = 1e-7",
            "NoL = 1e-4",
            "just below",
            "back-facing",
            "L = -V",
            "L = V",
            "N = H exactly",
            "roughness 0,",
            "roughness 1e-4",
            "roughness 1e-2",
            "fp16 smallest normal",
            "gamma 1 - 1e-6",
            "gamma 2,",
            "Blinn exponent",
            "Beckmann exp",
            "denormal",
            "zero normal",
            "length 0.5",
            "length 2",
            "F0 = 0",
            "F0 = 1",
            "NaN",
            "Inf",
        ] {
            assert!(cases.iter().any(|c| c.name.contains(needle)), "no case for {needle}");
        }
        let m = mirror(0.6, 0.5);
        let h = [m.v[0] + m.l[0], m.v[1] + m.l[1], m.v[2] + m.l[2]];
        assert!(h[0].abs() < 1e-7 && h[1].abs() < 1e-7, "mirror config has H = N");
    }
}
