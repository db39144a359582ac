#version 450
// The scene kernel: one G-buffer pixel per invocation, every light of the scene in one dispatch, for one model
// (the materials of the scene that use it). Light counts per type are specialisation constants and each
// type's loop is [[unroll]]ed (lavapipe turns rolled light loops into per-lane gathers; docs/measurement.md);
// effects are switched by constants (scene.glsl). No early return and no bounds check: buffers are padded
// to whole workgroups.
// Pixel: vec4 (n.xyz, roughness), vec4 (world position.xyz, metallic), vec4 (base colour.rgb, -).
// Extras (bound always, read only when an effect needs them): vec4 (tangent.xyz, anisotropy),
// vec4 (clear coat, clear coat roughness, diffuse lobe id, energy compensation flag).
// Light (3 vec4, directional first, then point, spot, sphere):
//   directional (direction of travel.xyz, -), (radiance.rgb, -), -
//   point       (position.xyz, -), (intensity.rgb, -), -
//   spot        (position.xyz, cone offset), (intensity.rgb, -), (axis.xyz, cone scale)
//   sphere      (centre.xyz, radius), (intensity.rgb, -), -
// Output: vec4 (reflected radiance.rgb, 1). Push constant: the camera position.
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
#define E_TABLE_BINDING 4
#include "scene.glsl"

layout(local_size_x = 64) in;
layout(std430, set = 0, binding = 0) readonly buffer Pixels { vec4 pixels[]; };
layout(std430, set = 0, binding = 1) buffer Radiance { vec4 radiance[]; };
layout(std430, set = 0, binding = 2) readonly buffer Lights { vec4 lights[]; };
layout(std430, set = 0, binding = 3) readonly buffer Extras { vec4 extras[]; };
layout(push_constant) uniform Push { vec4 camera; } pc;

void main() {
    uint i = gl_GlobalInvocationID.x;
    vec4 nr = pixels[3 * i];
    vec4 pm = pixels[3 * i + 1];
    vec4 base = pixels[3 * i + 2];
    Surface s;
    s.N = safe_normalize(nr.xyz);
    s.V = safe_normalize(pc.camera.xyz - pm.xyz);
    s.T = vec3(0);
    s.B = vec3(0);
    s.roughness = nr.w;
    s.f0 = mix(vec3(0.04), base.rgb, pm.w);
    s.diffuse_colour = base.rgb * (1.0 - pm.w);
#ifdef BRDF_FILE
    file_basecolor = base.rgb;
    file_metallic = pm.w;
#endif
    s.anisotropy = 0.0;
    s.coat = 0.0;
    s.coat_roughness = 1.0;
    s.diffuse = 0;
    s.energy = vec3(1.0);
    if (ANISOTROPY != 0) {
        vec4 t = extras[2 * i];
        s.T = safe_normalize(t.xyz - s.N * dot(s.N, t.xyz));
        s.B = cross(s.N, s.T);
        s.anisotropy = t.w;
#ifdef BRDF_FILE
        file_tangent = s.T;
#endif
    }
    if (CLEAR_COAT != 0 || DIFFUSE == 3 || ENERGY_COMPENSATION == 2) {
        vec4 e = extras[2 * i + 1];
        s.coat = e.x;
        s.coat_roughness = e.y;
        s.diffuse = int(e.z);
        if (ENERGY_COMPENSATION == 2 && e.w == 0.0) s.energy = vec3(1.0);
        else if (ENERGY_COMPENSATION != 0) s.energy = surface_energy(s.N, s.V, s.roughness, s.f0);
    } else if (ENERGY_COMPENSATION != 0) {
        s.energy = surface_energy(s.N, s.V, s.roughness, s.f0);
    }

    vec3 acc = vec3(0.0);
    int first = 0;
    [[unroll]] for (int j = 0; j < NUM_DIRECTIONAL; ++j) {
        int k = 3 * (first + j);
        vec3 L = safe_normalize(-lights[k].xyz);
        acc += shade(s, L, L, 1.0) * lights[k + 1].rgb;
    }
    first += NUM_DIRECTIONAL;
    [[unroll]] for (int j = 0; j < NUM_POINT; ++j) {
        int k = 3 * (first + j);
        vec3 Lv = lights[k].xyz - pm.xyz;
        vec3 L = safe_normalize(Lv);
        acc += shade(s, L, L, 1.0) * (lights[k + 1].rgb * inverse_square(dot(Lv, Lv)));
    }
    first += NUM_POINT;
    [[unroll]] for (int j = 0; j < NUM_SPOT; ++j) {
        int k = 3 * (first + j);
        vec4 axis = lights[k + 2];
        vec3 Lv = lights[k].xyz - pm.xyz;
        vec3 L = safe_normalize(Lv);
        float cone = spot_cone(dot(axis.xyz, -L), axis.w, lights[k].w);
        acc += shade(s, L, L, 1.0) * (lights[k + 1].rgb * (inverse_square(dot(Lv, Lv)) * cone));
    }
    first += NUM_SPOT;
    [[unroll]] for (int j = 0; j < NUM_SPHERE; ++j) {
        int k = 3 * (first + j);
        vec4 sphere = lights[k];
        vec3 Lc = sphere.xyz - pm.xyz;
        float d2 = dot(Lc, Lc);
        float d = max(sqrt(d2), max(sphere.w, MIN_LIGHT_DISTANCE));
        vec3 r = 2.0 * dot(s.N, s.V) * s.N - s.V;
        vec3 Ls = safe_normalize(sphere_representative_point(Lc, r, sphere.w));
        float norm = sphere_normalisation(float(perceptual_to_alpha(s.roughness)), sphere.w, d);
        acc += shade(s, safe_normalize(Lc), Ls, norm) * (lights[k + 1].rgb * inverse_square(d * d));
    }
    radiance[i] = vec4(acc, 1.0);
}
