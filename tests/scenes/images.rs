//! A G-buffer loaded from image files returns the values written, within each encoding's quantisation:
//! normals in 8-bit PNG (n = 2c - 1, step 2/255), 16-bit PNG (step 2/65535) and EXR (f32, exact); roughness
//! in 16-bit PNG; base colour in sRGB-encoded 8-bit PNG; metallic in 8-bit PNG; depth in EXR (positions then
//! follow from the camera) and in 16-bit PNG with a depth range; material indices in an 8-bit PNG (255 =
//! background). A missing image names the file.

use brdfprof::scene::Scene;
use brdfprof::scene::gbuffer::{self, BACKGROUND, srgb_to_linear};
use image::{ImageBuffer, Luma, Rgb};
use rand::{Rng, SeedableRng};
use std::path::Path;

const W: u32 = 37;
const H: u32 = 23;

struct Truth {
    normal: Vec<[f32; 3]>,
    roughness: Vec<f32>,
    base_code: Vec<[u8; 3]>,
    metallic_code: Vec<u8>,
    depth: Vec<f32>,
    material: Vec<u8>,
}

fn truth() -> Truth {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(3);
    let n = (W * H) as usize;
    let normal = (0..n)
        .map(|_| {
            loop {
                let v: [f32; 3] =
                    [rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0)];
                let l = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
                if l > 0.2 && l <= 1.0 {
                    break v.map(|x| x / l);
                }
            }
        })
        .collect();
    Truth {
        normal,
        roughness: (0..n).map(|_| rng.random()).collect(),
        base_code: (0..n).map(|_| [rng.random(), rng.random(), rng.random()]).collect(),
        metallic_code: (0..n).map(|_| rng.random()).collect(),
        depth: (0..n).map(|_| rng.random_range(0.5..50.0)).collect(),
        material: (0..n).map(|i| if i % 17 == 0 { 255 } else { rng.random_range(0..3) }).collect(),
    }
}

fn write_planes(dir: &Path, t: &Truth) {
    let enc = |x: f32, max: f32| (((x + 1.0) * 0.5) * max).round();
    ImageBuffer::<Rgb<u8>, _>::from_raw(
        W,
        H,
        t.normal.iter().flat_map(|n| n.map(|x| enc(x, 255.0) as u8)).collect::<Vec<_>>(),
    )
    .unwrap()
    .save(dir.join("n8.png"))
    .unwrap();
    ImageBuffer::<Rgb<u16>, _>::from_raw(
        W,
        H,
        t.normal.iter().flat_map(|n| n.map(|x| enc(x, 65535.0) as u16)).collect::<Vec<_>>(),
    )
    .unwrap()
    .save(dir.join("n16.png"))
    .unwrap();
    ImageBuffer::<Rgb<f32>, _>::from_raw(W, H, t.normal.iter().flat_map(|n| *n).collect::<Vec<_>>())
        .unwrap()
        .save(dir.join("n.exr"))
        .unwrap();
    ImageBuffer::<Luma<u16>, _>::from_raw(
        W,
        H,
        t.roughness.iter().map(|r| (r * 65535.0).round() as u16).collect::<Vec<_>>(),
    )
    .unwrap()
    .save(dir.join("r16.png"))
    .unwrap();
    ImageBuffer::<Rgb<u8>, _>::from_raw(W, H, t.base_code.iter().flatten().copied().collect::<Vec<_>>())
        .unwrap()
        .save(dir.join("base.png"))
        .unwrap();
    ImageBuffer::<Luma<u8>, _>::from_raw(W, H, t.metallic_code.clone()).unwrap().save(dir.join("metal.png")).unwrap();
    ImageBuffer::<Rgb<f32>, _>::from_raw(W, H, t.depth.iter().flat_map(|d| [*d, 0.0, 0.0]).collect::<Vec<_>>())
        .unwrap()
        .save(dir.join("depth.exr"))
        .unwrap();
    ImageBuffer::<Luma<u16>, _>::from_raw(
        W,
        H,
        t.depth.iter().map(|d| ((d - 0.5) / 49.5 * 65535.0).round() as u16).collect::<Vec<_>>(),
    )
    .unwrap()
    .save(dir.join("depth16.png"))
    .unwrap();
    ImageBuffer::<Luma<u8>, _>::from_raw(W, H, t.material.clone()).unwrap().save(dir.join("mat.png")).unwrap();
}

fn scene_json(normal: &str, depth: &str) -> String {
    format!(
        r#"{{"gbuffer": {{"images": {{"normal": "{normal}", "roughness": "r16.png", "base_colour": "base.png", "metallic": "metal.png",
              {depth}, "material": "mat.png"}}}},
            "camera": {{"position": [1, 2, 3], "look_at": [0, 0, -5], "fov_y_deg": 50}},
            "lights": [{{"type": "directional", "direction": [0, -1, 0]}}],
            "materials": [{{"name": "a", "model": "ggx"}}, {{"name": "b", "model": "blinn"}}, {{"name": "c", "model": "burley"}}]}}"#
    )
}

#[test]
fn image_gbuffers_round_trip_within_quantisation() {
    let dir = tempfile::tempdir().unwrap();
    let t = truth();
    write_planes(dir.path(), &t);
    let cases = [("n8.png", 1.0 / 255.0), ("n16.png", 1.0 / 65535.0), ("n.exr", 1e-7)];
    for (normal, step) in cases {
        for depth in [r#""depth": "depth.exr""#, r#""depth": "depth16.png", "depth_range": [0.5, 50]"#] {
            let path = dir.path().join("scene.json");
            std::fs::write(&path, scene_json(normal, depth)).unwrap();
            let scene = Scene::load(&path).unwrap();
            let g = gbuffer::build(&scene).unwrap();
            assert_eq!((g.width, g.height), (W, H));
            let rays = gbuffer::Rays::new(&g.camera, W, H);
            let (mut worst_n, mut worst_p) = (0f32, 0f32);
            for (i, p) in g.pixels.iter().enumerate() {
                // Positions: camera + ray * depth, for background pixels too.
                let dir_i = rays.dir(i as u32 % W, i as u32 / W);
                let d_step = if depth.contains("png") { 49.5 / 65535.0 } else { 0.0 };
                for c in 0..3 {
                    let expected = g.camera.position[c] + dir_i[c] * t.depth[i];
                    let err = (p.position[c] - expected).abs() - dir_i[c].abs() * d_step * 0.5;
                    worst_p = worst_p.max(err / expected.abs().max(1.0));
                }
                if t.material[i] == 255 {
                    assert_eq!(p.material, BACKGROUND);
                    continue;
                }
                assert_eq!(p.material, t.material[i] as u32);
                // Quantisation moves each component by at most one step (2c - 1 doubles half a step), and
                // renormalising a vector of length 1 +- 2 steps moves it by about as much again.
                for c in 0..3 {
                    worst_n = worst_n.max((p.normal[c] - t.normal[i][c]).abs() / step);
                }
                assert!(
                    (p.roughness - t.roughness[i]).abs() <= 0.5 / 65535.0 + 1e-6,
                    "roughness {} vs {}",
                    p.roughness,
                    t.roughness[i]
                );
                assert!((p.metallic - t.metallic_code[i] as f32 / 255.0).abs() <= 1e-6);
                for c in 0..3 {
                    let code = t.base_code[i][c] as f32 / 255.0;
                    assert!(
                        (p.base_colour[c] - srgb_to_linear(code)).abs() <= 1e-6,
                        "base colour {c}: {} vs {}",
                        p.base_colour[c],
                        srgb_to_linear(code)
                    );
                }
            }
            println!(
                "{normal} / {depth}: normal error {worst_n:.2} steps; position error (beyond depth quantisation) {worst_p:.1e} relative"
            );
            assert!(worst_n <= 3.0, "{normal}: normals off by {worst_n} quantisation steps");
            assert!(worst_p <= 1e-5, "{normal} {depth}: positions off by {worst_p}");
        }
    }
}

#[test]
fn a_missing_image_names_the_file() {
    let dir = tempfile::tempdir().unwrap();
    let t = truth();
    write_planes(dir.path(), &t);
    std::fs::remove_file(dir.path().join("metal.png")).unwrap();
    let path = dir.path().join("scene.json");
    std::fs::write(&path, scene_json("n8.png", r#""depth": "depth.exr""#)).unwrap();
    let scene = Scene::load(&path).unwrap();
    let e = gbuffer::build(&scene).unwrap_err().to_string();
    assert!(e.contains(&dir.path().join("metal.png").display().to_string()), "{e}");
    // A PNG depth without a range, and a size mismatch, are errors naming the file too.
    std::fs::write(
        &path,
        scene_json("n8.png", r#""depth": "depth16.png""#).replace(r#", "metallic": "metal.png""#, ""),
    )
    .unwrap();
    let e = gbuffer::build(&Scene::load(&path).unwrap()).unwrap_err().to_string();
    assert!(e.contains("depth16.png") && e.contains("depth_range"), "{e}");
    ImageBuffer::<Luma<u8>, _>::from_raw(3, 3, vec![0u8; 9]).unwrap().save(dir.path().join("mat.png")).unwrap();
    std::fs::write(&path, scene_json("n8.png", r#""depth": "depth.exr""#).replace(r#", "metallic": "metal.png""#, ""))
        .unwrap();
    let e = gbuffer::build(&Scene::load(&path).unwrap()).unwrap_err().to_string();
    assert!(e.contains("mat.png is 3x3"), "{e}");
}
