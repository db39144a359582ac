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
    Guard { name: "MIN_COSINE", value: MIN_COSINE, why: "Filament MIN_N_DOT_V; NoV, NoL, NoH, VoH floor once a light is visible" },
    Guard { name: "MIN_VECTOR", value: MIN_VECTOR, why: "FLT_MIN: a vector whose largest component is below it counts as zero" },
    Guard { name: "GTR_SERIES_BAND", value: GTR_SERIES_BAND, why: "|a2-1| below which the GTR normaliser uses its series (0/0 at a2 = 1)" },
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
    Switch { name: "safe-h", bit: 1, glsl: "GUARD_SAFE_H", guarded: "H = safe_normalize(V + L): scaled first, 0 for V = -L", unguarded: "H = normalize(V + L)" },
    Switch { name: "sin2h", bit: 2, glsl: "GUARD_SIN2H", guarded: "1 - NoH^2 as |N x H|^2, no cancellation at the peak", unguarded: "1 - NoH * NoH" },
    Switch { name: "cosine-floor", bit: 4, glsl: "GUARD_COSINE_FLOOR", guarded: "NoV, NoL, NoH, VoH clamped into [MIN_COSINE, 1]", unguarded: "clamped into [0, 1] (saturate)" },
    Switch { name: "f0-clamp", bit: 8, glsl: "GUARD_F0_CLAMP", guarded: "F0 clamped into [0, 1]", unguarded: "F0 as given" },
    Switch { name: "lit-mask", bit: 16, glsl: "GUARD_LIT_MASK", guarded: "f_s = 0 unless NoV > 0 and NoL > 0", unguarded: "f_s of the saturated cosines, whatever it is" },
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
            _ => format!("off:{}", SWITCHES.iter().filter(|s| self.0 & s.bit == 0).map(|s| s.name).collect::<Vec<_>>().join("+")),
        }
    }

    /// A visible cosine as the kernels guard it: into [MIN_COSINE, 1], or into [0, 1] without the floor.
    pub fn cosine(self, x: f64) -> f64 {
        if self.on("cosine-floor") { guard_cosine(x) } else { x.clamp(0.0, 1.0) }
    }
}
