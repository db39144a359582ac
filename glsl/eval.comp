#version 450
// f_s of the selected model for one sample per invocation: brdfprof eval, and the accuracy tests.
// Input: 4 vec4 per sample (n.xyz, roughness), (v.xyz, -), (l.xyz, -), (f0.rgb, -). Output: vec4 (f_s.rgb, 0).
#extension GL_GOOGLE_include_directive : require
#include "brdf.glsl"

#include "elementwise.glsl"

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= pc.count) return;
    vec4 nr = inputs[4 * i];
    vec4 v = inputs[4 * i + 1];
    vec4 l = inputs[4 * i + 2];
    vec4 f0 = inputs[4 * i + 3];
    outputs[i] = vec4(specular_brdf(nr.xyz, v.xyz, l.xyz, nr.w, f0.rgb), 0.0);
}
