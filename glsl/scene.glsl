// Scene effects and lights, on top of the specular term library (brdf.glsl). One function per term, each with
// the source it implements; every one has an f64 twin in src/scene/terms.rs (tests/scenes/terms.rs ties them).
// Specialisation constants switch effects in and out: with an effect's constant at 0 its code is dead and
// the driver (and spirv-opt, tests/scenes/spirv.rs) removes it, so an effect no material uses costs nothing.
// Effects are evaluated in fp32 whatever the model's precision, except the clear coat, which reuses the library's
// D_Ggx and Vis_Kelemen and so follows the model's precision (BRDF_F16).
#ifndef SCENE_GLSL
#define SCENE_GLSL
#include "brdf.glsl"

// The effect switches (ANISOTROPY, ENERGY_COMPENSATION, DIFFUSE, CLEAR_COAT) and the E table's size are
// specialisation constants declared in generated/kernel_constants.glsl.

// Guards of the scene path (docs/scenes.md): a light closer than MIN_LIGHT_DISTANCE (world units) is taken at
// that distance, so inverse-square falloff stays finite [Karis 2013 uses a 1 cm floor likewise]; anisotropic
// alphas are floored at MIN_ROUGHNESS^2 as Filament floors them [Filament, getAnisotropicRoughness].
const float MIN_LIGHT_DISTANCE = 1e-2;
const float CLEAR_COAT_F0 = 0.04; // Filament's clear coat: a polyurethane layer, IOR 1.5

// brdf.glsl's guard_cosine in fp32: a visible cosine clamped into [MIN_COSINE, 1].
float guard_cos(float x) { return clamp(x, MIN_COSINE, 1.0); }

// ---- Anisotropic GGX --------------------------------------------------------------------------------

// Anisotropic alphas from an isotropic a and anisotropy s in [-1, 1] [Kulla & Conty 2017, as Filament]:
// at = a (1 + s), ab = a (1 - s), each floored at MIN_ROUGHNESS^2.
vec2 anisotropic_alphas(float a, float s) {
    float floor_a = MIN_ROUGHNESS * MIN_ROUGHNESS;
    return vec2(max(a * (1.0 + s), floor_a), max(a * (1.0 - s), floor_a));
}

// Anisotropic GGX [Burley 2012, App. B, eq. 13; Filament D_GGX_Anisotropic]:
// 1 / (pi at ab ((ToH/at)^2 + (BoH/ab)^2 + NoH^2)^2), written a2^3 / (pi (ab ToH, at BoH, a2 NoH)^2^2), a2 = at ab.
float D_GgxAnisotropic(float NoH, float ToH, float BoH, float at, float ab) {
    float a2 = at * ab;
    vec3 d = vec3(ab * ToH, at * BoH, a2 * NoH);
    float d2 = dot(d, d);
    float w2 = a2 / d2;
    return a2 * w2 * w2 / PI_F32;
}

// Anisotropic Smith GGX, height-correlated [Heitz 2014, eq. 99 with the anisotropic Lambda; Filament
// V_SmithGGXCorrelated_Anisotropic]: 0.5 / (NoL |(at ToV, ab BoV, NoV)| + NoV |(at ToL, ab BoL, NoL)|).
float Vis_SmithGgxCorrelatedAnisotropic(float ToV, float BoV, float NoV, float ToL, float BoL, float NoL, float at, float ab) {
    float lambda_v = NoL * length(vec3(at * ToV, ab * BoV, NoV));
    float lambda_l = NoV * length(vec3(at * ToL, ab * BoL, NoL));
    return 0.5 / (lambda_v + lambda_l);
}

// f_s with anisotropic GGX D and Vis and the model's Fresnel, for unit N, V, L and a tangent frame T, B = N x T;
// 0 unless NoL > 0 and NoV > 0. Cosines guarded as in specular_brdf_unit.
vec3 specular_anisotropic(vec3 N, vec3 V, vec3 L, vec3 T, vec3 B, float roughness, float s, vec3 f0) {
    vec3 H = safe_normalize(V + L);
    float NoV = dot(N, V), NoL = dot(N, L);
    bool lit = NoV > 0.0 && NoL > 0.0;
    vec2 ab = anisotropic_alphas(float(perceptual_to_alpha(roughness)), s);
    float nv = guard_cos(NoV), nl = guard_cos(NoL);
    float D = D_GgxAnisotropic(guard_cos(dot(N, H)), dot(T, H), dot(B, H), ab.x, ab.y);
    float Vis = Vis_SmithGgxCorrelatedAnisotropic(dot(T, V), dot(B, V), nv, dot(T, L), dot(B, L), nl, ab.x, ab.y);
    vec3 F = vec3(F_term(real3(clamp(f0, vec3(0), vec3(1))), real(guard_cos(dot(V, H)))));
    return lit ? D * Vis * F : vec3(0);
}

// ---- Diffuse lobes -----------------------------------------------------------------------------------

// Lambert: f_d = 1/pi (times the diffuse colour).
float Fd_Lambert() { return 1.0 / PI_F32; }

// Burley diffuse [Burley 2012, sec. 5.3, eq. 8]: (1 + (F_D90 - 1)(1 - NoL)^5)(1 + (F_D90 - 1)(1 - NoV)^5) / pi,
// F_D90 = 0.5 + 2 r LoH^2 with r the perceptual roughness (Burley's "roughness"; Filament passes a = r^2).
float Fd_Burley(float NoV, float NoL, float LoH, float roughness) {
    float f90 = 0.5 + 2.0 * roughness * LoH * LoH;
    float l = 1.0 + (f90 - 1.0) * pow5(1.0 - NoL);
    float v = 1.0 + (f90 - 1.0) * pow5(1.0 - NoV);
    return l * v / PI_F32;
}

// ---- Clear coat [Filament documentation, sec. 4.9; surface_shading_model_standard.fs] -------------------

// Clear coat Fresnel: Schlick with F0 = 0.04 and f90 = 1, times the coat strength.
float clear_coat_fresnel(float LoH, float strength) {
    return float(F_Schlick(real3(CLEAR_COAT_F0), real(LoH)).x) * strength;
}

// Clear coat lobe D_GGX(a_c) Vis_Kelemen(LoH) Fc, a_c = the coat's perceptual roughness squared (floored), for
// unit N, V, L; 0 unless NoL > 0 and NoV > 0. Filament's base layer is then scaled by (1 - Fc).
float clear_coat_lobe(vec3 N, vec3 V, vec3 L, float coat_roughness, float strength) {
    vec3 H = safe_normalize(V + L);
    float NoH = guard_cos(dot(N, H));
    float LoH = guard_cos(dot(L, H));
    vec3 NxH = cross(N, H);
    bool lit = dot(N, V) > 0.0 && dot(N, L) > 0.0;
    float a = float(perceptual_to_alpha(coat_roughness));
    float lobe = float(D_Ggx(real(NoH), real(min(dot(NxH, NxH), 1.0)), real(a))) * float(vis_kelemen(real(LoH)))
               * clear_coat_fresnel(LoH, strength);
    return lit ? lobe : 0.0;
}

// ---- Multiple-scattering energy compensation ----------------------------------------------------------

// Filament's form [Filament documentation, sec. 4.7.2, after Kulla & Conty 2017]: f_s (1 + F0 (1/E - 1)), E the
// directional albedo of the model with F = 1 at (NoV, r); the factor per channel.
vec3 energy_compensation(vec3 f0, float E) {
    return vec3(1.0) + f0 * (1.0 / E - 1.0);
}

// ---- Lights -------------------------------------------------------------------------------------------

// Inverse-square falloff of a point source, distance floored at MIN_LIGHT_DISTANCE [Karis 2013, eq. 9 without
// its window: the issue asks for plain inverse-square].
float inverse_square(float d2) {
    return 1.0 / max(d2, MIN_LIGHT_DISTANCE * MIN_LIGHT_DISTANCE);
}

// Spot cone falloff [Karis 2013 / Filament getAngleAttenuation]: saturate((cd - cos_outer) / (cos_inner -
// cos_outer))^2, given as scale = 1 / max(cos_inner - cos_outer, 1e-4) and offset = -cos_outer scale (host-side);
// cd = dot(spot axis, -L).
float spot_cone(float cd, float scale, float offset) {
    float t = clamp(cd * scale + offset, 0.0, 1.0);
    return t * t;
}

// Sphere light, representative point [Karis 2013, eq. 11]: the point of the sphere (centre at Lc from the
// surface, radius R) closest to the reflection ray r: Lc + c saturate(R / |c|), c = (Lc . r) r - Lc; unnormalised.
vec3 sphere_representative_point(vec3 Lc, vec3 r, float radius) {
    vec3 c = dot(Lc, r) * r - Lc;
    return Lc + c * clamp(radius / max(length(c), 1e-20), 0.0, 1.0);
}

// The representative point's energy normalisation [Karis 2013, eqs. 10 and 14]: (a / a')^2 with
// a' = saturate(a + R / (2 d)), d the distance to the centre. Derived for GGX's D; applied to f_s of every model.
float sphere_normalisation(float a, float radius, float d) {
    float a_prime = clamp(a + radius / (2.0 * d), 0.0, 1.0);
    return (a / a_prime) * (a / a_prime);
}

// ---- E(mu, r) table lookup -----------------------------------------------------------------------------
// A kernel that includes this file with E_TABLE_BINDING defined gets the table (computed by brdfprof on the GPU,
// src/scene/effects.rs) and its bilinear lookup.
#ifdef E_TABLE_BINDING
layout(std430, set = 0, binding = E_TABLE_BINDING) readonly buffer ETable { float etable[]; };

// E at (mu, r) by bilinear interpolation between the nodes mu_i = (i + 0.5) / E_TABLE_MU and
// r_j = j / (E_TABLE_R - 1) (clamped to the first and last node); etable[j * E_TABLE_MU + i].
float e_lookup(float mu, float r) {
    float x = clamp(mu * float(E_TABLE_MU) - 0.5, 0.0, float(E_TABLE_MU - 1));
    float y = clamp(r * float(E_TABLE_R - 1), 0.0, float(E_TABLE_R - 1));
    int i = min(int(x), E_TABLE_MU - 2), j = min(int(y), E_TABLE_R - 2);
    float tx = x - float(i), ty = y - float(j);
    int k = j * E_TABLE_MU + i;
    return mix(mix(etable[k], etable[k + 1], tx), mix(etable[k + E_TABLE_MU], etable[k + E_TABLE_MU + 1], tx), ty);
}
#endif


// ---- One surface under one light ----------------------------------------------------------------------

// A G-buffer pixel as the lobes read it: unit N, V (and T, B = N x T when anisotropic), perceptual roughness,
// the specular F0, the diffuse colour (base (1 - metallic)), and the per-pixel effect parameters.
struct Surface {
    vec3 N; vec3 V; vec3 T; vec3 B;
    float roughness;
    vec3 f0;
    vec3 diffuse_colour;
    float anisotropy;     // [-1, 1]; 0 = isotropic
    float coat;           // clear coat strength [0, 1]
    float coat_roughness;
    int diffuse;          // 0 none, 1 Lambert, 2 Burley (read when DIFFUSE == 3)
    vec3 energy;          // energy-compensation factor (1 when off)
};

// f_s of the surface for light direction L: the model's terms (specular_brdf_unit, unchanged), or anisotropic
// GGX where the pixel asks for it and the kernel has ANISOTROPY compiled in.
vec3 specular_lobe(Surface s, vec3 L) {
    vec3 fs = vec3(0);
    bool anisotropic = false;
    if (ANISOTROPY != 0) { // nested, not &&: a constant-false condition is then a dead branch for any optimiser
        if (s.anisotropy != 0.0) {
            fs = specular_anisotropic(s.N, s.V, L, s.T, s.B, s.roughness, s.anisotropy, s.f0);
            anisotropic = true;
        }
    }
    if (!anisotropic) {
        fs = specular_brdf_unit(s.N, s.V, L, s.roughness, s.f0);
    }
    return fs;
}

// f_d / diffuse colour for light direction L; 0 unless NoL > 0 and NoV > 0.
float diffuse_lobe(Surface s, vec3 L) {
    int mode = (DIFFUSE == 3) ? s.diffuse : DIFFUSE;
    float NoV = dot(s.N, s.V), NoL = dot(s.N, L);
    bool lit = NoV > 0.0 && NoL > 0.0;
    float fd = 0.0;
    if (mode == 1) {
        fd = Fd_Lambert();
    } else if (mode == 2) {
        vec3 H = safe_normalize(s.V + L);
        fd = Fd_Burley(guard_cos(NoV), guard_cos(NoL), guard_cos(dot(L, H)), s.roughness);
    }
    return lit ? fd : 0.0;
}

// Reflected radiance per unit incident radiance: (f_d NoLd + f_s NoLs spec_scale), the base under a clear coat
// scaled by (1 - Fc) plus the coat lobe [Filament surface_shading_model_standard.fs]. Ld lights the diffuse lobe,
// Ls the specular lobes (they differ for sphere lights, whose spec_scale is the representative point's
// normalisation; 1 otherwise).
vec3 shade(Surface s, vec3 Ld, vec3 Ls, float spec_scale) {
    float NoLd = max(dot(s.N, Ld), 0.0);
    float NoLs = max(dot(s.N, Ls), 0.0);
#ifdef BRDF_FILE_RETURNS_F_NOL
    // The file's entry returns f_s NoL with its own cosine (returns=f_nol); a file takes no anisotropy (the
    // scene refuses it), so its lobe is the file's alone.
    vec3 c = specular_brdf_unit(s.N, s.V, Ls, s.roughness, s.f0) * spec_scale;
#else
    vec3 c = specular_lobe(s, Ls) * (spec_scale * NoLs);
#endif
    if (ENERGY_COMPENSATION != 0) {
        c *= s.energy;
    }
    if (DIFFUSE != 0) {
        c += s.diffuse_colour * (diffuse_lobe(s, Ld) * NoLd);
    }
    if (CLEAR_COAT != 0) {
        vec3 H = safe_normalize(s.V + Ls);
        float Fc = clear_coat_fresnel(guard_cos(dot(Ls, H)), s.coat);
        c = c * (1.0 - Fc) + vec3(clear_coat_lobe(s.N, s.V, Ls, s.coat_roughness, s.coat) * spec_scale * NoLs);
    }
    return c;
}

#ifdef E_TABLE_BINDING
// The energy-compensation factor of a surface: Filament's 1 + F0 (1/E - 1) with E looked up at (NoV, r).
vec3 surface_energy(vec3 N, vec3 V, float roughness, vec3 f0) {
    return energy_compensation(clamp(f0, vec3(0), vec3(1)), e_lookup(dot(N, V), roughness));
}
#endif

#endif
