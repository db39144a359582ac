#version 450
// The profiling kernel: one G-buffer pixel per invocation, lit by NUM_LIGHTS directional lights,
// out = sum_j f_s(n, v, l_j) NoL_j colour_j. Shaped by what costs on lavapipe (see README "Kernel design"):
// the light count is a specialisation constant and the loop is marked [[unroll]] (Mesa leaves an 8-light
// BRDF loop rolled otherwise), so light loads become broadcasts instead of per-lane gathers;
// there is no early return and no bounds check (buffers are padded to whole workgroups).
// BASELINE = 1 is the memory-only kernel: the same loads, normalisation, NoL and stores, no BRDF.
// Pixel: vec4 (n.xyz, roughness), vec4 (v.xyz, metallic), vec4 (base colour, -). Light: vec4 (l.xyz, -), vec4 (rgb, -).
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
#include "brdf.glsl"

layout(local_size_x = 64) in;
layout(std430, set = 0, binding = 0) readonly buffer Pixels { vec4 pixels[]; };
layout(std430, set = 0, binding = 1) buffer Radiance { vec4 radiance[]; };
layout(std430, set = 0, binding = 2) readonly buffer Lights { vec4 lights[]; };

void main() {
    uint i = gl_GlobalInvocationID.x;
    vec4 nr = pixels[3 * i];
    vec4 vm = pixels[3 * i + 1];
    vec4 base = pixels[3 * i + 2];
    vec3 f0 = mix(vec3(0.04), base.rgb, vm.w);
    vec3 N = safe_normalize(nr.xyz);
    vec3 V = safe_normalize(vm.xyz);
    vec3 acc = vec3(0.0);
    [[unroll]] for (int j = 0; j < NUM_LIGHTS; ++j) {
        vec3 L = safe_normalize(lights[2 * j].xyz);
        vec3 colour = lights[2 * j + 1].rgb;
        float NoL = max(dot(N, L), 0.0);
        vec3 fs = (BASELINE != 0) ? vec3(1.0) : specular_brdf_unit(N, V, L, nr.w, f0);
        acc += fs * (NoL * colour);
    }
    // The baseline folds every input it would otherwise skip into the result, so no load is dead code.
    if (BASELINE != 0) acc = acc * f0 + vec3(nr.w) + V;
    radiance[i] = vec4(acc, 1.0);
}
