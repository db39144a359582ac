#version 450
// Every term of scene.glsl on its own, one sample per invocation, for the tests that tie each to its f64 twin
// (tests/scenes/terms.rs, src/scene/terms.rs). Input, 13 vec4 per sample:
//  0 (NoH, ToH, BoH, at)  1 (ab, ToV, BoV, NoV)  2 (ToL, BoL, NoL, LoH)  3 (roughness, coat strength, cd, cone scale)
//  4 (cone offset, sphere radius, distance, a)  5 (f0.rgb, E)  6 (Lc.xyz, d2)  7 (reflection r.xyz, -)
//  8 (mu, r, -, -)  9 (N.xyz, anisotropy)  10 (V.xyz, coat roughness)  11 (L.xyz, -)  12 (T.xyz, -)
// Output, 6 vec4: (D_aniso, Vis_aniso, Fd_Lambert, Fd_Burley), (Fc, coat lobe, spot cone, sphere normalisation),
// (energy compensation rgb, inverse square), (representative point xyz, E lookup), (specular_anisotropic rgb, -),
// (anisotropic alphas at, ab, -, -).
#extension GL_GOOGLE_include_directive : require
#define E_TABLE_BINDING 2
#include "scene.glsl"

#include "elementwise.glsl"

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= pc.count) return;
    vec4 s[13];
    for (int k = 0; k < 13; ++k) s[k] = inputs[13 * i + k];
    vec3 N = s[9].xyz, V = s[10].xyz, L = s[11].xyz, T = s[12].xyz;
    vec3 B = cross(N, T);
    outputs[6 * i] = vec4(D_GgxAnisotropic(s[0].x, s[0].y, s[0].z, s[0].w, s[1].x),
                          Vis_SmithGgxCorrelatedAnisotropic(s[1].y, s[1].z, s[1].w, s[2].x, s[2].y, s[2].z, s[0].w, s[1].x),
                          Fd_Lambert(), Fd_Burley(s[1].w, s[2].z, s[2].w, s[3].x));
    outputs[6 * i + 1] = vec4(clear_coat_fresnel(s[2].w, s[3].y), clear_coat_lobe(N, V, L, s[10].w, s[3].y),
                              spot_cone(s[3].z, s[3].w, s[4].x), sphere_normalisation(s[4].w, s[4].y, s[4].z));
    outputs[6 * i + 2] = vec4(energy_compensation(s[5].rgb, s[5].w), inverse_square(s[6].w));
    outputs[6 * i + 3] = vec4(sphere_representative_point(s[6].xyz, s[7].xyz, s[4].y), e_lookup(s[8].x, s[8].y));
    outputs[6 * i + 4] = vec4(specular_anisotropic(N, V, L, T, B, s[3].x, s[9].w, s[5].rgb), 0.0);
    outputs[6 * i + 5] = vec4(anisotropic_alphas(s[4].w, s[9].w), 0.0, 0.0);
}
