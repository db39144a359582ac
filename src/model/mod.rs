//! The one model type every command takes. A model has a name, a precision, the kernels that evaluate it
//! (SPIR-V plus specialisation constants, for each kind of kernel) and, where one exists, an f64 twin and an
//! exact physical reference. A D x Vis x F spec is one constructor (`Model::spec`), a user's `.brdf` file the
//! other (`Model::parse` of `PATH.brdf[,NAME=VALUE...]`). Either may carry a `name=LABEL`: what tables, charts
//! and output file names call it. A label is not part of the maths: `canonical` (baselines, kernel hashes)
//! never shows it.

pub mod brdf_file;
pub use brdfprof_front as front;
pub mod csv_rows;
pub mod file_model;
pub mod labels;

use crate::brdf::terms::{PARAMS, ParamValue};
use crate::brdf::{ModelSpec, Precision};
use crate::gpu::{DeviceInfo, SpecConstants};
use crate::shaders::{Shaders, Spirv};
use anyhow::{Result, anyhow, bail};
use std::fmt;
use std::sync::Arc;

pub use labels::check_labels;
use labels::split_label;

/// The kinds of kernel a model is compiled into (the GLSL kernels of glsl/, each including brdf.glsl).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum KernelKind {
    /// f_s per sample (`eval`, accuracy, stability).
    Eval,
    /// Each term on its own per sample (tests of the twins).
    Terms,
    /// The profiling kernel over an engine-style packed G-buffer and lights (`profile`, `sweep`, `inspect`,
    /// `check`).
    Shade,
    /// The profiling kernel over a float G-buffer (`profile --gbuffer float`).
    ShadeFloat,
    /// Directional albedo (`stability`, accuracy, energy compensation).
    Albedo,
    /// The scene kernel, with lights and effects.
    Scene,
    /// The scene shading's white furnace.
    SceneAlbedo,
    /// Every scene.glsl term on its own (tests).
    SceneTerms,
}

impl KernelKind {
    /// The GLSL kernel's name in glsl/kernels.txt, before its precision suffix.
    pub fn base(self) -> &'static str {
        match self {
            KernelKind::Eval => "eval",
            KernelKind::Terms => "terms",
            KernelKind::Shade => "shade",
            KernelKind::ShadeFloat => "shade_float",
            KernelKind::Albedo => "albedo",
            KernelKind::Scene => "scene",
            KernelKind::SceneAlbedo => "scene_albedo",
            KernelKind::SceneTerms => "scene_terms",
        }
    }
}

/// A model's kernel: its SPIR-V and the specialisation constants that select the model in it (callers add
/// their kernel's own constants).
#[derive(Clone, Debug)]
pub struct ModelKernel {
    pub spirv: Spirv,
    pub constants: SpecConstants,
}

/// The label of the memory-only baseline kernel in every report (so no model may take it).
pub const BASELINE_LABEL: &str = "baseline";

/// The spec key that names a model.
pub const LABEL_KEY: &str = "name";

#[derive(Clone, Debug, PartialEq)]
pub enum Model {
    /// A D x Vis x F spec of the built-in term library, with its `name=` label if it was given one.
    Spec(ModelSpec, Option<Arc<str>>),
    /// A BRDF Explorer `.brdf` file with its parameter bindings.
    File(Arc<file_model::FileModel>),
}

impl From<ModelSpec> for Model {
    fn from(s: ModelSpec) -> Self {
        Model::Spec(s, None)
    }
}

/// The specialisation constants that select `spec`'s terms and set the parameters they read.
pub fn spec_constants(spec: &ModelSpec) -> SpecConstants {
    let mut c =
        SpecConstants::default().int(0, spec.d.id() as i32).int(1, spec.vis.id() as i32).int(2, spec.f.id() as i32);
    c = c.int(crate::brdf::guards::GUARDS_CONSTANT_ID, spec.guards.0 as i32);
    for p in &PARAMS {
        c = match spec.params.get(p.param) {
            ParamValue::Number(x) => c.float(p.constant_id, x as f32),
            ParamValue::Metal(m) => c.int(p.constant_id, m.id() as i32),
        };
    }
    c
}

impl Model {
    /// A model from its spec text (see `ModelSpec::parse`), less a `name=LABEL` item, which labels it.
    pub fn parse(text: &str) -> Result<Self> {
        let (rest, label) = split_label(text)?;
        let model = if file_model::names_a_file(&rest) {
            Model::File(Arc::new(file_model::FileModel::parse(&rest)?))
        } else {
            ModelSpec::parse(&rest).map(Model::spec).map_err(|e| anyhow!(e))?
        };
        let Some(label) = label else { return Ok(model) };
        let model = model.with_label(None);
        if label == model.label() {
            return Ok(model);
        }
        if let Ok(other) = ModelSpec::parse(&label) {
            bail!("`{text}`: {LABEL_KEY}={label} would read as the model `{}`; give another name", other.name());
        }
        Ok(model.with_label(Some(label)))
    }

    /// The same model under `label` (None: its own name).
    pub fn with_label(self, label: Option<String>) -> Self {
        match self {
            Model::Spec(s, _) => Model::Spec(s, label.map(Arc::from)),
            Model::File(f) => Model::File(Arc::new(file_model::FileModel { label, ..(*f).clone() })),
        }
    }

    /// The perceptual roughness range a `.brdf` file's engine admits (`domain roughness MIN MAX`), if it declares one.
    pub fn roughness_domain(&self) -> Option<(f64, f64)> {
        self.file().and_then(|f| f.file.roughness_domain).map(|(lo, hi, _)| (lo, hi))
    }

    /// The N.V and N.L ranges a `.brdf` file's engine calls it with (`domain nov|nol MIN MAX`), where declared.
    pub fn cosine_domains(&self) -> (Option<(f64, f64)>, Option<(f64, f64)>) {
        let pick = |d: Option<(f64, f64, usize)>| d.map(|(lo, hi, _)| (lo, hi));
        self.file().map_or((None, None), |f| (pick(f.file.nov_domain), pick(f.file.nol_domain)))
    }

    /// The built-in spec a `.brdf` file names as its reference (`reference SPEC`), if it does.
    pub fn declared_reference(&self) -> Option<crate::brdf::ModelSpec> {
        self.file()
            .and_then(|f| f.file.reference.as_ref())
            .and_then(|(text, _)| crate::brdf::ModelSpec::parse(text).ok())
    }

    /// The `.brdf` file, for a file model.
    pub fn file(&self) -> Option<&file_model::FileModel> {
        match self {
            Model::File(f) => Some(f),
            Model::Spec(..) => None,
        }
    }

    pub fn spec(spec: ModelSpec) -> Self {
        Model::Spec(spec, None)
    }

    /// The reference every cost is compared with (ggx).
    pub fn reference() -> Self {
        Model::spec(ModelSpec::reference())
    }

    /// The shortest text that parses back to this model, its label included.
    pub fn name(&self) -> String {
        let spec = match self {
            Model::Spec(s, _) => s.name(),
            Model::File(f) => f.name(),
        };
        match self.given_label() {
            Some(l) => format!("{spec},{LABEL_KEY}={l}"),
            None => spec,
        }
    }

    /// The `name=` label, when one was given.
    fn given_label(&self) -> Option<&str> {
        match self {
            Model::Spec(_, l) => l.as_deref(),
            Model::File(f) => f.label.as_deref(),
        }
    }

    /// What every table, chart and output file name calls the model: its `name=` label; else a spec's shortest
    /// name, or a `.brdf` file's stem (its file name where the stem is a preset's name) with the parameters that
    /// differ from the file's defaults.
    pub fn label(&self) -> String {
        if let Some(l) = self.given_label() {
            return l.to_string();
        }
        match self {
            Model::Spec(s, _) => s.name(),
            Model::File(f) => {
                let name = f.name_for_label();
                let path = std::path::Path::new(&f.path);
                let part = |p: Option<&std::ffi::OsStr>| p.map_or(f.path.clone(), |n| n.to_string_lossy().into_owned());
                // `ggx.brdf` keeps its extension: a stem that reads as a built-in model would take that one's rows.
                let stem = Some(part(path.file_stem()))
                    .filter(|s| ModelSpec::parse(s).is_err())
                    .unwrap_or_else(|| part(path.file_name()));
                // A file's name is the user's (or a pull request's): no control character of it reaches a table.
                crate::messages::escape_line(&(stem + &name[f.path.len()..]))
            }
        }
    }

    /// The eval CSV's material columns (`io::SAMPLE_COLUMNS[9..]`) this model does not read, which a CSV may
    /// then leave out: a built-in spec reads roughness always (every D is a function of a = r^2) and F0 where
    /// `ModelSpec::reads_f0`; a `.brdf` file reads those its bindings take (`@roughness`/`@alpha`,
    /// `@f0`/`@basecolor`).
    pub fn unread_columns(&self) -> Vec<&'static str> {
        let (roughness, f0) = match self {
            Model::Spec(s, _) => (true, s.reads_f0()),
            Model::File(f) => {
                let reads = |inputs: &[file_model::Input]| {
                    f.bindings.iter().any(|b| matches!(b, file_model::Binding::Input(i) if inputs.contains(i)))
                };
                (
                    reads(&[file_model::Input::Roughness, file_model::Input::Alpha]),
                    reads(&[file_model::Input::F0, file_model::Input::BaseColor]),
                )
            }
        };
        let mut unread = Vec::new();
        if !roughness {
            unread.push("roughness");
        }
        if !f0 {
            unread.extend(["f0r", "f0g", "f0b"]);
        }
        unread
    }

    /// The full form, with every parameter (what baselines and reports record).
    pub fn canonical(&self) -> String {
        match self {
            Model::Spec(s, _) => s.canonical(),
            Model::File(f) => f.canonical(),
        }
    }

    pub fn precision(&self) -> Precision {
        match self {
            Model::Spec(s, _) => s.precision,
            // The file's GLSL is fp32, as BRDF Explorer compiled it.
            Model::File(_) => Precision::F32,
        }
    }

    /// The f64 twin (and, through `brdf::exact`, the exact reference), where the model has one.
    pub fn twin(&self) -> Option<&ModelSpec> {
        match self {
            Model::Spec(s, _) => Some(s),
            Model::File(_) => None,
        }
    }

    /// Whether its D has an anisotropic form (a term spec whose D row says so): the scene kernel's anisotropic
    /// lobe extends that D, so it can stand in for the model's.
    pub fn takes_anisotropy(&self) -> bool {
        self.twin().is_some_and(|s| s.d.row().anisotropic)
    }

    /// Applies `key=value` overrides (`--param`).
    pub fn with_params(&self, params: &[String]) -> Result<Self> {
        match self {
            Model::Spec(s, l) => {
                s.with_params(params).map(|s| Model::Spec(s, l.clone())).map_err(|e| anyhow!("{}: {e:#}", s.name()))
            }
            Model::File(f) => f.with_params(params).map(|f| Model::File(Arc::new(f))),
        }
    }

    /// Whether an override key is a parameter of this model (so that `--param` skips models it does not fit).
    pub fn takes_param(&self, key: &str) -> bool {
        match self {
            Model::Spec(s, _) => {
                ["d", "vis", "f", "precision", "guards"].contains(&key) || s.reads().iter().any(|p| p.name() == key)
            }
            Model::File(f) => f.takes_param(key),
        }
    }

    /// The kernel of `kind` that evaluates this model.
    pub fn kernel(&self, kind: KernelKind, shaders: &Shaders) -> Result<ModelKernel> {
        match self {
            Model::Spec(s, _) => {
                if kind == KernelKind::SceneTerms && s.precision != Precision::F32 {
                    bail!("the scene terms kernel is compiled in fp32 only");
                }
                let name = if kind == KernelKind::SceneTerms {
                    "scene_terms_f32".to_string()
                } else {
                    format!("{}_{}", kind.base(), s.precision.name())
                };
                Ok(ModelKernel { spirv: shaders.get(&name)?, constants: spec_constants(s) })
            }
            Model::File(f) => Ok(ModelKernel { spirv: f.kernel(kind, shaders)?, constants: SpecConstants::default() }),
        }
    }

    /// `kernel` compiled with line information (glslang `-g`): the same code and constants, each instruction
    /// naming its file and line (the `.brdf` file's own lines for a file's shader).
    pub fn kernel_with_lines(&self, kind: KernelKind, shaders: &Shaders) -> Result<ModelKernel> {
        let mut k = self.kernel(kind, shaders)?;
        k.spirv = match self {
            Model::Spec(..) => shaders.with_lines(k.spirv.name.split(' ').next().unwrap_or(&k.spirv.name))?,
            Model::File(f) => f.kernel_with_lines(kind, shaders)?,
        };
        Ok(k)
    }

    /// Fails with a clear reason when the device cannot run this model's kernels.
    pub fn check_support(&self, info: &DeviceInfo) -> Result<()> {
        let half = self.precision() == Precision::F16 || matches!(self, Model::File(f) if f.file.uses_float16());
        if half && !info.shader_float16 {
            bail!("{self}: device `{}` has no shaderFloat16, so fp16 arithmetic cannot run there", info.name);
        }
        if matches!(self, Model::File(f) if f.file.uses_float64()) && !info.shader_float64 {
            bail!("{self}: device `{}` has no shaderFloat64, so fp64 arithmetic cannot run there", info.name);
        }
        Ok(())
    }
}

impl fmt::Display for Model {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.name())
    }
}

/// The models of `--model` (or `default` when none is given), with `--param` overrides applied to each model
/// that takes them; an override no model takes is an error.
pub fn models_from_args(models: &[String], params: &[String], default: &[&str]) -> Result<Vec<Model>> {
    let names: Vec<String> =
        if models.is_empty() { default.iter().map(|s| s.to_string()).collect() } else { models.to_vec() };
    let parsed =
        names.iter().map(|m| Model::parse(m).map_err(|e| anyhow!("--model {m}: {e:#}"))).collect::<Result<Vec<_>>>()?;
    for p in params {
        let key =
            p.split_once('=').map(|(k, _)| k.trim()).ok_or_else(|| anyhow!("--param `{p}`: expected KEY=VALUE"))?;
        if !parsed.iter().any(|m| m.takes_param(key)) {
            let described = |m: &Model| match m.file() {
                Some(f) => format!(
                    "{}, whose parameters are {}",
                    f.path,
                    f.file.params.iter().map(|q| q.name.as_str()).collect::<Vec<_>>().join(", ")
                ),
                None => m.name(),
            };
            bail!(
                "--param {p}: no model takes `{key}` ({})",
                parsed.iter().map(described).collect::<Vec<_>>().join("; ")
            );
        }
    }
    parsed
        .iter()
        .map(|m| {
            let mine: Vec<String> = params
                .iter()
                .filter(|p| p.split_once('=').is_some_and(|(k, _)| m.takes_param(k.trim())))
                .cloned()
                .collect();
            m.with_params(&mine).map_err(|e| anyhow!("--param: {e:#}"))
        })
        .collect::<Result<Vec<_>>>()
        .map(labels::distinguish)
        .and_then(|models| check_labels(&models, "--model").map(|_| models))
}

/// The models with the reference (plain ggx) first when they lack it: what every cost is compared with; where
/// a model is a shader file (an engine's own code, with fewer guards than a preset), `ggx,guards=off` after it,
/// so that the tables also say what the same formula costs without brdfprof's guards.
pub fn with_reference(models: &[Model]) -> Vec<Model> {
    let reference = Model::reference();
    let mut all = models.to_vec();
    if !all.contains(&reference) {
        all.insert(0, reference.clone());
    }
    let unguarded = Model::parse(crate::brdf::spec::UNGUARDED_REFERENCE_MODEL).expect("a built-in spec");
    if all.iter().any(|m| m.file().is_some()) && !all.iter().any(|m| m.canonical() == unguarded.canonical()) {
        let at = all.iter().position(|m| *m == reference).map_or(0, |i| i + 1);
        all.insert(at, unguarded);
    }
    all
}

#[cfg(test)]
mod tests {
    use super::*;

    const FILE: &str = "examples/brdf/ggx.brdf";

    #[test]
    fn a_label_names_the_model_but_not_its_maths() {
        for (text, plain) in [
            ("ggx,name=mine", "ggx"),
            ("d=beckmann,vis=vcavity,name=ct_2", "cook-torrance"),
            ("blinn, name = b+1", "blinn"),
        ] {
            let m = Model::parse(text).unwrap();
            let p = Model::parse(plain).unwrap();
            assert_eq!(m.label(), text.rsplit('=').next().unwrap().trim(), "{text}");
            assert_eq!(m.canonical(), p.canonical(), "{text}: the label is not part of the canonical spec");
            assert_eq!(
                format!("{:?}", spec_constants(m.twin().unwrap())),
                format!("{:?}", spec_constants(p.twin().unwrap())),
                "{text}: the same kernel constants"
            );
            assert_eq!(Model::parse(&m.name()).unwrap(), m, "{text}: its name reads back, label included");
            assert_ne!(m, p, "{text}");
        }
        assert_eq!(Model::parse("ggx").unwrap().label(), "ggx");
        assert_eq!(
            Model::parse("ggx,name=ggx").unwrap(),
            Model::reference(),
            "a label that is the model's own name is no label"
        );
    }

    #[test]
    fn a_brdf_file_is_called_by_its_stem_or_its_label() {
        let m = Model::parse(FILE).unwrap();
        assert_eq!(m.label(), "ggx.brdf", "a stem that is a preset's name keeps its extension");
        let named = Model::parse(&format!("{FILE},name=engine")).unwrap();
        assert_eq!(named.label(), "engine");
        assert_eq!(named.canonical(), m.canonical());
        assert_eq!(Model::parse(&named.name()).unwrap(), named);
        let bound = m.with_params(&["roughness=0.25".into()]).unwrap();
        assert_eq!(
            bound.label(),
            "ggx.brdf,roughness=0.25",
            "the stem with the parameters that differ from the file's"
        );
    }

    #[test]
    fn bad_and_clashing_labels_are_errors_naming_the_flag() {
        for (text, why) in [
            ("ggx,name=", "a label is"),
            ("ggx,name=a/b", "a label is"),
            ("ggx,name=x,name=y", "given twice"),
            ("ggx,name=baseline", "baseline"),
            ("ggx,name=blinn", "would read as the model `blinn`"),
        ] {
            let e = format!("{:#}", Model::parse(text).unwrap_err());
            assert!(e.contains(why), "{text}: {e}");
        }
        let e = format!("{:#}", models_from_args(&["ggx,name=a".into(), "blinn,name=a".into()], &[], &[]).unwrap_err());
        assert!(e.contains("--model ggx,name=a and --model blinn,name=a") && e.contains("labelled `a`"), "{e}");
        assert_eq!(
            models_from_args(&["ggx".into(), "ggx".into()], &[], &[]).unwrap().len(),
            2,
            "the same model twice is not a clash"
        );
        let e = format!(
            "{:#}",
            models_from_args(&[format!("{FILE},name=x"), "blinn,name=x".into()], &[], &[]).unwrap_err()
        );
        assert!(e.contains("labelled `x`"), "{e}");
    }
}
