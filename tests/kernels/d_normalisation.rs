//! Every D term, as the GPU evaluates it, integrates to 1 as projected area: integral of D(h) NoH dh = 1 within
//! 1% for r in [0.1, 1] (and its f64 twin within 1e-4). D values come from the per-term kernel at the nodes of a
//! piecewise Gauss-Legendre rule in theta_h (pieces at the lobe's scales, tan theta = a, 4a, ...).

use crate::common;
use brdfprof::kernels::{self, TermInput};
use gauss_quad::legendre::GaussLegendre;
use std::f64::consts::{FRAC_PI_2, PI};

/// (theta, weight) nodes over [0, pi/2] for the projected-area integral of a lobe of scale a.
fn nodes(a: f64) -> Vec<(f64, f64)> {
    let rule = GaussLegendre::new(64.try_into().unwrap());
    let mut breaks = vec![0.0, FRAC_PI_2];
    let mut t = a;
    while t < 1e3 {
        breaks.push(t.atan());
        t *= 4.0;
    }
    breaks.sort_by(f64::total_cmp);
    breaks
        .windows(2)
        .flat_map(|w| {
            let (half, mid) = (0.5 * (w[1] - w[0]), 0.5 * (w[1] + w[0]));
            rule.as_node_weight_pairs().iter().map(move |&(x, wt)| (mid + half * x, wt * half)).collect::<Vec<_>>()
        })
        .collect()
}

#[test]
fn every_d_integrates_to_one_as_projected_area() {
    let gpu = common::gpu();
    let mut failures = Vec::new();
    for spec in common::every_d() {
        let d = spec.d;
        for r in [0.1, 0.2, 0.35, 0.5, 0.75, 1.0] {
            let a = spec.alpha(r);
            let nodes = nodes(a);
            let inputs: Vec<TermInput> = nodes
                .iter()
                .map(|&(th, _)| TermInput {
                    nov: 1.0,
                    nol: 1.0,
                    noh: th.cos() as f32,
                    voh: 1.0,
                    sin2h: th.sin().powi(2) as f32,
                    roughness: r as f32,
                    f0: [1.0; 3],
                })
                .collect();
            let gpu_d = kernels::terms(&gpu, &common::model(spec), &inputs).unwrap();
            let (mut on_gpu, mut twin) = (0.0, 0.0);
            for (&(th, w), out) in nodes.iter().zip(&gpu_d) {
                let (s, c) = th.sin_cos();
                on_gpu += w * out.d as f64 * c * s * 2.0 * PI;
                twin += w * d.eval(c.max(1e-4), s * s, a, &spec.params) * c * s * 2.0 * PI;
            }
            println!("{:40} r {r}: GPU {on_gpu:.6} f64 {twin:.8}", spec.name());
            if (on_gpu - 1.0).abs() > 0.01 || (twin - 1.0).abs() > 1e-4 {
                failures.push(format!("{} r {r}: GPU {on_gpu}, f64 {twin}", spec.name()));
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    common::assert_no_validation_messages(&gpu);
}
