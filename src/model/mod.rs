//! The one model type every command takes. A model has a name, a precision, the kernels that evaluate it
//! (SPIR-V plus specialisation constants, for each kind of kernel) and, where one exists, an f64 twin and an
//! exact physical reference. A D x Vis x F spec is one constructor (`Model::spec`), a user's `.brdf` file the
//! other (`Model::parse` of `PATH.brdf[,NAME=VALUE...]`).

pub mod brdf_file;
pub mod csv_rows;
pub mod file_model;

use crate::brdf::terms::{ParamValue, PARAMS};
use crate::brdf::{ModelSpec, Precision};
use crate::gpu::{DeviceInfo, SpecConstants};
use crate::shaders::{Shaders, Spirv};
use anyhow::{anyhow, bail, Result};
use std::fmt;
use std::sync::Arc;

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

#[derive(Clone, Debug, PartialEq)]
pub enum Model {
    /// A D x Vis x F spec of the built-in term library.
    Spec(ModelSpec),
    /// A BRDF Explorer `.brdf` file with its parameter bindings.
    File(Arc<file_model::FileModel>),
}

impl From<ModelSpec> for Model {
    fn from(s: ModelSpec) -> Self {
        Model::Spec(s)
    }
}

/// The specialisation constants that select `spec`'s terms and set the parameters they read.
pub fn spec_constants(spec: &ModelSpec) -> SpecConstants {
    let mut c = SpecConstants::default().int(0, spec.d.id() as i32).int(1, spec.vis.id() as i32).int(2, spec.f.id() as i32);
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
    /// A model from its spec text (see `ModelSpec::parse`).
    pub fn parse(text: &str) -> Result<Self> {
        if file_model::names_a_file(text) {
            return file_model::FileModel::parse(text).map(|f| Model::File(Arc::new(f)));
        }
        ModelSpec::parse(text).map(Model::Spec).map_err(|e| anyhow!(e))
    }

    /// The `.brdf` file, for a file model.
    pub fn file(&self) -> Option<&file_model::FileModel> {
        match self {
            Model::File(f) => Some(f),
            Model::Spec(_) => None,
        }
    }

    pub fn spec(spec: ModelSpec) -> Self {
        Model::Spec(spec)
    }

    /// The reference every cost is compared with (ggx).
    pub fn reference() -> Self {
        Model::Spec(ModelSpec::reference())
    }

    /// The shortest name that parses back to this model.
    pub fn name(&self) -> String {
        match self {
            Model::Spec(s) => s.name(),
            Model::File(f) => f.name(),
        }
    }

    /// The name without a `.brdf` file's directory, for labels and output file names.
    pub fn short_name(&self) -> String {
        match self {
            Model::Spec(s) => s.name(),
            Model::File(f) => {
                let name = f.name();
                let file_name = std::path::Path::new(&f.path).file_name().map_or(f.path.clone(), |n| n.to_string_lossy().into_owned());
                file_name + &name[f.path.len()..]
            }
        }
    }

    /// The eval CSV's material columns (`io::SAMPLE_COLUMNS[9..]`) this model does not read, which a CSV may
    /// then leave out: a built-in spec reads roughness always (every D is a function of a = r^2) and F0 where
    /// `ModelSpec::reads_f0`; a `.brdf` file reads those its bindings take (`@roughness`/`@alpha`,
    /// `@f0`/`@basecolor`).
    pub fn unread_columns(&self) -> Vec<&'static str> {
        let (roughness, f0) = match self {
            Model::Spec(s) => (true, s.reads_f0()),
            Model::File(f) => {
                let reads = |inputs: &[file_model::Input]| f.bindings.iter().any(|b| matches!(b, file_model::Binding::Input(i) if inputs.contains(i)));
                (reads(&[file_model::Input::Roughness, file_model::Input::Alpha]), reads(&[file_model::Input::F0, file_model::Input::BaseColor]))
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
            Model::Spec(s) => s.canonical(),
            Model::File(f) => f.canonical(),
        }
    }

    pub fn precision(&self) -> Precision {
        match self {
            Model::Spec(s) => s.precision,
            // The file's GLSL is fp32, as BRDF Explorer compiled it.
            Model::File(_) => Precision::F32,
        }
    }

    /// The f64 twin (and, through `brdf::exact`, the exact reference), where the model has one.
    pub fn twin(&self) -> Option<&ModelSpec> {
        match self {
            Model::Spec(s) => Some(s),
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
            Model::Spec(s) => s.with_params(params).map(Model::Spec).map_err(|e| anyhow!("{}: {e:#}", s.name())),
            Model::File(f) => f.with_params(params).map(|f| Model::File(Arc::new(f))),
        }
    }

    /// Whether an override key is a parameter of this model (so that `--param` skips models it does not fit).
    pub fn takes_param(&self, key: &str) -> bool {
        match self {
            Model::Spec(s) => ["d", "vis", "f", "precision", "guards"].contains(&key) || s.reads().iter().any(|p| p.name() == key),
            Model::File(f) => f.takes_param(key),
        }
    }

    /// The kernel of `kind` that evaluates this model.
    pub fn kernel(&self, kind: KernelKind, shaders: &Shaders) -> Result<ModelKernel> {
        match self {
            Model::Spec(s) => {
                if kind == KernelKind::SceneTerms && s.precision != Precision::F32 {
                    bail!("the scene terms kernel is compiled in fp32 only");
                }
                let name = if kind == KernelKind::SceneTerms { "scene_terms_f32".to_string() } else { format!("{}_{}", kind.base(), s.precision.name()) };
                Ok(ModelKernel { spirv: shaders.get(&name)?, constants: spec_constants(s) })
            }
            Model::File(f) => Ok(ModelKernel { spirv: f.kernel(kind, shaders)?, constants: SpecConstants::default() }),
        }
    }

    /// Fails with a clear reason when the device cannot run this model's kernels.
    pub fn check_support(&self, info: &DeviceInfo) -> Result<()> {
        if self.precision() == Precision::F16 && !info.shader_float16 {
            bail!("{self}: device `{}` has no shaderFloat16, so fp16 arithmetic cannot run there", info.name);
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
    let names: Vec<String> = if models.is_empty() { default.iter().map(|s| s.to_string()).collect() } else { models.to_vec() };
    let parsed = names.iter().map(|m| Model::parse(m).map_err(|e| anyhow!("--model {m}: {e:#}"))).collect::<Result<Vec<_>>>()?;
    for p in params {
        let key = p.split_once('=').map(|(k, _)| k.trim()).ok_or_else(|| anyhow!("--param `{p}`: expected KEY=VALUE"))?;
        if !parsed.iter().any(|m| m.takes_param(key)) {
            let described = |m: &Model| match m.file() {
                Some(f) => format!("{}, whose parameters are {}", f.path, f.file.params.iter().map(|q| q.name.as_str()).collect::<Vec<_>>().join(", ")),
                None => m.name(),
            };
            bail!("--param {p}: no model takes `{key}` ({})", parsed.iter().map(described).collect::<Vec<_>>().join("; "));
        }
    }
    parsed
        .iter()
        .map(|m| {
            let mine: Vec<String> = params.iter().filter(|p| p.split_once('=').is_some_and(|(k, _)| m.takes_param(k.trim()))).cloned().collect();
            m.with_params(&mine).map_err(|e| anyhow!("--param: {e:#}"))
        })
        .collect()
}
