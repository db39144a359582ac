// The profiling kernel's body: one G-buffer pixel per invocation, lit by NUM_LIGHTS directional lights per
// dispatch, out (+)= sum_j f_s(n, v, l_j) NoL_j colour_j. A profile of L lights runs ceil(L / LIGHT_BLOCK)
// dispatches of at most LIGHT_BLOCK lights each, each adding to what the earlier ones wrote (ACCUMULATE), as a
// lighting pass adds light volumes into its target. Shaped by what costs on lavapipe (docs/measurement.md):
// the block's lights are a uniform buffer at a dynamic offset, read with constant
// indices in a loop [[unroll]]ed over the block (a rolled loop turns light loads into per-lane gathers), so the
// unrolled code stays one block long at any light count. Light directions are unit vectors (normalised on the
// host, as engines pass them). No early return and no bounds check (buffers are padded to whole workgroups).
// BASELINE = 1 is the memory-only kernel: the same loads, decode, NoL and stores, no BRDF. Every kernel adds
// every input it loads times a factor no compiler can know (keep_inputs, always 0; a product, not a branch, so
// the kernels stay branch-free), so a BRDF that ignores an input cannot drop loads or decode the memory-only
// kernel keeps: no kernel undercuts it.
// The including kernel defines GBUFFER_PACKED (engine-style G-buffer, R11G11B10F output) or not (48-byte float
// pixels, fp32 output).
#extension GL_GOOGLE_include_directive : require
#extension GL_EXT_control_flow_attributes : require
#include "brdf.glsl"

layout(local_size_x = 64) in;
#ifdef GBUFFER_PACKED
// Per pixel, as a deferred renderer stores it (thesis 4.5.1, UE5 GBufferA/B/C): (octahedral normal, snorm
// 16:16), (metallic, specular, roughness, shading model: RGBA8), (base colour, AO: RGBA8), (depth, float bits).
// Read through a typed texel view (texelFetch), as a lighting pass reads its render targets; on lavapipe 22.3
// this is also far cheaper than a storage buffer, whose every access is a per-lane loop.
layout(set = 0, binding = 0) uniform usamplerBuffer gbuffer;
// The lighting target: R11G11B10F, 4 bytes per pixel (UE5's and Frostbite's HDR scene colour format).
layout(set = 0, binding = 1, r11f_g11f_b10f) uniform imageBuffer radiance;
#else
// Per pixel: vec4 (n.xyz, roughness), vec4 (v.xyz, metallic), vec4 (base colour, -).
layout(std430, set = 0, binding = 0) readonly buffer Pixels { vec4 pixels[]; };
layout(std430, set = 0, binding = 1) buffer Radiance { vec4 radiance[]; };
#endif
// This dispatch's block of lights: vec4 (l.xyz, -), vec4 (rgb, -) per light.
layout(std140, set = 0, binding = 2) uniform Lights { vec4 lights[2 * LIGHT_BLOCK]; };

// first_pixel: the chunk's first pixel in the picture (the binding windows start there). width: the picture's
// width. keep_inputs: 0 (see above). camera: sx = (x + 0.5) camera.x + camera.y and sy = (y + 0.5) camera.z +
// camera.w, the pinhole
// camera's image-plane coordinates of pixel (x, y); V is normalize(-sx, -sy, 1) (the camera at the origin
// looks down -z).
layout(push_constant) uniform Push {
    uint first_pixel;
    uint width;
    uint keep_inputs;
    uint pad1;
    vec4 camera;
} pc;

struct Pixel {
    vec3 N;
    vec3 V;
    float roughness;
    vec3 f0;
};

// Octahedral normal [Cigolle et al. 2014, "A Survey of Efficient Representations for Independent Unit
// Vectors", Listing 2]: the xy of the octahedron, folded over for z < 0.
vec3 octahedral_decode(vec2 e) {
    vec3 n = vec3(e, 1.0 - abs(e.x) - abs(e.y));
    float t = max(-n.z, 0.0);
    n.xy += mix(vec2(t), vec2(-t), greaterThanEqual(n.xy, vec2(0.0)));
    return n;
}

Pixel load_pixel(uint i) {
    Pixel p;
#ifdef GBUFFER_PACKED
    uvec4 g = texelFetch(gbuffer, int(i));
    p.N = safe_normalize(octahedral_decode(unpackSnorm2x16(g.x)));
    vec4 b = unpackUnorm4x8(g.y);
    vec4 c = unpackUnorm4x8(g.z);
    uint pixel = pc.first_pixel + i;
    vec2 s = (vec2(pixel % pc.width, pixel / pc.width) + 0.5) * pc.camera.xz + pc.camera.yw;
    p.V = safe_normalize(vec3(-s, 1.0));
    p.roughness = b.z;
    p.f0 = mix(vec3(0.04), c.rgb, b.x);
#ifdef BRDF_FILE
    file_basecolor = c.rgb;
    file_metallic = b.x;
#endif
#else
    vec4 nr = pixels[3 * i];
    vec4 vm = pixels[3 * i + 1];
    vec4 base = pixels[3 * i + 2];
    p.N = safe_normalize(nr.xyz);
    p.V = safe_normalize(vm.xyz);
    p.roughness = nr.w;
    p.f0 = mix(vec3(0.04), base.rgb, vm.w);
#ifdef BRDF_FILE
    file_basecolor = base.rgb;
    file_metallic = vm.w;
#endif
#endif
    return p;
}

vec3 load_radiance(uint i) {
#ifdef GBUFFER_PACKED
    return imageLoad(radiance, int(i)).rgb;
#else
    return radiance[i].rgb;
#endif
}

void store_radiance(uint i, vec3 c) {
#ifdef GBUFFER_PACKED
    imageStore(radiance, int(i), vec4(c, 0.0));
#else
    radiance[i] = vec4(c, 1.0);
#endif
}

#if defined(BRDF_FILE_KEEPS_LOOPS)
// One light's weighted f_s of a file's BRDF, as the loop below computes it.
vec3 file_light(Pixel p, vec3 L) {
#if defined(BRDF_FILE_RETURNS_F_NOL)
    return specular_brdf_unit(p.N, p.V, L, p.roughness, p.f0);
#else
    vec3 fs = (BASELINE != 0) ? vec3(1.0) : specular_brdf_unit(p.N, p.V, L, p.roughness, p.f0);
    return fs * max(dot(p.N, L), 0.0);
#endif
}
#endif

void main() {
    uint i = gl_GlobalInvocationID.x;
    Pixel p = load_pixel(i);
    vec3 acc = vec3(0.0);
#if defined(BRDF_FILE_KEEPS_LOOPS)
    // The file's BRDF has a loop no compiler can count (a data-dependent trip count). A loop holding a kept
    // loop is kept too ([[unroll]] and NIR unroll innermost loops only; ptxas kept it as well), and a kept light
    // loop is one light's work per pass where every cost rule divides by the block's lights: so the block is
    // written out, one call per light, each guarded by the block's size (folded by the specialisation).
#define ONE_LIGHT(j) if ((j) < NUM_LIGHTS) acc += file_light(p, lights[2 * (j)].xyz) * lights[2 * (j) + 1].rgb;
    ONE_LIGHT(0) ONE_LIGHT(1) ONE_LIGHT(2) ONE_LIGHT(3) ONE_LIGHT(4) ONE_LIGHT(5) ONE_LIGHT(6) ONE_LIGHT(7)
#if LIGHT_BLOCK != 8
#error "ONE_LIGHT is written out for a LIGHT_BLOCK of 8"
#endif
#else
    [[unroll]] for (int j = 0; j < NUM_LIGHTS; ++j) {
        vec3 L = lights[2 * j].xyz;
        vec3 colour = lights[2 * j + 1].rgb;
#if defined(BRDF_FILE_RETURNS_F_NOL)
        // The file's entry returns f_s NoL with its own cosine (returns=f_nol): taken as it is, no second NoL.
        acc += specular_brdf_unit(p.N, p.V, L, p.roughness, p.f0) * colour;
#elif defined(BRDF_FILE)
        // A file's f_s is weighted (f_s NoL) colour with NoL taken after the call, as its returns=f_nol form
        // weighs its own, so that one BRDF written in either form compiles to the same code.
        vec3 fs = (BASELINE != 0) ? vec3(1.0) : specular_brdf_unit(p.N, p.V, L, p.roughness, p.f0);
        acc += (fs * max(dot(p.N, L), 0.0)) * colour;
#else
        float NoL = max(dot(p.N, L), 0.0);
        vec3 fs = (BASELINE != 0) ? vec3(1.0) : specular_brdf_unit(p.N, p.V, L, p.roughness, p.f0);
        acc += fs * (NoL * colour);
#endif
    }
#endif
    acc += float(pc.keep_inputs) * (p.f0 + vec3(p.roughness) + p.V);
    if (ACCUMULATE != 0) acc += load_radiance(i);
    store_radiance(i, acc);
}
