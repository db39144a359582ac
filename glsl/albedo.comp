#version 450
// Directional albedo E(NoV, r) = integral of f_s(v, l) NoL over the hemisphere, for the selected model.
// Importance sampling with a defensive mixture that suits every D without a sampler per D: a third of the
// samples draw a GGX(a) half-vector (lobes around the normal), a third a half-vector with cos theta_h = u^2,
// dense towards the horizon (heavy tails, Charlie's grazing lobe), a third a cosine-weighted l; each weighs f_s NoL / pdf with pdf the mixture's
// density [Veach 1997, one-sample MIS, balance heuristic]. Each component has its own midpoint grid of
// ALBEDO_N columns u1 (exactly a third of the samples, evenly spaced), and there are ALBEDO_N rows in
// azimuth; one invocation per (cell, row) returns its row's mean and the mean over its even columns, from
// which the host forms E and a half-resolution estimate (their difference is the error bound it reports).
// N = +z, V in the xz plane.
// Cell input: vec4 (NoV, roughness, -, -), vec4 (f0.rgb, -). Output per (cell, row): vec4 (mean rgb, -),
// vec4 (mean rgb over even columns, -).
#extension GL_GOOGLE_include_directive : require
#include "brdf.glsl"

layout(constant_id = 7) const int ALBEDO_N = 256;

layout(local_size_x = 64) in;
layout(std430, set = 0, binding = 0) readonly buffer Cells { vec4 cells[]; };
layout(std430, set = 0, binding = 1) buffer Rows { vec4 rows[]; };
layout(push_constant) uniform Push { uint count; } pc;

const float PI_F = 3.14159265358979;

// The proposal's GGX density of half-vectors, D(h) NoH, in fp32 whatever the model's precision.
float ggx_pdf_h(float NoH, float a) {
    float a2 = a * a;
    float d = NoH * NoH * (a2 - 1.0) + 1.0;
    return a2 / (PI_F * d * d) * NoH;
}

void main() {
    uint id = gl_GlobalInvocationID.x;
    if (id >= pc.count) return;
    uint cell = id / uint(ALBEDO_N);
    uint row = id % uint(ALBEDO_N);
    vec4 c = cells[2 * cell];
    vec3 f0 = cells[2 * cell + 1].rgb;
    float NoV = clamp(c.x, 0.0, 1.0);
    vec3 N = vec3(0.0, 0.0, 1.0);
    vec3 V = vec3(sqrt(max(1.0 - NoV * NoV, 0.0)), 0.0, NoV);
    float a = float(perceptual_to_alpha(c.y));
    float phi = 2.0 * PI_F * (float(row) + 0.5) / float(ALBEDO_N);
    vec2 cs = vec2(cos(phi), sin(phi));
    vec3 sum = vec3(0.0), even = vec3(0.0);
    for (int i = 0; i < 3 * ALBEDO_N; ++i) {
        int component = i / ALBEDO_N;
        int column = i - component * ALBEDO_N;
        float u = (float(column) + 0.5) / float(ALBEDO_N);
        vec3 L;
        if (component < 2) {
            // GGX: cos^2 = (1-u) / (1 + (a^2-1) u); horizon-dense: cos = u^2.
            float cos2 = (component == 0) ? (1.0 - u) / (1.0 + (a * a - 1.0) * u) : u * u * u * u;
            float st = sqrt(max(1.0 - cos2, 0.0));
            vec3 H = vec3(st * cs, sqrt(cos2));
            L = 2.0 * dot(V, H) * H - V;
        } else {
            L = vec3(sqrt(u) * cs, sqrt(1.0 - u));
        }
        float NoL = L.z;
        if (NoL <= 0.0) continue;
        vec3 H = normalize(V + L);
        float VoH = max(dot(V, H), 1e-7);
        // Densities of l: half-vector densities / (4 VoH); cos theta_h = u^2 has density 1 / (4 pi sqrt(NoH)).
        float horizon_h = 1.0 / (4.0 * PI_F * sqrt(max(H.z, 1e-12)));
        float pdf = ((ggx_pdf_h(H.z, a) + horizon_h) / (4.0 * VoH) + NoL / PI_F) / 3.0;
        vec3 w = specular_brdf_unit(N, V, L, c.y, f0) * (NoL / pdf);
        sum += w;
        if ((column & 1) == 0) even += w;
    }
    rows[2 * id] = vec4(sum / float(3 * ALBEDO_N), 0.0);
    rows[2 * id + 1] = vec4(even / float(3 * (ALBEDO_N / 2)), 0.0);
}
