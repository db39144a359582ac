//! Every preset (the thesis' four models first) on the GPU against its f64 twin: >= 100,000 random
//! well-conditioned samples (NoV, NoL >= 0.05, roughness in [0.2, 1)), max relative error <= 1e-3 relative
//! to max(|reference|, 1e-3).

use crate::common::{self, Worst};
use brdfprof::brdf::spec::with_each_param_sample;
use brdfprof::brdf::{samples, ModelSpec, PRESETS};
use brdfprof::kernels::{self, RunLimits};

fn check(gpu: &brdfprof::gpu::Gpu, spec: &ModelSpec, count: usize, seed: u64) -> Worst {
    let samples = samples::well_conditioned(count, seed, 0.05, 0.2..1.0);
    let got = kernels::eval(gpu, &common::model(*spec), &samples, RunLimits::default()).unwrap();
    let mut worst = Worst::default();
    for (s, g) in samples.iter().zip(&got) {
        let reference = spec.eval(s);
        for c in 0..3 {
            worst.update(common::rel_err(g[c] as f64, reference[c]), || format!("{s:?} channel {c}: gpu {} f64 {}", g[c], reference[c]));
        }
    }
    worst
}

#[test]
fn every_preset_matches_its_f64_twin() {
    let gpu = common::gpu();
    for (i, preset) in PRESETS.iter().enumerate() {
        let spec = ModelSpec::preset(preset.name).unwrap();
        let worst = check(&gpu, &spec, 100_000, 100 + i as u64);
        println!("{:16} max rel err {:.2e}", preset.name, worst.err);
        assert!(worst.err <= 1e-3, "{}: max relative error {:.3e} at {}", preset.name, worst.err, worst.what);
    }
    common::assert_no_validation_messages(&gpu);
}

#[test]
fn every_preset_parameter_value_and_a_limit() {
    let gpu = common::gpu();
    // Every parameter a preset's terms read, at each of its sample values (range ends, default, middle).
    for preset in PRESETS {
        for spec in with_each_param_sample(ModelSpec::preset(preset.name).unwrap()).into_iter().skip(1) {
            let worst = check(&gpu, &spec, 30_000, 7);
            assert!(worst.err <= 1e-3, "{}: max relative error {:.3e} at {}", spec.name(), worst.err, worst.what);
        }
    }
    // GTR at gamma = 2 is GGX's D (Burley 2012, App. B): the two kernels must agree.
    let gtr2 = common::model(ModelSpec::parse("d=gtr,vis=implicit,f=none,gamma=2").unwrap());
    let ggx = common::model(ModelSpec::parse("d=ggx,vis=implicit,f=none").unwrap());
    let s = samples::well_conditioned(20_000, 9, 0.05, 0.2..1.0);
    let (a, b) = (kernels::eval(&gpu, &gtr2, &s, RunLimits::default()).unwrap(), kernels::eval(&gpu, &ggx, &s, RunLimits::default()).unwrap());
    for (x, y) in a.iter().zip(&b) {
        assert!(common::rel_err(x[0] as f64, y[0] as f64) < 1e-3, "GTR(2) {} vs GGX {}", x[0], y[0]);
    }
    common::assert_no_validation_messages(&gpu);
}
