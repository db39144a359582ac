//! One execution's values judged against the f64 reference (`host::Bounded`: the kernel's operations in
//! double, and the bound the Vulkan precision rules of those operations put on a conforming implementation):
//! a value is within when its distance from the reference is at most the bound, plus what the output adds
//! (R11G11B10F's rounding, a denormal result flushed to zero) and the reference's own double rounding. The
//! measure is the distance beyond the output's rounding in units of the bound (1: at the allowance).
//!
//! Non-finite values: where the reference is finite and its range stays inside f32, the value must be finite;
//! where the range reaches past the largest f32, an infinity of its sign is within (Vulkan lets such a result be
//! infinite); an exact infinity must be met exactly; where the reference is NaN the result is undefined in
//! SPIR-V (not judged, counted); where the bound is infinite the rules give none (a comparison within rounding
//! of its threshold, a divisor that may be 0: not judged, counted).

use super::host::Bounded;
use serde::{Deserialize, Serialize};

/// The reference's own rounding: its operations in double, far below any f32 bound (2^-40 relative).
pub const REFERENCE_ROUNDING: f64 = 1.0 / (1u64 << 40) as f64;

/// How one value stands against the reference.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Judgement {
    /// Its distance beyond the output's rounding in units of the bound (<= 1: within).
    Measured(f64),
    /// The rules bound nothing here.
    Unbounded,
    /// The reference is NaN: SPIR-V leaves the result undefined.
    Undefined,
}

/// `x` against `r`, with `extra` added to the allowance (the output format's rounding at this value). The
/// measure is the distance beyond what the output's own rounding explains (the format's `extra`, a denormal
/// result flushed to zero, the reference's double rounding) in units of the bound of the kernel's arithmetic,
/// so that it is at most 1 exactly when the value is within the whole allowance.
pub fn judge(x: f32, r: Bounded, extra: f64) -> Judgement {
    if r.value.is_nan() {
        return Judgement::Undefined;
    }
    if !r.bound.is_finite() {
        return Judgement::Unbounded;
    }
    let x = f64::from(x);
    if r.value.is_infinite() {
        return Judgement::Measured(if x == r.value { 0.0 } else { f64::INFINITY });
    }
    let flushed = if r.value.abs() < f64::from(f32::MIN_POSITIVE) { r.value.abs() } else { 0.0 };
    let rounding = extra + flushed + REFERENCE_ROUNDING * r.value.abs();
    // fp32 overflows to an infinity of the sign of whichever end of the range lies past its largest value.
    let reach = if x > 0.0 { r.value + r.bound + rounding } else { -(r.value - r.bound - rounding) };
    if x.is_infinite() && reach >= f64::from(f32::MAX) {
        return Judgement::Measured(0.0);
    }
    let beyond = (x - r.value).abs() - rounding;
    Judgement::Measured(if !(beyond > 0.0) && beyond.is_finite() {
        0.0
    } else if beyond.is_finite() && r.bound > 0.0 {
        beyond / r.bound
    } else {
        f64::INFINITY
    })
}

/// The largest finite value of an R11G11B10F channel with a `mantissa`-bit mantissa: 65024 (6 bits, red and
/// green), 64512 (5 bits, blue).
pub fn r11g11b10_max(mantissa: u32) -> f64 {
    32768.0 * (2.0 - 2f64.powi(-(mantissa as i32)))
}

/// A reference value as the R11G11B10F store holds it: saturated at the channel's largest finite value, as
/// the kernels' packing writes it (a radiance of 3.5e5 is stored as 65024 by the device and the translation
/// alike; the unsaturated reference called that a translator defect). An upper end past fp32's largest value
/// is kept: fp32 overflows there to Inf, which the format stores as Inf.
pub fn r11g11b10_saturated(r: Bounded, mantissa: u32) -> Bounded {
    if !(r.value + r.bound).is_finite() {
        return r;
    }
    let max = r11g11b10_max(mantissa);
    let hi = r.value + r.bound;
    let (lo, hi) = ((r.value - r.bound).min(max), if hi >= f64::from(f32::MAX) { hi } else { hi.min(max) });
    Bounded { value: 0.5 * (lo + hi), bound: 0.5 * (hi - lo) }
}

/// The rounding R11G11B10F's conversion may add to a value of magnitude up to `m` (one step of its 6-bit,
/// blue's 5-bit, mantissa: the Vulkan spec lets the conversion round either way), plus the value itself where
/// it is negative (stored as 0).
pub fn r11g11b10_step(r: Bounded, mantissa: u32) -> f64 {
    let m = r.value.abs() + r.bound;
    let exponent = if m > 0.0 { m.log2().floor().max(-14.0) } else { -14.0 };
    let below = if r.value - r.bound < 0.0 { (r.value - r.bound).abs() } else { 0.0 };
    2f64.powf(exponent - f64::from(mantissa)) + below
}

/// Serde for an f64 that may be infinite or NaN (JSON has neither): as a number where finite, else as the
/// string "inf", "-inf" or "NaN".
pub mod any_f64 {
    use serde::{Deserialize, Deserializer, Serializer};

    pub fn serialize<S: Serializer>(x: &f64, s: S) -> Result<S::Ok, S::Error> {
        if x.is_finite() { s.serialize_f64(*x) } else { s.serialize_str(&x.to_string()) }
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
        #[derive(Deserialize)]
        #[serde(untagged)]
        enum Either {
            Number(f64),
            Text(String),
        }
        match Either::deserialize(d)? {
            Either::Number(x) => Ok(x),
            Either::Text(t) => t.parse().map_err(serde::de::Error::custom),
        }
    }
}

/// The judgements of one execution of a kernel.
#[derive(Clone, Debug, Default, Serialize, Deserialize, PartialEq)]
pub struct Tally {
    /// Values compared.
    pub values: usize,
    /// Values the rules bound nothing for, or whose reference is undefined.
    pub unbounded: usize,
    /// The largest distance beyond the output's rounding, in units of the bound.
    #[serde(with = "any_f64")]
    pub worst: f64,
    /// Where: "value 123 (sample 41, channel 0): 0.31 against 0.3100012 +- 1.9e-7".
    pub worst_at: String,
    /// The median and largest relative bound of the arithmetic (bound / |reference|) over the judged values in
    /// f32's normal range.
    #[serde(with = "any_f64")]
    pub bound_median: f64,
    #[serde(with = "any_f64")]
    pub bound_max: f64,
}

/// A value as a message shows it: as Rust writes it, in scientific form (9 significant digits, an f32's
/// round trip) far from 1, where the decimal form of a subnormal runs to hundreds of digits.
fn readable(v: f64) -> String {
    if v != 0.0 && v.is_finite() && !(1e-4..1e9).contains(&v.abs()) { format!("{v:.8e}") } else { format!("{v}") }
}

/// Judges every `xs[i]` against `refs[i]` (`extra(i)`: the format's rounding there).
pub fn tally(xs: &[f32], refs: &[Bounded], extra: impl Fn(usize) -> f64, per_item: usize) -> Tally {
    let mut t = Tally { values: xs.len(), ..Tally::default() };
    let mut relative = Vec::new();
    for (i, (&x, &r)) in xs.iter().zip(refs).enumerate() {
        match judge(x, r, extra(i)) {
            Judgement::Measured(m) => {
                if r.value.abs() >= f64::from(f32::MIN_POSITIVE) && r.bound.is_finite() {
                    relative.push(r.bound / r.value.abs());
                }
                if m > t.worst || (m.is_nan() && !t.worst.is_nan()) {
                    t.worst = m;
                    t.worst_at = format!(
                        "value {i} (item {}, channel {}): {} against {} +- {:.2e}",
                        i / per_item,
                        i % per_item,
                        readable(f64::from(x)),
                        readable(r.value),
                        r.bound + extra(i)
                    );
                }
            }
            Judgement::Unbounded | Judgement::Undefined => t.unbounded += 1,
        }
    }
    relative.sort_by(f64::total_cmp);
    t.bound_median = relative.get(relative.len() / 2).copied().unwrap_or(0.0);
    t.bound_max = relative.last().copied().unwrap_or(0.0);
    t
}

#[cfg(test)]
mod tests {
    use super::*;

    fn b(value: f64, bound: f64) -> Bounded {
        Bounded { value, bound }
    }

    /// A subnormal reference (an uninitialised read's garbage) is named in a few characters, not hundreds.
    #[test]
    fn the_worst_value_is_named_readably() {
        let t = tally(&[-1.3615041e13], &[b(6.916220881493e-310, 6.92e-310)], |_| 0.0, 3);
        assert!(t.worst_at.contains("-1.36150411e13 against 6.91622088e-310 +- 6.92e-310"), "{}", t.worst_at);
        let t = tally(&[0.25], &[b(0.5, 1e-7)], |_| 0.0, 3);
        assert!(t.worst_at.contains("0.25 against 0.5"), "{}", t.worst_at);
    }

    #[test]
    fn a_value_is_within_its_bound_and_beyond_it_is_not() {
        assert_eq!(judge(1.0, b(1.0, 0.0), 0.0), Judgement::Measured(0.0));
        let Judgement::Measured(m) = judge(1.0000001, b(1.0, 1e-6), 0.0) else { panic!() };
        assert!(m < 0.2, "{m}");
        let Judgement::Measured(m) = judge(1.01, b(1.0, 1e-6), 0.0) else { panic!() };
        assert!(m > 1e3, "{m}");
        // An exact zero must be met exactly.
        assert_eq!(judge(1e-30, b(0.0, 0.0), 0.0), Judgement::Measured(f64::INFINITY));
    }

    #[test]
    fn non_finite_values_are_within_only_where_the_reference_allows_them() {
        assert_eq!(judge(f32::NAN, b(1.0, 1e-6), 0.0), Judgement::Measured(f64::INFINITY));
        assert_eq!(judge(f32::INFINITY, b(1.0, 1e-6), 0.0), Judgement::Measured(f64::INFINITY));
        assert_eq!(judge(f32::INFINITY, b(3.4e38, 1e36), 0.0), Judgement::Measured(0.0));
        assert_eq!(judge(f32::NEG_INFINITY, b(3.4e38, 1e36), 0.0), Judgement::Measured(f64::INFINITY));
        assert_eq!(judge(f32::INFINITY, b(f64::INFINITY, 0.0), 0.0), Judgement::Measured(0.0));
        // A range of either sign reaching past fp32's largest value allows the infinity of that side.
        assert_eq!(judge(f32::INFINITY, b(-7.3e101, 2.2e102), 0.0), Judgement::Measured(0.0));
        assert_eq!(judge(f32::NEG_INFINITY, b(-7.3e101, 2.2e102), 0.0), Judgement::Measured(0.0));
        assert_eq!(judge(f32::NEG_INFINITY, b(7.3e101, 1e100), 0.0), Judgement::Measured(f64::INFINITY));
        assert_eq!(judge(1.0, b(f64::NAN, 0.0), 0.0), Judgement::Undefined);
        assert_eq!(judge(1.0, b(1.0, f64::INFINITY), 0.0), Judgement::Unbounded);
    }

    #[test]
    fn non_finite_figures_survive_json() {
        let t = Tally { worst: f64::INFINITY, bound_max: f64::NAN, ..Tally::default() };
        let back: Tally = serde_json::from_str(&serde_json::to_string(&t).unwrap()).unwrap();
        assert!(back.worst == f64::INFINITY && back.bound_max.is_nan());
    }

    #[test]
    fn the_saturated_reference_keeps_an_end_that_overflows_fp32() {
        let within = r11g11b10_saturated(b(3.5e5, 4e3), 6);
        assert_eq!((within.value + within.bound, within.value - within.bound), (65024.0, 65024.0));
        let overflowing = r11g11b10_saturated(b(-7.3e101, 2.2e102), 6);
        assert!(overflowing.value + overflowing.bound > 1e102);
        assert_eq!(judge(f32::INFINITY, overflowing, 0.0), Judgement::Measured(0.0));
        assert!(matches!(judge(65024.0, overflowing, 0.0), Judgement::Measured(m) if m <= 1.0));
        assert_eq!(r11g11b10_saturated(b(f64::INFINITY, 0.0), 6).value, f64::INFINITY);
    }

    #[test]
    fn r11g11b10_steps_follow_the_mantissa_and_clamp_negatives() {
        assert_eq!(r11g11b10_step(b(1.5, 0.0), 6), 1.0 / 64.0);
        assert_eq!(r11g11b10_step(b(1.5, 0.0), 5), 1.0 / 32.0);
        assert_eq!(r11g11b10_step(b(0.0, 0.0), 6), 2f64.powi(-20));
        assert!(r11g11b10_step(b(-0.5, 0.0), 6) >= 0.5);
    }
}
