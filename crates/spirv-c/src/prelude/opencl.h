// ---- brdfprof prelude: OpenCL C 1.2, for Intel's IGC (ocloc) and PoCL. The transcendental functions and
// division are the native_ forms (the precision freedom Vulkan gives a driver) unless BRDFPROF_PRECISE is
// defined; see docs/targets.md for the build options beside every figure. ----
typedef uchar u8;
typedef ushort u16;
typedef uint u32;
typedef int i32;
typedef ulong u64;
#define GLOBAL __global
// A lookup table as one object in constant memory read in place (constants.rs, `define_large`), through
// pointers into __constant space: OpenCL C keeps its address spaces apart.
#define BRDFPROF_CONST_TABLE __constant
#define BRDFPROF_TABLE_SPACE __constant
// inspect --lines defines BRDFPROF_FN first (the helpers without debug information) and BRDFPROF_LINED_FN
// (the module's own functions, which carry #line directives): Translation::source_with_lines.
#ifndef BRDFPROF_FN
#define BRDFPROF_FN static inline
#endif
#ifdef BRDFPROF_EXECUTED
// brdfprof runs this build itself (PoCL): an invocation stops after 2^20 loop iterations, as on the host;
// the build a compiler only costs has no such counter.
#define BRDFPROF_LOOP_LIMIT(env) (++(env)->loop_iterations > (1u << 20) && ((env)->flags |= 1u))
#else
#define BRDFPROF_LOOP_LIMIT(env) 0
#endif

#ifdef cl_khr_fp16
typedef half half_t;
BRDFPROF_FN half_t h_from_bits(u32 b) { return as_half((ushort)b); }
BRDFPROF_FN u32 h_bits(half_t h) { return as_ushort(h); }
BRDFPROF_FN float h_to_f32(half_t h) { return (float)h; }
BRDFPROF_FN half_t h_from_f32(float f) { return (half_t)f; }
BRDFPROF_FN half_t h_add(half_t a, half_t b) { return a + b; }
BRDFPROF_FN half_t h_sub(half_t a, half_t b) { return a - b; }
BRDFPROF_FN half_t h_mul(half_t a, half_t b) { return a * b; }
BRDFPROF_FN half_t h_fma(half_t a, half_t b, half_t c) { return fma(a, b, c); }
BRDFPROF_FN half_t h_neg(half_t a) { return -a; }
BRDFPROF_FN half_t h_div(half_t a, half_t b) { return (half_t)((float)a / (float)b); }
#else
// Without cl_khr_fp16, halves are storage only: bits, converted with vload_half/vstore_half.
typedef struct { ushort b; } half_t;
BRDFPROF_FN half_t h_from_bits(u32 b) { half_t h; h.b = (ushort)b; return h; }
BRDFPROF_FN u32 h_bits(half_t h) { return h.b; }
BRDFPROF_FN float h_to_f32(half_t h) { return vload_half(0, (const __private half*)&h.b); }
BRDFPROF_FN half_t h_from_f32(float f) { half_t h; vstore_half_rte(f, 0, (__private half*)&h.b); return h; }
BRDFPROF_FN half_t h_add(half_t a, half_t b) { return h_from_f32(h_to_f32(a) + h_to_f32(b)); }
BRDFPROF_FN half_t h_sub(half_t a, half_t b) { return h_from_f32(h_to_f32(a) - h_to_f32(b)); }
BRDFPROF_FN half_t h_mul(half_t a, half_t b) { return h_from_f32(h_to_f32(a) * h_to_f32(b)); }
BRDFPROF_FN half_t h_fma(half_t a, half_t b, half_t c) { return h_from_f32(fma(h_to_f32(a), h_to_f32(b), h_to_f32(c))); }
BRDFPROF_FN half_t h_neg(half_t a) { return h_from_bits(a.b ^ 0x8000u); }
BRDFPROF_FN half_t h_div(half_t a, half_t b) { return h_from_f32(h_to_f32(a) / h_to_f32(b)); }
#endif
// Comparisons and min/max in f32 (exact for halves).
BRDFPROF_FN bool h_lt(half_t a, half_t b) { return h_to_f32(a) < h_to_f32(b); }
BRDFPROF_FN bool h_le(half_t a, half_t b) { return h_to_f32(a) <= h_to_f32(b); }
BRDFPROF_FN bool h_gt(half_t a, half_t b) { return h_to_f32(a) > h_to_f32(b); }
BRDFPROF_FN bool h_ge(half_t a, half_t b) { return h_to_f32(a) >= h_to_f32(b); }
BRDFPROF_FN bool h_eq(half_t a, half_t b) { return h_to_f32(a) == h_to_f32(b); }
BRDFPROF_FN half_t h_min(half_t a, half_t b) { return h_from_f32(fmin(h_to_f32(a), h_to_f32(b))); }
BRDFPROF_FN half_t h_max(half_t a, half_t b) { return h_from_f32(fmax(h_to_f32(a), h_to_f32(b))); }

BRDFPROF_FN u32 f32_bits(float x) { return as_uint(x); }
BRDFPROF_FN float f32_from_bits(u32 b) { return as_float(b); }
#ifdef BRDFPROF_F64
BRDFPROF_FN double f64_from_bits(u64 b) { return as_double(b); }
#endif

#ifdef BRDFPROF_PRECISE
// The precise build (PoCL's check of the translation): no contraction into FMA either (OpenCL C contracts by
// default, as a Vulkan driver may).
#pragma OPENCL FP_CONTRACT OFF
BRDFPROF_FN float m_fdiv(float a, float b) { return a / b; }
BRDFPROF_FN float m_sqrt(float x) { return sqrt(x); }
BRDFPROF_FN float m_rsqrt(float x) { return rsqrt(x); }
BRDFPROF_FN float m_exp(float x) { return exp(x); }
BRDFPROF_FN float m_exp2(float x) { return exp2(x); }
BRDFPROF_FN float m_log(float x) { return log(x); }
BRDFPROF_FN float m_log2(float x) { return log2(x); }
BRDFPROF_FN float m_pow(float x, float y) { return pow(x, y); }
BRDFPROF_FN float m_sin(float x) { return sin(x); }
BRDFPROF_FN float m_cos(float x) { return cos(x); }
BRDFPROF_FN float m_tan(float x) { return tan(x); }
#else
BRDFPROF_FN float m_fdiv(float a, float b) { return native_divide(a, b); }
BRDFPROF_FN float m_sqrt(float x) { return native_sqrt(x); }
BRDFPROF_FN float m_rsqrt(float x) { return native_rsqrt(x); }
BRDFPROF_FN float m_exp(float x) { return native_exp(x); }
BRDFPROF_FN float m_exp2(float x) { return native_exp2(x); }
BRDFPROF_FN float m_log(float x) { return native_log(x); }
BRDFPROF_FN float m_log2(float x) { return native_log2(x); }
// GLSL's pow is undefined for x < 0 (as powr is); both are exp2(y log2 x) on GPUs.
BRDFPROF_FN float m_pow(float x, float y) { return native_powr(x, y); }
BRDFPROF_FN float m_sin(float x) { return native_sin(x); }
BRDFPROF_FN float m_cos(float x) { return native_cos(x); }
BRDFPROF_FN float m_tan(float x) { return native_tan(x); }
#endif
BRDFPROF_FN float m_asin(float x) { return asin(x); }
BRDFPROF_FN float m_acos(float x) { return acos(x); }
BRDFPROF_FN float m_atan(float x) { return atan(x); }
BRDFPROF_FN float m_atan2(float y, float x) { return atan2(y, x); }
BRDFPROF_FN float m_sinh(float x) { return sinh(x); }
BRDFPROF_FN float m_cosh(float x) { return cosh(x); }
BRDFPROF_FN float m_tanh(float x) { return tanh(x); }
BRDFPROF_FN float m_asinh(float x) { return asinh(x); }
BRDFPROF_FN float m_acosh(float x) { return acosh(x); }
BRDFPROF_FN float m_atanh(float x) { return atanh(x); }
BRDFPROF_FN float m_floor(float x) { return floor(x); }
BRDFPROF_FN float m_ceil(float x) { return ceil(x); }
BRDFPROF_FN float m_trunc(float x) { return trunc(x); }
BRDFPROF_FN float m_round(float x) { return round(x); }
BRDFPROF_FN float m_rint(float x) { return rint(x); }
BRDFPROF_FN float m_fabs(float x) { return fabs(x); }
BRDFPROF_FN float m_fmin(float a, float b) { return fmin(a, b); }
BRDFPROF_FN float m_fmax(float a, float b) { return fmax(a, b); }
BRDFPROF_FN float m_fma(float a, float b, float c) { return fma(a, b, c); }
BRDFPROF_FN float m_ldexp(float x, i32 e) { return ldexp(x, e); }
BRDFPROF_FN float m_fmod(float a, float b) { return fmod(a, b); }
BRDFPROF_FN bool m_isnan(float x) { return isnan(x) != 0; }
BRDFPROF_FN bool m_isinf(float x) { return isinf(x) != 0; }
#ifdef BRDFPROF_F64
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
#endif

BRDFPROF_FN u32 m_udiv(u32 a, u32 b) { return a / b; }
BRDFPROF_FN u32 m_umod(u32 a, u32 b) { return a % b; }
BRDFPROF_FN i32 m_sdiv(i32 a, i32 b) { return a / b; }
BRDFPROF_FN i32 m_srem(i32 a, i32 b) { return a % b; }

BRDFPROF_FN u32 ld_u32(__global const u8* p, u32 off) { return *(__global const u32*)(p + off); }
BRDFPROF_FN i32 ld_i32(__global const u8* p, u32 off) { return *(__global const i32*)(p + off); }
BRDFPROF_FN float ld_f32(__global const u8* p, u32 off) { return *(__global const float*)(p + off); }
BRDFPROF_FN half_t ld_f16(__global const u8* p, u32 off) { return h_from_bits(*(__global const u16*)(p + off)); }
#ifdef BRDFPROF_F64
BRDFPROF_FN double ld_f64(__global const u8* p, u32 off) { return *(__global const double*)(p + off); }
BRDFPROF_FN void st_f64(__global u8* p, u32 off, double v) { *(__global double*)(p + off) = v; }
#define ldro_f64 ld_f64
#endif
#define ldro_u32 ld_u32
#define ldro_i32 ld_i32
#define ldro_f32 ld_f32
#define ldro_f16 ld_f16
BRDFPROF_FN void ld4_f32(__global const u8* p, u32 off, float* o) { float4 v = *(__global const float4*)(p + off); o[0] = v.x; o[1] = v.y; o[2] = v.z; o[3] = v.w; }
BRDFPROF_FN void ld4_u32(__global const u8* p, u32 off, u32* o) { uint4 v = *(__global const uint4*)(p + off); o[0] = v.x; o[1] = v.y; o[2] = v.z; o[3] = v.w; }
#define ldro4_f32 ld4_f32
#define ldro4_u32 ld4_u32
// Uniform and push-constant blocks in constant memory: `__constant` kernel arguments, as an OpenCL author
// passes them (OpenCL C 1.2 has no program-scope constant data the host can write).
#define BRDFPROF_CONSTANT_BLOCK(name, bytes)
#define BRDFPROF_CONSTANT_FIELD(name) __constant u8* name;
#define BRDFPROF_CONSTANT_REF(env, name) ((env)->name)
BRDFPROF_FN u32 ldc_u32(__constant u8* p, u32 off) { return *(__constant u32*)(p + off); }
BRDFPROF_FN i32 ldc_i32(__constant u8* p, u32 off) { return *(__constant i32*)(p + off); }
BRDFPROF_FN float ldc_f32(__constant u8* p, u32 off) { return *(__constant float*)(p + off); }
BRDFPROF_FN half_t ldc_f16(__constant u8* p, u32 off) { return h_from_bits(*(__constant u16*)(p + off)); }
#ifdef BRDFPROF_F64
BRDFPROF_FN double ldc_f64(__constant u8* p, u32 off) { return *(__constant double*)(p + off); }
#endif
BRDFPROF_FN void ldc4_f32(__constant u8* p, u32 off, float* o) { float4 v = *(__constant float4*)(p + off); o[0] = v.x; o[1] = v.y; o[2] = v.z; o[3] = v.w; }
BRDFPROF_FN void ldc4_u32(__constant u8* p, u32 off, u32* o) { uint4 v = *(__constant uint4*)(p + off); o[0] = v.x; o[1] = v.y; o[2] = v.z; o[3] = v.w; }
// OpenCL C has no R11G11B10F image format (cl_channel_type lists no packed 11/11/10-bit float), so a
// writable R11G11B10F texel buffer is packed in software, as an OpenCL author must.
#define BRDFPROF_SURFACE_FIELD(name) __global u8* name;
#define BRDFPROF_INVOCATION_BEGIN()

BRDFPROF_FN void st_u32(__global u8* p, u32 off, u32 v) { *(__global u32*)(p + off) = v; }
BRDFPROF_FN void st_i32(__global u8* p, u32 off, i32 v) { *(__global i32*)(p + off) = v; }
BRDFPROF_FN void st_f32(__global u8* p, u32 off, float v) { *(__global float*)(p + off) = v; }
BRDFPROF_FN void st_f16(__global u8* p, u32 off, half_t v) { *(__global u16*)(p + off) = (u16)h_bits(v); }
BRDFPROF_FN void st4_f32(__global u8* p, u32 off, float a, float b, float c, float d) { *(__global float4*)(p + off) = (float4)(a, b, c, d); }
BRDFPROF_FN void st4_u32(__global u8* p, u32 off, u32 a, u32 b, u32 c, u32 d) { *(__global uint4*)(p + off) = (uint4)(a, b, c, d); }
