//! SPIR-V counts of specialised kernels (`brdfprof::spirv`), on the kernels glslang built.

use brdfprof::kernels::shade::{GBufferFormat, shade_kernel};
use brdfprof::kernels::{constants, embedded};
use brdfprof::model::Model;
use brdfprof::spirv::{count, spec_default_values, specialise};

fn frozen(model: Option<&str>, lights: u32) -> Vec<u32> {
    let m = model.map(|m| Model::parse(m).unwrap());
    let k = shade_kernel(m.as_ref(), GBufferFormat::Packed, lights, false, embedded()).unwrap();
    specialise(&k.spirv.words, &k.constants).unwrap()
}

#[test]
fn spec_values_follow_the_module_types() {
    let k = shade_kernel(Some(&Model::parse("burley,gamma=2").unwrap()), GBufferFormat::Packed, 4, false, embedded())
        .unwrap();
    let text = spec_default_values(&k.spirv.words, &k.constants).unwrap();
    assert!(text.contains("3:2.0"), "{text}");
    assert!(
        text.contains(&format!("{}:4", constants::NUM_LIGHTS.id))
            && text.contains(&format!("{}:0", constants::BASELINE.id)),
        "{text}"
    );
}

#[test]
fn specialisation_keeps_only_the_selected_terms() {
    let words = embedded().get("shade_f32").unwrap().words.to_vec();
    let ggx = count(&frozen(Some("ggx"), 8)).unwrap();
    let burley = count(&frozen(Some("burley"), 8)).unwrap();
    let baseline = count(&frozen(None, 8)).unwrap();
    let whole = count(&words).unwrap();
    // GTR's D raises to the power gamma; GGX's D has no pow.
    assert!(
        burley.glsl.get("Pow").copied().unwrap_or(0) > ggx.glsl.get("Pow").copied().unwrap_or(0),
        "{burley:?} {ggx:?}"
    );
    assert!(baseline.total < ggx.total && ggx.total < whole.total, "{} {} {}", baseline.total, ggx.total, whole.total);
    assert_eq!(ggx.total, ggx.classes.values().sum::<u64>() + ggx.glsl.values().sum::<u64>());
}
