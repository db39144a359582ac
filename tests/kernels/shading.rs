//! The profile's shading kernel computes what it claims: over the packed G-buffer (texel views, R11G11B10F
//! out) and the float one, lit in one block and in several (accumulating, the last block partial), each
//! pixel's radiance sum_j f_s(n, v, l_j) NoL_j colour_j matches the f64 twin of the values that layout
//! stores, and the two layouts give the same picture within what the packing quantises.

use crate::common;
use brdfprof::brdf::THESIS_MODELS;
use brdfprof::measure::gbuffer::{self, Camera, GBufferFormat, LIGHT_FLOATS, R11G11B10_REL_ERROR, Surface};
use brdfprof::measure::protocol::Timed;
use brdfprof::measure::workload::{Variant, Workload, light_blocks};
use brdfprof::model::Model;
use glam::DVec3;

const W: u32 = 96;
const H: u32 = 64;

/// The f64 radiance of one pixel (glsl/shade.glsl's sum, the BRDF by the model's twin).
fn twin_radiance(model: &Model, s: &Surface, lights: &[f32]) -> [f64; 3] {
    let spec = model.twin().expect("built-in models have twins");
    let n = s.normal.as_dvec3().normalize();
    let v = s.view.as_dvec3().normalize();
    let base = s.base.as_dvec3();
    let f0 = DVec3::splat(0.04).lerp(base, f64::from(s.metallic));
    let mut sum = DVec3::ZERO;
    for light in lights.chunks_exact(LIGHT_FLOATS) {
        let l = DVec3::new(light[0].into(), light[1].into(), light[2].into());
        let colour = DVec3::new(light[4].into(), light[5].into(), light[6].into());
        let fs = DVec3::from(spec.eval_f64(n, v, l, f64::from(s.roughness), f0.into()));
        sum += fs * n.dot(l).max(0.0) * colour;
    }
    sum.into()
}

/// The picture the kernel of `model` shades over `format`.
fn shade(gpu: &brdfprof::gpu::Gpu, model: &Model, format: GBufferFormat, lights: &[f32]) -> Vec<[f32; 3]> {
    let work = Workload::upload(gpu, &gbuffer::synthetic(W, H, format), lights, None).unwrap();
    let variant = Variant::new(gpu, &work, Some(model), brdfprof::kernels::embedded(), 1).unwrap();
    gpu.submit(|cmd| variant.record(cmd, 0)).unwrap();
    work.radiance().unwrap()
}

#[test]
fn both_gbuffer_layouts_shade_their_values_and_agree_within_the_packing() {
    let gpu = common::gpu();
    let camera = Camera::new(W, H);
    for light_count in [8, 21] {
        assert_eq!(
            light_blocks(light_count).len() > 1,
            light_count > 8,
            "21 lights take three blocks, the last partial"
        );
        let lights = gbuffer::lights(light_count);
        let blocks = light_blocks(light_count).len() as f64;
        for name in THESIS_MODELS {
            let model = Model::parse(name).unwrap();
            let packed = shade(&gpu, &model, GBufferFormat::Packed, &lights);
            let float = shade(&gpu, &model, GBufferFormat::Float, &lights);
            let packed_words = gbuffer::synthetic(W, H, GBufferFormat::Packed).words;
            let (mut worst_packed, mut worst_float) = (0f64, 0f64);
            let mut picture_diff = Vec::new();
            for y in 0..H {
                for x in 0..W {
                    let i = (y * W + x) as usize;
                    let exact = gbuffer::surface(&camera, W, H, x, y);
                    let stored = gbuffer::unpack(&packed_words[4 * i..4 * i + 4], &camera, x, y);
                    let want_float = twin_radiance(&model, &exact, &lights);
                    let want_packed = twin_radiance(&model, &stored, &lights);
                    // Relative to the pixel's brightest channel: a dim channel next to a bright one is judged by
                    // the bright one's precision, as the eye and the float formats do.
                    let scale = want_float.iter().chain(&want_packed).fold(1e-3f64, |a, b| a.max(b.abs()));
                    for c in 0..3 {
                        let e_float = (f64::from(float[i][c]) - want_float[c]).abs() / scale;
                        let e_packed = (f64::from(packed[i][c]) - want_packed[c]).abs() / scale;
                        worst_float = worst_float.max(e_float);
                        worst_packed = worst_packed.max(e_packed);
                        assert!(
                            e_float <= 2e-3,
                            "{name}, {light_count} lights, float, pixel ({x}, {y}) channel {c}: {} vs twin {}",
                            float[i][c],
                            want_float[c]
                        );
                        // Each block's sum is rounded to R11G11B10F once, and read back by the next.
                        let bound = f64::from(R11G11B10_REL_ERROR) * blocks + 2e-3;
                        assert!(
                            e_packed <= bound,
                            "{name}, {light_count} lights, packed, pixel ({x}, {y}) channel {c}: {} vs twin of the stored values {} (bound {bound})",
                            packed[i][c],
                            want_packed[c]
                        );
                        picture_diff.push((f64::from(packed[i][c]) - f64::from(float[i][c])).abs() / scale);
                    }
                }
            }
            picture_diff.sort_by(f64::total_cmp);
            let median = picture_diff[picture_diff.len() / 2];
            let p99 = picture_diff[picture_diff.len() * 99 / 100];
            eprintln!(
                "{name}, {light_count} lights: worst float {worst_float:.2e}, worst packed {worst_packed:.2e}; packed vs float median {median:.2e}, p99 {p99:.2e}"
            );
            // The two pictures differ by the packing: R11G11B10F rounding, 8-bit roughness and base colour,
            // 16-bit octahedral normals.
            assert!(
                median <= f64::from(R11G11B10_REL_ERROR) / 2.0 && p99 <= 0.1,
                "{name}, {light_count} lights: packed and float pictures differ by median {median}, p99 {p99}"
            );
        }
    }
    common::assert_no_validation_messages(&gpu);
}
