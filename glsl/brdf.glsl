// The specular term library: one function per term, each with the paper and formula it implements.
// Specialisation constants pick one D, one Vis and one F; the driver folds the switches, so a kernel
// carries only the terms its model uses. Term ids, guards and the metal table must match
// src/brdf/terms.rs and src/brdf/guards.rs (tests/terms_gpu.rs ties every GLSL term to its f64 twin).
// Compiled twice: fp32, and with -DBRDF_F16 for fp16 arithmetic (inputs and outputs stay fp32).
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

// ---- Selectors (specialisation constants) --------------------------------------------------------
layout(constant_id = 0) const int D_TERM = 0;
layout(constant_id = 1) const int VIS_TERM = 8;
layout(constant_id = 2) const int F_TERM = 1;
layout(constant_id = 3) const float GTR_GAMMA = 1.5;
layout(constant_id = 4) const int METAL = 0;

// D ids
#define D_GGX 0
#define D_BECKMANN 1
#define D_BLINN 2
#define D_GTR 3
#define D_CHARLIE 4
// Vis ids
#define VIS_IMPLICIT 0
#define VIS_NEUMANN 1
#define VIS_KELEMEN 2
#define VIS_VCAVITY 3
#define VIS_SCHLICK_BECKMANN 4
#define VIS_SCHLICK_GGX 5
#define VIS_SMITH_GGX_SEPARABLE 6
#define VIS_SMITH_GGX_CORRELATED 7
#define VIS_SMITH_GGX_JOINT_APPROX 8
#define VIS_SMITH_GGX_CORRELATED_FAST 9
#define VIS_HAMMON 10
#define VIS_SMITH_BECKMANN_SEPARABLE 11
#define VIS_SMITH_BECKMANN_CORRELATED 12
#define VIS_SMITH_BECKMANN_WALTER 13
// F ids
#define F_NONE 0
#define F_SCHLICK 1
#define F_SCHLICK_SG 2
#define F_SCHLICK_UE 3
#define F_SCHLICK_FILAMENT 4
#define F_DIELECTRIC 5
#define F_CONDUCTOR 6
#define F_F82 7

// ---- Guards (named once; README "Guards") ----------------------------------------------------------
#ifdef BRDF_F16
const float MIN_ROUGHNESS = 0.089; // Filament MIN_PERCEPTUAL_ROUGHNESS for mediump: a2 stays a normal fp16
#else
const float MIN_ROUGHNESS = 0.045; // Filament MIN_PERCEPTUAL_ROUGHNESS (highp)
#endif
const float MIN_COSINE = 1e-4;       // Filament MIN_N_DOT_V; NoV, NoL, NoH, VoH floor once a light is visible
const float MIN_VECTOR = 1.17549435e-38; // FLT_MIN: a vector whose largest component is below it counts as zero
const float GTR_SERIES_BAND = 0.05;  // |a2-1| below which the GTR normaliser uses its series (0/0 at a2 = 1)
const float F0_MAX = 0.9999;         // dielectric F0 cap: the IOR (1+sqrt F0)/(1-sqrt F0) is infinite at 1

const real PI = real(3.14159265358979);
const real INV_PI = real(0.318309886183791);

real pow5(real x) { real x2 = x * x; return x2 * x2 * x; }

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

// GTR normaliser c = (g-1)(a2-1) / (1 - a2^(1-g)) [Burley 2012, App. B]; g = 1: (a2-1)/ln(a2).
// Both forms are 0/0 at a2 = 1 (limit 1); within GTR_SERIES_BAND of it c = 1/S with
// S = 1 - g u/2 + g(g+1) u^2/6 - g(g+1)(g+2) u^3/24, u = a2-1 (truncation < 1e-5 there).
real gtr_normaliser(real a2, real g) {
    real u = a2 - real(1);
    real S = real(1) - g * u / real(2) + g * (g + real(1)) * u * u / real(6)
           - g * (g + real(1)) * (g + real(2)) * u * u * u / real(24);
    real closed = (GTR_GAMMA == 1.0) ? u / log(a2) : (g - real(1)) * u / (real(1) - pow(a2, real(1) - g));
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

real D_term(real NoH, real sin2h, real a) {
    switch (D_TERM) {
    case D_GGX: return D_Ggx(NoH, sin2h, a);
    case D_BECKMANN: return D_Beckmann(NoH, sin2h, a);
    case D_BLINN: return D_Blinn(NoH, sin2h, a);
    case D_GTR: return D_Gtr(NoH, sin2h, a);
    default: return D_Charlie(NoH, sin2h, a);
    }
}

// ---- Vis = G / (4 NoL NoV): masking-shadowing folded with the microfacet denominator ---------------

// Implicit [Hoffman 2010]: G = NoL NoV
real Vis_Implicit() { return real(0.25); }

// Neumann [Neumann et al. 1999]: G = NoL NoV / max(NoL, NoV)
real Vis_Neumann(real NoV, real NoL) { return real(0.25) / max(NoL, NoV); }

// Kelemen [Kelemen & Szirmay-Kalos 2001]: G = NoL NoV / VoH^2
real Vis_Kelemen(real VoH) { return real(0.25) / (VoH * VoH); }

// Cook-Torrance V-cavity [Cook & Torrance 1982, eq. 6]: G = min(1, 2 NoH NoV / VoH, 2 NoH NoL / VoH),
// divided through by 4 NoL NoV term by term: min(1/(4 NoL NoV), NoH / (2 VoH max(NoL, NoV))).
real Vis_VCavity(real NoV, real NoL, real NoH, real VoH) {
    return min(real(1) / (real(4) * NoL * NoV), NoH / (real(2) * VoH * max(NoL, NoV)));
}

// Schlick's separable Smith form with G1(x) = x / (x (1-k) + k) [Schlick 1994]
real vis_schlick(real NoV, real NoL, real k) {
    return real(0.25) / ((NoL * (real(1) - k) + k) * (NoV * (real(1) - k) + k));
}

// Schlick-Beckmann [Schlick 1994; Karis 2013]: k = a sqrt(2/pi)
real Vis_SchlickBeckmann(real NoV, real NoL, real a) { return vis_schlick(NoV, NoL, a * real(0.797884560802865)); }

// Schlick-GGX [Karis 2013]: k = a/2
real Vis_SchlickGgx(real NoV, real NoL, real a) { return vis_schlick(NoV, NoL, a * real(0.5)); }

// Smith GGX separable, exact [Walter et al. 2007, eq. 34]:
// 1 / ((NoV + sqrt(NoV (NoV - NoV a2) + a2)) (NoL + sqrt(NoL (NoL - NoL a2) + a2)))
real Vis_SmithGgxSeparable(real NoV, real NoL, real a) {
    real a2 = a * a;
    return real(1) / ((NoV + sqrt(NoV * (NoV - NoV * a2) + a2)) * (NoL + sqrt(NoL * (NoL - NoL * a2) + a2)));
}

// Smith GGX height-correlated, exact [Heitz 2014, eq. 99]:
// 0.5 / (NoL sqrt(NoV (NoV - NoV a2) + a2) + NoV sqrt(NoL (NoL - NoL a2) + a2))
real Vis_SmithGgxCorrelated(real NoV, real NoL, real a) {
    real a2 = a * a;
    return real(0.5) / (NoL * sqrt(NoV * (NoV - NoV * a2) + a2) + NoV * sqrt(NoL * (NoL - NoL * a2) + a2));
}

// UE Vis_SmithJointApprox [Heitz 2014; Karis, UE5 BRDF.ush]: 0.5 / (NoL (NoV (1-a) + a) + NoV (NoL (1-a) + a))
real Vis_SmithGgxJointApprox(real NoV, real NoL, real a) {
    return real(0.5) / (NoL * (NoV * (real(1) - a) + a) + NoV * (NoL * (real(1) - a) + a));
}

// Filament V_SmithGGXCorrelatedFast [Filament documentation, sec. 4.4.2]: the correlated form with the
// square roots removed, 0.5 / (NoL (NoV (1-a) + a) + NoV (NoL (1-a) + a)); the same function as UE's.
real Vis_SmithGgxCorrelatedFast(real NoV, real NoL, real a) {
    real GGXV = NoL * (NoV * (real(1) - a) + a);
    real GGXL = NoV * (NoL * (real(1) - a) + a);
    return real(0.5) / (GGXV + GGXL);
}

// Hammon [Hammon 2017, "PBR Diffuse Lighting for GGX+Smith Microsurfaces"]: 0.5 / mix(2 NoL NoV, NoL + NoV, a)
real Vis_Hammon(real NoV, real NoL, real a) {
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

// Smith Beckmann separable, exact erf Lambda: G = G1(v) G1(l), G1 = 1 / (1 + Lambda)
real Vis_SmithBeckmannSeparable(real NoV, real NoL, real a) {
    real G = real(1) / ((real(1) + lambda_beckmann(NoV, a)) * (real(1) + lambda_beckmann(NoL, a)));
    return G / (real(4) * NoL * NoV);
}

// Smith Beckmann height-correlated, exact erf Lambda [Heitz 2014, eq. 99]: G = 1 / (1 + Lambda(v) + Lambda(l))
real Vis_SmithBeckmannCorrelated(real NoV, real NoL, real a) {
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

real Vis_SmithBeckmannWalter(real NoV, real NoL, real a) {
    return g1_walter(NoV, a) * g1_walter(NoL, a) / (real(4) * NoL * NoV);
}

real Vis_term(real NoV, real NoL, real NoH, real VoH, real a) {
    switch (VIS_TERM) {
    case VIS_IMPLICIT: return Vis_Implicit();
    case VIS_NEUMANN: return Vis_Neumann(NoV, NoL);
    case VIS_KELEMEN: return Vis_Kelemen(VoH);
    case VIS_VCAVITY: return Vis_VCavity(NoV, NoL, NoH, VoH);
    case VIS_SCHLICK_BECKMANN: return Vis_SchlickBeckmann(NoV, NoL, a);
    case VIS_SCHLICK_GGX: return Vis_SchlickGgx(NoV, NoL, a);
    case VIS_SMITH_GGX_SEPARABLE: return Vis_SmithGgxSeparable(NoV, NoL, a);
    case VIS_SMITH_GGX_CORRELATED: return Vis_SmithGgxCorrelated(NoV, NoL, a);
    case VIS_SMITH_GGX_JOINT_APPROX: return Vis_SmithGgxJointApprox(NoV, NoL, a);
    case VIS_SMITH_GGX_CORRELATED_FAST: return Vis_SmithGgxCorrelatedFast(NoV, NoL, a);
    case VIS_HAMMON: return Vis_Hammon(NoV, NoL, a);
    case VIS_SMITH_BECKMANN_SEPARABLE: return Vis_SmithBeckmannSeparable(NoV, NoL, a);
    case VIS_SMITH_BECKMANN_CORRELATED: return Vis_SmithBeckmannCorrelated(NoV, NoL, a);
    default: return Vis_SmithBeckmannWalter(NoV, NoL, a);
    }
}

// ---- F: Fresnel, per RGB channel ----------------------------------------------------------------

// Metals: complex IOR n + ik at 650/550/450 nm (refractiveindex.info: Johnson & Christy 1972 for Au, Ag, Cu;
// Rakic 1995 for Al; Johnson & Christy 1974 for Fe), order gold, silver, copper, aluminium, iron.
// (A switch, not a const array: glslang 12 emits invalid SPIR-V when a spec constant indexes one.)
void metal_nk(out vec3 n, out vec3 k) {
    switch (METAL) {
    case 0: n = vec3(0.18299, 0.42108, 1.3734); k = vec3(3.4242, 2.3459, 1.7704); break;   // gold
    case 1: n = vec3(0.15943, 0.14512, 0.13547); k = vec3(3.9291, 3.19, 2.3808); break;   // silver
    case 2: n = vec3(0.27105, 0.67693, 1.3164); k = vec3(3.6092, 2.6248, 2.2921); break;  // copper
    case 3: n = vec3(1.3456, 0.96521, 0.61722); k = vec3(7.4746, 6.3995, 5.3031); break;  // aluminium
    default: n = vec3(2.9114, 2.9497, 2.5845); k = vec3(3.0893, 2.9318, 2.767); break;    // iron
    }
}

// No Fresnel [Karis 2013, "Specular BRDF Reference"]: F = F0
real3 F_None(real3 f0) { return f0; }

// Schlick [Schlick 1994, eq. 15]: F0 + (1 - F0)(1 - VoH)^5
real3 F_Schlick(real3 f0, real VoH) { return f0 + (real3(1) - f0) * pow5(real(1) - VoH); }

// Schlick with a spherical-Gaussian exponent [Karis 2013, p. 3]: F0 + (1 - F0) 2^((-5.55473 VoH - 6.98316) VoH)
real3 F_SchlickSg(real3 f0, real VoH) {
    return f0 + (real3(1) - f0) * exp2((real(-5.55473) * VoH - real(6.98316)) * VoH);
}

// UE5 F_Schlick [BRDF.ush]: f90 = saturate(50 F0.g) (pre-baked specular occlusion); F0 (1 - Fc) + f90 Fc
real3 F_SchlickUe(real3 f0, real VoH) {
    real Fc = pow5(real(1) - VoH);
    return clamp(real(50) * f0.g, real(0), real(1)) * Fc + (real(1) - Fc) * f0;
}

// Filament fresnel() [surface_brdf.fs]: f90 = saturate(dot(F0, 50 * 0.33)); F0 + (f90 - F0)(1 - VoH)^5
real3 F_SchlickFilament(real3 f0, real VoH) {
    real f90 = clamp(dot(f0, real3(real(50.0 * 0.33))), real(0), real(1));
    return f0 + (real3(f90) - f0) * pow5(real(1) - VoH);
}

// Exact unpolarised dielectric Fresnel [Walter et al. 2007, eq. 22], n = (1 + sqrt F0)/(1 - sqrt F0):
// g = sqrt(n^2 - 1 + c^2), F = (g-c)^2 / (2 (g+c)^2) (1 + ((c (g+c) - 1) / (c (g-c) + 1))^2), c = VoH
real F_DielectricChannel(real f0, real c) {
    real s = sqrt(min(f0, real(F0_MAX)));
    real n = (real(1) + s) / (real(1) - s);
    real g = sqrt(n * n - real(1) + c * c);
    real A = (g - c) / (g + c);
    real B = (c * (g + c) - real(1)) / (c * (g - c) + real(1));
    return real(0.5) * A * A * (real(1) + B * B);
}

real3 F_Dielectric(real3 f0, real VoH) {
    return real3(F_DielectricChannel(f0.r, VoH), F_DielectricChannel(f0.g, VoH), F_DielectricChannel(f0.b, VoH));
}

// Exact conductor Fresnel, complex IOR n + ik, unpolarised [Lagarde 2013, "Memo on Fresnel equations"]
real3 F_ConductorNK(real3 n, real3 k, real c) {
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

real3 F_Conductor(real VoH) {
    vec3 n, k;
    metal_nk(n, k);
    return F_ConductorNK(real3(n), real3(k), VoH);
}

// F82-tint [Kutz et al. 2021, "Novel aspects of the Adobe Standard Material"; Hoffman 2019]:
// Schlick(F0) - b VoH (1 - VoH)^6 with b = Schlick(F0, 1/7)(1 - tint) / ((1/7)(6/7)^6), fitted to the metal:
// F0 = F_conductor(1), tint = F_conductor(1/7) / Schlick(F0, 1/7), so it matches the conductor at 0 and 82 deg.
real3 F_F82Tint(real VoH) {
    const float MU_BAR = 1.0 / 7.0;
    vec3 n, k;
    metal_nk(n, k);
    vec3 f0 = vec3(F_ConductorNK(real3(n), real3(k), real(1)));
    vec3 schlick_bar = f0 + (vec3(1) - f0) * pow(1.0 - MU_BAR, 5.0);
    vec3 tint = vec3(F_ConductorNK(real3(n), real3(k), real(MU_BAR))) / schlick_bar;
    vec3 b = schlick_bar * (vec3(1) - tint) / (MU_BAR * pow(1.0 - MU_BAR, 6.0));
    real x = real(1) - VoH;
    return F_Schlick(real3(f0), VoH) - real3(b) * VoH * pow5(x) * x;
}

real3 F_term(real3 f0, real VoH) {
    switch (F_TERM) {
    case F_NONE: return F_None(f0);
    case F_SCHLICK: return F_Schlick(f0, VoH);
    case F_SCHLICK_SG: return F_SchlickSg(f0, VoH);
    case F_SCHLICK_UE: return F_SchlickUe(f0, VoH);
    case F_SCHLICK_FILAMENT: return F_SchlickFilament(f0, VoH);
    case F_DIELECTRIC: return F_Dielectric(f0, VoH);
    case F_CONDUCTOR: return F_Conductor(VoH);
    default: return F_F82Tint(VoH);
    }
}

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

real guard_cosine(real x) { return clamp(x, real(MIN_COSINE), real(1)); }

// f_s = D Vis F from cosines already guarded and sin2h = 1 - NoH^2 (the kernels' shared core).
real3 specular_from_cosines(real NoV, real NoL, real NoH, real VoH, real sin2h, real a, real3 f0) {
    return D_term(NoH, sin2h, a) * Vis_term(NoV, NoL, NoH, VoH, a) * F_term(f0, VoH);
}

// f_s for unit (or zero) N, V, L; 0 unless NoL > 0 and NoV > 0 (not multiplied by NoL).
vec3 specular_brdf_unit(vec3 N, vec3 V, vec3 L, float roughness, vec3 f0) {
    vec3 H = safe_normalize(V + L);
    real3 Nr = real3(N), Hr = real3(H);
    real NoV = dot(Nr, real3(V));
    real NoL = dot(Nr, real3(L));
    real3 NxH = cross(Nr, Hr);
    bool lit = NoV > real(0) && NoL > real(0);
    real3 fs = specular_from_cosines(guard_cosine(NoV), guard_cosine(NoL), guard_cosine(dot(Nr, Hr)),
                                     guard_cosine(dot(real3(V), Hr)), min(dot(NxH, NxH), real(1)),
                                     perceptual_to_alpha(roughness), real3(clamp(f0, vec3(0), vec3(1))));
    return mix(vec3(0), vec3(fs), bvec3(lit));
}

// f_s for unnormalised world-space n, v, l.
vec3 specular_brdf(vec3 n, vec3 v, vec3 l, float roughness, vec3 f0) {
    return specular_brdf_unit(safe_normalize(n), safe_normalize(v), safe_normalize(l), roughness, f0);
}

#endif
