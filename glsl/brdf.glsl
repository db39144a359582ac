// The specular term library: one function per term, each with the paper and formula it implements, named
// D_<Variant>, Vis_<Variant>, F_<Variant> after the rows of src/brdf/terms.rs, with one signature per kind.
// Specialisation constants pick one D, one Vis and one F; the driver folds the generated switches
// (generated/brdf_dispatch.glsl), so a kernel carries only the terms its model uses. Every GLSL term has an
// f64 twin (tests tie each pair and check that the citations match). Compiled twice: fp32, and with
// -DBRDF_F16 for fp16 arithmetic (inputs and outputs stay fp32).
#ifndef BRDF_GLSL
#define BRDF_GLSL

#ifdef BRDF_F16
#extension GL_EXT_shader_explicit_arithmetic_types_float16 : require
#define real float16_t
#define real3 f16vec3
#else
#define real float
#define real3 vec3
#endif

// Ids, selector and parameter constants, guards and the metal table, and every kernel-level specialisation
// constant, generated from the Rust tables.
#include "generated/brdf_table.glsl"
#include "generated/kernel_constants.glsl"

const float PI_F32 = 3.14159265358979;
const real PI = real(PI_F32);

float pow5(float x) { float x2 = x * x; return x2 * x2 * x; }
#ifdef BRDF_F16
float16_t pow5(float16_t x) { float16_t x2 = x * x; return x2 * x2 * x; }
#endif

// log(1 + x) accurate to a few ulps relative for |x| < 0.05, where GLSL's log(1 + x) is not (1 + x rounds, and
// drivers' log near 1 is only accurate in absolute terms, ~1e-7 on lavapipe): there, the Taylor series to x^6
// (truncation below 2e-9 relative); log(1 + x) elsewhere. GLSL has no log1p.
real log1p_accurate(real x) {
    real series = x * (real(1) + x * (real(-1.0 / 2.0) + x * (real(1.0 / 3.0) + x * (real(-1.0 / 4.0) + x * (real(1.0 / 5.0) + x * real(-1.0 / 6.0))))));
    return (abs(x) < real(0.05)) ? series : log(real(1) + x);
}

// ---- D: normal distribution functions, D(NoH; a) with a = roughness^2 -------------------------------
// Each D also receives sin2h = 1 - NoH^2 = |N x H|^2 (Lagrange's identity), computed from the vectors: near
// the peak 1 - NoH^2 from a rounded NoH, and NoH^2 (a2-1) + 1 at low roughness, lose most of their digits
// (Filament's D_GGX does the same). Every use below is an exact identity of the formula it cites.

// GGX / Trowbridge-Reitz [Walter et al. 2007, eq. 33]: a2 / (pi (NoH^2 (a2-1) + 1)^2),
// with NoH^2 (a2-1) + 1 = NoH^2 a2 + sin2h.
real D_Ggx(real NoH, real sin2h, real a) {
    real a2 = a * a;
    real d = NoH * NoH * a2 + sin2h;
    return a2 / (PI * d * d);
}

// Beckmann [Beckmann & Spizzichino 1963; Walter et al. 2007, eq. 25]:
// exp((NoH^2-1) / (a2 NoH^2)) / (pi a2 NoH^4), with NoH^2 - 1 = -sin2h.
real D_Beckmann(real NoH, real sin2h, real a) {
    real a2 = a * a;
    real NoH2 = NoH * NoH;
    return exp(-sin2h / (a2 * NoH2)) / (PI * a2 * NoH2 * NoH2);
}

// Normalised Blinn-Phong [Blinn 1977; m = 2/a2 - 2 from Walter et al. 2007]: (m+2)/(2 pi) NoH^m,
// with NoH^m = exp(m/2 log(1 - sin2h)): m reaches 5e5 at the roughness floor, where a rounded NoH is useless.
// The log stops at log(MIN_COSINE^2), as NoH stops at MIN_COSINE (so m = 0 at r = 1 gives NoH^0 = 1, not 0 x -inf).
real D_Blinn(real NoH, real sin2h, real a) {
    real m = real(2) / (a * a) - real(2);
    real log_noh2 = max(log1p_accurate(-sin2h), real(2.0 * log(MIN_COSINE)));
    return (m + real(2)) / (real(2) * PI) * exp(real(0.5) * m * log_noh2);
}

// expm1(t) / t: its series 1 + t/2 + t^2/6 + t^3/24 + t^4/120 for |t| < 0.1 (truncation < 2e-8), where
// (exp(t) - 1) / t cancels; that quotient beyond. GLSL has no expm1.
real expm1_over_t(real t) {
    real series = real(1) + t * (real(0.5) + t * (real(1.0 / 6.0) + t * (real(1.0 / 24.0) + t * real(1.0 / 120.0))));
    return (abs(t) < real(0.1)) ? series : (exp(t) - real(1)) / t;
}

// GTR normaliser c = (g-1)(a2-1) / (1 - a2^(1-g)) [Burley 2012, App. B]; g = 1: (a2-1)/ln(a2). Evaluated as
// u / (ln(a2) E(t)), u = a2-1, t = (1-g) ln(a2), E = expm1_over_t, an identity that does not cancel near g = 1
// (the closed form lost 0.5% at g = 1 +- 1e-6 at the roughness floor) and is the g = 1 form at g = 1. Both
// are 0/0 at a2 = 1 (limit 1); within GTR_SERIES_BAND of it c = 1/S with
// S = 1 - g u/2 + g(g+1) u^2/6 - g(g+1)(g+2) u^3/24 (truncation < 1e-5 there).
real gtr_normaliser(real a2, real g) {
    real u = a2 - real(1);
    real S = real(1) - g * u / real(2) + g * (g + real(1)) * u * u / real(6)
           - g * (g + real(1)) * (g + real(2)) * u * u * u / real(24);
    real l = log(a2);
    real closed = u / (l * expm1_over_t((real(1) - g) * l));
    return (abs(u) < real(GTR_SERIES_BAND)) ? real(1) / S : closed;
}

// Generalized Trowbridge-Reitz [Burley 2012, App. B, eq. 4]:
// (g-1)(a2-1) / (pi (1 - a2^(1-g)) (1 + (a2-1) NoH^2)^g); g = 1 and a2 -> 1 take their limits;
// 1 + (a2-1) NoH^2 = NoH^2 a2 + sin2h.
real D_Gtr(real NoH, real sin2h, real a) {
    real a2 = a * a;
    real g = real(GTR_GAMMA);
    real t = NoH * NoH * a2 + sin2h;
    return gtr_normaliser(a2, g) / (PI * pow(t, g));
}

// Charlie sheen [Estevez & Kulla 2017, eq. 2]: (2 + 1/a) sin(theta_h)^(1/a) / (2 pi), sin^2 = sin2h
real D_Charlie(real NoH, real sin2h, real a) {
    real inv_a = real(1) / a;
    return (real(2) + inv_a) * pow(sin2h, real(0.5) * inv_a) / (real(2) * PI);
}

// ---- Vis = G / (4 NoL NoV): masking-shadowing folded with the microfacet denominator ---------------

// Every Vis term takes (NoV, NoL, NoH, VoH, a) and reads what it needs.

// Implicit [Hoffman 2010]: G = NoL NoV
real Vis_Implicit(real NoV, real NoL, real NoH, real VoH, real a) { return real(0.25); }

// Neumann [Neumann et al. 1999]: G = NoL NoV / max(NoL, NoV)
real Vis_Neumann(real NoV, real NoL, real NoH, real VoH, real a) { return real(0.25) / max(NoL, NoV); }

real vis_kelemen(real VoH) { return real(0.25) / (VoH * VoH); }

// Kelemen [Kelemen & Szirmay-Kalos 2001]: G = NoL NoV / VoH^2
real Vis_Kelemen(real NoV, real NoL, real NoH, real VoH, real a) { return vis_kelemen(VoH); }

// Cook-Torrance V-cavity [Cook & Torrance 1982, eq. 6]: G = min(1, 2 NoH NoV / VoH, 2 NoH NoL / VoH),
// divided through by 4 NoL NoV term by term: min(1/(4 NoL NoV), NoH / (2 VoH max(NoL, NoV))).
real Vis_VCavity(real NoV, real NoL, real NoH, real VoH, real a) {
    return min(real(1) / (real(4) * NoL * NoV), NoH / (real(2) * VoH * max(NoL, NoV)));
}

// Schlick's separable Smith form with G1(x) = x / (x (1-k) + k) [Schlick 1994]
real vis_schlick(real NoV, real NoL, real k) {
    return real(0.25) / ((NoL * (real(1) - k) + k) * (NoV * (real(1) - k) + k));
}

// Schlick-Beckmann [Schlick 1994; Karis 2013]: k = a sqrt(2/pi)
real Vis_SchlickBeckmann(real NoV, real NoL, real NoH, real VoH, real a) { return vis_schlick(NoV, NoL, a * real(0.797884560802865)); }

// Schlick-GGX [Karis 2013]: k = a/2
real Vis_SchlickGgx(real NoV, real NoL, real NoH, real VoH, real a) { return vis_schlick(NoV, NoL, a * real(0.5)); }

// Schlick-GGX with Karis' remap for analytic lights [Karis 2013, p. 3; de Vries, LearnOpenGL "PBR: Theory" 2014]:
// k = (r + 1)^2 / 8, r = sqrt(a)
real Vis_SchlickGgxKaris(real NoV, real NoL, real NoH, real VoH, real a) {
    real r1 = sqrt(a) + real(1);
    return vis_schlick(NoV, NoL, r1 * r1 * real(0.125));
}

// Smith GGX separable, exact [Walter et al. 2007, eq. 34]:
// 1 / ((NoV + sqrt(NoV (NoV - NoV a2) + a2)) (NoL + sqrt(NoL (NoL - NoL a2) + a2)))
real Vis_SmithGgxSeparable(real NoV, real NoL, real NoH, real VoH, real a) {
    real a2 = a * a;
    return real(1) / ((NoV + sqrt(NoV * (NoV - NoV * a2) + a2)) * (NoL + sqrt(NoL * (NoL - NoL * a2) + a2)));
}

// Smith GGX height-correlated, exact [Heitz 2014, eq. 99]:
// 0.5 / (NoL sqrt(NoV (NoV - NoV a2) + a2) + NoV sqrt(NoL (NoL - NoL a2) + a2))
real Vis_SmithGgxCorrelated(real NoV, real NoL, real NoH, real VoH, real a) {
    real a2 = a * a;
    return real(0.5) / (NoL * sqrt(NoV * (NoV - NoV * a2) + a2) + NoV * sqrt(NoL * (NoL - NoL * a2) + a2));
}

// UE Vis_SmithJointApprox [Heitz 2014; Karis, UE5 BRDF.ush]: 0.5 / (NoL (NoV (1-a) + a) + NoV (NoL (1-a) + a))
real Vis_SmithGgxJointApprox(real NoV, real NoL, real NoH, real VoH, real a) {
    return real(0.5) / (NoL * (NoV * (real(1) - a) + a) + NoV * (NoL * (real(1) - a) + a));
}

// Filament V_SmithGGXCorrelatedFast [Filament documentation, sec. 4.4.2]: the correlated form with the
// square roots removed, 0.5 / (NoL (NoV (1-a) + a) + NoV (NoL (1-a) + a)); the same function as UE's.
real Vis_SmithGgxCorrelatedFast(real NoV, real NoL, real NoH, real VoH, real a) {
    real GGXV = NoL * (NoV * (real(1) - a) + a);
    real GGXL = NoV * (NoL * (real(1) - a) + a);
    return real(0.5) / (GGXV + GGXL);
}

// Hammon [Hammon 2017, "PBR Diffuse Lighting for GGX+Smith Microsurfaces"]: 0.5 / mix(2 NoL NoV, NoL + NoV, a)
real Vis_Hammon(real NoV, real NoL, real NoH, real VoH, real a) {
    return real(0.5) / mix(real(2) * NoL * NoV, NoL + NoV, a);
}

// erf, Abramowitz & Stegun 7.1.26 (|error| < 1.5e-7); GLSL has none.
real erf_as(real x) {
    real t = real(1) / (real(1) + real(0.3275911) * abs(x));
    real y = real(1) - (((((real(1.061405429) * t - real(1.453152027)) * t) + real(1.421413741)) * t
             - real(0.284496736)) * t + real(0.254829592)) * t * exp(-x * x);
    return sign(x) * y;
}

// Smith Lambda for Beckmann, exact [Walter et al. 2007, eq. 25 / Heitz 2014, eq. 80]:
// (erf(c) - 1)/2 + exp(-c^2) / (2 c sqrt(pi)), c = cos / (a sin).
real lambda_beckmann(real cosv, real a) {
    real c = cosv / (a * sqrt(max(real(1) - cosv * cosv, real(MIN_COSINE * MIN_COSINE))));
    return (erf_as(c) - real(1)) * real(0.5) + exp(-c * c) / (real(3.544907701811032) * c);
}

// Smith Beckmann separable, exact erf Lambda [Walter et al. 2007, eq. 25]: G = G1(v) G1(l), G1 = 1 / (1 + Lambda)
real Vis_SmithBeckmannSeparable(real NoV, real NoL, real NoH, real VoH, real a) {
    real G = real(1) / ((real(1) + lambda_beckmann(NoV, a)) * (real(1) + lambda_beckmann(NoL, a)));
    return G / (real(4) * NoL * NoV);
}

// Smith Beckmann height-correlated, exact erf Lambda [Heitz 2014, eq. 99]: G = 1 / (1 + Lambda(v) + Lambda(l))
real Vis_SmithBeckmannCorrelated(real NoV, real NoL, real NoH, real VoH, real a) {
    real G = real(1) / (real(1) + lambda_beckmann(NoV, a) + lambda_beckmann(NoL, a));
    return G / (real(4) * NoL * NoV);
}

// Walter's rational G1 for Beckmann [Walter et al. 2007, eq. 27]: c = cos/(a sin);
// c < 1.6: (3.535 c + 2.181 c^2) / (1 + 2.276 c + 2.577 c^2), else 1. Separable: G = G1(v) G1(l).
real g1_walter(real cosv, real a) {
    real c = cosv / (a * sqrt(max(real(1) - cosv * cosv, real(MIN_COSINE * MIN_COSINE))));
    real g = (real(3.535) * c + real(2.181) * c * c) / (real(1) + real(2.276) * c + real(2.577) * c * c);
    return (c < real(1.6)) ? g : real(1);
}

// Smith Beckmann, Walter's rational G1 [Walter et al. 2007, eq. 27], separable: G = G1(v) G1(l)
real Vis_SmithBeckmannWalter(real NoV, real NoL, real NoH, real VoH, real a) {
    return g1_walter(NoV, a) * g1_walter(NoL, a) / (real(4) * NoL * NoV);
}

// ---- F: Fresnel, per RGB channel ----------------------------------------------------------------

// Every F term takes (f0, VoH).

// Schlick with a reflectance at grazing: F0 + (f90 - F0) (1 - VoH)^5, the form every Schlick term below shares.
real3 schlick_f90(real3 f0, real3 f90, real VoH) { return f0 + (f90 - f0) * pow5(real(1) - VoH); }

// No Fresnel [Karis 2013, "Specular BRDF Reference"]: F = F0
real3 F_None(real3 f0, real VoH) { return f0; }

// Schlick [Schlick 1994, eq. 15]: F0 + (1 - F0)(1 - VoH)^5
real3 F_Schlick(real3 f0, real VoH) { return schlick_f90(f0, real3(1), VoH); }

// Schlick with a spherical-Gaussian exponent [Karis 2013, p. 3]: F0 + (1 - F0) 2^((-5.55473 VoH - 6.98316) VoH)
real3 F_SchlickSg(real3 f0, real VoH) {
    return f0 + (real3(1) - f0) * exp2((real(-5.55473) * VoH - real(6.98316)) * VoH);
}

// UE5 F_Schlick [BRDF.ush]: F0 + (f90 - F0) Fc with f90 = saturate(50 F0.g) (pre-baked specular occlusion)
real3 F_SchlickUe(real3 f0, real VoH) {
    return schlick_f90(f0, real3(clamp(real(50) * f0.g, real(0), real(1))), VoH);
}

// Filament fresnel() [surface_brdf.fs]: f90 = saturate(dot(F0, 50 * 0.33)); F0 + (f90 - F0)(1 - VoH)^5
real3 F_SchlickFilament(real3 f0, real VoH) {
    return schlick_f90(f0, real3(clamp(dot(f0, real3(real(50.0 * 0.33))), real(0), real(1))), VoH);
}

// g = sqrt(n^2 - 1 + c^2), F = (g-c)^2 / (2 (g+c)^2) (1 + ((c (g+c) - 1) / (c (g-c) + 1))^2), c = VoH,
// for one channel, n = (1 + sqrt F0)/(1 - sqrt F0) with F0 capped at F0_MAX.
real dielectric_channel(real f0, real c) {
    real s = sqrt(min(f0, real(F0_MAX)));
    real n = (real(1) + s) / (real(1) - s);
    real g = sqrt(n * n - real(1) + c * c);
    real A = (g - c) / (g + c);
    real B = (c * (g + c) - real(1)) / (c * (g - c) + real(1));
    return real(0.5) * A * A * (real(1) + B * B);
}

// Exact unpolarised dielectric Fresnel [Walter et al. 2007, eq. 22], IOR n = (1 + sqrt F0)/(1 - sqrt F0)
real3 F_Dielectric(real3 f0, real VoH) {
    return real3(dielectric_channel(f0.r, VoH), dielectric_channel(f0.g, VoH), dielectric_channel(f0.b, VoH));
}

// The unpolarised conductor Fresnel of complex IOR n + ik [Lagarde 2013, "Memo on Fresnel equations"]
real3 conductor_nk(real3 n, real3 k, real c) {
    real c2 = c * c;
    real s2 = real(1) - c2;
    real3 n2 = n * n, k2 = k * k;
    real3 t0 = n2 - k2 - real3(s2);
    real3 a2b2 = sqrt(t0 * t0 + real(4) * n2 * k2);
    real3 t1 = a2b2 + real3(c2);
    real3 a = sqrt(real(0.5) * (a2b2 + t0));
    real3 t2 = real(2) * c * a;
    real3 Rs = (t1 - t2) / (t1 + t2);
    real3 t3 = c2 * a2b2 + real3(s2 * s2);
    real3 t4 = t2 * s2;
    real3 Rp = Rs * (t3 - t4) / (t3 + t4);
    return real(0.5) * (Rp + Rs);
}

// Exact unpolarised conductor Fresnel, complex IOR n + ik [Lagarde 2013, "Memo on Fresnel equations"]
real3 F_Conductor(real3 f0, real VoH) {
    vec3 n, k;
    metal_nk(n, k);
    return conductor_nk(real3(n), real3(k), VoH);
}

// F82-tint [Kutz et al. 2021, "Novel aspects of the Adobe Standard Material"; Hoffman 2019]:
// Schlick(F0) - b VoH (1 - VoH)^6 with b = Schlick(F0, 1/7)(1 - tint) / ((1/7)(6/7)^6), fitted to the metal:
// F0 = F_conductor(1), tint = F_conductor(1/7) / Schlick(F0, 1/7), so it matches the conductor at 0 and 82 deg.
real3 F_F82Tint(real3 sample_f0, real VoH) {
    const float MU_BAR = 1.0 / 7.0;
    vec3 n, k;
    metal_nk(n, k);
    vec3 f0 = vec3(conductor_nk(real3(n), real3(k), real(1)));
    vec3 schlick_bar = f0 + (vec3(1) - f0) * pow(1.0 - MU_BAR, 5.0);
    vec3 tint = vec3(conductor_nk(real3(n), real3(k), real(MU_BAR))) / schlick_bar;
    vec3 b = schlick_bar * (vec3(1) - tint) / (MU_BAR * pow(1.0 - MU_BAR, 6.0));
    real x = real(1) - VoH;
    return F_Schlick(real3(f0), VoH) - real3(b) * VoH * pow5(x) * x;
}

// The dispatch switches, generated from the Rust tables.
#include "generated/brdf_dispatch.glsl"

// ---- Geometry and the assembled specular BRDF -------------------------------------------------------

// Unit vector, robust to any finite length (scaled by its largest component first);
// 0 when that component is below MIN_VECTOR, so a zero or denormal vector gives no light.
vec3 safe_normalize(vec3 v) {
    float m = max(max(abs(v.x), abs(v.y)), abs(v.z));
    vec3 u = v * (1.0 / max(m, MIN_VECTOR));
    return (m >= MIN_VECTOR) ? u * inversesqrt(dot(u, u)) : vec3(0);
}

real perceptual_to_alpha(float roughness) {
    float r = clamp(roughness, MIN_ROUGHNESS, 1.0);
    return real(r * r);
}

// A visible cosine into [MIN_COSINE, 1]; without the cosine-floor guard into [0, 1], as engines saturate.
real guard_cosine(real x) { return clamp(x, guarded(GUARD_COSINE_FLOOR) ? real(MIN_COSINE) : real(0), real(1)); }

// f_s = D Vis F from cosines already guarded and sin2h = 1 - NoH^2 (the kernels' shared core).
real3 specular_from_cosines(real NoV, real NoL, real NoH, real VoH, real sin2h, real a, real3 f0) {
    return D_term(NoH, sin2h, a) * Vis_term(NoV, NoL, NoH, VoH, a) * F_term(f0, VoH);
}

#ifdef BRDF_FILE
// A user's .brdf file composed before this library (src/model/file_model.rs): f_s is the file's BRDF(L, V, N,
// X, Y), returned as is, with its bound parameters (BRDF_FILE_BIND) set from this call's inputs and the
// material and tangent the kernel sets below.
vec3 file_tangent = vec3(0.0);
vec3 file_basecolor = vec3(0.0);
float file_metallic = 1.0;

// |t - N (N.t)|^2 / |t|^2 below which a tangent counts as parallel to N (TANGENT_PARALLEL in file_model.rs).
const float FILE_TANGENT_PARALLEL = 1e-6;

// X of the tangent frame: t made orthogonal to N, or, for t = 0 or parallel to N, the first vector of the
// branchless orthonormal basis [Duff et al. 2017, "Building an Orthonormal Basis, Revisited", Listing 3].
vec3 file_tangent_frame(vec3 N, vec3 t) {
    vec3 x = t - N * dot(N, t);
    float len2 = dot(x, x), t2 = dot(t, t);
    if (t2 > 0.0 && len2 > FILE_TANGENT_PARALLEL * t2) return x * inversesqrt(len2);
    float s = (N.z >= 0.0) ? 1.0 : -1.0;
    float a = -1.0 / (s + N.z);
    float b = N.x * N.y * a;
    return vec3(1.0 + s * N.x * N.x * a, s * b, -s * N.x);
}

vec3 specular_brdf_unit(vec3 N, vec3 V, vec3 L, float roughness, vec3 f0) {
    BRDF_FILE_BIND
    vec3 X = file_tangent_frame(N, file_tangent);
    return BRDF_FILE_FUNCTION(L, V, N, X, cross(N, X));
}
#else
// f_s for unit (or zero) N, V, L; 0 unless NoL > 0 and NoV > 0 (not multiplied by NoL).
vec3 specular_brdf_unit(vec3 N, vec3 V, vec3 L, float roughness, vec3 f0) {
    // The switchable guards (GUARDS, a specialisation constant: the driver folds every `guarded` test).
    vec3 H = guarded(GUARD_SAFE_H) ? safe_normalize(V + L) : normalize(V + L);
    real3 Nr = real3(N), Hr = real3(H);
    real NoV = dot(Nr, real3(V));
    real NoL = dot(Nr, real3(L));
    real NoH = guard_cosine(dot(Nr, Hr));
    real3 NxH = cross(Nr, Hr);
    real sin2h = guarded(GUARD_SIN2H) ? min(dot(NxH, NxH), real(1)) : real(1) - NoH * NoH;
    real3 F0 = real3(guarded(GUARD_F0_CLAMP) ? clamp(f0, vec3(0), vec3(1)) : f0);
    bool lit = NoV > real(0) && NoL > real(0);
    real3 fs = specular_from_cosines(guard_cosine(NoV), guard_cosine(NoL), NoH, guard_cosine(dot(real3(V), Hr)), sin2h,
                                     perceptual_to_alpha(roughness), F0);
    return guarded(GUARD_LIT_MASK) ? mix(vec3(0), vec3(fs), bvec3(lit)) : vec3(fs);
}
#endif

// f_s for unnormalised world-space n, v, l.
vec3 specular_brdf(vec3 n, vec3 v, vec3 l, float roughness, vec3 f0) {
    return specular_brdf_unit(safe_normalize(n), safe_normalize(v), safe_normalize(l), roughness, f0);
}

#endif
