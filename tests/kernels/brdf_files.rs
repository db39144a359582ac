//! The thesis models as .brdf files (examples/brdf/) on the GPU: each computes what its built-in preset
//! computes, within 1e-4 relative on well-conditioned samples (NoV, NoL >= 0.05, roughness in [0.2, 1)).

use crate::common;
use brdfprof::brdf::samples;
use brdfprof::gpu::{Buffer, Gpu, MemoryKind, SpecConstants, WORKGROUP};
use brdfprof::kernels::{self, RunLimits};
use brdfprof::model::brdf_file::{self, BrdfFile};
use brdfprof::model::Model;
use brdfprof::shaders::{glslang, Spirv};
use std::path::Path;

/// An eval kernel around the file, with eval.comp's interface: roughness and f0 are private globals set from
/// each sample; every other parameter is a constant at its default.
fn compose(f: &BrdfFile) -> String {
    let r = f.renamed_shader().unwrap();
    let mut s = format!(
        "#version 450\n#extension GL_GOOGLE_cpp_style_line_directive : require\nlayout(local_size_x = {WORKGROUP}) in;\n\
         layout(std430, set = 0, binding = 0) readonly buffer Inputs {{ vec4 inputs[]; }};\n\
         layout(std430, set = 0, binding = 1) buffer Outputs {{ vec4 outputs[]; }};\n\
         layout(push_constant) uniform Push {{ uint count; }} pc;\n"
    );
    for p in &f.params {
        s += &match p.name.as_str() {
            "roughness" | "f0" => format!("{} {};\n", p.glsl_type(), f.glsl_name(&p.name)),
            _ => format!("const {} {} = {};\n", p.glsl_type(), f.glsl_name(&p.name), p.default_glsl()),
        };
    }
    s += &format!("{}\n{}#line 1 \"main\"\n", f.line_directive(), r.text());
    s + &format!(
        "void main() {{\n    uint i = gl_GlobalInvocationID.x;\n    if (i >= pc.count) return;\n\
         {r} = inputs[4 * i].w;\n    {f0} = inputs[4 * i + 3].rgb;\n\
         vec3 N = normalize(inputs[4 * i].xyz), V = normalize(inputs[4 * i + 1].xyz), L = normalize(inputs[4 * i + 2].xyz);\n\
         outputs[i] = vec4({brdf}(L, V, N, vec3(0.0), vec3(0.0)), 0.0);\n}}\n",
        r = f.glsl_name("roughness"),
        f0 = f.glsl_name("f0"),
        brdf = f.glsl_name("BRDF")
    )
}

fn eval_file(gpu: &Gpu, f: &BrdfFile, samples: &[brdfprof::brdf::Sample]) -> Vec<[f32; 3]> {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join(format!("{}.comp", f.name));
    std::fs::write(&path, compose(f)).unwrap();
    let spirv = Spirv { name: f.name.clone(), words: glslang(&path, &[], &[]).unwrap().into() };
    let kernel = kernels::kernel(gpu, &spirv, &SpecConstants::default(), 2, 4).unwrap();
    let floats: Vec<f32> = samples
        .iter()
        .flat_map(|s| [s.n[0], s.n[1], s.n[2], s.roughness, s.v[0], s.v[1], s.v[2], 0.0, s.l[0], s.l[1], s.l[2], 0.0, s.f0[0], s.f0[1], s.f0[2], 0.0])
        .collect();
    let n = samples.len() as u64;
    let inputs = Buffer::with_data(gpu, bytemuck::cast_slice(&floats), MemoryKind::Device).unwrap();
    let outputs = Buffer::new(gpu, n * 16, MemoryKind::Device).unwrap();
    let set = kernel.bind(&[(&inputs, 0, n * 64), (&outputs, 0, n * 16)]).unwrap();
    gpu.submit(|cmd| kernel.dispatch(cmd, set, &(n as u32).to_ne_bytes(), n)).unwrap();
    let out: Vec<f32> = outputs.read_as(0, 4 * n as usize).unwrap();
    out.chunks_exact(4).map(|c| [c[0], c[1], c[2]]).collect()
}

#[test]
fn example_files_match_their_presets() {
    let gpu = common::gpu();
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/brdf");
    for (i, name) in ["ggx", "blinn", "cook-torrance", "burley"].into_iter().enumerate() {
        let f = brdf_file::load(&dir.join(format!("{name}.brdf"))).unwrap();
        let s = samples::well_conditioned(20_000, 40 + i as u64, 0.05, 0.2..1.0);
        let got = eval_file(&gpu, &f, &s);
        let builtin = kernels::eval(&gpu, &Model::parse(name).unwrap(), &s, RunLimits::default()).unwrap();
        let mut worst = common::Worst::default();
        for ((g, b), sample) in got.iter().zip(&builtin).zip(&s) {
            for c in 0..3 {
                worst.update(common::rel_err(g[c] as f64, b[c] as f64), || format!("{sample:?} channel {c}: file {} built-in {}", g[c], b[c]));
            }
        }
        println!("{name:14} max rel diff to the built-in {:.2e}", worst.err);
        assert!(worst.err <= 1e-4, "{name}.brdf: max relative difference {:.3e} at {}", worst.err, worst.what);
    }
    common::assert_no_validation_messages(&gpu);
}
