//! The scene file: JSON read with serde through `serde_path_to_error`, so that every error names the JSON path
//! of the problem (`materials[2].roughness: invalid type: string "x", expected f32`). Values are range-checked
//! while they are read (the same path errors), names and combinations after (errors name the path too).
//! `brdfprof scene --explain` prints `explain_text()` (docs/scenes.md's format block) with an example.

use crate::model;
use anyhow::{Result, anyhow, bail};
use serde::{Deserialize, Deserializer, Serialize, de};
use std::path::{Path, PathBuf};

/// A scene as read from its file.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct SceneFile {
    #[serde(default)]
    pub name: Option<String>,
    #[serde(default)]
    pub description: Option<String>,
    pub gbuffer: GBufferSource,
    /// Pinhole camera; procedural scenes have a default, image G-buffers need one (view vectors come from it).
    #[serde(default)]
    pub camera: Option<Camera>,
    pub lights: Vec<Light>,
    pub materials: Vec<Material>,
    #[serde(default)]
    pub render: RenderSettings,
}

#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(rename_all = "kebab-case", deny_unknown_fields)]
pub enum GBufferSource {
    Procedural(Procedural),
    Images(ImageFiles),
}

/// Built-in geometry, ray-cast on the CPU into a G-buffer; materials are named. Read through `RawProcedural`
/// (a plain struct), so that errors inside keep their full JSON path.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(tag = "kind", rename_all = "kebab-case", try_from = "RawProcedural")]
pub enum Procedural {
    /// Thesis Fig. 5.2: one row of spheres per material in `rows`, `columns` roughness steps r = (c + 0.5) /
    /// columns along each row (the material's own roughness is not used here), before a backdrop of `floor`.
    SphereGrid {
        size: Size,
        rows: Vec<String>,
        #[serde(default = "default_columns")]
        columns: u32,
        floor: String,
    },
    /// Thesis "metal statues": statues (pedestal, body, head) of the `statues` materials in a row on a floor.
    Statues { size: Size, statues: Vec<String>, floor: String },
    /// Thesis "Old West": a street of rough wooden and plaster buildings with roofs, on dirt ground.
    OldWest { size: Size, ground: String, walls: Vec<String>, roofs: String },
}

fn default_columns() -> u32 {
    8
}

#[derive(Clone, Copy, Debug, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "kebab-case")]
pub enum ProceduralKind {
    SphereGrid,
    Statues,
    OldWest,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawProcedural {
    kind: ProceduralKind,
    size: Size,
    rows: Option<Vec<String>>,
    columns: Option<u32>,
    floor: Option<String>,
    statues: Option<Vec<String>>,
    ground: Option<String>,
    walls: Option<Vec<String>>,
    roofs: Option<String>,
}

impl TryFrom<RawProcedural> for Procedural {
    type Error = String;
    fn try_from(r: RawProcedural) -> Result<Self, String> {
        let kind = match r.kind {
            ProceduralKind::SphereGrid => "sphere-grid",
            ProceduralKind::Statues => "statues",
            ProceduralKind::OldWest => "old-west",
        };
        let allowed: &[&str] = match r.kind {
            ProceduralKind::SphereGrid => &["rows", "columns", "floor"],
            ProceduralKind::Statues => &["statues", "floor"],
            ProceduralKind::OldWest => &["ground", "walls", "roofs"],
        };
        let given = [
            ("rows", r.rows.is_some()),
            ("columns", r.columns.is_some()),
            ("floor", r.floor.is_some()),
            ("statues", r.statues.is_some()),
            ("ground", r.ground.is_some()),
            ("walls", r.walls.is_some()),
            ("roofs", r.roofs.is_some()),
        ];
        if let Some((extra, _)) = given.iter().find(|(k, g)| *g && !allowed.contains(k)) {
            return Err(format!("`{extra}` is not a field of kind {kind} (its fields: size, {})", allowed.join(", ")));
        }
        let need = |v: Option<String>, k: &str| v.ok_or_else(|| format!("kind {kind} needs `{k}`"));
        let needv = |v: Option<Vec<String>>, k: &str| v.ok_or_else(|| format!("kind {kind} needs `{k}`"));
        Ok(match r.kind {
            ProceduralKind::SphereGrid => Procedural::SphereGrid {
                size: r.size,
                rows: needv(r.rows, "rows")?,
                columns: r.columns.unwrap_or_else(default_columns),
                floor: need(r.floor, "floor")?,
            },
            ProceduralKind::Statues => Procedural::Statues {
                size: r.size,
                statues: needv(r.statues, "statues")?,
                floor: need(r.floor, "floor")?,
            },
            ProceduralKind::OldWest => Procedural::OldWest {
                size: r.size,
                ground: need(r.ground, "ground")?,
                walls: needv(r.walls, "walls")?,
                roofs: need(r.roofs, "roofs")?,
            },
        })
    }
}

/// The largest G-buffer width or height, procedural or from images.
pub const MAX_SIZE: u32 = 16384;

/// Width and height in pixels, 1 to MAX_SIZE each.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct Size(pub [u32; 2]);

impl<'de> Deserialize<'de> for Size {
    fn deserialize<Dz: Deserializer<'de>>(d: Dz) -> Result<Self, Dz::Error> {
        let s = <[u32; 2]>::deserialize(d)?;
        if s.iter().any(|&x| x == 0 || x > MAX_SIZE) {
            return Err(de::Error::custom(format!("size {s:?}: width and height must be 1 to {MAX_SIZE}")));
        }
        Ok(Size(s))
    }
}

/// G-buffer planes as image files, paths relative to the scene file. All must have the same size.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct ImageFiles {
    /// Normals: PNG (8 or 16 bit, RGB or RGBA) encoded n = 2c - 1 with c = value / max; EXR (float RGB) as stored.
    /// Normalised after decoding.
    pub normal: PathBuf,
    /// Perceptual roughness: PNG grey (8 or 16 bit) c = value / max; EXR R. Default: each pixel's material's.
    #[serde(default)]
    pub roughness: Option<PathBuf>,
    /// Base colour: PNG sRGB-encoded (decoded with the sRGB EOTF); EXR linear RGB. Default: the material's.
    #[serde(default)]
    pub base_colour: Option<PathBuf>,
    /// Metallic: PNG grey (8 or 16 bit) c = value / max; EXR R. Default: the material's.
    #[serde(default)]
    pub metallic: Option<PathBuf>,
    /// View-space depth (distance along the camera's forward axis): EXR R, or 16-bit PNG with `depth_range`.
    /// Exactly one of depth and position.
    #[serde(default)]
    pub depth: Option<PathBuf>,
    /// [near, far]: a PNG depth c = value / max means near + c (far - near).
    #[serde(default)]
    pub depth_range: Option<[f32; 2]>,
    /// World-space position: EXR RGB.
    #[serde(default)]
    pub position: Option<PathBuf>,
    /// Material per pixel: 8-bit PNG grey, value = index into `materials`, 255 = background (not shaded).
    /// Default: every pixel is materials[0].
    #[serde(default)]
    pub material: Option<PathBuf>,
    /// Tangents for anisotropy, encoded as normals. Default: a tangent frame built from the normal.
    #[serde(default)]
    pub tangent: Option<PathBuf>,
}

#[derive(Clone, Copy, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Camera {
    pub position: [f32; 3],
    pub look_at: [f32; 3],
    #[serde(default = "default_up")]
    pub up: [f32; 3],
    /// Vertical field of view, degrees (1 to 170).
    #[serde(default = "default_fov")]
    pub fov_y_deg: f32,
}

fn default_up() -> [f32; 3] {
    [0.0, 1.0, 0.0]
}
fn default_fov() -> f32 {
    40.0
}

/// A light. Colours are linear RGB, multiplied by `intensity`. Read through `RawLight` (a plain struct), so
/// that errors inside keep their full JSON path.
#[derive(Clone, Copy, Debug, Deserialize, Serialize)]
#[serde(tag = "type", rename_all = "kebab-case", try_from = "RawLight")]
pub enum Light {
    /// Radiance `colour * intensity` arriving along `direction` (the direction the light travels).
    Directional {
        direction: [f32; 3],
        #[serde(default = "white")]
        colour: [f32; 3],
        #[serde(default = "one")]
        intensity: f32,
    },
    /// Intensity `colour * intensity` at `position`, falling off as 1/d^2.
    Point {
        position: [f32; 3],
        #[serde(default = "white")]
        colour: [f32; 3],
        #[serde(default = "one")]
        intensity: f32,
    },
    /// A point light restricted to a cone around `direction`: full inside `inner_angle_deg`, zero outside
    /// `outer_angle_deg` (half-angles), smooth in between.
    Spot {
        position: [f32; 3],
        direction: [f32; 3],
        #[serde(default = "default_inner")]
        inner_angle_deg: f32,
        #[serde(default = "default_outer")]
        outer_angle_deg: f32,
        #[serde(default = "white")]
        colour: [f32; 3],
        #[serde(default = "one")]
        intensity: f32,
    },
    /// A sphere area light: specular by Karis' representative point with its normalisation, diffuse as a point
    /// light at the centre, 1/d^2 falloff.
    Sphere {
        position: [f32; 3],
        radius: f32,
        #[serde(default = "white")]
        colour: [f32; 3],
        #[serde(default = "one")]
        intensity: f32,
    },
}

#[derive(Clone, Copy, Debug, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "kebab-case")]
pub enum LightType {
    Directional,
    Point,
    Spot,
    Sphere,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawLight {
    r#type: LightType,
    direction: Option<[f32; 3]>,
    position: Option<[f32; 3]>,
    radius: Option<f32>,
    inner_angle_deg: Option<f32>,
    outer_angle_deg: Option<f32>,
    #[serde(default = "white")]
    colour: [f32; 3],
    #[serde(default = "one")]
    intensity: f32,
}

impl TryFrom<RawLight> for Light {
    type Error = String;
    fn try_from(r: RawLight) -> Result<Self, String> {
        let (kind, allowed): (&str, &[&str]) = match r.r#type {
            LightType::Directional => ("directional", &["direction"]),
            LightType::Point => ("point", &["position"]),
            LightType::Spot => ("spot", &["position", "direction", "inner_angle_deg", "outer_angle_deg"]),
            LightType::Sphere => ("sphere", &["position", "radius"]),
        };
        let given = [
            ("direction", r.direction.is_some()),
            ("position", r.position.is_some()),
            ("radius", r.radius.is_some()),
            ("inner_angle_deg", r.inner_angle_deg.is_some()),
            ("outer_angle_deg", r.outer_angle_deg.is_some()),
        ];
        if let Some((extra, _)) = given.iter().find(|(k, g)| *g && !allowed.contains(k)) {
            return Err(format!(
                "a {kind} light has no `{extra}` (its fields: {}, colour, intensity)",
                allowed.join(", ")
            ));
        }
        let need = |v: Option<[f32; 3]>, k: &str| v.ok_or_else(|| format!("a {kind} light needs `{k}`"));
        let (colour, intensity) = (r.colour, r.intensity);
        Ok(match r.r#type {
            LightType::Directional => {
                Light::Directional { direction: need(r.direction, "direction")?, colour, intensity }
            }
            LightType::Point => Light::Point { position: need(r.position, "position")?, colour, intensity },
            LightType::Spot => Light::Spot {
                position: need(r.position, "position")?,
                direction: need(r.direction, "direction")?,
                inner_angle_deg: r.inner_angle_deg.unwrap_or_else(default_inner),
                outer_angle_deg: r.outer_angle_deg.unwrap_or_else(default_outer),
                colour,
                intensity,
            },
            LightType::Sphere => Light::Sphere {
                position: need(r.position, "position")?,
                radius: r.radius.ok_or("a sphere light needs `radius`")?,
                colour,
                intensity,
            },
        })
    }
}

fn white() -> [f32; 3] {
    [1.0; 3]
}
fn one() -> f32 {
    1.0
}
fn default_inner() -> f32 {
    20.0
}
fn default_outer() -> f32 {
    30.0
}

impl Light {
    pub fn type_name(&self) -> &'static str {
        match self {
            Light::Directional { .. } => "directional",
            Light::Point { .. } => "point",
            Light::Spot { .. } => "spot",
            Light::Sphere { .. } => "sphere",
        }
    }
}

/// A model spec string (`ggx`, `burley,gamma=2`, `d=ggx,vis=smith-ggx-correlated,f=schlick`), parsed on read.
#[derive(Clone, Debug, PartialEq)]
pub struct Model(pub model::Model);

impl<'de> Deserialize<'de> for Model {
    fn deserialize<Dz: Deserializer<'de>>(d: Dz) -> Result<Self, Dz::Error> {
        let text = String::deserialize(d)?;
        let text = if model::file_model::names_a_file(&text) { relative_to_scene(&text) } else { text };
        model::Model::parse(&text).map(Model).map_err(|e| de::Error::custom(format!("{e:#}")))
    }
}

thread_local! {
    /// The directory of the scene file being parsed (a `.brdf` model path is relative to it).
    static SCENE_DIR: std::cell::RefCell<PathBuf> = std::cell::RefCell::default();
}

/// A `.brdf` model text with a relative path made relative to the scene file's directory.
fn relative_to_scene(text: &str) -> String {
    let dir = SCENE_DIR.with(|d| d.borrow().clone());
    let Some((path, fields)) = model::file_model::split_path(text, &dir) else { return text.to_string() };
    let path = Path::new(path);
    if path.is_absolute() {
        return text.to_string();
    }
    let joined = dir.join(path).display().to_string();
    let fields: Vec<String> = fields.iter().map(|f| include_relative_to(&dir, f)).collect();
    std::iter::once(joined).chain(fields).collect::<Vec<_>>().join(",")
}

/// A model text's `include=DIR` or `include-map=VIRTUAL=DIR` field with a relative DIR made relative to the
/// scene's directory `dir`; any other field as it is.
fn include_relative_to(dir: &Path, field: &str) -> String {
    let (key, value) = field.split_once('=').unwrap_or((field, ""));
    let (prefix, d) = match key.trim() {
        model::file_model::INCLUDE => (String::new(), value),
        model::file_model::INCLUDE_MAP => match value.split_once('=') {
            Some((v, d)) => (format!("{v}="), d),
            None => return field.to_string(),
        },
        _ => return field.to_string(),
    };
    let d = Path::new(d.trim());
    if d.is_absolute() {
        return field.to_string();
    }
    format!("{}={prefix}{}", key.trim(), dir.join(d).display())
}

impl Serialize for Model {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(&self.0.name())
    }
}

/// A parameter value in a material's `params`: a number, a string, or a colour as [r, g, b].
#[derive(Clone, Debug, PartialEq, Deserialize, Serialize)]
#[serde(untagged)]
pub enum ParamValue {
    Number(f64),
    Text(String),
    Colour([f64; 3]),
}

impl ParamValue {
    fn text(&self) -> String {
        match self {
            ParamValue::Number(x) => format!("{x}"),
            ParamValue::Text(t) => t.clone(),
            ParamValue::Colour([r, g, b]) => format!("{r},{g},{b}"),
        }
    }
}

/// A number in [0, 1].
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Unit(pub f32);

impl<'de> Deserialize<'de> for Unit {
    fn deserialize<Dz: Deserializer<'de>>(d: Dz) -> Result<Self, Dz::Error> {
        let x = f32::deserialize(d)?;
        if !(0.0..=1.0).contains(&x) {
            return Err(de::Error::custom(format!("{x} is outside [0, 1]")));
        }
        Ok(Unit(x))
    }
}

/// An RGB colour, each channel in [0, 1].
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Colour(pub [f32; 3]);

impl<'de> Deserialize<'de> for Colour {
    fn deserialize<Dz: Deserializer<'de>>(d: Dz) -> Result<Self, Dz::Error> {
        let c = <[f32; 3]>::deserialize(d)?;
        if c.iter().any(|x| !(0.0..=1.0).contains(x)) {
            return Err(de::Error::custom(format!("colour {c:?} has a channel outside [0, 1]")));
        }
        Ok(Colour(c))
    }
}

#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct Material {
    pub name: String,
    /// A model spec from the term library.
    pub model: Model,
    #[serde(default = "grey")]
    pub base_colour: Colour,
    #[serde(default = "zero_unit")]
    pub metallic: Unit,
    #[serde(default = "half_unit")]
    pub roughness: Unit,
    /// Parameters of the model, overriding its own (`{"gamma": 2}`), as `--param` does.
    #[serde(default)]
    pub params: std::collections::BTreeMap<String, ParamValue>,
    /// Shorthand for `params: {"gamma": G}` (the GTR exponent).
    #[serde(default)]
    pub gamma: Option<f64>,
    /// Macros for a `.brdf` model's shader (`{"QUALITY": 1}`), as `--define` gives them.
    #[serde(default)]
    pub define: std::collections::BTreeMap<String, ParamValue>,
    #[serde(default)]
    pub effects: Effects,
}

fn grey() -> Colour {
    Colour([0.5; 3])
}
fn zero_unit() -> Unit {
    Unit(0.0)
}
fn half_unit() -> Unit {
    Unit(0.5)
}

impl Material {
    /// The material's parameter overrides as `KEY=VALUE` items.
    fn param_items(&self) -> Vec<String> {
        let mut items: Vec<String> = self.params.iter().map(|(k, v)| format!("{k}={}", v.text())).collect();
        items.extend(self.gamma.map(|g| format!("gamma={g}")));
        items.extend(self.define.iter().map(|(k, v)| format!("{}={k}={}", model::file_model::DEFINE, v.text())));
        items
    }

    /// The model with the material's parameters applied (checked when the scene is read).
    pub fn model(&self) -> model::Model {
        self.try_model().expect("material parameters are checked when the scene is read")
    }

    fn try_model(&self) -> Result<model::Model> {
        if self.gamma.is_some() && self.params.contains_key("gamma") {
            bail!("gamma is given both as `gamma` and in `params`");
        }
        self.model.0.with_params(&self.param_items())
    }
}

/// What a material calls for beyond the model's specular lobe.
#[derive(Clone, Copy, Debug, Default, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct Effects {
    /// Anisotropic GGX strength in [-1, 1] (0: isotropic). Replaces the model's D and Vis, so needs d = ggx.
    #[serde(default)]
    pub anisotropy: Signed,
    /// Multiple-scattering energy compensation (Filament's 1 + F0 (1/E - 1)).
    #[serde(default)]
    pub energy_compensation: bool,
    #[serde(default)]
    pub diffuse: DiffuseLobe,
    #[serde(default)]
    pub clear_coat: Option<ClearCoat>,
}

/// A number in [-1, 1].
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct Signed(pub f32);

impl<'de> Deserialize<'de> for Signed {
    fn deserialize<Dz: Deserializer<'de>>(d: Dz) -> Result<Self, Dz::Error> {
        let x = f32::deserialize(d)?;
        if !(-1.0..=1.0).contains(&x) {
            return Err(de::Error::custom(format!("{x} is outside [-1, 1]")));
        }
        Ok(Signed(x))
    }
}

#[derive(Clone, Copy, Debug, Default, Deserialize, Serialize, PartialEq, Eq, Hash, PartialOrd, Ord)]
#[serde(rename_all = "kebab-case")]
pub enum DiffuseLobe {
    #[default]
    None,
    Lambert,
    Burley,
}

impl DiffuseLobe {
    /// The id the kernel reads (scene.glsl DIFFUSE / Surface.diffuse).
    pub fn id(self) -> i32 {
        self as i32
    }
    pub fn name(self) -> &'static str {
        match self {
            DiffuseLobe::None => "none",
            DiffuseLobe::Lambert => "lambert",
            DiffuseLobe::Burley => "burley",
        }
    }
}

#[derive(Clone, Copy, Debug, Deserialize, Serialize, PartialEq)]
#[serde(deny_unknown_fields)]
pub struct ClearCoat {
    #[serde(default = "one_unit")]
    pub strength: Unit,
    #[serde(default = "coat_roughness")]
    pub roughness: Unit,
}

fn one_unit() -> Unit {
    Unit(1.0)
}
fn coat_roughness() -> Unit {
    Unit(0.1)
}

/// How `brdfprof render` draws the scene.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct RenderSettings {
    /// Radiance is multiplied by this before tone mapping.
    #[serde(default = "one")]
    pub exposure: f32,
    /// Models compared: the scene is rendered once per model, every material's model replaced by it (as the
    /// thesis switched the master material's shading model). Default: the four thesis models.
    #[serde(default = "thesis_models")]
    pub models: Vec<Model>,
    /// Materials of the comparison grid (rows). Default: every material.
    #[serde(default)]
    pub grid: Vec<String>,
    /// Roughness of each polar lobe panel.
    #[serde(default = "lobe_roughness")]
    pub lobe_roughness: Vec<Unit>,
    /// Colour of pixels no surface covers (linear RGB, before tone mapping).
    #[serde(default)]
    pub background: [f32; 3],
}

fn thesis_models() -> Vec<Model> {
    crate::brdf::THESIS_MODELS
        .iter()
        .map(|m| Model(model::Model::parse(m).expect("thesis models are presets")))
        .collect()
}
fn lobe_roughness() -> Vec<Unit> {
    [0.2, 0.4, 0.6, 0.8].map(Unit).to_vec()
}

impl Default for RenderSettings {
    fn default() -> Self {
        RenderSettings {
            exposure: 1.0,
            models: thesis_models(),
            grid: Vec::new(),
            lobe_roughness: lobe_roughness(),
            background: [0.0; 3],
        }
    }
}

/// A loaded, checked scene and where it came from (image paths are relative to `dir`).
#[derive(Clone, Debug)]
pub struct Scene {
    pub file: SceneFile,
    pub path: PathBuf,
    pub dir: PathBuf,
}

impl Scene {
    /// Reads and checks a scene file; errors name the file and the JSON path.
    pub fn load(path: &Path) -> Result<Scene> {
        let bytes = crate::io::read_input(path).map_err(|e| anyhow!("scene file: {e}"))?;
        let text = String::from_utf8(bytes).map_err(|e| {
            anyhow!("cannot read scene file {}: not UTF-8 at byte {}", path.display(), e.utf8_error().valid_up_to())
        })?;
        let dir = path.parent().map(Path::to_path_buf).unwrap_or_default();
        Scene::parse(&text, &path.display().to_string(), dir, path.to_path_buf())
    }

    /// Parses scene JSON; `name` prefixes errors.
    pub fn parse(text: &str, name: &str, dir: PathBuf, path: PathBuf) -> Result<Scene> {
        SCENE_DIR.with(|d| *d.borrow_mut() = dir.clone());
        let mut de = serde_json::Deserializer::from_str(text);
        let file: SceneFile = serde_path_to_error::deserialize(&mut de).map_err(|e| {
            let path = e.path().to_string();
            let inner = e.into_inner();
            if path == "." { anyhow!("{name}: {inner}") } else { anyhow!("{name}: {path}: {inner}") }
        })?;
        check(&file).map_err(|e| anyhow!("{name}: {e}"))?;
        Ok(Scene { file, path, dir })
    }

    /// The scene's name (a plain file name: it names output files): its `name`, else the file stem, else
    /// "scene".
    pub fn name(&self) -> String {
        let stem = || {
            self.path.file_stem().map(|s| s.to_string_lossy().into_owned()).filter(|s| plain_name_fault(s).is_none())
        };
        self.file.name.clone().or_else(stem).unwrap_or_else(|| "scene".into())
    }

    pub fn material_index(&self, name: &str) -> Option<usize> {
        self.file.materials.iter().position(|m| m.name == name)
    }
}

fn finite3(v: &[f32; 3]) -> bool {
    v.iter().all(|x| x.is_finite())
}

fn nonzero3(v: &[f32; 3]) -> bool {
    finite3(v) && v.iter().any(|x| *x != 0.0)
}

/// Why `name` cannot be used as a file name inside an output directory, or None.
fn plain_name_fault(name: &str) -> Option<&'static str> {
    match name {
        "" => Some("it is empty"),
        "." | ".." => Some("`.` and `..` name directories"),
        _ if name.contains('/') || name.contains('\\') => Some("it contains a path separator (`/` or `\\`)"),
        _ if name.contains('\0') => Some("it contains a NUL character"),
        _ => None,
    }
}

/// `name` names output files (results/scenes/NAME/, results/scene-NAME-DEVICE.json), so it must be a plain
/// file name: no path that escapes or reaches elsewhere.
fn check_name(f: &SceneFile) -> Result<()> {
    match f.name.as_deref().map(|n| (n, plain_name_fault(n))) {
        Some((n, Some(why))) => {
            bail!("name: {n:?} is not a plain file name: {why} (it names the scene's output files)")
        }
        _ => Ok(()),
    }
}

/// Checks what serde cannot: names, references and combinations. Errors name the JSON path.
fn check(f: &SceneFile) -> Result<()> {
    check_name(f)?;
    check_materials(&f.materials)?;
    check_gbuffer(f)?;
    if let Some(c) = &f.camera {
        check_camera(c)?;
    }
    if f.lights.len() > MAX_LIGHTS {
        bail!(
            "lights: at most {MAX_LIGHTS} lights ({} given): the scene kernel unrolls every light, and lavapipe's compile time grows faster than the count (measured here: 64 lights 2.8 s, 128 lights 6.8 s, 200 lights 17 s, 300 over 100 s per model)",
            f.lights.len()
        );
    }
    for (i, l) in f.lights.iter().enumerate() {
        check_light(&format!("lights[{i}]"), l)?;
    }
    check_render(f)
}

/// Lights a scene may have (docs/limits.md).
pub const MAX_LIGHTS: usize = 128;

/// `path: no material named ...` unless `name` is one of the scene's materials.
fn need(f: &SceneFile, path: String, name: &str) -> Result<()> {
    if f.materials.iter().any(|m| m.name == name) {
        Ok(())
    } else {
        bail!("{path}: no material named `{name}` (materials are {})", names(f))
    }
}

/// Each of `names` (at `path[i]`) must be a material; `what` says what at least one of them is.
fn need_all(f: &SceneFile, path: &str, names: &[String], what: &str) -> Result<()> {
    if names.is_empty() {
        bail!("{path}: at least one {what}");
    }
    names.iter().enumerate().try_for_each(|(i, n)| need(f, format!("{path}[{i}]"), n))
}

fn check_materials(materials: &[Material]) -> Result<()> {
    if materials.is_empty() {
        bail!("materials: a scene needs at least one material");
    }
    if materials.len() > 255 {
        bail!("materials: at most 255 materials ({} given)", materials.len());
    }
    for (i, m) in materials.iter().enumerate() {
        if materials[..i].iter().any(|o| o.name == m.name) {
            bail!("materials[{i}].name: `{}` is used by an earlier material", m.name);
        }
        let field = if !m.define.is_empty() && m.model.0.file().is_none() {
            bail!(
                "materials[{i}].define: a define is for a .brdf model's shader, and `{}` is a built-in spec",
                m.model.0.name()
            );
        } else if m.gamma.is_some() {
            "gamma"
        } else if m.define.is_empty() {
            "params"
        } else {
            "params/define"
        };
        let model = m.try_model().map_err(|e| anyhow!("materials[{i}].{field}: {e:#}"))?;
        if m.effects.anisotropy.0 != 0.0 && !model.takes_anisotropy() {
            bail!(
                "materials[{i}].effects.anisotropy: anisotropic GGX replaces the model's D and Vis, so it needs d=ggx (model `{}`)",
                model.name()
            );
        }
    }
    Ok(())
}

fn check_gbuffer(f: &SceneFile) -> Result<()> {
    let p = "gbuffer.procedural";
    match &f.gbuffer {
        GBufferSource::Procedural(Procedural::SphereGrid { rows, columns, floor, .. }) => {
            need_all(f, &format!("{p}.rows"), rows, "row")?;
            if *columns == 0 || *columns > 64 {
                bail!("{p}.columns: {columns} is outside 1 to 64");
            }
            need(f, format!("{p}.floor"), floor)
        }
        GBufferSource::Procedural(Procedural::Statues { statues, floor, .. }) => {
            need_all(f, &format!("{p}.statues"), statues, "statue")?;
            need(f, format!("{p}.floor"), floor)
        }
        GBufferSource::Procedural(Procedural::OldWest { ground, walls, roofs, .. }) => {
            need(f, format!("{p}.ground"), ground)?;
            need_all(f, &format!("{p}.walls"), walls, "wall material")?;
            need(f, format!("{p}.roofs"), roofs)
        }
        GBufferSource::Images(im) => {
            if f.camera.is_none() {
                bail!("camera: required when the G-buffer comes from images (view vectors are derived from it)");
            }
            match (&im.depth, &im.position) {
                (Some(_), Some(_)) => bail!("gbuffer.images: give depth or position, not both"),
                (None, None) => bail!("gbuffer.images: give depth or position (view vectors are derived from it)"),
                _ => {}
            }
            if let Some([near, far]) = im.depth_range {
                if !(near.is_finite() && far.is_finite() && far > near) {
                    bail!("gbuffer.images.depth_range: [{near}, {far}] must have far > near");
                }
            }
            Ok(())
        }
    }
}

fn check_camera(c: &Camera) -> Result<()> {
    if !(finite3(&c.position) && finite3(&c.look_at) && nonzero3(&c.up)) {
        bail!("camera: position, look_at and up must be finite, up non-zero");
    }
    if c.position == c.look_at {
        bail!("camera.look_at: equals camera.position");
    }
    if !(1.0..=170.0).contains(&c.fov_y_deg) {
        bail!("camera.fov_y_deg: {} is outside 1 to 170", c.fov_y_deg);
    }
    Ok(())
}

fn check_light(p: &str, l: &Light) -> Result<()> {
    let (colour, intensity) = match l {
        Light::Directional { direction, colour, intensity } => {
            if !nonzero3(direction) {
                bail!("{p}.direction: must be finite and non-zero");
            }
            (colour, intensity)
        }
        Light::Point { position, colour, intensity } => {
            if !finite3(position) {
                bail!("{p}.position: must be finite");
            }
            (colour, intensity)
        }
        Light::Spot { position, direction, inner_angle_deg, outer_angle_deg, colour, intensity } => {
            if !finite3(position) || !nonzero3(direction) {
                bail!("{p}: position must be finite and direction finite and non-zero");
            }
            if !(*inner_angle_deg >= 0.0 && inner_angle_deg <= outer_angle_deg && *outer_angle_deg <= 90.0) {
                bail!(
                    "{p}: need 0 <= inner_angle_deg ({inner_angle_deg}) <= outer_angle_deg ({outer_angle_deg}) <= 90"
                );
            }
            (colour, intensity)
        }
        Light::Sphere { position, radius, colour, intensity } => {
            if !finite3(position) {
                bail!("{p}.position: must be finite");
            }
            if !(radius.is_finite() && *radius > 0.0) {
                bail!("{p}.radius: {radius} must be positive");
            }
            (colour, intensity)
        }
    };
    if !(colour.iter().all(|c| c.is_finite() && *c >= 0.0) && intensity.is_finite() && *intensity >= 0.0) {
        bail!("{p}: colour and intensity must be finite and non-negative");
    }
    Ok(())
}

fn check_render(f: &SceneFile) -> Result<()> {
    let r = &f.render;
    if !(r.exposure.is_finite() && r.exposure > 0.0) {
        bail!("render.exposure: {} must be positive", r.exposure);
    }
    if r.models.is_empty() {
        bail!("render.models: at least one model");
    }
    for (i, g) in r.grid.iter().enumerate() {
        need(f, format!("render.grid[{i}]"), g)?;
    }
    if r.lobe_roughness.is_empty() {
        bail!("render.lobe_roughness: at least one roughness");
    }
    Ok(())
}

fn names(f: &SceneFile) -> String {
    f.materials.iter().map(|m| format!("`{}`", m.name)).collect::<Vec<_>>().join(", ")
}

/// docs/scenes.md, whose block between the `scene --explain` markers is the scene format: one text for the
/// reader of the docs and for `brdfprof scene --explain`.
const SCENES_DOC: &str = include_str!("../../docs/scenes.md");

/// `brdfprof scene --explain`: the scene format, as docs/scenes.md gives it between its markers.
pub fn explain_text() -> &'static str {
    const BEGIN: &str = "<!-- scene --explain: begin -->\n```text\n";
    const END: &str = "```\n<!-- scene --explain: end -->";
    let start = SCENES_DOC.find(BEGIN).expect("docs/scenes.md has the `scene --explain: begin` marker") + BEGIN.len();
    let len = SCENES_DOC[start..].find(END).expect("docs/scenes.md has the `scene --explain: end` marker");
    &SCENES_DOC[start..start + len]
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<Scene> {
        Scene::parse(text, "t.json", PathBuf::new(), PathBuf::from("t.json"))
    }

    const GOOD: &str = r#"{"gbuffer": {"procedural": {"kind": "sphere-grid", "size": [64, 32], "rows": ["a"], "floor": "a"}},
        "lights": [{"type": "directional", "direction": [0, -1, -1]}],
        "materials": [{"name": "a", "model": "ggx"}, {"name": "b", "model": "blinn", "roughness": 0.3}]}"#;

    #[test]
    fn the_explain_text_is_the_docs_format_block() {
        let t = explain_text();
        assert!(t.starts_with("brdfprof scene files (JSON)\n"), "{t}");
        assert!(t.ends_with("Example (scenes/sphere-grid.json):\n"), "{t}");
        assert!(!t.contains("```") && !t.contains("<!--"), "{t}");
    }

    #[test]
    fn a_good_scene_parses_with_defaults() {
        let s = parse(GOOD).unwrap();
        assert_eq!(s.file.materials[1].roughness, Unit(0.3));
        assert_eq!(s.file.materials[0].effects, Effects::default());
        assert_eq!(s.file.render.models.len(), 4);
    }

    /// A material's `define` reaches a `.brdf` model's shader as `--define` does; a built-in spec refuses it.
    #[test]
    fn a_material_define_preprocesses_its_file() {
        let file = GOOD.replace(
            r#""model": "ggx"}"#,
            r#""model": "tests/fixtures/brdf/quality-switch.brdf", "define": {"QUALITY_LEVEL": 1}}"#,
        );
        let s = parse(&file).unwrap();
        let m = s.file.materials[0].model();
        assert!(m.canonical().contains(",define=QUALITY_LEVEL=1"), "{}", m.canonical());
        let shader = m.file().unwrap().file.shader.iter().map(|l| l.1.clone()).collect::<Vec<_>>().join("\n");
        assert!(
            shader.contains("pow5(1.0 - VoH)") || shader.replace(' ', "").contains("pow5(1.0-VoH)"),
            "the high branch: {shader}"
        );
        let spec = GOOD.replace(r#""model": "ggx"}"#, r#""model": "ggx", "define": {"Q": 1}}"#);
        let e = parse(&spec).unwrap_err().to_string();
        assert!(e.contains("materials[0].define") && e.contains("built-in spec"), "{e}");
    }

    #[test]
    fn errors_name_the_json_path() {
        let bad = GOOD.replace(r#""roughness": 0.3"#, r#""roughness": "x""#);
        let e = parse(&bad).unwrap_err().to_string();
        assert!(e.contains("t.json: materials[1].roughness: invalid type: string \"x\", expected f32"), "{e}");
        let bad = GOOD.replace(r#""roughness": 0.3"#, r#""roughness": 1.5"#);
        let e = parse(&bad).unwrap_err().to_string();
        assert!(e.contains("materials[1].roughness: 1.5 is outside [0, 1]"), "{e}");
        let bad = GOOD.replace(r#""model": "blinn""#, r#""model": "phong""#);
        let e = parse(&bad).unwrap_err().to_string();
        assert!(e.contains("materials[1].model: unknown model `phong`"), "{e}");
        let bad = GOOD.replace(r#""type": "directional""#, r#""type": "area""#);
        let e = parse(&bad).unwrap_err().to_string();
        assert!(e.contains("lights[0]") && e.contains("unknown variant `area`"), "{e}");
        let bad = GOOD.replace(r#""rows": ["a"]"#, r#""rows": ["a", "zz"]"#);
        let e = parse(&bad).unwrap_err().to_string();
        assert!(e.contains("gbuffer.procedural.rows[1]: no material named `zz`"), "{e}");
        let bad = GOOD.replace(r#""model": "blinn""#, r#""model": "blinn", "effects": {"anisotropy": 0.5}"#);
        let e = parse(&bad).unwrap_err().to_string();
        assert!(e.contains("materials[1].effects.anisotropy: anisotropic GGX") && e.contains("needs d=ggx"), "{e}");
        let bad = GOOD.replace(r#""model": "blinn""#, r#""model": "blinn", "colour": 1"#);
        let e = parse(&bad).unwrap_err().to_string();
        assert!(e.contains("materials[1]") && e.contains("unknown field `colour`"), "{e}");
        let bad = GOOD.replace(r#""direction": [0, -1, -1]"#, r#""direction": [0, "x", -1]"#);
        let e = parse(&bad).unwrap_err().to_string();
        assert!(e.contains("lights[0].direction[1]: invalid type: string \"x\", expected f32"), "{e}");
        let bad = GOOD.replace(r#""direction": [0, -1, -1]"#, r#""direction": [0, -1, -1], "radius": 2"#);
        let e = parse(&bad).unwrap_err().to_string();
        assert!(e.contains("lights[0]: a directional light has no `radius`"), "{e}");
        let bad = GOOD.replace(r#""size": [64, 32]"#, r#""size": [64, "y"]"#);
        let e = parse(&bad).unwrap_err().to_string();
        assert!(e.contains("gbuffer.procedural.size[1]: invalid type"), "{e}");
        let e = parse("{").unwrap_err().to_string();
        assert!(e.contains("t.json") && e.contains("EOF"), "{e}");
    }

    #[test]
    fn the_name_must_be_a_plain_file_name() {
        let named = |n: &str| GOOD.replacen('{', &format!("{{\"name\": {n},"), 1);
        for (json, shown, why) in [
            (r#""../../escape""#, r#""../../escape""#, "path separator"),
            (r#""/tmp/abs""#, r#""/tmp/abs""#, "path separator"),
            (r#""a\\b""#, r#""a\\b""#, "path separator"),
            (r#""""#, r#""""#, "empty"),
            (r#"".""#, r#"".""#, "name directories"),
            (r#""..""#, r#""..""#, "name directories"),
            (r#""a\u0000b""#, r#""a\0b""#, "NUL"),
        ] {
            let e = parse(&named(json)).unwrap_err().to_string();
            assert!(
                e.starts_with(&format!("t.json: name: {shown} is not a plain file name")) && e.contains(why),
                "{json}: {e}"
            );
        }
        assert_eq!(parse(&named(r#""my scene""#)).unwrap().name(), "my scene");
        assert_eq!(parse(GOOD).unwrap().name(), "t", "default: the file stem");
    }
}
