#version 450
// Each selected term on its own, from cosines given directly (guards applied as in specular_brdf):
// ties every GLSL term to its f64 twin. Input: vec4 (NoV, NoL, NoH, VoH), vec4 (roughness, f0.rgb),
// vec4 (sin2h = 1 - NoH^2, -, -, -). Output: vec4 (D, Vis, 0, 0), vec4 (F.rgb, 0).
#extension GL_GOOGLE_include_directive : require
#include "brdf.glsl"

#include "elementwise.glsl"

void main() {
    uint i = gl_GlobalInvocationID.x;
    if (i >= pc.count) return;
    vec4 c = inputs[3 * i];
    vec4 rf = inputs[3 * i + 1];
    real sin2h = real(inputs[3 * i + 2].x);
    real NoV = guard_cosine(real(c.x)), NoL = guard_cosine(real(c.y));
    real NoH = guard_cosine(real(c.z)), VoH = guard_cosine(real(c.w));
    real a = perceptual_to_alpha(rf.x);
    outputs[2 * i] = vec4(float(D_term(NoH, sin2h, a)), float(Vis_term(NoV, NoL, NoH, VoH, a)), 0.0, 0.0);
    outputs[2 * i + 1] = vec4(vec3(F_term(real3(rf.yzw), VoH)), 0.0);
}
