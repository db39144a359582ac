#version 450
// White furnace of the scene's shading: the directional albedo E = integral of shade(l) over the hemisphere
// (scene.glsl's shade(): f_s NoL with the effects that specialisation constants 9..12 compile in, the diffuse
// and clear coat layers included), per cell. The estimator is albedo.comp's, unchanged: a defensive mixture of a
// GGX(a) half-vector, a horizon-dense half-vector (cos theta_h = u^2) and a cosine-weighted l, each a third of
// the samples on its own midpoint grid of ALBEDO_N columns, ALBEDO_N azimuth rows [Veach 1997, one-sample MIS,
// balance heuristic]; one invocation per (cell, row) returns its row's mean and its even columns' mean.
// N = +z, V in the xz plane, T = +x.
// Cell: vec4 (NoV, roughness, anisotropy, clear coat), vec4 (f0.rgb, clear coat roughness),
// vec4 (diffuse colour.rgb, diffuse lobe id). Output per (cell, row): vec4 (mean rgb, -), vec4 (even mean rgb, -).
#extension GL_GOOGLE_include_directive : require
#define E_TABLE_BINDING 2
#include "scene.glsl"

layout(constant_id = 7) const int ALBEDO_N = 256;

layout(local_size_x = 64) in;
layout(std430, set = 0, binding = 0) readonly buffer Cells { vec4 cells[]; };
layout(std430, set = 0, binding = 1) buffer Rows { vec4 rows[]; };
layout(push_constant) uniform Push { uint count; } pc;

float ggx_pdf_h(float NoH, float a) {
    float a2 = a * a;
    float d = NoH * NoH * (a2 - 1.0) + 1.0;
    return a2 / (PI_SCENE * d * d) * NoH;
}

void main() {
    uint id = gl_GlobalInvocationID.x;
    if (id >= pc.count) return;
    uint cell = id / uint(ALBEDO_N);
    uint row = id % uint(ALBEDO_N);
    vec4 c0 = cells[3 * cell], c1 = cells[3 * cell + 1], c2 = cells[3 * cell + 2];
    float NoV = clamp(c0.x, 0.0, 1.0);
    Surface s;
    s.N = vec3(0.0, 0.0, 1.0);
    s.V = vec3(sqrt(max(1.0 - NoV * NoV, 0.0)), 0.0, NoV);
    s.T = vec3(1.0, 0.0, 0.0);
    s.B = vec3(0.0, 1.0, 0.0);
    s.roughness = c0.y;
    s.f0 = c1.rgb;
    s.diffuse_colour = c2.rgb;
    s.anisotropy = c0.z;
    s.coat = c0.w;
    s.coat_roughness = c1.w;
    s.diffuse = int(c2.w);
    s.energy = (ENERGY_COMPENSATION != 0) ? surface_energy(s.N, s.V, s.roughness, s.f0) : vec3(1.0);
    float a = float(perceptual_to_alpha(s.roughness));
    float phi = 2.0 * PI_SCENE * (float(row) + 0.5) / float(ALBEDO_N);
    vec2 cs = vec2(cos(phi), sin(phi));
    vec3 sum = vec3(0.0), even = vec3(0.0);
    for (int i = 0; i < 3 * ALBEDO_N; ++i) {
        int component = i / ALBEDO_N;
        int column = i - component * ALBEDO_N;
        float u = (float(column) + 0.5) / float(ALBEDO_N);
        vec3 L;
        if (component < 2) {
            float cos2 = (component == 0) ? (1.0 - u) / (1.0 + (a * a - 1.0) * u) : u * u * u * u;
            float st = sqrt(max(1.0 - cos2, 0.0));
            vec3 H = vec3(st * cs, sqrt(cos2));
            L = 2.0 * dot(s.V, H) * H - s.V;
        } else {
            L = vec3(sqrt(u) * cs, sqrt(1.0 - u));
        }
        float NoL = L.z;
        if (NoL <= 0.0) continue;
        vec3 H = normalize(s.V + L);
        float VoH = max(dot(s.V, H), 1e-7);
        float horizon_h = 1.0 / (4.0 * PI_SCENE * sqrt(max(H.z, 1e-12)));
        float pdf = ((ggx_pdf_h(H.z, a) + horizon_h) / (4.0 * VoH) + NoL / PI_SCENE) / 3.0;
        vec3 w = shade(s, L, L, 1.0) / pdf;
        sum += w;
        if ((column & 1) == 0) even += w;
    }
    rows[2 * id] = vec4(sum / float(3 * ALBEDO_N), 0.0);
    rows[2 * id + 1] = vec4(even / float(3 * (ALBEDO_N / 2)), 0.0);
}
