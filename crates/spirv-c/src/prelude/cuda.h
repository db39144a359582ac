// ---- brdfprof prelude: CUDA C++ for NVRTC (no headers: NVRTC's built-in device functions only) ----
// Precision is the compiler options' to decide (brdfprof passes -use_fast_math: approximate division,
// square root, exp2/log2-based pow, denormals flushed, as a Vulkan driver may; see docs/targets.md).
typedef unsigned char u8;
typedef unsigned short u16;
typedef unsigned int u32;
typedef int i32;
typedef unsigned long long u64;
#define GLOBAL
#define BRDFPROF_FN static __device__ __forceinline__
// A lookup table as one object read in place (constants.rs, `define_large`).
#define BRDFPROF_CONST_TABLE static __constant__ const
#define BRDFPROF_TABLE_SPACE
#define BRDFPROF_LOOP_LIMIT(env) 0

// fp16 as its bits, with PTX's f16 instructions (sm_53 and later): add, sub, mul, fma and negation in half
// precision; division and everything else in f32 between exact conversions.
typedef struct { unsigned short b; } half_t;
BRDFPROF_FN half_t h_from_bits(u32 b) { half_t h; h.b = (unsigned short)b; return h; }
BRDFPROF_FN u32 h_bits(half_t h) { return h.b; }
BRDFPROF_FN float h_to_f32(half_t h) { float f; asm("cvt.f32.f16 %0, %1;" : "=f"(f) : "h"(h.b)); return f; }
BRDFPROF_FN half_t h_from_f32(float f) { half_t h; asm("cvt.rn.f16.f32 %0, %1;" : "=h"(h.b) : "f"(f)); return h; }
BRDFPROF_FN half_t h_add(half_t a, half_t b) { half_t r; asm("add.f16 %0, %1, %2;" : "=h"(r.b) : "h"(a.b), "h"(b.b)); return r; }
BRDFPROF_FN half_t h_sub(half_t a, half_t b) { half_t r; asm("sub.f16 %0, %1, %2;" : "=h"(r.b) : "h"(a.b), "h"(b.b)); return r; }
BRDFPROF_FN half_t h_mul(half_t a, half_t b) { half_t r; asm("mul.f16 %0, %1, %2;" : "=h"(r.b) : "h"(a.b), "h"(b.b)); return r; }
BRDFPROF_FN half_t h_fma(half_t a, half_t b, half_t c) { half_t r; asm("fma.rn.f16 %0, %1, %2, %3;" : "=h"(r.b) : "h"(a.b), "h"(b.b), "h"(c.b)); return r; }
BRDFPROF_FN half_t h_neg(half_t a) { half_t r; asm("neg.f16 %0, %1;" : "=h"(r.b) : "h"(a.b)); return r; }
BRDFPROF_FN half_t h_div(half_t a, half_t b) { return h_from_f32(h_to_f32(a) / h_to_f32(b)); }
// Comparisons (ordered, as PTX's setp.f16) and min/max (PTX's min.f16 and max.f16 from sm_80; before that in
// f32, exact) in half precision, so that no conversion stands where a native fp16 compiler would put none.
#define BRDFPROF_H_CMP(name, rel) BRDFPROF_FN bool name(half_t a, half_t b) { u32 r; asm("{ .reg .pred p; setp." rel ".f16 p, %1, %2; selp.u32 %0, 1, 0, p; }" : "=r"(r) : "h"(a.b), "h"(b.b)); return r != 0u; }
BRDFPROF_H_CMP(h_lt, "lt") BRDFPROF_H_CMP(h_le, "le") BRDFPROF_H_CMP(h_gt, "gt") BRDFPROF_H_CMP(h_ge, "ge") BRDFPROF_H_CMP(h_eq, "eq")
#if __CUDA_ARCH__ >= 800
BRDFPROF_FN half_t h_min(half_t a, half_t b) { half_t r; asm("min.f16 %0, %1, %2;" : "=h"(r.b) : "h"(a.b), "h"(b.b)); return r; }
BRDFPROF_FN half_t h_max(half_t a, half_t b) { half_t r; asm("max.f16 %0, %1, %2;" : "=h"(r.b) : "h"(a.b), "h"(b.b)); return r; }
#else
BRDFPROF_FN half_t h_min(half_t a, half_t b) { return h_from_f32(fminf(h_to_f32(a), h_to_f32(b))); }
BRDFPROF_FN half_t h_max(half_t a, half_t b) { return h_from_f32(fmaxf(h_to_f32(a), h_to_f32(b))); }
#endif

BRDFPROF_FN u32 f32_bits(float x) { return __float_as_uint(x); }
BRDFPROF_FN float f32_from_bits(u32 b) { return __uint_as_float(b); }
BRDFPROF_FN double f64_from_bits(u64 b) { return __longlong_as_double((long long)b); }

BRDFPROF_FN float m_fdiv(float a, float b) { return a / b; }
BRDFPROF_FN float m_sqrt(float x) { return sqrtf(x); }
BRDFPROF_FN float m_rsqrt(float x) { return rsqrtf(x); }
BRDFPROF_FN float m_exp(float x) { return expf(x); }
BRDFPROF_FN float m_exp2(float x) { return exp2f(x); }
BRDFPROF_FN float m_log(float x) { return logf(x); }
BRDFPROF_FN float m_log2(float x) { return log2f(x); }
BRDFPROF_FN float m_pow(float x, float y) { return powf(x, y); }
BRDFPROF_FN float m_sin(float x) { return sinf(x); }
BRDFPROF_FN float m_cos(float x) { return cosf(x); }
BRDFPROF_FN float m_tan(float x) { return tanf(x); }
BRDFPROF_FN float m_asin(float x) { return asinf(x); }
BRDFPROF_FN float m_acos(float x) { return acosf(x); }
BRDFPROF_FN float m_atan(float x) { return atanf(x); }
BRDFPROF_FN float m_atan2(float y, float x) { return atan2f(y, x); }
BRDFPROF_FN float m_sinh(float x) { return sinhf(x); }
BRDFPROF_FN float m_cosh(float x) { return coshf(x); }
BRDFPROF_FN float m_tanh(float x) { return tanhf(x); }
BRDFPROF_FN float m_asinh(float x) { return asinhf(x); }
BRDFPROF_FN float m_acosh(float x) { return acoshf(x); }
BRDFPROF_FN float m_atanh(float x) { return atanhf(x); }
BRDFPROF_FN float m_floor(float x) { return floorf(x); }
BRDFPROF_FN float m_ceil(float x) { return ceilf(x); }
BRDFPROF_FN float m_trunc(float x) { return truncf(x); }
BRDFPROF_FN float m_round(float x) { return roundf(x); }
BRDFPROF_FN float m_rint(float x) { return rintf(x); }
BRDFPROF_FN float m_fabs(float x) { return fabsf(x); }
BRDFPROF_FN float m_fmin(float a, float b) { return fminf(a, b); }
BRDFPROF_FN float m_fmax(float a, float b) { return fmaxf(a, b); }
BRDFPROF_FN float m_fma(float a, float b, float c) { return fmaf(a, b, c); }
BRDFPROF_FN float m_ldexp(float x, i32 e) { return ldexpf(x, e); }
BRDFPROF_FN float m_fmod(float a, float b) { return fmodf(a, b); }
BRDFPROF_FN bool m_isnan(float x) { return isnan(x); }
BRDFPROF_FN bool m_isinf(float x) { return isinf(x); }
#define m_sqrt_d sqrt
#define m_rsqrt_d rsqrt
#define m_exp_d exp
#define m_exp2_d exp2
#define m_log_d log
#define m_log2_d log2
#define m_pow_d pow
#define m_sin_d sin
#define m_cos_d cos
#define m_tan_d tan
#define m_asin_d asin
#define m_acos_d acos
#define m_atan_d atan
#define m_atan2_d atan2
#define m_floor_d floor
#define m_ceil_d ceil
#define m_trunc_d trunc
#define m_round_d round
#define m_rint_d rint
#define m_fabs_d fabs
#define m_fmin_d fmin
#define m_fmax_d fmax
#define m_fma_d fma

// Integer division as the hardware does it (SPIR-V leaves a zero divisor undefined).
BRDFPROF_FN u32 m_udiv(u32 a, u32 b) { return a / b; }
BRDFPROF_FN u32 m_umod(u32 a, u32 b) { return a % b; }
BRDFPROF_FN i32 m_sdiv(i32 a, i32 b) { return a / b; }
BRDFPROF_FN i32 m_srem(i32 a, i32 b) { return a % b; }

// Buffers: byte addresses; read-only bindings through the read-only data cache (LDG.CONSTANT), as NVIDIA
// reads a read-only storage buffer or a texel buffer.
BRDFPROF_FN u32 ld_u32(const u8* p, u32 off) { return *(const u32*)(p + off); }
BRDFPROF_FN i32 ld_i32(const u8* p, u32 off) { return *(const i32*)(p + off); }
BRDFPROF_FN float ld_f32(const u8* p, u32 off) { return *(const float*)(p + off); }
BRDFPROF_FN half_t ld_f16(const u8* p, u32 off) { return h_from_bits(*(const u16*)(p + off)); }
BRDFPROF_FN double ld_f64(const u8* p, u32 off) { return *(const double*)(p + off); }
BRDFPROF_FN u32 ldro_u32(const u8* p, u32 off) { return __ldg((const unsigned int*)(p + off)); }
BRDFPROF_FN i32 ldro_i32(const u8* p, u32 off) { return __ldg((const int*)(p + off)); }
BRDFPROF_FN float ldro_f32(const u8* p, u32 off) { return __ldg((const float*)(p + off)); }
BRDFPROF_FN half_t ldro_f16(const u8* p, u32 off) { return h_from_bits(__ldg((const unsigned short*)(p + off))); }
BRDFPROF_FN double ldro_f64(const u8* p, u32 off) { return __ldg((const double*)(p + off)); }
BRDFPROF_FN void ld4_f32(const u8* p, u32 off, float* o) { float4 v = *(const float4*)(p + off); o[0] = v.x; o[1] = v.y; o[2] = v.z; o[3] = v.w; }
BRDFPROF_FN void ldro4_f32(const u8* p, u32 off, float* o) { float4 v = __ldg((const float4*)(p + off)); o[0] = v.x; o[1] = v.y; o[2] = v.z; o[3] = v.w; }
BRDFPROF_FN void ld4_u32(const u8* p, u32 off, u32* o) { uint4 v = *(const uint4*)(p + off); o[0] = v.x; o[1] = v.y; o[2] = v.z; o[3] = v.w; }
BRDFPROF_FN void ldro4_u32(const u8* p, u32 off, u32* o) { uint4 v = __ldg((const uint4*)(p + off)); o[0] = v.x; o[1] = v.y; o[2] = v.z; o[3] = v.w; }
// Uniform and push-constant blocks in constant memory, as a CUDA author keeps them: one `__constant__` array
// per block (the host fills it with cudaMemcpyToSymbol), read at offsets ptxas folds into `c[bank][offset]`
// operands.
#define BRDFPROF_CONSTANT_BLOCK(name, bytes) __constant__ __align__(16) u8 brdfprof_cb_##name[bytes];
#define BRDFPROF_CONSTANT_FIELD(name)
#define BRDFPROF_CONSTANT_REF(env, name) brdfprof_cb_##name
BRDFPROF_FN u32 ldc_u32(const u8* p, u32 off) { return *(const u32*)(p + off); }
BRDFPROF_FN i32 ldc_i32(const u8* p, u32 off) { return *(const i32*)(p + off); }
BRDFPROF_FN float ldc_f32(const u8* p, u32 off) { return *(const float*)(p + off); }
BRDFPROF_FN half_t ldc_f16(const u8* p, u32 off) { return h_from_bits(*(const u16*)(p + off)); }
BRDFPROF_FN double ldc_f64(const u8* p, u32 off) { return *(const double*)(p + off); }
BRDFPROF_FN void ldc4_f32(const u8* p, u32 off, float* o) { float4 v = *(const float4*)(p + off); o[0] = v.x; o[1] = v.y; o[2] = v.z; o[3] = v.w; }
BRDFPROF_FN void ldc4_u32(const u8* p, u32 off, u32* o) { uint4 v = *(const uint4*)(p + off); o[0] = v.x; o[1] = v.y; o[2] = v.z; o[3] = v.w; }
// A writable R11G11B10F texel buffer is a surface object, stored to with PTX's formatted surface store
// (`sust.p`, SASS SUST.P: the texture unit converts to the surface's format, as NVIDIA's Vulkan driver stores
// a storage texel buffer) and read with an unformatted 32-bit load (`suld.b`, byte addressed) decoded here.
#define BRDFPROF_NATIVE_R11G11B10F 1
typedef unsigned long long brdfprof_surface;
#define BRDFPROF_SURFACE_FIELD(name) brdfprof_surface name;
BRDFPROF_FN void brdfprof_surface_st_rgb(brdfprof_surface s, u32 i, float r, float g, float b) {
  asm volatile("sust.p.1d.v4.b32.trap [%0, {%1}], {%2, %3, %4, %5};" :: "l"(s), "r"(i), "r"(__float_as_uint(r)), "r"(__float_as_uint(g)), "r"(__float_as_uint(b)), "r"(0u) : "memory");
}
BRDFPROF_FN u32 brdfprof_surface_ld32(brdfprof_surface s, u32 i) { u32 t; asm volatile("suld.b.1d.b32.trap {%0}, [%1, {%2}];" : "=r"(t) : "l"(s), "r"(4u * i) : "memory"); return t; }
#define BRDFPROF_INVOCATION_BEGIN()

BRDFPROF_FN void st_u32(u8* p, u32 off, u32 v) { *(u32*)(p + off) = v; }
BRDFPROF_FN void st_i32(u8* p, u32 off, i32 v) { *(i32*)(p + off) = v; }
BRDFPROF_FN void st_f32(u8* p, u32 off, float v) { *(float*)(p + off) = v; }
BRDFPROF_FN void st_f16(u8* p, u32 off, half_t v) { *(u16*)(p + off) = (u16)v.b; }
BRDFPROF_FN void st_f64(u8* p, u32 off, double v) { *(double*)(p + off) = v; }
BRDFPROF_FN void st4_f32(u8* p, u32 off, float a, float b, float c, float d) { *(float4*)(p + off) = make_float4(a, b, c, d); }
BRDFPROF_FN void st4_u32(u8* p, u32 off, u32 a, u32 b, u32 c, u32 d) { *(uint4*)(p + off) = make_uint4(a, b, c, d); }
