//! Every GLSL term against its f64 twin, term by term (the per-term kernel): random well-conditioned
//! cosines in [0.05, 1], roughness in [0.2, 1), F0 in [0, 1]; relative error <= 1e-3 in fp32.

use crate::common::{self, Worst};
use brdfprof::brdf::guards::guard_cosine;
use brdfprof::brdf::spec::with_each_param_sample;
use brdfprof::brdf::{Cosines, D, F, ModelSpec, Vis};
use brdfprof::kernels::{self, TermInput};
use rand::{Rng, SeedableRng};

fn inputs(count: usize, seed: u64) -> Vec<TermInput> {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(seed);
    (0..count)
        .map(|_| {
            let noh: f32 = rng.random_range(0.05..=1.0);
            TermInput {
                nov: rng.random_range(0.05..=1.0),
                nol: rng.random_range(0.05..=1.0),
                noh,
                voh: rng.random_range(0.05..=1.0),
                sin2h: (1.0 - (noh as f64).powi(2)) as f32,
                roughness: rng.random_range(0.2..1.0),
                f0: [rng.random(), rng.random(), rng.random()],
            }
        })
        .collect()
}

fn cosines(t: &TermInput) -> Cosines {
    Cosines {
        nov: guard_cosine(t.nov as f64),
        nol: guard_cosine(t.nol as f64),
        noh: guard_cosine(t.noh as f64),
        voh: guard_cosine(t.voh as f64),
        sin2h: t.sin2h as f64,
    }
}

#[test]
fn every_term_matches_its_f64_twin() {
    let gpu = common::gpu();
    let ins = inputs(20_000, 42);
    let mut failures = Vec::new();
    let mut check = |spec: ModelSpec, pick: &dyn Fn(&kernels::TermOutput, &TermInput) -> Vec<(f64, f64)>| {
        let label = spec.name();
        let out = kernels::terms(&gpu, &common::model(spec), &ins).unwrap();
        let mut worst = Worst::default();
        for (o, t) in out.iter().zip(&ins) {
            for (g, r) in pick(o, t) {
                worst.update(common::rel_err(g, r), || format!("{t:?}: gpu {g} f64 {r}"));
            }
        }
        println!("{label:40} max rel err {:.2e}", worst.err);
        if worst.err > 1e-3 {
            failures.push(format!("{label}: {:.3e} at {}", worst.err, worst.what));
        }
    };
    // Every row of every table, with each sample of the parameters the term reads.
    for spec in common::every_d() {
        check(spec, &|o, t| {
            vec![(o.d as f64, {
                let c = cosines(t);
                spec.d.eval(c.noh, c.sin2h, spec.alpha(t.roughness as f64), &spec.params)
            })]
        });
    }
    for &vis in Vis::ALL {
        let spec = ModelSpec::new(D::ALL[0], vis, F::ALL[0]);
        check(spec, &|o, t| vec![(o.vis as f64, vis.eval(&cosines(t), spec.alpha(t.roughness as f64)))]);
    }
    for &f in F::ALL {
        for spec in with_each_param_sample(ModelSpec::new(D::ALL[0], Vis::ALL[0], f)) {
            check(spec, &|o, t| {
                let r = f.eval(t.f0.map(f64::from), cosines(t).voh, &spec.params);
                (0..3).map(|c| (o.f[c] as f64, r[c])).collect()
            });
        }
    }
    assert!(failures.is_empty(), "terms off their twins:\n{}", failures.join("\n"));
    common::assert_no_validation_messages(&gpu);
}
