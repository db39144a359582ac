// ---- brdfprof prelude: the CUDA C++ text compiled for the CPU by g++ (brdfprof runs it to check the
// translation against the Vulkan kernel). Precise C library maths; halves as _Float16, rounded after every
// operation as PTX's f16 instructions round. ----
typedef unsigned char u8;
typedef unsigned short u16;
typedef unsigned int u32;
typedef int i32;
typedef unsigned long long u64;
#define GLOBAL
#define BRDFPROF_FN static inline
// A lookup table as one object read in place (constants.rs, `define_large`).
#define BRDFPROF_CONST_TABLE static const
#define BRDFPROF_TABLE_SPACE
// An invocation stops after 2^20 loop iterations and flags itself (lavapipe stops every loop at 65535).
#define BRDFPROF_LOOP_LIMIT(env) (++(env)->loop_iterations > (1u << 20) && ((env)->flags |= 1u))

typedef _Float16 half_t;
BRDFPROF_FN half_t h_from_bits(u32 b) { u16 x = (u16)b; half_t h; memcpy(&h, &x, 2); return h; }
BRDFPROF_FN u32 h_bits(half_t h) { u16 x; memcpy(&x, &h, 2); return x; }
BRDFPROF_FN float h_to_f32(half_t h) { return (float)h; }
BRDFPROF_FN half_t h_from_f32(float f) { return (half_t)f; }
BRDFPROF_FN half_t h_add(half_t a, half_t b) { return (half_t)((float)a + (float)b); }
BRDFPROF_FN half_t h_sub(half_t a, half_t b) { return (half_t)((float)a - (float)b); }
BRDFPROF_FN half_t h_mul(half_t a, half_t b) { return (half_t)((float)a * (float)b); }
BRDFPROF_FN half_t h_fma(half_t a, half_t b, half_t c) { return (half_t)hm::fma((float)a, (float)b, (float)c); }
BRDFPROF_FN half_t h_neg(half_t a) { return (half_t)(-(float)a); }
BRDFPROF_FN half_t h_div(half_t a, half_t b) { return (half_t)((float)a / (float)b); }
// Comparisons and min/max in f32 (exact for halves).
BRDFPROF_FN bool h_lt(half_t a, half_t b) { return h_to_f32(a) < h_to_f32(b); }
BRDFPROF_FN bool h_le(half_t a, half_t b) { return h_to_f32(a) <= h_to_f32(b); }
BRDFPROF_FN bool h_gt(half_t a, half_t b) { return h_to_f32(a) > h_to_f32(b); }
BRDFPROF_FN bool h_ge(half_t a, half_t b) { return h_to_f32(a) >= h_to_f32(b); }
BRDFPROF_FN bool h_eq(half_t a, half_t b) { return h_to_f32(a) == h_to_f32(b); }
BRDFPROF_FN half_t h_min(half_t a, half_t b) { return h_from_f32(hm::fmin(h_to_f32(a), h_to_f32(b))); }
BRDFPROF_FN half_t h_max(half_t a, half_t b) { return h_from_f32(hm::fmax(h_to_f32(a), h_to_f32(b))); }

BRDFPROF_FN u32 f32_bits(float x) { u32 b; memcpy(&b, &x, 4); return b; }
BRDFPROF_FN float f32_from_bits(u32 b) { float x; memcpy(&x, &b, 4); return x; }
BRDFPROF_FN double f64_from_bits(u64 b) { double x; memcpy(&x, &b, 8); return x; }

BRDFPROF_FN float m_fdiv(float a, float b) { return a / b; }
BRDFPROF_FN float m_sqrt(float x) { return hm::sqrt(x); }
BRDFPROF_FN float m_rsqrt(float x) { return 1.0f / hm::sqrt(x); }
BRDFPROF_FN float m_exp(float x) { return hm::exp2(x * 1.44269504f); }
BRDFPROF_FN float m_exp2(float x) { return hm::exp2(x); }
BRDFPROF_FN float m_log(float x) { return hm::log2(x) * 0.693147181f; }
BRDFPROF_FN float m_log2(float x) { return hm::log2(x); }
BRDFPROF_FN float m_pow(float x, float y) { return hm::exp2(y * hm::log2(x)); }
BRDFPROF_FN float m_sin(float x) { return hm::sin(x); }
BRDFPROF_FN float m_cos(float x) { return hm::cos(x); }
BRDFPROF_FN float m_tan(float x) { return hm::tan(x); }
BRDFPROF_FN float m_asin(float x) { return hm::asin(x); }
BRDFPROF_FN float m_acos(float x) { return hm::acos(x); }
BRDFPROF_FN float m_atan(float x) { return hm::atan(x); }
BRDFPROF_FN float m_atan2(float y, float x) { return hm::atan2(y, x); }
BRDFPROF_FN float m_sinh(float x) { return hm::sinh(x); }
BRDFPROF_FN float m_cosh(float x) { return hm::cosh(x); }
BRDFPROF_FN float m_tanh(float x) { return hm::tanh(x); }
BRDFPROF_FN float m_asinh(float x) { return hm::asinh(x); }
BRDFPROF_FN float m_acosh(float x) { return hm::acosh(x); }
BRDFPROF_FN float m_atanh(float x) { return hm::atanh(x); }
BRDFPROF_FN float m_floor(float x) { return hm::floor(x); }
BRDFPROF_FN float m_ceil(float x) { return hm::ceil(x); }
BRDFPROF_FN float m_trunc(float x) { return hm::trunc(x); }
BRDFPROF_FN float m_round(float x) { return hm::round(x); }
BRDFPROF_FN float m_rint(float x) { return hm::rint(x); }
BRDFPROF_FN float m_fabs(float x) { return hm::fabs(x); }
BRDFPROF_FN float m_fmin(float a, float b) { return hm::fmin(a, b); }
BRDFPROF_FN float m_fmax(float a, float b) { return hm::fmax(a, b); }
BRDFPROF_FN float m_fma(float a, float b, float c) { return hm::fma(a, b, c); }
BRDFPROF_FN float m_ldexp(float x, i32 e) { return hm::ldexp(x, e); }
BRDFPROF_FN float m_fmod(float a, float b) { return hm::fmod(a, b); }
BRDFPROF_FN bool m_isnan(float x) { return hm::isnan(x); }
BRDFPROF_FN bool m_isinf(float x) { return hm::isinf(x); }

BRDFPROF_FN u32 ld_u32(const u8* p, u32 off) { u32 v; memcpy(&v, p + off, 4); return v; }
BRDFPROF_FN i32 ld_i32(const u8* p, u32 off) { i32 v; memcpy(&v, p + off, 4); return v; }
BRDFPROF_FN float ld_f32(const u8* p, u32 off) { float v; memcpy(&v, p + off, 4); return v; }
BRDFPROF_FN half_t ld_f16(const u8* p, u32 off) { half_t v; memcpy(&v, p + off, 2); return v; }
BRDFPROF_FN double ld_f64(const u8* p, u32 off) { double v; memcpy(&v, p + off, 8); return v; }
#define ldro_u32 ld_u32
#define ldro_i32 ld_i32
#define ldro_f32 ld_f32
#define ldro_f16 ld_f16
#define ldro_f64 ld_f64
BRDFPROF_FN void ld4_f32(const u8* p, u32 off, float* o) { memcpy(o, p + off, 16); }
BRDFPROF_FN void ld4_u32(const u8* p, u32 off, u32* o) { memcpy(o, p + off, 16); }
#define ldro4_f32 ld4_f32
#define ldro4_u32 ld4_u32
// Constant blocks are bytes the caller passes, like every other binding.
#define BRDFPROF_CONSTANT_BLOCK(name, bytes)
#define BRDFPROF_CONSTANT_FIELD(name) const u8* name;
#define BRDFPROF_CONSTANT_REF(env, name) ((env)->name)
#define ldc_u32 ld_u32
#define ldc_i32 ld_i32
#define ldc_f32 ld_f32
#define ldc_f16 ld_f16
#define ldc_f64 ld_f64
#define ldc4_f32 ld4_f32
#define ldc4_u32 ld4_u32
#define BRDFPROF_SURFACE_FIELD(name) u8* name;
#define BRDFPROF_INVOCATION_BEGIN()

BRDFPROF_FN void st_u32(u8* p, u32 off, u32 v) { memcpy(p + off, &v, 4); }
BRDFPROF_FN void st_i32(u8* p, u32 off, i32 v) { memcpy(p + off, &v, 4); }
BRDFPROF_FN void st_f32(u8* p, u32 off, float v) { memcpy(p + off, &v, 4); }
BRDFPROF_FN void st_f16(u8* p, u32 off, half_t v) { memcpy(p + off, &v, 2); }
BRDFPROF_FN void st_f64(u8* p, u32 off, double v) { memcpy(p + off, &v, 8); }
BRDFPROF_FN void st4_f32(u8* p, u32 off, float a, float b, float c, float d) { float v[4] = {a, b, c, d}; memcpy(p + off, v, 16); }
BRDFPROF_FN void st4_u32(u8* p, u32 off, u32 a, u32 b, u32 c, u32 d) { u32 v[4] = {a, b, c, d}; memcpy(p + off, v, 16); }
