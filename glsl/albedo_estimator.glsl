// Directional albedo E(v) = integral of the reflected radiance over the hemisphere of light directions, one
// azimuth row per invocation. Importance sampling with a defensive mixture that suits every D without a sampler
// per D: a third of the samples draw a GGX(a) half-vector (lobes around the normal), a third a half-vector with
// cos theta_h = u^2, dense towards the horizon (heavy tails, Charlie's grazing lobe), a third a cosine-weighted
// l; each weighs the integrand / pdf with pdf the mixture's density [Veach 1997, one-sample MIS, balance
// heuristic]. Each component has its own midpoint grid of ALBEDO_N columns u1 (exactly a third of the samples,
// evenly spaced), and there are ALBEDO_N rows in azimuth; a row returns its mean and the mean over its even
// columns, from which the host forms E and a half-resolution estimate (their difference is the error bound it
// reports). N = +z, V in the xz plane.
// The including kernel defines `vec3 albedo_integrand(vec3 L)` (the radiance reflected towards V per unit
// radiance from L, NoL included) before including this file.
#ifndef ALBEDO_ESTIMATOR_GLSL
#define ALBEDO_ESTIMATOR_GLSL

// The proposal's GGX density of half-vectors, D(h) NoH, in fp32 whatever the model's precision.
float ggx_pdf_h(float NoH, float a) {
    float a2 = a * a;
    float d = NoH * NoH * (a2 - 1.0) + 1.0;
    return a2 / (PI_F32 * d * d) * NoH;
}

// Row `row` of the estimator for view V and proposal roughness a: its mean and its even columns' mean.
void albedo_row(vec3 V, float a, uint row, out vec3 mean, out vec3 even_mean) {
    float phi = 2.0 * PI_F32 * (float(row) + 0.5) / float(ALBEDO_N);
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
        float horizon_h = 1.0 / (4.0 * PI_F32 * sqrt(max(H.z, 1e-12)));
        float pdf = ((ggx_pdf_h(H.z, a) + horizon_h) / (4.0 * VoH) + NoL / PI_F32) / 3.0;
        vec3 w = albedo_integrand(L) / pdf;
        sum += w;
        if ((column & 1) == 0) even += w;
    }
    mean = sum / float(3 * ALBEDO_N);
    even_mean = even / float(3 * (ALBEDO_N / 2));
}

#endif
