#version 450
// White furnace of the scene's shading: the directional albedo E = integral of shade(l) over the hemisphere
// (scene.glsl's shade(): f_s NoL with the effects that the scene constants compile in, the diffuse and clear
// coat layers included), per cell, by albedo_estimator.glsl's estimator (the one albedo.comp uses).
// N = +z, V in the xz plane, T = +x.
// Cell: vec4 (NoV, roughness, anisotropy, clear coat), vec4 (f0.rgb, clear coat roughness),
// vec4 (diffuse colour.rgb, diffuse lobe id). Output per (cell, row): vec4 (mean rgb, -), vec4 (even mean rgb, -).
#extension GL_GOOGLE_include_directive : require
#define E_TABLE_BINDING 2
#include "scene.glsl"

#include "elementwise.glsl"

// The cell's surface (set before albedo_row).
Surface cell;

vec3 albedo_integrand(vec3 L) {
    return shade(cell, L, L, 1.0);
}

#include "albedo_estimator.glsl"

void main() {
    uint id = gl_GlobalInvocationID.x;
    if (id >= pc.count) return;
    uint c = id / uint(ALBEDO_N);
    vec4 c0 = inputs[3 * c], c1 = inputs[3 * c + 1], c2 = inputs[3 * c + 2];
    float NoV = clamp(c0.x, 0.0, 1.0);
    cell.N = vec3(0.0, 0.0, 1.0);
    cell.V = vec3(sqrt(max(1.0 - NoV * NoV, 0.0)), 0.0, NoV);
    cell.T = vec3(1.0, 0.0, 0.0);
    cell.B = vec3(0.0, 1.0, 0.0);
    cell.roughness = c0.y;
    cell.f0 = c1.rgb;
#ifdef BRDF_FILE
    file_basecolor = cell.f0;
#endif
    cell.diffuse_colour = c2.rgb;
    cell.anisotropy = c0.z;
    cell.coat = c0.w;
    cell.coat_roughness = c1.w;
    cell.diffuse = int(c2.w);
    cell.energy = (ENERGY_COMPENSATION != 0) ? surface_energy(cell.N, cell.V, cell.roughness, cell.f0) : vec3(1.0);
    vec3 mean, even;
    albedo_row(cell.V, float(perceptual_to_alpha(cell.roughness)), id % uint(ALBEDO_N), mean, even);
    outputs[2 * id] = vec4(mean, 0.0);
    outputs[2 * id + 1] = vec4(even, 0.0);
}
