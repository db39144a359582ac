#version 450
// Directional albedo E(NoV, r) = integral of f_s(v, l) NoL over the hemisphere, for the selected model, by the
// estimator of albedo_estimator.glsl. One invocation per (cell, azimuth row).
// Cell input: vec4 (NoV, roughness, -, -), vec4 (f0.rgb, -). Output per (cell, row): vec4 (mean rgb, -),
// vec4 (mean rgb over even columns, -).
#extension GL_GOOGLE_include_directive : require
#include "brdf.glsl"

#include "elementwise.glsl"

// The cell being integrated (set before albedo_row).
vec3 cell_V;
float cell_roughness;
vec3 cell_f0;

vec3 albedo_integrand(vec3 L) {
#ifdef BRDF_FILE_RETURNS_F_NOL
    // The file's entry returns f_s NoL itself (returns=f_nol).
    return specular_brdf_unit(vec3(0.0, 0.0, 1.0), cell_V, L, cell_roughness, cell_f0);
#else
    return specular_brdf_unit(vec3(0.0, 0.0, 1.0), cell_V, L, cell_roughness, cell_f0) * L.z;
#endif
}

#include "albedo_estimator.glsl"

void main() {
    uint id = gl_GlobalInvocationID.x;
    if (id >= pc.count) return;
    uint cell = id / uint(ALBEDO_N);
    vec4 c = inputs[2 * cell];
    float NoV = clamp(c.x, 0.0, 1.0);
    cell_V = vec3(sqrt(max(1.0 - NoV * NoV, 0.0)), 0.0, NoV);
    cell_roughness = c.y;
    cell_f0 = inputs[2 * cell + 1].rgb;
#ifdef BRDF_FILE
    file_basecolor = cell_f0;
#endif
    vec3 mean, even;
    albedo_row(cell_V, float(perceptual_to_alpha(c.y)), id % uint(ALBEDO_N), mean, even);
    outputs[2 * id] = vec4(mean, 0.0);
    outputs[2 * id + 1] = vec4(even, 0.0);
}
