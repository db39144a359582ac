//! The scene kernel on lavapipe (validation layer on): through the scene path, the sphere grid lit by one
//! directional light with no effects equals `eval` of the same pixels (same N, V, L, roughness, F0) times NoL;
//! with every light type and every effect on, each pixel equals the f64 twin of the kernel (src/scene/terms.rs);
//! a G-buffer chunked into many dispatches gives the same pixels as one dispatch.

use crate::common;
use brdfprof::brdf::guards::unit;
use brdfprof::brdf::{Sample, THESIS_MODELS};
use brdfprof::kernels::{self, RunLimits};
use brdfprof::model::Model;
use brdfprof::scene::Scene;
use brdfprof::scene::gbuffer::{self, BACKGROUND};
use brdfprof::scene::plan::{self, ScenePlan};
use brdfprof::scene::run;
use brdfprof::scene::terms::{self, Surface};
use glam::DVec3;
use std::path::PathBuf;

fn scene(text: &str) -> Scene {
    Scene::parse(text, "test", PathBuf::new(), PathBuf::from("test.json")).unwrap()
}

const GRID_ONE_LIGHT: &str = r#"{
  "gbuffer": {"procedural": {"kind": "sphere-grid", "size": [96, 40], "rows": ["metal", "rubber", "black"], "columns": 8, "floor": "floor"}},
  "lights": [{"type": "directional", "direction": [0.45, -0.55, -0.7], "colour": [1.0, 0.9, 0.8], "intensity": 2.0}],
  "materials": [
    {"name": "metal", "model": "ggx", "base_colour": [0.91, 0.92, 0.92], "metallic": 1.0},
    {"name": "rubber", "model": "ggx", "base_colour": [0.55, 0.07, 0.05]},
    {"name": "black", "model": "ggx", "base_colour": [0.02, 0.02, 0.02]},
    {"name": "floor", "model": "ggx", "base_colour": [0.4, 0.4, 0.4], "roughness": 0.8}
  ]
}"#;

fn f0_of(p: &gbuffer::Pixel) -> [f32; 3] {
    // mix(vec3(0.04), base, metallic) as GLSL defines mix: x (1 - a) + y a.
    p.base_colour.map(|b| 0.04 * (1.0 - p.metallic) + b * p.metallic)
}

#[test]
fn sphere_grid_through_the_scene_path_equals_eval() {
    let gpu = common::gpu();
    let s = scene(GRID_ONE_LIGHT);
    let g = gbuffer::build(&s).unwrap();
    let cam = g.camera.position;
    let [dir] = s.file.lights[..] else { panic!() };
    let brdfprof::scene::format::Light::Directional { direction, colour, intensity } = dir else { panic!() };
    let radiance = colour.map(|c| c * intensity);
    for name in THESIS_MODELS {
        let spec = Model::parse(name).unwrap();
        let p = plan::plan(&s, &g, Some(&spec));
        assert_eq!(p.kernels.len(), 1, "one model, one kernel");
        assert_eq!(p.kernels[0].switches, Default::default(), "no effects compiled in");
        let out = run::shade(&gpu, &s, &g, &p, &[None], RunLimits::default()).unwrap();
        let shaded: Vec<usize> = (0..g.pixels.len()).filter(|&i| g.pixels[i].material != BACKGROUND).collect();
        let samples: Vec<Sample> = shaded
            .iter()
            .map(|&i| {
                let px = &g.pixels[i];
                let v = [cam[0] - px.position[0], cam[1] - px.position[1], cam[2] - px.position[2]];
                Sample { n: px.normal, v, l: direction.map(|d| -d), roughness: px.roughness, f0: f0_of(px) }
            })
            .collect();
        let fs = kernels::eval(&gpu, &spec, &samples, RunLimits::default()).unwrap();
        let scale = out.iter().flat_map(|c| c.iter().copied()).fold(0f32, f32::max) as f64;
        let mut worst = common::Worst::default();
        let mut lit = 0;
        for ((&i, s), f) in shaded.iter().zip(&samples).zip(&fs) {
            let nol = unit(s.n).dot(unit(s.l)).max(0.0);
            lit += (nol > 0.0 && f[0] > 0.0) as usize;
            for c in 0..3 {
                let expected = f[c] as f64 * nol * radiance[c] as f64;
                let got = out[i][c] as f64;
                let err = (got - expected).abs() / expected.abs().max(1e-4 * scale);
                worst.update(err, || format!("pixel {i} channel {c}: scene {got} eval x NoL {expected}"));
            }
        }
        println!("{name}: {} pixels, {lit} lit, max rel err {:.2e}", shaded.len(), worst.err);
        assert!(lit > shaded.len() / 3, "{name}: too few lit pixels ({lit})");
        assert!(worst.err < 2e-5, "{name}: scene path differs from eval: {:.3e} at {}", worst.err, worst.what);
    }
    common::assert_no_validation_messages(&gpu);
}

const EVERYTHING: &str = r#"{
  "gbuffer": {"procedural": {"kind": "statues", "size": [120, 72], "statues": ["brushed", "paint", "rough", "plain"], "floor": "floor"}},
  "lights": [
    {"type": "directional", "direction": [0.3, -1.0, -0.4], "colour": [1.0, 0.95, 0.9], "intensity": 1.5},
    {"type": "point", "position": [-3.0, 3.0, 2.0], "intensity": 8.0},
    {"type": "point", "position": [3.0, 2.0, 3.0], "colour": [0.6, 0.7, 1.0], "intensity": 6.0},
    {"type": "spot", "position": [0.0, 5.0, 3.0], "direction": [0.0, -1.0, -0.6], "inner_angle_deg": 15, "outer_angle_deg": 35, "intensity": 30.0},
    {"type": "sphere", "position": [2.0, 2.5, 1.5], "radius": 0.4, "colour": [1.0, 0.8, 0.6], "intensity": 10.0}
  ],
  "materials": [
    {"name": "brushed", "model": "ggx", "base_colour": [0.9, 0.9, 0.92], "metallic": 1.0, "roughness": 0.35,
     "effects": {"anisotropy": 0.7, "energy_compensation": true}},
    {"name": "paint", "model": "ggx", "base_colour": [0.5, 0.05, 0.05], "roughness": 0.5,
     "effects": {"diffuse": "burley", "clear_coat": {"strength": 1.0, "roughness": 0.15}}},
    {"name": "rough", "model": "ggx", "base_colour": [0.3, 0.5, 0.3], "roughness": 0.8, "effects": {"diffuse": "lambert", "energy_compensation": true}},
    {"name": "plain", "model": "burley", "base_colour": [0.95, 0.64, 0.54], "metallic": 1.0, "roughness": 0.4, "effects": {"energy_compensation": true}},
    {"name": "floor", "model": "ggx", "base_colour": [0.4, 0.4, 0.4], "roughness": 0.7, "effects": {"diffuse": "lambert"}}
  ]
}"#;

/// The f64 twin of the whole scene kernel for pixel `i` of kernel `k`.
fn twin(s: &Scene, g: &gbuffer::GBuffer, p: &ScenePlan, tables: &[Option<terms::ETable>], k: usize, i: usize) -> DVec3 {
    let kp = &p.kernels[k];
    let px = &g.pixels[i];
    let m = &s.file.materials[px.material as usize];
    let cam = g.camera.position;
    let n = unit(px.normal);
    let v = unit([cam[0] - px.position[0], cam[1] - px.position[1], cam[2] - px.position[2]]);
    let t0 = DVec3::from(px.tangent.map(f64::from));
    let t = brdfprof::brdf::guards::safe_normalize(t0 - n * n.dot(t0));
    let metallic = px.metallic as f64;
    let base = DVec3::from(px.base_colour.map(f64::from));
    let f0 = base.map(|b| 0.04 * (1.0 - metallic) + b * metallic);
    let (coat, coat_roughness) =
        m.effects.clear_coat.map_or((0.0, 1.0), |c| (c.strength.0 as f64, c.roughness.0 as f64));
    let roughness = px.roughness as f64;
    let energy_on = kp.switches.energy == 1 || (kp.switches.energy == 2 && m.effects.energy_compensation);
    let energy = match (&tables[k], energy_on) {
        (Some(table), true) => terms::energy_compensation(f0, table.lookup(n.dot(v), roughness)),
        _ => DVec3::ONE,
    };
    let surface = Surface {
        n,
        v,
        t,
        b: n.cross(t),
        roughness,
        f0,
        diffuse_colour: base * (1.0 - metallic),
        anisotropy: p.anisotropy[px.material as usize] as f64,
        coat,
        coat_roughness,
        diffuse: m.effects.diffuse.id(),
        energy,
    };
    terms::shade_pixel(
        kp.model.twin().unwrap(),
        kp.switches,
        &surface,
        DVec3::from(px.position.map(f64::from)),
        &p.lights,
    )
}

#[test]
fn scene_kernel_with_every_light_and_effect_matches_its_f64_twin() {
    let gpu = common::gpu();
    let s = scene(EVERYTHING);
    let g = gbuffer::build(&s).unwrap();
    let p = plan::plan(&s, &g, None);
    assert_eq!(p.kernels.len(), 2, "ggx and burley materials: two kernels");
    let ggx = &p.kernels[0];
    assert!(
        ggx.switches.anisotropy && ggx.switches.clear_coat && ggx.switches.energy == 2 && ggx.switches.diffuse == 3,
        "{:?}",
        ggx.switches
    );
    assert_eq!((p.counts.directional, p.counts.point, p.counts.spot, p.counts.sphere), (1, 2, 1, 1));
    let tables = run::e_tables(&gpu, &p).unwrap();
    let out = run::shade(&gpu, &s, &g, &p, &tables, RunLimits::default()).unwrap();
    let scale = out.iter().flat_map(|c| c.iter().copied()).fold(0f32, f32::max) as f64;
    for (k, kp) in p.kernels.iter().enumerate() {
        let mut worst = common::Worst::default();
        for &i in &kp.pixels {
            let r = twin(&s, &g, &p, &tables, k, i as usize);
            for c in 0..3 {
                let got = out[i as usize][c] as f64;
                let err = (got - r[c]).abs() / r[c].abs().max(1e-3 * scale);
                worst.update(err, || {
                    format!(
                        "pixel {i} ({}) channel {c}: GPU {got} f64 {}",
                        s.file.materials[g.pixels[i as usize].material as usize].name, r[c]
                    )
                });
            }
        }
        println!("{}: {} pixels, max rel err {:.2e}", kp.model.name(), kp.pixels.len(), worst.err);
        assert!(worst.err < 1e-3, "{}: {:.3e} at {}", kp.model.name(), worst.err, worst.what);
    }
    common::assert_no_validation_messages(&gpu);
}

#[test]
fn chunked_dispatches_give_the_same_pixels() {
    let gpu = common::gpu();
    let s = scene(&EVERYTHING.replace("[120, 72]", "[160, 100]"));
    let g = gbuffer::build(&s).unwrap();
    let p = plan::plan(&s, &g, None);
    let tables = run::e_tables(&gpu, &p).unwrap();
    let whole = run::shade(&gpu, &s, &g, &p, &tables, RunLimits::default()).unwrap();
    let chunked = run::shade(&gpu, &s, &g, &p, &tables, RunLimits { max_chunk: Some(2048) }).unwrap();
    let work = run::SceneWork::upload(&gpu, &s, &g, &p, &tables, RunLimits { max_chunk: Some(2048) }).unwrap();
    assert!(work.chunks(0) >= 4, "the test must chunk: {} chunks", work.chunks(0));
    assert_eq!(whole, chunked);
    common::assert_no_validation_messages(&gpu);
}
