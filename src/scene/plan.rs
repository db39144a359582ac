//! Specialisation: what a scene compiles in. One kernel per model that covers at least one pixel; in it every
//! light type's count (the constants `NUM_DIRECTIONAL`..`NUM_SPHERE` of `kernels::constants`, ids there only; a
//! type with count 0 has no loop) and each effect only when a material of that model uses it (`ANISOTROPY`,
//! `ENERGY_COMPENSATION`, `DIFFUSE`, `CLEAR_COAT`). The plan also packs the lights and each kernel's pixels.

use super::format::{Light, Scene};
use super::gbuffer::{BACKGROUND, GBuffer};
use super::terms::{self, KernelLight, Switches};
use crate::gpu::{DeviceInfo, SpecConstants};
use crate::kernels::WithConstant;
use crate::kernels::constants::{self as k, Constant};
use crate::model::Model;
use anyhow::Result;
use glam::DVec3;
use serde::Serialize;

/// The E(mu, r) table's size: mu nodes x r nodes.
pub const E_TABLE_MU: usize = 32;
pub const E_TABLE_R: usize = 16;

/// Floats per light in the light buffer (3 vec4).
pub const LIGHT_FLOATS: usize = 12;

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct LightCounts {
    pub directional: u32,
    pub point: u32,
    pub spot: u32,
    pub sphere: u32,
}

impl LightCounts {
    pub fn total(&self) -> u32 {
        self.directional + self.point + self.spot + self.sphere
    }
}

/// An effect a kernel can compile in, for reports and for toggling it off.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub enum Effect {
    Anisotropy,
    EnergyCompensation,
    Diffuse,
    ClearCoat,
}

impl Effect {
    pub const ALL: [Effect; 4] = [Effect::Anisotropy, Effect::EnergyCompensation, Effect::Diffuse, Effect::ClearCoat];
    pub fn name(self) -> &'static str {
        match self {
            Effect::Anisotropy => "anisotropy",
            Effect::EnergyCompensation => "energy-compensation",
            Effect::Diffuse => "diffuse",
            Effect::ClearCoat => "clear-coat",
        }
    }
    pub fn is_on(self, s: &Switches) -> bool {
        match self {
            Effect::Anisotropy => s.anisotropy,
            Effect::EnergyCompensation => s.energy != 0,
            Effect::Diffuse => s.diffuse != 0,
            Effect::ClearCoat => s.clear_coat,
        }
    }
    /// The switches with this effect compiled out.
    pub fn off(self, s: Switches) -> Switches {
        match self {
            Effect::Anisotropy => Switches { anisotropy: false, ..s },
            Effect::EnergyCompensation => Switches { energy: 0, ..s },
            Effect::Diffuse => Switches { diffuse: 0, ..s },
            Effect::ClearCoat => Switches { clear_coat: false, ..s },
        }
    }
}

/// One kernel of the scene: a model and the pixels whose material uses it.
#[derive(Clone, Debug)]
pub struct KernelPlan {
    pub model: Model,
    /// Indices of the scene materials shaded by this kernel (those covering at least one pixel).
    pub materials: Vec<usize>,
    /// G-buffer indices of its pixels.
    pub pixels: Vec<u32>,
    pub switches: Switches,
}

#[derive(Clone, Debug)]
pub struct ScenePlan {
    pub kernels: Vec<KernelPlan>,
    pub counts: LightCounts,
    /// LIGHT_FLOATS per light, directional first, then point, spot, sphere (glsl/scene.comp).
    pub light_data: Vec<f32>,
    /// The same lights for the f64 twin, in the same order.
    pub lights: Vec<KernelLight>,
    /// Per material: the anisotropy the kernel applies (0 where the model in force cannot take it).
    pub anisotropy: Vec<f32>,
    /// Things changed to fit a model override (e.g. anisotropy dropped for a non-GGX model).
    pub notes: Vec<String>,
}

fn unit3(v: [f32; 3]) -> [f32; 3] {
    glam::Vec3::from(v).normalize().to_array()
}

/// Packs the lights in kernel order and counts them per type.
pub fn pack_lights(lights: &[Light]) -> (LightCounts, Vec<f32>, Vec<KernelLight>) {
    let mut counts = LightCounts::default();
    let mut data = Vec::new();
    let mut twins = Vec::new();
    let f64s = |v: [f32; 3]| DVec3::from(v.map(f64::from));
    for kind in ["directional", "point", "spot", "sphere"] {
        for l in lights.iter().filter(|l| l.type_name() == kind) {
            let rgb = |c: [f32; 3], i: f32| c.map(|x| x * i);
            let (v, twin) = match *l {
                Light::Directional { direction, colour, intensity } => {
                    counts.directional += 1;
                    let (d, c) = (unit3(direction), rgb(colour, intensity));
                    (
                        [d[0], d[1], d[2], 0.0, c[0], c[1], c[2], 0.0, 0.0, 0.0, 0.0, 0.0],
                        KernelLight::Directional { direction: f64s(d), radiance: f64s(c) },
                    )
                }
                Light::Point { position: p, colour, intensity } => {
                    counts.point += 1;
                    let c = rgb(colour, intensity);
                    (
                        [p[0], p[1], p[2], 0.0, c[0], c[1], c[2], 0.0, 0.0, 0.0, 0.0, 0.0],
                        KernelLight::Point { position: f64s(p), intensity: f64s(c) },
                    )
                }
                Light::Spot { position: p, direction, inner_angle_deg, outer_angle_deg, colour, intensity } => {
                    counts.spot += 1;
                    let (a, c) = (unit3(direction), rgb(colour, intensity));
                    let (scale, offset) = terms::spot_scale_offset(inner_angle_deg as f64, outer_angle_deg as f64);
                    let (scale, offset) = (scale as f32, offset as f32);
                    (
                        [p[0], p[1], p[2], offset, c[0], c[1], c[2], 0.0, a[0], a[1], a[2], scale],
                        KernelLight::Spot {
                            position: f64s(p),
                            intensity: f64s(c),
                            axis: f64s(a),
                            scale: scale as f64,
                            offset: offset as f64,
                        },
                    )
                }
                Light::Sphere { position: p, radius, colour, intensity } => {
                    counts.sphere += 1;
                    let c = rgb(colour, intensity);
                    (
                        [p[0], p[1], p[2], radius, c[0], c[1], c[2], 0.0, 0.0, 0.0, 0.0, 0.0],
                        KernelLight::Sphere { position: f64s(p), radius: radius as f64, intensity: f64s(c) },
                    )
                }
            };
            data.extend_from_slice(&v);
            twins.push(twin);
        }
    }
    (counts, data, twins)
}

/// The plan for `scene` over `gbuffer`; `model` replaces every material's model (for `render`'s comparison).
pub fn plan(scene: &Scene, gbuffer: &GBuffer, model: Option<&Model>) -> ScenePlan {
    let mats = &scene.file.materials;
    let mut notes = Vec::new();
    let specs: Vec<Model> = mats.iter().map(|m| model.cloned().unwrap_or_else(|| m.model())).collect();
    let anisotropy: Vec<f32> = mats
        .iter()
        .zip(&specs)
        .map(|(m, s)| {
            let a = m.effects.anisotropy.0;
            if a != 0.0 && !s.takes_anisotropy() {
                notes.push(format!("material `{}`: anisotropy needs d=ggx, so it is off under {}", m.name, s.name()));
                0.0
            } else {
                a
            }
        })
        .collect();
    let mut used = vec![false; mats.len()];
    for p in &gbuffer.pixels {
        if p.material != BACKGROUND {
            used[p.material as usize] = true;
        }
    }
    let mut kernels: Vec<KernelPlan> = Vec::new();
    let mut kernel_of = vec![usize::MAX; mats.len()];
    for (i, spec) in specs.iter().enumerate().filter(|(i, _)| used[*i]) {
        let k = match kernels.iter().position(|k| k.model == *spec) {
            Some(k) => k,
            None => {
                kernels.push(KernelPlan {
                    model: spec.clone(),
                    materials: Vec::new(),
                    pixels: Vec::new(),
                    switches: Switches::default(),
                });
                kernels.len() - 1
            }
        };
        kernels[k].materials.push(i);
        kernel_of[i] = k;
    }
    for (i, p) in gbuffer.pixels.iter().enumerate() {
        if p.material != BACKGROUND {
            kernels[kernel_of[p.material as usize]].pixels.push(i as u32);
        }
    }
    for k in &mut kernels {
        let ms: Vec<_> = k.materials.iter().map(|&i| &mats[i]).collect();
        let energy = ms.iter().filter(|m| m.effects.energy_compensation).count();
        let mut lobes: Vec<_> = ms.iter().map(|m| m.effects.diffuse).collect();
        lobes.sort();
        lobes.dedup();
        k.switches = Switches {
            anisotropy: k.materials.iter().any(|&i| anisotropy[i] != 0.0),
            energy: if energy == 0 {
                0
            } else if energy == ms.len() {
                1
            } else {
                2
            },
            diffuse: if lobes.len() == 1 { lobes[0].id() } else { 3 },
            clear_coat: ms.iter().any(|m| m.effects.clear_coat.is_some_and(|c| c.strength.0 > 0.0)),
        };
    }
    let (counts, light_data, lights) = pack_lights(&scene.file.lights);
    ScenePlan { kernels, counts, light_data, lights, anisotropy, notes }
}

/// The effect switches as specialisation constants (scene.glsl), with the E table's size.
pub fn effect_constants(c: SpecConstants, switches: Switches) -> SpecConstants {
    let set: [(Constant, f64); 6] = [
        (k::ANISOTROPY, switches.anisotropy as i32 as f64),
        (k::ENERGY_COMPENSATION, switches.energy as f64),
        (k::DIFFUSE, switches.diffuse as f64),
        (k::CLEAR_COAT, switches.clear_coat as i32 as f64),
        (k::E_TABLE_MU, E_TABLE_MU as f64),
        (k::E_TABLE_R, E_TABLE_R as f64),
    ];
    set.into_iter().fold(c, |c, (k, v)| c.with(k, v))
}

impl ScenePlan {
    /// The light counts and effect switches of kernel `kernels[k]` compiled with `switches`, on top of the
    /// model's own constants `model`.
    pub fn constants(&self, model: SpecConstants, switches: Switches) -> SpecConstants {
        let c = &self.counts;
        let lights = [
            (k::NUM_DIRECTIONAL, c.directional),
            (k::NUM_POINT, c.point),
            (k::NUM_SPOT, c.spot),
            (k::NUM_SPHERE, c.sphere),
        ];
        effect_constants(lights.into_iter().fold(model, |m, (k, n)| m.with(k, n as f64)), switches)
    }

    /// Per-pixel extras of kernel `k`: (tangent, anisotropy), (coat, coat roughness, diffuse id, energy flag).
    pub fn extras(&self, scene: &Scene, gbuffer: &GBuffer, k: usize) -> Vec<f32> {
        let mats = &scene.file.materials;
        self.kernels[k]
            .pixels
            .iter()
            .flat_map(|&i| {
                let p = &gbuffer.pixels[i as usize];
                let m = &mats[p.material as usize];
                let (coat, coat_r) = m.effects.clear_coat.map_or((0.0, 1.0), |c| (c.strength.0, c.roughness.0));
                let t = p.tangent;
                [
                    t[0],
                    t[1],
                    t[2],
                    self.anisotropy[p.material as usize],
                    coat,
                    coat_r,
                    m.effects.diffuse.id() as f32,
                    m.effects.energy_compensation as i32 as f32,
                ]
            })
            .collect()
    }

    /// Fails with a clear reason when the device cannot run a kernel of this plan.
    pub fn check_device(&self, info: &DeviceInfo) -> Result<()> {
        self.kernels.iter().try_for_each(|k| k.model.check_support(info))
    }

    /// What is compiled in, one line per kernel.
    pub fn describe(&self, scene: &Scene) -> Vec<String> {
        let c = &self.counts;
        self.kernels
            .iter()
            .map(|k| {
                let mats: Vec<&str> = k.materials.iter().map(|&i| scene.file.materials[i].name.as_str()).collect();
                let effects: Vec<String> = Effect::ALL
                    .iter()
                    .filter(|e| e.is_on(&k.switches))
                    .map(|e| match e {
                        Effect::EnergyCompensation if k.switches.energy == 2 => {
                            "energy-compensation (per pixel)".to_string()
                        }
                        Effect::Diffuse => format!(
                            "diffuse ({})",
                            ["none", "lambert", "burley", "per pixel"][k.switches.diffuse as usize]
                        ),
                        e => e.name().to_string(),
                    })
                    .collect();
                format!(
                    "{}: {} pixels of [{}]; lights {} directional, {} point, {} spot, {} sphere; effects: {}",
                    k.model.name(),
                    k.pixels.len(),
                    mats.join(", "),
                    c.directional,
                    c.point,
                    c.spot,
                    c.sphere,
                    if effects.is_empty() { "none".to_string() } else { effects.join(", ") }
                )
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scene::{Scene, gbuffer};

    #[test]
    fn fp16_without_shader_float16_is_a_clear_error() {
        let text = r#"{"gbuffer": {"procedural": {"kind": "sphere-grid", "size": [16, 8], "rows": ["a"], "floor": "a"}},
            "lights": [], "materials": [{"name": "a", "model": "ggx,precision=f16"}]}"#;
        let s = Scene::parse(text, "t", Default::default(), "t.json".into()).unwrap();
        let g = gbuffer::build(&s).unwrap();
        let p = plan(&s, &g, None);
        let mut info = crate::gpu::DeviceInfo {
            index: 0,
            name: "no-fp16 device".into(),
            device_type: "cpu".into(),
            vendor_id: 0,
            device_id: 0,
            driver_name: String::new(),
            driver_info: String::new(),
            driver_version: String::new(),
            api_version: String::new(),
            timestamp_period: 1.0,
            timestamp_valid_bits: 64,
            max_storage_buffer_range: 1 << 27,
            max_texel_buffer_elements: 1 << 27,
            max_compute_work_group_count: [65535; 3],
            max_compute_work_group_invocations: 256,
            min_storage_buffer_offset_alignment: 16,
            max_memory_allocation_size: 1 << 30,
            shader_float16: false,
            shader_float64: false,
            pipeline_executable_properties: false,
        };
        let e = p.check_device(&info).unwrap_err().to_string();
        assert!(e.contains("fp16") && e.contains("shaderFloat16") && e.contains("no-fp16 device"), "{e}");
        info.shader_float16 = true;
        p.check_device(&info).unwrap();
    }

    #[test]
    fn effects_follow_the_materials_of_each_model() {
        let text = r#"{"gbuffer": {"procedural": {"kind": "sphere-grid", "size": [64, 24], "rows": ["a", "b", "c"], "floor": "d"}},
            "lights": [{"type": "point", "position": [0, 0, 3]}, {"type": "directional", "direction": [0, 0, -1]}],
            "materials": [
              {"name": "a", "model": "ggx", "effects": {"diffuse": "lambert", "energy_compensation": true}},
              {"name": "b", "model": "ggx", "effects": {"diffuse": "lambert"}},
              {"name": "c", "model": "blinn", "effects": {"clear_coat": {}}},
              {"name": "d", "model": "burley"},
              {"name": "unused", "model": "ggx", "effects": {"anisotropy": 0.5}}]}"#;
        let s = Scene::parse(text, "t", Default::default(), "t.json".into()).unwrap();
        let g = gbuffer::build(&s).unwrap();
        let p = plan(&s, &g, None);
        let names: Vec<String> = p.kernels.iter().map(|k| k.model.name()).collect();
        assert_eq!(
            names,
            ["ggx", "blinn", "burley"],
            "one kernel per model covering pixels; the unused material adds none"
        );
        assert_eq!(p.kernels[0].switches, Switches { anisotropy: false, energy: 2, diffuse: 1, clear_coat: false });
        assert_eq!(p.kernels[1].switches, Switches { clear_coat: true, ..Default::default() });
        assert_eq!(p.kernels[2].switches, Switches::default());
        assert_eq!((p.counts.directional, p.counts.point), (1, 1));
        assert_eq!(&p.light_data[..3], &[0.0, 0.0, -1.0], "directional lights come first");
    }
}
