//! Every preset (the thesis' four models first) on the GPU against its f64 twin: >= 100,000 random
//! well-conditioned samples (NoV, NoL >= 0.05, roughness in [0.2, 1)), max relative error <= 1e-3 relative
//! to max(|reference|, 1e-3).

use crate::common::{self, Worst};
use brdfprof::brdf::spec::with_each_param_sample;
use brdfprof::brdf::{ModelSpec, PRESETS, samples};
use brdfprof::kernels::{self, RunLimits};

fn check(gpu: &brdfprof::gpu::Gpu, spec: &ModelSpec, count: usize, seed: u64) -> Worst {
    let samples = samples::well_conditioned(count, seed, 0.05, 0.2..1.0);
    let got = kernels::eval(gpu, &common::model(*spec), &samples, RunLimits::default()).unwrap();
    let mut worst = Worst::default();
    for (s, g) in samples.iter().zip(&got) {
        let reference = spec.eval(s);
        for c in 0..3 {
            worst.update(common::rel_err(g[c] as f64, reference[c]), || {
                format!("{s:?} channel {c}: gpu {} f64 {}", g[c], reference[c])
            });
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
    let (a, b) = (
        kernels::eval(&gpu, &gtr2, &s, RunLimits::default()).unwrap(),
        kernels::eval(&gpu, &ggx, &s, RunLimits::default()).unwrap(),
    );
    for (x, y) in a.iter().zip(&b) {
        assert!(common::rel_err(x[0] as f64, y[0] as f64) < 1e-3, "GTR(2) {} vs GGX {}", x[0], y[0]);
    }
    common::assert_no_validation_messages(&gpu);
}

#[test]
fn every_preset_without_its_guards_matches_its_unguarded_twin() {
    use brdfprof::brdf::guards::{GuardSet, SWITCHES};
    let gpu = common::gpu();
    // All guards off, and each one off alone: the twin follows the same switches (`spec::cosines_with`).
    let sets: Vec<GuardSet> =
        std::iter::once(GuardSet::NONE).chain(SWITCHES.iter().map(|s| GuardSet(GuardSet::ALL.0 & !s.bit))).collect();
    for preset in PRESETS {
        for &guards in &sets {
            let spec = ModelSpec { guards, ..ModelSpec::preset(preset.name).unwrap() };
            let worst = check(&gpu, &spec, 20_000, 31);
            assert!(worst.err <= 1e-3, "{}: max relative error {:.3e} at {}", spec.name(), worst.err, worst.what);
        }
    }
    // Off the well-conditioned set the switches change the result, on the GPU as in the twin: a back-facing
    // light gives 0 with the lit mask and not without it; F0 = 2 is clamped to 1 only with the F0 clamp.
    let back = brdfprof::brdf::Sample {
        n: [0.0, 0.0, 1.0],
        v: [0.0, 0.6, 0.8],
        l: [0.6, 0.0, -0.8],
        roughness: 0.5,
        f0: [0.04; 3],
    };
    let bright = brdfprof::brdf::Sample { l: [0.6, 0.0, 0.8], f0: [2.0; 3], ..back };
    for (text, sample) in [("ggx,guards=off:lit-mask", back), ("ggx,guards=off:f0-clamp", bright)] {
        let spec = ModelSpec::parse(text).unwrap();
        let [on, off] = [ModelSpec::preset("ggx").unwrap(), spec]
            .map(|s| kernels::eval(&gpu, &common::model(s), &[sample], RunLimits::default()).unwrap()[0][0] as f64);
        assert!(on != off, "{text}: guarded {on}, unguarded {off}");
        let twin = spec.eval(&sample)[0];
        assert!(common::rel_err(off, twin) <= 1e-3 || (off.is_nan() && twin.is_nan()), "{text}: gpu {off} twin {twin}");
    }
    common::assert_no_validation_messages(&gpu);
}
