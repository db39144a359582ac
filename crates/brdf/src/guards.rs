//! The guards every kernel applies, named once. `brdf::glsl_gen` writes the same constants into the GLSL
//! (glsl/generated/brdf_table.glsl); docs/limits.md ("Guards and evaluation forms") says why each exists and
//! where it comes from.

use glam::DVec3;

/// Perceptual roughness floor in fp32 kernels: Filament's MIN_PERCEPTUAL_ROUGHNESS (highp).
/// Below it a2 = r^4 makes D_GGX's `NoH^2 (a2-1) + 1` cancel to 0 at the peak in fp32.
pub const MIN_ROUGHNESS_F32: f64 = 0.045;
/// Perceptual roughness floor in fp16 kernels: Filament's mediump value, so that a2 stays a normal fp16.
pub const MIN_ROUGHNESS_F16: f64 = 0.089;
/// Floor of NoV, NoL, NoH and VoH once a light is visible: Filament's MIN_N_DOT_V. Keeps every Vis term
/// finite at grazing angles, where several are 0/0 at exactly 0.
pub const MIN_COSINE: f64 = 1e-4;
/// A vector whose largest component is below FLT_MIN counts as zero (GPUs may flush denormals).
pub const MIN_VECTOR: f64 = f32::MIN_POSITIVE as f64;
/// |a2 - 1| below which the GLSL GTR normaliser uses its series instead of the 0/0 closed form.
pub const GTR_SERIES_BAND: f64 = 0.05;
/// Dielectric F0 cap: the IOR (1 + sqrt F0)/(1 - sqrt F0) is infinite at F0 = 1.
pub const F0_MAX: f64 = 0.9999;

/// One guard as the GLSL declares it: name, value, and the comment that says why.
pub struct Guard {
    pub name: &'static str,
    pub value: f64,
    pub why: &'static str,
}

/// The guards the GLSL declares (MIN_ROUGHNESS, which depends on the precision, is written apart).
pub const GLSL_GUARDS: [Guard; 4] = [
    Guard {
        name: "MIN_COSINE",
        value: MIN_COSINE,
        why: "Filament MIN_N_DOT_V; NoV, NoL, NoH, VoH floor once a light is visible",
    },
    Guard {
        name: "MIN_VECTOR",
        value: MIN_VECTOR,
        why: "FLT_MIN: a vector whose largest component is below it counts as zero",
    },
    Guard {
        name: "GTR_SERIES_BAND",
        value: GTR_SERIES_BAND,
        why: "|a2-1| below which the GTR normaliser uses its series (0/0 at a2 = 1)",
    },
    Guard { name: "F0_MAX", value: F0_MAX, why: "dielectric F0 cap: the IOR (1+sqrt F0)/(1-sqrt F0) is infinite at 1" },
];

/// Clamp of a visible cosine into [MIN_COSINE, 1].
pub fn guard_cosine(x: f64) -> f64 {
    x.clamp(MIN_COSINE, 1.0)
}

/// Unit vector scaled by its largest component first; zero when that component is below MIN_VECTOR.
pub fn safe_normalize(v: DVec3) -> DVec3 {
    let m = v.abs().max_element();
    if !(m >= MIN_VECTOR) {
        return DVec3::ZERO;
    }
    let u = v / m;
    u / u.length()
}

/// `safe_normalize` of an f32 triple, in f64.
pub fn unit(v: [f32; 3]) -> DVec3 {
    safe_normalize(DVec3::from(v.map(f64::from)))
}

/// A guard a spec can switch off (`guards=off`, or `guards=off:NAME+NAME` for some): one bit of the GUARDS
/// specialisation constant, tested by the GLSL's `guarded(GUARD_...)` and by the f64 twin (`GuardSet::on`).
/// docs/guards.md lists them with what each removes and what it saves.
pub struct Switch {
    pub name: &'static str,
    pub bit: u32,
    /// The GLSL macro of its bit.
    pub glsl: &'static str,
    /// What the guard does, and what the kernel does instead without it (what engine code does).
    pub guarded: &'static str,
    pub unguarded: &'static str,
}

/// The switchable guards. The roughness floor (MIN_ROUGHNESS, which engines apply too), F0_MAX and
/// GTR_SERIES_BAND (inside terms: without them the terms are 0/0 on valid inputs) and the normalisation of the
/// inputs N, V, L (the eval kernel's contract: unnormalised vectors) stay.
pub const SWITCHES: [Switch; 5] = [
    Switch {
        name: "safe-h",
        bit: 1,
        glsl: "GUARD_SAFE_H",
        guarded: "H = safe_normalize(V + L): scaled first, 0 for V = -L",
        unguarded: "H = normalize(V + L)",
    },
    Switch {
        name: "sin2h",
        bit: 2,
        glsl: "GUARD_SIN2H",
        guarded: "1 - NoH^2 as |N x H|^2, no cancellation at the peak",
        unguarded: "1 - NoH * NoH",
    },
    Switch {
        name: "cosine-floor",
        bit: 4,
        glsl: "GUARD_COSINE_FLOOR",
        guarded: "NoV, NoL, NoH, VoH clamped into [MIN_COSINE, 1]",
        unguarded: "clamped into [0, 1] (saturate)",
    },
    Switch {
        name: "f0-clamp",
        bit: 8,
        glsl: "GUARD_F0_CLAMP",
        guarded: "F0 clamped into [0, 1]",
        unguarded: "F0 as given",
    },
    Switch {
        name: "lit-mask",
        bit: 16,
        glsl: "GUARD_LIT_MASK",
        guarded: "f_s = 0 unless NoV > 0 and NoL > 0",
        unguarded: "f_s of the saturated cosines, whatever it is",
    },
];

/// The GUARDS specialisation constant's id (3..16 belong to the term parameters; 15 is the last of them).
pub const GUARDS_CONSTANT_ID: u32 = 15;

/// Which switchable guards a spec keeps, as the bits of `SWITCHES`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct GuardSet(pub u32);

impl Default for GuardSet {
    fn default() -> Self {
        GuardSet::ALL
    }
}

impl GuardSet {
    pub const ALL: GuardSet = GuardSet(31);
    pub const NONE: GuardSet = GuardSet(0);
    /// What a reference keeps (`ModelSpec::eval_reference`): the lit mask (f_s is defined above the horizon
    /// only), the safe H, |N x H|^2 and the F0 clamp (exact in f64, or no-ops on valid inputs); not the cosine
    /// floor, which changes the formula's value below MIN_COSINE.
    pub const FORMULA: GuardSet = GuardSet(GuardSet::ALL.0 & !SWITCHES[2].bit);

    /// Whether the guard `name` (a name of `SWITCHES`) is on.
    pub fn on(self, name: &str) -> bool {
        let s = SWITCHES.iter().find(|s| s.name == name).expect("a guard of SWITCHES");
        self.0 & s.bit != 0
    }

    /// `on`, `off`, or `off:NAME+NAME` (those off, the others on).
    pub fn parse(text: &str) -> Result<GuardSet, String> {
        match text {
            "on" => return Ok(GuardSet::ALL),
            "off" => return Ok(GuardSet::NONE),
            _ => {}
        }
        let names: Vec<&str> = SWITCHES.iter().map(|s| s.name).collect();
        let bad = || format!("guards `{text}`: give on, off, or off:NAME+NAME with names among {}", names.join(", "));
        let list = text.strip_prefix("off:").ok_or_else(bad)?;
        let mut set = GuardSet::ALL;
        for name in list.split('+') {
            let s = SWITCHES.iter().find(|s| s.name == name.trim()).ok_or_else(bad)?;
            set.0 &= !s.bit;
        }
        Ok(set)
    }

    /// The spec text: `on`, `off` or `off:NAME+NAME`.
    pub fn text(self) -> String {
        match self {
            GuardSet::ALL => "on".into(),
            GuardSet::NONE => "off".into(),
            _ => format!(
                "off:{}",
                SWITCHES.iter().filter(|s| self.0 & s.bit == 0).map(|s| s.name).collect::<Vec<_>>().join("+")
            ),
        }
    }

    /// A visible cosine as the kernels guard it: into [MIN_COSINE, 1], or into [0, 1] without the floor.
    pub fn cosine(self, x: f64) -> f64 {
        if self.on("cosine-floor") { guard_cosine(x) } else { x.clamp(0.0, 1.0) }
    }
}

/// A guard applied to a model's inputs, as an engine's caller could apply it before calling a BRDF it cannot
/// change (a `.brdf` file): what `stability` tries on each failing input to say which guard removes the
/// failure. Each is the input-side form of a kernel guard above, under the same name.
pub struct InputGuard {
    pub name: &'static str,
    /// What it does to the inputs.
    pub does: &'static str,
    /// The guarded inputs, or None where the caller would not call the BRDF at all (its result is then 0).
    pub apply: fn(&super::Sample, min_roughness: f64) -> Option<super::Sample>,
}

/// The input guards, in the order `stability` lists them.
pub const INPUT_GUARDS: [InputGuard; 5] = [
    InputGuard {
        name: "roughness-floor",
        does: "roughness clamped into [MIN_ROUGHNESS, 1] (0.045 fp32, 0.089 fp16)",
        apply: floor_roughness,
    },
    InputGuard {
        name: "cosine-floor",
        does: "V and L less than MIN_COSINE = 1e-4 above the horizon turned up to it",
        apply: floor_cosines,
    },
    InputGuard {
        name: "safe-h",
        does: "not called where V + L of the unit vectors is 0 (largest component below FLT_MIN in f32): no half vector",
        apply: skip_without_half_vector,
    },
    InputGuard { name: "lit-mask", does: "not called unless NoV > 0 and NoL > 0", apply: skip_unlit },
    InputGuard { name: "f0-clamp", does: "F0 clamped into [0, 1]", apply: clamp_f0 },
];

/// Every input guard at once (in `INPUT_GUARDS` order).
pub fn apply_all_input_guards(s: &super::Sample, min_roughness: f64) -> Option<super::Sample> {
    INPUT_GUARDS.iter().try_fold(*s, |s, g| (g.apply)(&s, min_roughness))
}

fn floor_roughness(s: &super::Sample, min_roughness: f64) -> Option<super::Sample> {
    Some(super::Sample { roughness: (f64::from(s.roughness).clamp(min_roughness, 1.0)) as f32, ..*s })
}

/// `x` (unit) turned about the plane of `n` and itself so that n.x = MIN_COSINE, where 0 <= n.x < MIN_COSINE.
fn turn_up(n: DVec3, x: DVec3) -> DVec3 {
    let c = n.dot(x);
    if n == DVec3::ZERO || x == DVec3::ZERO || !(0.0..MIN_COSINE).contains(&c) {
        return x;
    }
    let t = (x - c * n).try_normalize().unwrap_or_else(|| n.any_orthonormal_vector());
    t * (1.0 - MIN_COSINE * MIN_COSINE).sqrt() + n * MIN_COSINE
}

fn floor_cosines(s: &super::Sample, _: f64) -> Option<super::Sample> {
    let n = unit(s.n);
    let f32s = |v: DVec3| v.to_array().map(|x| x as f32);
    Some(super::Sample { v: f32s(turn_up(n, unit(s.v))), l: f32s(turn_up(n, unit(s.l))), ..*s })
}

fn skip_without_half_vector(s: &super::Sample, _: f64) -> Option<super::Sample> {
    let (v, l) = (unit(s.v), unit(s.l));
    let h = [0, 1, 2].map(|i| v[i] as f32 + l[i] as f32);
    (h.iter().map(|x| f64::from(x.abs())).fold(0.0, f64::max) >= MIN_VECTOR).then_some(*s)
}

fn skip_unlit(s: &super::Sample, _: f64) -> Option<super::Sample> {
    let n = unit(s.n);
    (n.dot(unit(s.v)) > 0.0 && n.dot(unit(s.l)) > 0.0).then_some(*s)
}

fn clamp_f0(s: &super::Sample, _: f64) -> Option<super::Sample> {
    Some(super::Sample { f0: s.f0.map(|x| x.clamp(0.0, 1.0)), ..*s })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Sample;

    #[test]
    fn each_input_guard_is_a_kernel_guard_or_the_roughness_floor() {
        for g in &INPUT_GUARDS {
            assert!(
                g.name == "roughness-floor" || SWITCHES.iter().any(|s| s.name == g.name),
                "{} names no kernel guard",
                g.name
            );
        }
    }

    #[test]
    fn input_guards_do_what_they_say() {
        let s = Sample {
            n: [0.0, 0.0, 2.0],
            v: [1.0, 0.0, 0.0],
            l: [-1.0, 0.0, 0.0],
            roughness: 0.0,
            f0: [1.5, -0.1, 0.5],
        };
        let by = |name: &str| INPUT_GUARDS.iter().find(|g| g.name == name).unwrap().apply;
        assert_eq!(by("roughness-floor")(&s, MIN_ROUGHNESS_F32).unwrap().roughness, MIN_ROUGHNESS_F32 as f32);
        let up = by("cosine-floor")(&s, MIN_ROUGHNESS_F32).unwrap();
        assert!(
            (f64::from(up.v[2]) - MIN_COSINE).abs() < 1e-9 && (f64::from(up.l[2]) - MIN_COSINE).abs() < 1e-9,
            "{up:?}"
        );
        assert!(by("safe-h")(&s, 0.0).is_none(), "V = -L has no half vector");
        assert!(by("safe-h")(&up, 0.0).is_some());
        assert!(by("lit-mask")(&s, 0.0).is_none() && by("lit-mask")(&up, 0.0).is_some());
        assert_eq!(by("f0-clamp")(&s, 0.0).unwrap().f0, [1.0, 0.0, 0.5]);
        let below = Sample { l: [0.6, 0.0, -0.8], ..s };
        assert_eq!(by("cosine-floor")(&below, 0.0).unwrap().l, below.l, "light below the horizon is the lit mask's");
        // All at once: the cosine floor lifts V and L off the horizon first, so the others let it through.
        let all = apply_all_input_guards(&s, MIN_ROUGHNESS_F32).expect("called once the cosines are floored");
        assert_eq!((all.roughness, all.f0, all.v, all.l), (MIN_ROUGHNESS_F32 as f32, [1.0, 0.0, 0.5], up.v, up.l));
    }
}

#[cfg(test)]
mod formula_tests {
    use super::*;

    #[test]
    fn the_formulas_guards_are_all_but_the_cosine_floor() {
        assert!(!GuardSet::FORMULA.on("cosine-floor"));
        for s in SWITCHES.iter().filter(|s| s.name != "cosine-floor") {
            assert!(GuardSet::FORMULA.on(s.name), "{}", s.name);
        }
        assert_eq!(GuardSet::FORMULA.cosine(1e-7), 1e-7, "a cosine below MIN_COSINE is kept");
    }
}
