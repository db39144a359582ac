//! Model specs: a D, a Vis, an F and a precision (plus GTR's gamma and the metal of conductor Fresnel),
//! written `d=ggx,vis=smith-ggx-correlated,f=schlick,precision=f16` or as a preset (`burley`), optionally
//! followed by overrides (`burley,gamma=2`, `ggx,precision=f16`).

use super::guards::{self, MIN_ROUGHNESS_F16, MIN_ROUGHNESS_F32};
use super::terms::{Cosines, D, F, Metal, Vis};
use super::Sample;
use std::fmt;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Precision {
    F32,
    F16,
}

impl Precision {
    pub const ALL: [Precision; 2] = [Precision::F32, Precision::F16];
    pub fn name(self) -> &'static str {
        match self {
            Precision::F32 => "f32",
            Precision::F16 => "f16",
        }
    }
    pub fn from_name(s: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|p| p.name() == s)
    }
    /// Perceptual roughness floor of kernels in this precision.
    pub fn min_roughness(self) -> f64 {
        match self {
            Precision::F32 => MIN_ROUGHNESS_F32,
            Precision::F16 => MIN_ROUGHNESS_F16,
        }
    }
}

/// Default GTR exponent: the thesis hard-coded 1.5, the middle of Burley's [1, 2].
pub const DEFAULT_GAMMA: f64 = 1.5;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ModelSpec {
    pub d: D,
    pub vis: Vis,
    pub f: F,
    pub precision: Precision,
    /// GTR exponent (read when d = gtr).
    pub gamma: f64,
    /// Metal of the conductor and F82 Fresnel terms.
    pub metal: Metal,
}

/// A named combination, as an engine or the thesis ships it.
pub struct Preset {
    pub name: &'static str,
    pub d: D,
    pub vis: Vis,
    pub f: F,
    pub source: &'static str,
}

pub const PRESETS: &[Preset] = &[
    Preset { name: "ggx", d: D::Ggx, vis: Vis::SmithGgxJointApprox, f: F::Schlick, source: "thesis 4.1: UE5 Default Lit (GGX, SmithJointApprox, Schlick)" },
    Preset { name: "blinn", d: D::Blinn, vis: Vis::SchlickBeckmann, f: F::Schlick, source: "thesis 4.2: normalised Blinn-Phong, Smith-Schlick with k = a sqrt(2/pi)" },
    Preset { name: "cook-torrance", d: D::Beckmann, vis: Vis::VCavity, f: F::Schlick, source: "thesis 4.3: Beckmann, Cook-Torrance V-cavity" },
    Preset { name: "burley", d: D::Gtr, vis: Vis::SmithGgxSeparable, f: F::Schlick, source: "thesis 4.4: GTR (gamma 1.5), separable Smith GGX" },
    Preset { name: "ue-default-lit", d: D::Ggx, vis: Vis::SmithGgxJointApprox, f: F::SchlickUe, source: "UE5 Default Lit with its f90 = saturate(50 F0.g) Schlick" },
    Preset { name: "filament-high", d: D::Ggx, vis: Vis::SmithGgxCorrelated, f: F::SchlickFilament, source: "Filament high quality: GGX, exact correlated Smith, Schlick with f90" },
    Preset { name: "filament-low", d: D::Ggx, vis: Vis::Hammon, f: F::Schlick, source: "Filament low quality: GGX, V_SmithGGXCorrelated_Fast (Hammon), Schlick f90 = 1" },
];

/// The four models of the thesis, in its order.
pub const THESIS_MODELS: [&str; 4] = ["ggx", "blinn", "cook-torrance", "burley"];

impl ModelSpec {
    pub fn new(d: D, vis: Vis, f: F) -> Self {
        ModelSpec { d, vis, f, precision: Precision::F32, gamma: DEFAULT_GAMMA, metal: Metal::Gold }
    }

    pub fn preset(name: &str) -> Option<Self> {
        PRESETS.iter().find(|p| p.name == name).map(|p| ModelSpec::new(p.d, p.vis, p.f))
    }

    /// Parses a spec; the error names the offending item and lists what is accepted.
    pub fn parse(text: &str) -> Result<Self, String> {
        let text = text.trim();
        if text.is_empty() {
            return Err("empty model spec".into());
        }
        let mut items = text.split(',').map(str::trim);
        let first = items.clone().next().unwrap();
        let mut spec = if first.contains('=') {
            ModelSpec::new(D::Ggx, Vis::SmithGgxJointApprox, F::Schlick)
        } else {
            items.next();
            ModelSpec::preset(first).ok_or_else(|| {
                format!("unknown model `{first}`: presets are {}; or give d=..,vis=..,f=..", preset_names().join(", "))
            })?
        };
        let (mut saw_d, mut saw_vis) = (!first.contains('='), !first.contains('='));
        for item in items {
            let (key, value) = item
                .split_once('=')
                .ok_or_else(|| format!("`{item}` in model spec `{text}` is not key=value"))?;
            let (key, value) = (key.trim(), value.trim());
            match key {
                "d" => {
                    spec.d = D::from_name(value).ok_or_else(|| unknown("d", value, &D::names()))?;
                    saw_d = true;
                }
                "vis" => {
                    spec.vis = Vis::from_name(value).ok_or_else(|| unknown("vis", value, &Vis::names()))?;
                    saw_vis = true;
                }
                "f" => {
                    if let Some(metal) = value.strip_prefix("conductor-") {
                        spec.f = F::Conductor;
                        spec.metal = Metal::from_name(metal).ok_or_else(|| unknown("metal", metal, &Metal::names()))?;
                    } else {
                        spec.f = F::from_name(value).filter(|f| *f != F::Conductor).ok_or_else(|| unknown("f", value, &f_names()))?;
                    }
                }
                "metal" => spec.metal = Metal::from_name(value).ok_or_else(|| unknown("metal", value, &Metal::names()))?,
                "precision" => {
                    spec.precision = Precision::from_name(value).ok_or_else(|| unknown("precision", value, &["f32", "f16"]))?
                }
                "gamma" => spec.gamma = parse_gamma(value)?,
                _ => return Err(format!("unknown key `{key}` in model spec `{text}`: keys are d, vis, f, precision, gamma, metal")),
            }
        }
        if !saw_d || !saw_vis {
            return Err(format!("model spec `{text}` needs both d= and vis= (f defaults to schlick)"));
        }
        Ok(spec)
    }

    /// Applies `key=value` overrides, as given by `--param`.
    pub fn with_params(self, params: &[String]) -> Result<Self, String> {
        if params.is_empty() {
            return Ok(self);
        }
        ModelSpec::parse(&format!("{},{}", self.canonical(), params.join(",")))
    }

    /// The full `d=..,vis=..,f=..` form, with every parameter that matters.
    pub fn canonical(&self) -> String {
        let mut s = format!("d={},vis={},f={}", self.d.name(), self.vis.name(), self.f_name());
        if self.d == D::Gtr {
            s += &format!(",gamma={}", self.gamma);
        }
        if self.f == F::F82 {
            s += &format!(",metal={}", self.metal.name());
        }
        if self.precision != Precision::F32 {
            s += &format!(",precision={}", self.precision.name());
        }
        s
    }

    /// The shortest spec that parses back to this one: a preset name plus overrides where one matches.
    pub fn name(&self) -> String {
        for p in PRESETS {
            if (p.d, p.vis, p.f) == (self.d, self.vis, self.f) {
                let mut s = p.name.to_string();
                if self.d == D::Gtr && self.gamma != DEFAULT_GAMMA {
                    s += &format!(",gamma={}", self.gamma);
                }
                if self.precision != Precision::F32 {
                    s += &format!(",precision={}", self.precision.name());
                }
                return s;
            }
        }
        self.canonical()
    }

    pub fn f_name(&self) -> String {
        match self.f {
            F::Conductor => format!("conductor-{}", self.metal.name()),
            f => f.name().to_string(),
        }
    }

    pub fn min_roughness(&self) -> f64 {
        self.precision.min_roughness()
    }

    /// a = r^2 after the roughness floor of this precision (roughness above 1 is taken as 1).
    pub fn alpha(&self, roughness: f64) -> f64 {
        let r = roughness.clamp(self.min_roughness(), 1.0);
        r * r
    }

    /// The f64 twin of `specular_from_cosines`: D Vis F from guarded cosines.
    pub fn from_cosines(&self, c: &Cosines, a: f64, f0: [f64; 3]) -> [f64; 3] {
        let dv = self.d.eval(c.noh, c.sin2h, a, self.gamma) * self.vis.eval(c, a);
        self.f.eval(f0, c.voh, self.metal).map(|f| dv * f)
    }

    /// The f64 twin of `specular_brdf`: f_s for unnormalised vectors, 0 unless NoL > 0 and NoV > 0.
    pub fn eval(&self, s: &Sample) -> [f64; 3] {
        self.eval_f64(s.n.map(f64::from), s.v.map(f64::from), s.l.map(f64::from), f64::from(s.roughness), s.f0.map(f64::from))
    }

    /// `eval` for inputs already in f64.
    pub fn eval_f64(&self, n: [f64; 3], v: [f64; 3], l: [f64; 3], roughness: f64, f0: [f64; 3]) -> [f64; 3] {
        let unit = guards::safe_normalize;
        self.eval_unit(unit(n), unit(v), unit(l), roughness, f0)
    }

    /// The twin of `specular_brdf_unit`: N, V, L taken as given (the kernel's unit vectors, rounding and all).
    pub fn eval_unit(&self, n: [f64; 3], v: [f64; 3], l: [f64; 3], roughness: f64, f0: [f64; 3]) -> [f64; 3] {
        match guarded_cosines_unit(n, v, l, f0) {
            Some((c, f0)) => self.from_cosines(&c, self.alpha(roughness), f0),
            None => [0.0; 3],
        }
    }
}

/// The twin of the kernels' geometry: normalised vectors, the cosines guarded and F0 clamped to [0, 1];
/// None when NoV <= 0 or NoL <= 0 (no light).
pub fn guarded_cosines(s: &Sample) -> Option<(Cosines, [f64; 3])> {
    guarded_cosines_f64(s.n.map(f64::from), s.v.map(f64::from), s.l.map(f64::from), s.f0.map(f64::from))
}

pub fn guarded_cosines_f64(n: [f64; 3], v: [f64; 3], l: [f64; 3], f0: [f64; 3]) -> Option<(Cosines, [f64; 3])> {
    let unit = guards::safe_normalize;
    guarded_cosines_unit(unit(n), unit(v), unit(l), f0)
}

/// As `guarded_cosines_f64` for vectors already normalised (only H is formed and normalised here).
pub fn guarded_cosines_unit(n: [f64; 3], v: [f64; 3], l: [f64; 3], f0: [f64; 3]) -> Option<(Cosines, [f64; 3])> {
    let h = guards::safe_normalize(guards::add(v, l));
    let (nov, nol) = (guards::dot(n, v), guards::dot(n, l));
    if !(nov > 0.0 && nol > 0.0) {
        return None;
    }
    let nxh = guards::cross(n, h);
    let c = Cosines {
        nov: guards::guard_cosine(nov),
        nol: guards::guard_cosine(nol),
        noh: guards::guard_cosine(guards::dot(n, h)),
        voh: guards::guard_cosine(guards::dot(v, h)),
        sin2h: guards::dot(nxh, nxh).min(1.0),
    };
    Some((c, f0.map(|x| x.clamp(0.0, 1.0))))
}

impl fmt::Display for ModelSpec {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.name())
    }
}

pub fn preset_names() -> Vec<&'static str> {
    PRESETS.iter().map(|p| p.name).collect()
}

/// Fresnel names as specs spell them: `conductor-<metal>` for each metal.
pub fn f_names() -> Vec<String> {
    let mut names: Vec<String> = F::ALL.iter().filter(|f| **f != F::Conductor).map(|f| f.name().to_string()).collect();
    names.extend(Metal::ALL.iter().map(|m| format!("conductor-{}", m.name())));
    names
}

fn unknown(key: &str, value: &str, valid: &[impl AsRef<str>]) -> String {
    let valid: Vec<&str> = valid.iter().map(|v| v.as_ref()).collect();
    format!("unknown {key} `{value}`: valid are {}", valid.join(", "))
}

fn parse_gamma(value: &str) -> Result<f64, String> {
    let g: f64 = value.parse().map_err(|_| format!("gamma `{value}` is not a number"))?;
    if !(g.is_finite() && (0.0..=16.0).contains(&g)) {
        return Err(format!("gamma {value} is outside [0, 16]"));
    }
    Ok(g)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn presets_and_overrides_round_trip() {
        for p in PRESETS {
            let spec = ModelSpec::parse(p.name).unwrap();
            assert_eq!(spec.name(), p.name);
            assert_eq!(ModelSpec::parse(&spec.canonical()).unwrap(), spec);
        }
        let s = ModelSpec::parse("burley,gamma=2,precision=f16").unwrap();
        assert_eq!((s.gamma, s.precision), (2.0, Precision::F16));
        assert_eq!(ModelSpec::parse(&s.name()).unwrap(), s);
        let c = ModelSpec::parse("d=beckmann,vis=smith-beckmann-walter,f=conductor-copper").unwrap();
        assert_eq!((c.f, c.metal), (F::Conductor, Metal::Copper));
        assert_eq!(ModelSpec::parse(&c.name()).unwrap(), c);
    }

    #[test]
    fn bad_specs_name_the_problem() {
        assert!(ModelSpec::parse("phong").unwrap_err().contains("unknown model `phong`"));
        assert!(ModelSpec::parse("d=ggx").unwrap_err().contains("needs both"));
        assert!(ModelSpec::parse("d=ggx,vis=nope").unwrap_err().contains("unknown vis `nope`"));
        assert!(ModelSpec::parse("ggx,gamma=-1").unwrap_err().contains("outside"));
        assert!(ModelSpec::parse("ggx,colour=red").unwrap_err().contains("unknown key `colour`"));
    }
}
