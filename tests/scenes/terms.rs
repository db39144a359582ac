//! Every GLSL term of glsl/scene.glsl against its f64 twin in src/scene/terms.rs, term by term (the per-term
//! kernel glsl/scene_terms.comp): random well-conditioned inputs (cosines >= 0.05, alphas >= 0.04); relative
//! error <= 1e-3 in fp32 (relative to max(|ref|, 1e-3)).

use crate::common;
use brdfprof::brdf::ModelSpec;
use brdfprof::brdf::guards::safe_normalize;
use brdfprof::scene::effects::{self, TERM_IN};
use brdfprof::scene::terms::{self, ETable};
use common::Worst;
use glam::DVec3;
use rand::{Rng, SeedableRng};

type V3 = DVec3;

fn unit(rng: &mut impl Rng) -> V3 {
    loop {
        let v = DVec3::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0));
        let l = v.length_squared();
        if l > 1e-3 && l <= 1.0 {
            return safe_normalize(v);
        }
    }
}

/// N = +z rotated at random: V, L with NoV, NoL >= 0.05, T orthogonal to N.
fn frame(rng: &mut impl Rng) -> (V3, V3, V3, V3) {
    loop {
        let (n, v, l) = (unit(rng), unit(rng), unit(rng));
        if n.dot(v) >= 0.05 && n.dot(l) >= 0.05 && v.dot(l) > -0.9 {
            let t = safe_normalize(n.cross(unit(rng)));
            return (n, v, l, t);
        }
    }
}

struct Input {
    raw: [f32; TERM_IN],
}

fn f(x: [f32; TERM_IN], k: usize) -> f64 {
    x[k] as f64
}
fn v3(x: [f32; TERM_IN], k: usize) -> V3 {
    DVec3::new(x[k] as f64, x[k + 1] as f64, x[k + 2] as f64)
}

#[test]
fn every_scene_term_matches_its_f64_twin() {
    let gpu = common::gpu();
    let mut rng = rand_pcg::Pcg64::seed_from_u64(7);
    let table = ETable { mu_nodes: 32, r_nodes: 16, values: (0..512).map(|_| rng.random_range(0.3..1.0)).collect() };
    let inputs: Vec<Input> = (0..20_000)
        .map(|_| {
            let (n, v, l, t) = frame(&mut rng);
            let b = n.cross(t);
            let h = safe_normalize(v + l);
            let (at, ab) = (rng.random_range(0.04..1.0), rng.random_range(0.04..1.0));
            let (inner, outer) = (rng.random_range(0.0..40.0), rng.random_range(40.0..80.0));
            let (scale, offset) = terms::spot_scale_offset(inner, outer);
            let radius = rng.random_range(0.01..1.0);
            let d = rng.random_range(radius..10.0);
            let lc = unit(&mut rng) * rng.random_range(0.5..5.0);
            let r = unit(&mut rng);
            let a = rng.random_range(0.04..1.0);
            let x = |v: f64| v as f32;
            let raw: Vec<f32> = [
                [n.dot(h), t.dot(h), b.dot(h), at],
                [ab, t.dot(v), b.dot(v), n.dot(v)],
                [t.dot(l), b.dot(l), n.dot(l), l.dot(h)],
                [rng.random_range(0.2..1.0), rng.random(), rng.random_range(-1.0..1.0), scale],
                [offset, radius, d, a],
                [rng.random(), rng.random(), rng.random(), rng.random_range(0.3..1.0)],
                [lc.x, lc.y, lc.z, rng.random_range(0.0..20.0)],
                [r.x, r.y, r.z, 0.0],
                [rng.random(), rng.random(), 0.0, 0.0],
                [n.x, n.y, n.z, rng.random_range(-0.9..0.9)],
                [v.x, v.y, v.z, rng.random_range(0.2..1.0)],
                [l.x, l.y, l.z, 0.0],
                [t.x, t.y, t.z, 0.0],
            ]
            .iter()
            .flatten()
            .map(|&y| x(y))
            .collect();
            Input { raw: raw.try_into().unwrap() }
        })
        .collect();
    let spec = ModelSpec::preset("ggx").unwrap();
    let raw: Vec<[f32; TERM_IN]> = inputs.iter().map(|i| i.raw).collect();
    let out = effects::scene_terms(&gpu, &common::model(spec), &table, &raw).unwrap();
    let names = [
        "D_GgxAnisotropic",
        "Vis_SmithGgxCorrelatedAnisotropic",
        "Fd_Lambert",
        "Fd_Burley",
        "clear_coat_fresnel",
        "clear_coat_lobe",
        "spot_cone",
        "sphere_normalisation",
        "energy_compensation.r",
        "energy_compensation.g",
        "energy_compensation.b",
        "inverse_square",
        "sphere_representative_point.x",
        "sphere_representative_point.y",
        "sphere_representative_point.z",
        "e_lookup",
        "specular_anisotropic.r",
        "specular_anisotropic.g",
        "specular_anisotropic.b",
        "-",
        "anisotropic_alphas.at",
        "anisotropic_alphas.ab",
        "-",
        "-",
    ];
    let mut worst: Vec<Worst> = vec![Worst::default(); 24];
    for (x, o) in raw.iter().zip(&out) {
        let x = *x;
        let (n, v, l, t) = (v3(x, 36), v3(x, 40), v3(x, 44), v3(x, 48));
        let rep = terms::sphere_representative_point(v3(x, 24), v3(x, 28), f(x, 17));
        let e = terms::energy_compensation(v3(x, 20), f(x, 23));
        let spa = terms::specular_anisotropic(&spec, n, v, l, t, n.cross(t), f(x, 12), f(x, 39), v3(x, 20));
        let (at, ab) = terms::anisotropic_alphas(f(x, 19), f(x, 39), spec.min_roughness());
        let reference = [
            terms::d_ggx_anisotropic(f(x, 0), f(x, 1), f(x, 2), f(x, 3), f(x, 4)),
            terms::vis_smith_ggx_correlated_anisotropic(
                f(x, 5),
                f(x, 6),
                f(x, 7),
                f(x, 8),
                f(x, 9),
                f(x, 10),
                f(x, 3),
                f(x, 4),
            ),
            terms::fd_lambert(),
            terms::fd_burley(f(x, 7), f(x, 10), f(x, 11), f(x, 12)),
            terms::clear_coat_fresnel(f(x, 11), f(x, 13)),
            terms::clear_coat_lobe(n, v, l, f(x, 43), f(x, 13), spec.min_roughness()),
            terms::spot_cone(f(x, 14), f(x, 15), f(x, 16)),
            terms::sphere_normalisation(f(x, 19), f(x, 17), f(x, 18)),
            e[0],
            e[1],
            e[2],
            terms::inverse_square(f(x, 27)),
            rep[0],
            rep[1],
            rep[2],
            table.lookup(f(x, 32), f(x, 33)),
            spa[0],
            spa[1],
            spa[2],
            0.0,
            at,
            ab,
            0.0,
            0.0,
        ];
        for k in 0..24 {
            let err = common::rel_err(o[k] as f64, reference[k]);
            worst[k].update(err, || format!("gpu {} f64 {} at {x:?}", o[k], reference[k]));
        }
    }
    let mut failures = Vec::new();
    for (k, w) in worst.iter().enumerate().filter(|(k, _)| names[*k] != "-") {
        println!("{:36} max rel err {:.2e}", names[k], w.err);
        if w.err > 1e-3 {
            failures.push(format!("{}: {:.3e} at {}", names[k], w.err, w.what));
        }
    }
    assert!(failures.is_empty(), "scene terms off their twins:\n{}", failures.join("\n"));
    common::assert_no_validation_messages(&gpu);
}
