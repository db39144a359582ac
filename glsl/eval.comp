#version 450
// f_s of the selected model for one sample per invocation: brdfprof eval, and the accuracy tests.
// Input: 4 vec4 per sample (n.xyz, roughness), (v.xyz, -), (l.xyz, -), (f0.rgb, -). Output: vec4 (f_s.rgb, 0).
#extension GL_GOOGLE_include_directive : require
#include "brdf.glsl"

layout(local_size_x = 64) in;
layout(std430, set = 0, binding = 0) readonly buffer Samples { vec4 samples[]; };
layout(std430, set = 0, binding = 1) buffer Results { vec4 results[]; };
layout(push_constant) uniform Push { uint count; } pc;

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= pc.count) return;
    vec4 nr = samples[4 * i];
    vec4 v = samples[4 * i + 1];
    vec4 l = samples[4 * i + 2];
    vec4 f0 = samples[4 * i + 3];
    results[i] = vec4(specular_brdf(nr.xyz, v.xyz, l.xyz, nr.w, f0.rgb), 0.0);
}
