//! Model specs: a D, a Vis, an F, a precision and the values of the parameters those terms read, written
//! `d=ggx,vis=smith-ggx-correlated,f=schlick,precision=f16` or as a preset (`burley`), optionally followed by
//! overrides (`burley,gamma=2`, `ggx,precision=f16`). Every key is checked once: a parameter no term of the
//! spec reads, or a key given twice, is an error.

use super::Sample;
use super::guards::{self, GuardSet, MIN_ROUGHNESS_F16, MIN_ROUGHNESS_F32};
use super::terms::{Cosines, D, Exact, F, Metal, Param, ParamKind, ParamValue, Params, Vis};
use glam::DVec3;
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

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ModelSpec {
    pub d: D,
    pub vis: Vis,
    pub f: F,
    pub precision: Precision,
    /// Every parameter's value; only those the terms read matter (`reads`).
    pub params: Params,
    /// The switchable guards it keeps (`guards=`; all by default).
    pub guards: GuardSet,
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
    Preset {
        name: "ggx",
        d: D::Ggx,
        vis: Vis::SmithGgxJointApprox,
        f: F::Schlick,
        source: "thesis 4.1: UE5 Default Lit (GGX, SmithJointApprox, Schlick)",
    },
    Preset {
        name: "blinn",
        d: D::Blinn,
        vis: Vis::SchlickBeckmann,
        f: F::Schlick,
        source: "thesis 4.2: normalised Blinn-Phong, Smith-Schlick with k = a sqrt(2/pi)",
    },
    Preset {
        name: "cook-torrance",
        d: D::Beckmann,
        vis: Vis::VCavity,
        f: F::Schlick,
        source: "thesis 4.3: Beckmann, Cook-Torrance V-cavity",
    },
    Preset {
        name: "burley",
        d: D::Gtr,
        vis: Vis::SmithGgxSeparable,
        f: F::Schlick,
        source: "thesis 4.4: GTR (gamma 1.5), separable Smith GGX",
    },
    Preset {
        name: "ue-default-lit",
        d: D::Ggx,
        vis: Vis::SmithGgxJointApprox,
        f: F::SchlickUe,
        source: "UE5 Default Lit with its f90 = saturate(50 F0.g) Schlick",
    },
    Preset {
        name: "filament-high",
        d: D::Ggx,
        vis: Vis::SmithGgxCorrelated,
        f: F::SchlickFilament,
        source: "Filament high quality: GGX, exact correlated Smith, Schlick with f90",
    },
    Preset {
        name: "filament-low",
        d: D::Ggx,
        vis: Vis::Hammon,
        f: F::Schlick,
        source: "Filament low quality: GGX, V_SmithGGXCorrelated_Fast (Hammon), Schlick f90 = 1",
    },
    Preset {
        name: "learnopengl",
        d: D::Ggx,
        vis: Vis::SchlickGgxKaris,
        f: F::Schlick,
        source: "LearnOpenGL PBR (de Vries 2014) and UE4's 2013 course notes' direct-light remap: GGX, Schlick-GGX with k = (r+1)^2/8, Schlick",
    },
];

/// The four models of the thesis, in its order.
pub const THESIS_MODELS: [&str; 4] = ["ggx", "blinn", "cook-torrance", "burley"];

/// The reference every cost is compared with: the thesis' (and UE's) GGX.
pub const REFERENCE_MODEL: &str = "ggx";

/// The reference without brdfprof's guards: engine code carries fewer guards than the presets (docs/guards.md),
/// so an engine's own function is also compared with this, what the same formula costs unguarded.
pub const UNGUARDED_REFERENCE_MODEL: &str = "ggx,guards=off";

/// Keys of a spec besides the parameters.
const TERM_KEYS: [&str; 5] = ["d", "vis", "f", "precision", "guards"];

impl ModelSpec {
    pub fn new(d: D, vis: Vis, f: F) -> Self {
        ModelSpec { d, vis, f, precision: Precision::F32, params: Params::default(), guards: GuardSet::ALL }
    }

    pub fn preset(name: &str) -> Option<Self> {
        PRESETS.iter().find(|p| p.name == name).map(|p| ModelSpec::new(p.d, p.vis, p.f))
    }

    /// The reference model (`REFERENCE_MODEL`).
    pub fn reference() -> Self {
        ModelSpec::preset(REFERENCE_MODEL).expect("the reference is a preset")
    }

    /// The parameters this spec's terms read, in `Param` order.
    pub fn reads(&self) -> Vec<Param> {
        let mut reads: Vec<Param> = self.d.row().reads.iter().chain(self.f.row().reads).copied().collect();
        reads.sort();
        reads.dedup();
        reads
    }

    /// Whether it reads the sample's F0: a Fresnel term for a dielectric does (its IOR comes from F0), one for a
    /// conductor reads the metal's complex IOR instead (`Exact`, tied to the f64 terms by a test in terms.rs).
    /// Every D term is a function of a = roughness^2, so every spec reads roughness.
    pub fn reads_f0(&self) -> bool {
        self.f.row().exact == Exact::Dielectric
    }

    /// This spec with `p` set to `value` if one of its terms reads `p` (else unchanged).
    pub fn with_param(mut self, p: Param, value: ParamValue) -> Self {
        if self.reads().contains(&p) {
            self.params.set(p, value);
        }
        self
    }

    /// Parses a spec; the error names the offending item and lists what is accepted.
    pub fn parse(text: &str) -> Result<Self, String> {
        let text = text.trim();
        if text.is_empty() {
            return Err("empty model spec".into());
        }
        let mut items = text.split(',').map(str::trim).peekable();
        let first = *items.peek().unwrap();
        let preset = !first.contains('=');
        let mut spec = if preset {
            items.next();
            ModelSpec::preset(first).ok_or_else(|| {
                format!("unknown model `{first}`: presets are {}; or give d=..,vis=..,f=..", preset_names().join(", "))
            })?
        } else {
            ModelSpec::new(D::Ggx, Vis::SmithGgxJointApprox, F::Schlick)
        };
        let mut seen: Vec<&str> = Vec::new();
        let mut given: Vec<(Param, ParamValue)> = Vec::new();
        for item in items {
            let (key, value) =
                item.split_once('=').ok_or_else(|| format!("`{item}` in model spec `{text}` is not key=value"))?;
            let (key, value) = (key.trim(), value.trim());
            if seen.contains(&key) {
                return Err(format!("`{key}` is given twice in model spec `{text}`"));
            }
            seen.push(key);
            match key {
                "d" => spec.d = D::from_name(value).ok_or_else(|| unknown("d", value, &D::names()))?,
                "vis" => spec.vis = Vis::from_name(value).ok_or_else(|| unknown("vis", value, &Vis::names()))?,
                "f" => spec.f = parse_f(value, &mut given)?,
                "precision" => {
                    spec.precision =
                        Precision::from_name(value).ok_or_else(|| unknown("precision", value, &["f32", "f16"]))?
                }
                "guards" => spec.guards = GuardSet::parse(value)?,
                _ => {
                    let p = Param::from_name(key).ok_or_else(|| {
                        let keys: Vec<&str> = TERM_KEYS.into_iter().chain(Param::ALL.map(Param::name)).collect();
                        format!("unknown key `{key}` in model spec `{text}`: keys are {}", keys.join(", "))
                    })?;
                    given.push((p, Params::parse_value(p, value)?));
                }
            }
        }
        if !preset && !(seen.contains(&"d") && seen.contains(&"vis")) {
            return Err(format!("model spec `{text}` needs both d= and vis= (f defaults to schlick)"));
        }
        let reads = spec.reads();
        for (p, value) in given {
            if !reads.contains(&p) {
                return Err(format!(
                    "`{}` is read by no term of model spec `{text}` (d={}, vis={}, f={})",
                    p.name(),
                    spec.d.name(),
                    spec.vis.name(),
                    spec.f.name()
                ));
            }
            spec.params.set(p, value);
        }
        Ok(spec)
    }

    /// Applies `key=value` overrides, as given by `--param`: each replaces the spec's own value of that key.
    pub fn with_params(self, params: &[String]) -> Result<Self, String> {
        if params.is_empty() {
            return Ok(self);
        }
        let overridden: Vec<&str> = params.iter().filter_map(|p| p.split_once('=').map(|(k, _)| k.trim())).collect();
        let canonical = self.canonical();
        let kept: Vec<&str> = canonical
            .split(',')
            .filter(|item| !item.split_once('=').is_some_and(|(k, _)| overridden.contains(&k)))
            .collect();
        ModelSpec::parse(&format!("{},{}", kept.join(","), params.join(",")))
    }

    /// The full `d=..,vis=..,f=..` form, with every parameter its terms read.
    pub fn canonical(&self) -> String {
        let mut s = format!("d={},vis={},f={}", self.d.name(), self.vis.name(), self.f.name());
        for p in self.reads() {
            s += &format!(",{}={}", p.name(), self.params.get(p).text());
        }
        if self.precision != Precision::F32 {
            s += &format!(",precision={}", self.precision.name());
        }
        if self.guards != GuardSet::ALL {
            s += &format!(",guards={}", self.guards.text());
        }
        s
    }

    /// The shortest spec that parses back to this one: a preset name plus the parameters that differ from its
    /// defaults where a preset matches, else the canonical form.
    pub fn name(&self) -> String {
        let Some(p) = PRESETS.iter().find(|p| (p.d, p.vis, p.f) == (self.d, self.vis, self.f)) else {
            return self.canonical();
        };
        let mut s = p.name.to_string();
        let defaults = Params::default();
        for param in self.reads().into_iter().filter(|&q| self.params.get(q) != defaults.get(q)) {
            s += &format!(",{}={}", param.name(), self.params.get(param).text());
        }
        if self.precision != Precision::F32 {
            s += &format!(",precision={}", self.precision.name());
        }
        if self.guards != GuardSet::ALL {
            s += &format!(",guards={}", self.guards.text());
        }
        s
    }

    /// The Fresnel with its metal where it reads one (`conductor-gold`), for labels.
    pub fn f_label(&self) -> String {
        if self.f.row().reads.contains(&Param::Metal) {
            format!("{}-{}", self.f.name(), self.params.metal().name())
        } else {
            self.f.name().to_string()
        }
    }

    /// The exact Fresnel this spec's F stands for, as a spec term: the metal's conductor Fresnel, or the
    /// dielectric one.
    pub fn exact_fresnel(&self) -> F {
        match self.f.row().exact {
            Exact::Conductor => F::Conductor,
            Exact::Dielectric => F::Dielectric,
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
        let dv = self.d.eval(c.noh, c.sin2h, a, &self.params) * self.vis.eval(c, a);
        self.f.eval(f0, c.voh, &self.params).map(|f| dv * f)
    }

    /// The f64 twin of `specular_brdf`: f_s for unnormalised vectors, 0 unless NoL > 0 and NoV > 0.
    pub fn eval(&self, s: &Sample) -> [f64; 3] {
        self.eval_unit(
            guards::unit(s.n),
            guards::unit(s.v),
            guards::unit(s.l),
            f64::from(s.roughness),
            s.f0.map(f64::from),
        )
    }

    /// `eval` for inputs already in f64.
    pub fn eval_f64(&self, n: DVec3, v: DVec3, l: DVec3, roughness: f64, f0: [f64; 3]) -> [f64; 3] {
        let unit = guards::safe_normalize;
        self.eval_unit(unit(n), unit(v), unit(l), roughness, f0)
    }

    /// The formula itself as a reference, at the sampled roughness and cosines: `eval` without the roughness
    /// floor and without the cosine floor (`GuardSet::FORMULA`; both are guards of fp32 kernels and engines, not
    /// of the mathematics: a reference that applied them would blame a model for the inputs below them). None
    /// at roughness 0, where D is singular (a Dirac delta): such an input has no reference value.
    pub fn eval_reference(&self, s: &Sample) -> Option<[f64; 3]> {
        let (n, v, l) = (guards::unit(s.n), guards::unit(s.v), guards::unit(s.l));
        self.eval_reference_unit(n, v, l, f64::from(s.roughness), s.f0.map(f64::from))
    }

    /// `eval_reference` for N, V, L taken as given (the stability suite perturbs them to find what rounding
    /// alone moves the value).
    pub fn eval_reference_unit(&self, n: DVec3, v: DVec3, l: DVec3, roughness: f64, f0: [f64; 3]) -> Option<[f64; 3]> {
        let r = roughness.min(1.0);
        if r.is_nan() || r <= 0.0 {
            return None;
        }
        Some(match cosines_with(n, v, l, f0, GuardSet::FORMULA) {
            Some((c, f0)) => self.from_cosines(&c, r * r, f0),
            None => [0.0; 3],
        })
    }

    /// The twin of `specular_brdf_unit`: N, V, L taken as given (the kernel's unit vectors, rounding and all).
    pub fn eval_unit(&self, n: DVec3, v: DVec3, l: DVec3, roughness: f64, f0: [f64; 3]) -> [f64; 3] {
        match cosines_with(n, v, l, f0, self.guards) {
            Some((c, f0)) => self.from_cosines(&c, self.alpha(roughness), f0),
            None => [0.0; 3],
        }
    }
}

/// `f=NAME`, or `f=NAME-METAL` for a Fresnel term that reads the metal (`conductor-gold`).
fn parse_f(value: &str, given: &mut Vec<(Param, ParamValue)>) -> Result<F, String> {
    if let Some(f) = F::from_name(value) {
        return Ok(f);
    }
    for f in F::ALL.iter().filter(|f| f.row().reads.contains(&Param::Metal)) {
        if let Some(metal) = value.strip_prefix(f.name()).and_then(|m| m.strip_prefix('-')) {
            given.push((Param::Metal, Params::parse_value(Param::Metal, metal)?));
            return Ok(*f);
        }
    }
    Err(unknown("f", value, &f_names()))
}

/// The twin of the kernels' geometry: normalised vectors, the cosines guarded and F0 clamped to [0, 1];
/// None when NoV <= 0 or NoL <= 0 (no light).
pub fn guarded_cosines(s: &Sample) -> Option<(Cosines, [f64; 3])> {
    guarded_cosines_unit(guards::unit(s.n), guards::unit(s.v), guards::unit(s.l), s.f0.map(f64::from))
}

/// As `guarded_cosines` for vectors already normalised (only H is formed and normalised here).
pub fn guarded_cosines_unit(n: DVec3, v: DVec3, l: DVec3, f0: [f64; 3]) -> Option<(Cosines, [f64; 3])> {
    cosines_with(n, v, l, f0, GuardSet::ALL)
}

/// The twin of `specular_brdf_unit`'s geometry with the guards of `g` (`guards::SWITCHES`); None when the lit
/// mask is on and NoV <= 0 or NoL <= 0.
pub fn cosines_with(n: DVec3, v: DVec3, l: DVec3, f0: [f64; 3], g: GuardSet) -> Option<(Cosines, [f64; 3])> {
    let h = if g.on("safe-h") { guards::safe_normalize(v + l) } else { (v + l) / (v + l).length() };
    let (nov, nol) = (n.dot(v), n.dot(l));
    if g.on("lit-mask") && !(nov > 0.0 && nol > 0.0) {
        return None;
    }
    let noh = g.cosine(n.dot(h));
    let c = Cosines {
        nov: g.cosine(nov),
        nol: g.cosine(nol),
        noh,
        voh: g.cosine(v.dot(h)),
        sin2h: if g.on("sin2h") { n.cross(h).length_squared().min(1.0) } else { 1.0 - noh * noh },
    };
    Some((c, if g.on("f0-clamp") { f0.map(|x| x.clamp(0.0, 1.0)) } else { f0 }))
}

impl fmt::Display for ModelSpec {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.name())
    }
}

pub fn preset_names() -> Vec<&'static str> {
    PRESETS.iter().map(|p| p.name).collect()
}

/// Fresnel names as specs may spell them (`NAME-<metal>` for terms that read the metal).
pub fn f_names() -> Vec<String> {
    let mut names: Vec<String> = F::names().into_iter().map(str::to_string).collect();
    for f in F::ALL.iter().filter(|f| f.row().reads.contains(&Param::Metal)) {
        names.push(format!("{}-<{}>", f.name(), Metal::names().join("|")));
    }
    names
}

/// Every value of a parameter worth measuring: each metal, or the ends and middle of a number's stable range.
pub fn param_samples(p: Param) -> Vec<ParamValue> {
    match p.def().kind {
        ParamKind::Metal => Metal::ALL.iter().map(|m| ParamValue::Metal(*m)).collect(),
        ParamKind::Number { default, min, max, .. } => {
            let mut v = vec![min, default, 0.5 * (min + max), max];
            v.sort_by(f64::total_cmp);
            v.dedup();
            v.into_iter().map(ParamValue::Number).collect()
        }
    }
}

/// `spec` with each combination of `param_samples` of the parameters its terms read (just `spec` when none).
pub fn with_each_param_sample(spec: ModelSpec) -> Vec<ModelSpec> {
    let mut out = vec![spec];
    for p in spec.reads() {
        out = out.into_iter().flat_map(|s| param_samples(p).into_iter().map(move |v| s.with_param(p, v))).collect();
    }
    out
}

fn unknown(key: &str, value: &str, valid: &[impl AsRef<str>]) -> String {
    let valid: Vec<&str> = valid.iter().map(|v| v.as_ref()).collect();
    format!("unknown {key} `{value}`: valid are {}", valid.join(", "))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The reference is the formula at the inputs: below the 1e-4 cosine floor (N.V = N.L = 1e-5, a mirror
    /// configuration) GGX with the exact correlated Smith term grows as 1/NoV, ten times the floored twin's value.
    #[test]
    fn a_reference_has_no_cosine_floor() {
        let ggx = ModelSpec::parse("d=ggx,vis=smith-ggx-correlated,f=schlick").unwrap();
        let c = 1e-5f64;
        let s = (1.0 - c * c).sqrt();
        let (n, v, l) = (DVec3::Z, DVec3::new(s, 0.0, c), DVec3::new(-s, 0.0, c));
        let exact = ggx.eval_reference_unit(n, v, l, 0.5, [0.04; 3]).unwrap()[0];
        let floored = ggx.eval_unit(n, v, l, 0.5, [0.04; 3])[0];
        // At N = H: D = 1 / (pi a2), Vis = 0.5 / (2 NoV sqrt(NoV^2 (1 - a2) + a2)), F at VoH = c.
        let (a2, f) = (0.0625f64, 0.04 + 0.96 * (1.0 - c).powi(5));
        let formula = 1.0 / (std::f64::consts::PI * a2) * 0.5 / (2.0 * c * (c * c * (1.0 - a2) + a2).sqrt()) * f;
        assert!((exact / formula - 1.0).abs() < 1e-9, "{exact} vs the formula's {formula}");
        assert!((exact / floored - 10.0).abs() < 0.01, "{exact} against the floored twin's {floored}");
        assert_eq!(ggx.eval_reference_unit(n, v, l, 0.0, [0.04; 3]), None, "roughness 0: D is a Dirac delta");
        assert_eq!(ggx.eval_reference_unit(n, v, -l, 0.5, [0.04; 3]), Some([0.0; 3]), "light below the horizon");
    }

    /// Karis' remap for analytic lights: k = (r + 1)^2 / 8 in Schlick's G1 = x / (x (1 - k) + k).
    #[test]
    fn schlick_ggx_karis_remaps_the_roughness() {
        let spec = ModelSpec::parse("d=ggx,vis=schlick-ggx-karis,f=none").unwrap();
        let (r, nov, nol) = (0.5f64, 0.3f64, 0.8f64);
        let k = (r + 1.0) * (r + 1.0) / 8.0;
        let g = nov / (nov * (1.0 - k) + k) * nol / (nol * (1.0 - k) + k);
        let c = Cosines { nov, nol, noh: 0.9, voh: 0.7, sin2h: 0.19 };
        let vis = spec.vis.eval(&c, r * r);
        assert!((vis - g / (4.0 * nov * nol)).abs() < 1e-15, "{vis}");
        assert_eq!(ModelSpec::preset("learnopengl").unwrap().vis, Vis::SchlickGgxKaris);
    }

    #[test]
    fn presets_and_overrides_round_trip() {
        for p in PRESETS {
            let spec = ModelSpec::parse(p.name).unwrap();
            assert_eq!(spec.name(), p.name);
            assert_eq!(ModelSpec::parse(&spec.canonical()).unwrap(), spec);
        }
        let s = ModelSpec::parse("burley,gamma=2,precision=f16").unwrap();
        assert_eq!((s.params.number(Param::Gamma), s.precision), (2.0, Precision::F16));
        assert_eq!(ModelSpec::parse(&s.name()).unwrap(), s);
        let c = ModelSpec::parse("d=beckmann,vis=smith-beckmann-walter,f=conductor-copper").unwrap();
        assert_eq!((c.f, c.params.metal()), (F::Conductor, Metal::Copper));
        assert_eq!(ModelSpec::parse(&c.name()).unwrap(), c);
        for text in ["ggx,guards=off", "burley,guards=off:sin2h+f0-clamp", "ggx,guards=on"] {
            let g = ModelSpec::parse(text).unwrap();
            assert_eq!(ModelSpec::parse(&g.name()).unwrap(), g, "{text}");
            assert_eq!(ModelSpec::parse(&g.canonical()).unwrap(), g, "{text}");
        }
        assert_eq!(ModelSpec::parse("ggx,guards=on").unwrap(), ModelSpec::parse("ggx").unwrap());
        assert_eq!(
            ModelSpec::parse("ggx,guards=off:safe-h+sin2h+cosine-floor+f0-clamp+lit-mask").unwrap().guards,
            GuardSet::NONE
        );
        assert_eq!(ModelSpec::parse("d=beckmann,vis=smith-beckmann-walter,f=conductor,metal=copper").unwrap(), c);
        assert_eq!(
            ModelSpec::parse("burley").unwrap().with_params(&["gamma=2.5".into()]).unwrap().params.number(Param::Gamma),
            2.5
        );
        assert_eq!(
            ModelSpec::parse("burley,gamma=2")
                .unwrap()
                .with_params(&["gamma=2.5".into()])
                .unwrap()
                .params
                .number(Param::Gamma),
            2.5
        );
    }

    #[test]
    fn bad_specs_name_the_problem() {
        assert!(ModelSpec::parse("phong").unwrap_err().contains("unknown model `phong`"));
        assert!(ModelSpec::parse("d=ggx").unwrap_err().contains("needs both"));
        assert!(ModelSpec::parse("d=ggx,vis=nope").unwrap_err().contains("unknown vis `nope`"));
        assert!(ModelSpec::parse("burley,gamma=-1").unwrap_err().contains("outside"));
        assert!(ModelSpec::parse("ggx,colour=red").unwrap_err().contains("unknown key `colour`"));
        assert!(ModelSpec::parse("burley,gamma=1,gamma=2").unwrap_err().contains("given twice"));
        assert!(ModelSpec::parse("ggx,gamma=2").unwrap_err().contains("read by no term"));
        assert!(ModelSpec::parse("ggx,metal=gold").unwrap_err().contains("read by no term"));
        assert!(ModelSpec::parse("ggx,f=conductor-tin").unwrap_err().contains("unknown metal `tin`"));
        assert!(ModelSpec::parse("ggx,guards=of").unwrap_err().contains("guards `of`"));
        assert!(ModelSpec::parse("ggx,guards=off:sin2h+nope").unwrap_err().contains("cosine-floor"));
    }

    #[test]
    fn each_parameter_read_is_sampled() {
        for p in PRESETS {
            let spec = ModelSpec::preset(p.name).unwrap();
            let all = with_each_param_sample(spec);
            let expected: usize = spec.reads().iter().map(|&q| param_samples(q).len()).product();
            assert_eq!(all.len(), expected, "{}", p.name);
        }
    }

    /// What a spec says it reads (`reads_f0`, and roughness always) is what its f64 terms depend on: every F
    /// for a dielectric changes with F0 and every other F does not; every D changes with a.
    #[test]
    fn the_inputs_a_spec_reads_are_those_its_terms_depend_on() {
        let p = Params::default();
        for &f in F::ALL {
            let spec = ModelSpec::new(D::Ggx, Vis::Implicit, f);
            let varies = (f.row().eval)([0.04; 3], 0.7, &p) != (f.row().eval)([0.9; 3], 0.7, &p);
            assert_eq!(spec.reads_f0(), varies, "{f:?}: reads_f0 {} but F varies with F0: {varies}", spec.reads_f0());
        }
        for &d in D::ALL {
            assert_ne!(d.at(0.9, 0.1, &p), d.at(0.9, 0.5, &p), "{d:?} does not vary with a");
        }
    }
}
