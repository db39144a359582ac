#version 450
// f_s of the selected model for one sample per invocation: brdfprof eval, and the accuracy tests.
// Input: 4 vec4 per sample (n.xyz, roughness), (v.xyz, tx), (l.xyz, ty), (f0.rgb, tz). Output: vec4 (f_s.rgb, 0).
#extension GL_GOOGLE_include_directive : require
#include "brdf.glsl"

#include "elementwise.glsl"

// vec4s per sample: 4, or more for a .brdf model's per-row parameters (file_model.rs).
#ifndef EVAL_STRIDE
#define EVAL_STRIDE 4
#endif

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= pc.count) return;
    vec4 nr = inputs[EVAL_STRIDE * i];
    vec4 v = inputs[EVAL_STRIDE * i + 1];
    vec4 l = inputs[EVAL_STRIDE * i + 2];
    vec4 f0 = inputs[EVAL_STRIDE * i + 3];
#ifdef BRDF_FILE
    // A .brdf model: the tangent (tx,ty,tz; 0 for none) in the w components, parameters set per row after.
    file_tangent = vec3(v.w, l.w, f0.w);
    file_basecolor = f0.rgb;
    BRDF_FILE_ROWS(EVAL_STRIDE * i + 4)
#endif
    outputs[i] = vec4(specular_brdf(nr.xyz, v.xyz, l.xyz, nr.w, f0.rgb), 0.0);
}
