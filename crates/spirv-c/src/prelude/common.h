// ---- brdfprof prelude, every dialect: GLSL functions without a C library equivalent and texel formats,
// in the C that C++, CUDA C++ and OpenCL C share. ----
// GLSL 4.50 8.3: mod(x, y) = x - y floor(x / y).
BRDFPROF_FN float m_glsl_mod(float x, float y) { return x - y * m_floor(m_fdiv(x, y)); }
// GLSL 4.50 8.3: t = clamp((x - e0) / (e1 - e0), 0, 1); t t (3 - 2 t).
BRDFPROF_FN float m_smoothstep(float e0, float e1, float x) { float t = m_fmin(m_fmax(m_fdiv(x - e0, e1 - e0), 0.0f), 1.0f); return t * t * (3.0f - 2.0f * t); }
#ifndef BRDFPROF_OWN_HALF_MATHS
BRDFPROF_FN half_t m_smoothstep_h(half_t e0, half_t e1, half_t x) { return h_from_f32(m_smoothstep(h_to_f32(e0), h_to_f32(e1), h_to_f32(x))); }
#endif
#ifndef BRDFPROF_OWN_HALF_MATHS
// GLSL's functions of halves: the f32 function between exact conversions, as NVIDIA and Intel evaluate them.
#define BRDFPROF_HALF1(f) BRDFPROF_FN half_t f##_h(half_t x) { return h_from_f32(f(h_to_f32(x))); }
#define BRDFPROF_HALF2(f) BRDFPROF_FN half_t f##_h(half_t x, half_t y) { return h_from_f32(f(h_to_f32(x), h_to_f32(y))); }
BRDFPROF_HALF1(m_round) BRDFPROF_HALF1(m_rint) BRDFPROF_HALF1(m_trunc) BRDFPROF_HALF1(m_fabs) BRDFPROF_HALF1(m_floor)
BRDFPROF_HALF1(m_ceil) BRDFPROF_HALF1(m_sin) BRDFPROF_HALF1(m_cos) BRDFPROF_HALF1(m_tan) BRDFPROF_HALF1(m_asin)
BRDFPROF_HALF1(m_acos) BRDFPROF_HALF1(m_atan) BRDFPROF_HALF1(m_sinh) BRDFPROF_HALF1(m_cosh) BRDFPROF_HALF1(m_tanh)
BRDFPROF_HALF1(m_asinh) BRDFPROF_HALF1(m_acosh) BRDFPROF_HALF1(m_atanh) BRDFPROF_HALF1(m_exp) BRDFPROF_HALF1(m_log)
BRDFPROF_HALF1(m_exp2) BRDFPROF_HALF1(m_log2) BRDFPROF_HALF1(m_sqrt) BRDFPROF_HALF1(m_rsqrt)
BRDFPROF_HALF2(m_pow) BRDFPROF_HALF2(m_atan2)
BRDFPROF_FN half_t m_ldexp_h(half_t x, i32 e) { return h_from_f32(m_ldexp(h_to_f32(x), e)); }
#endif
// A dynamic index clamped into its composite (robust drivers' treatment of an out-of-bounds index).
BRDFPROF_FN u32 m_index(u32 i, u32 n) { return i < n ? i : n - 1u; }
#ifdef BRDFPROF_SMOD_AS_SREM
// Only in the host build that tests whether a disagreement is lavapipe's: it computes OpSMod as srem.
BRDFPROF_FN i32 m_smod(i32 a, i32 b) { return m_srem(a, b); }
#else
// SPIR-V OpSMod: the sign of the result is the divisor's.
BRDFPROF_FN i32 m_smod(i32 a, i32 b) { i32 r = m_srem(a, b); return (r != 0 && ((r < 0) != (b < 0))) ? r + b : r; }
#endif
BRDFPROF_FN i32 m_sabs(i32 a) { return a < 0 ? (i32)(0u - (u32)a) : a; }
BRDFPROF_FN u32 m_umin(u32 a, u32 b) { return a < b ? a : b; }
BRDFPROF_FN u32 m_umax(u32 a, u32 b) { return a > b ? a : b; }
BRDFPROF_FN i32 m_smin(i32 a, i32 b) { return a < b ? a : b; }
BRDFPROF_FN i32 m_smax(i32 a, i32 b) { return a > b ? a : b; }
BRDFPROF_FN i32 m_findlsb(u32 x) { if (x == 0u) return -1; i32 n = 0; while ((x & 1u) == 0u) { x >>= 1; ++n; } return n; }
BRDFPROF_FN i32 m_findumsb(u32 x) { i32 n = -1; while (x != 0u) { x >>= 1; ++n; } return n; }
BRDFPROF_FN i32 m_findsmsb(i32 x) { return m_findumsb(x < 0 ? ~(u32)x : (u32)x); }

// Unsigned 11- and 10-bit floats (Vulkan 1.3, "Unsigned 11-Bit Floating-Point Numbers"): 5-bit exponent
// (bias 15), 6- or 5-bit mantissa; negative values and NaN's sign give 0, values past the largest finite one
// the largest, the mantissa truncated.
BRDFPROF_FN u32 uf_encode(float v, u32 mbits) {
  u32 b = f32_bits(v);
  u32 e = (b >> 23) & 255u, m = b & 0x7fffffu;
  if (e == 255u) return m != 0u ? ((31u << mbits) | 1u) : ((b >> 31) != 0u ? 0u : (31u << mbits));
  if ((b >> 31) != 0u || v == 0.0f) return 0u;
  if (e > 142u) return (30u << mbits) | ((1u << mbits) - 1u);
  if (e < 113u) return (u32)(v * f32_from_bits((u32)(127 + 14 + (i32)mbits) << 23));
  return ((e - 112u) << mbits) | (m >> (23u - mbits));
}
BRDFPROF_FN float uf_decode(u32 x, u32 mbits) {
  u32 e = x >> mbits, m = x & ((1u << mbits) - 1u);
  if (e == 0u) return (float)m * f32_from_bits((u32)(127 - 14 - (i32)mbits) << 23);
  if (e == 31u) return m != 0u ? f32_from_bits(0x7fc00000u) : f32_from_bits(0x7f800000u);
  return f32_from_bits(((e + 112u) << 23) | (m << (23u - mbits)));
}
BRDFPROF_FN void uf_decode3(u32 t, float* o) { o[0] = uf_decode(t & 2047u, 6u); o[1] = uf_decode((t >> 11) & 2047u, 6u); o[2] = uf_decode(t >> 22, 5u); }
#ifndef BRDFPROF_OWN_TEXELS
BRDFPROF_FN void tex_ld_r11g11b10f(GLOBAL const u8* p, u32 i, float* o) { uf_decode3(ldro_u32(p, 4u * i), o); }
#ifdef BRDFPROF_NATIVE_R11G11B10F
// The dialect's formatted store and raw load of a writable R11G11B10F texel buffer (its prelude says how).
BRDFPROF_FN void tex_ld_r11g11b10f(brdfprof_surface s, u32 i, float* o) { uf_decode3(brdfprof_surface_ld32(s, i), o); }
BRDFPROF_FN void tex_st_r11g11b10f(brdfprof_surface s, u32 i, float r, float g, float b) { brdfprof_surface_st_rgb(s, i, r, g, b); }
#else
BRDFPROF_FN void tex_st_r11g11b10f(GLOBAL u8* p, u32 i, float r, float g, float b) {
  st_u32(p, 4u * i, uf_encode(r, 6u) | (uf_encode(g, 6u) << 11) | (uf_encode(b, 5u) << 22));
}
#endif
BRDFPROF_FN void tex_ld_rgba32ui(GLOBAL const u8* p, u32 i, u32* o) { ldro4_u32(p, 16u * i, o); }
BRDFPROF_FN void tex_st_rgba32ui(GLOBAL u8* p, u32 i, u32 a, u32 b, u32 c, u32 d) { st4_u32(p, 16u * i, a, b, c, d); }
BRDFPROF_FN void tex_ld_rgba32f(GLOBAL const u8* p, u32 i, float* o) { ldro4_f32(p, 16u * i, o); }
BRDFPROF_FN void tex_st_rgba32f(GLOBAL u8* p, u32 i, float a, float b, float c, float d) { st4_f32(p, 16u * i, a, b, c, d); }
BRDFPROF_FN void tex_ld_r32ui(GLOBAL const u8* p, u32 i, u32* o) { o[0] = ldro_u32(p, 4u * i); }
BRDFPROF_FN void tex_st_r32ui(GLOBAL u8* p, u32 i, u32 a) { st_u32(p, 4u * i, a); }
BRDFPROF_FN void tex_ld_r32f(GLOBAL const u8* p, u32 i, float* o) { o[0] = ldro_f32(p, 4u * i); }
BRDFPROF_FN void tex_st_r32f(GLOBAL u8* p, u32 i, float a) { st_f32(p, 4u * i, a); }
BRDFPROF_FN void tex_ld_rgba8(GLOBAL const u8* p, u32 i, float* o) {
  u32 t = ldro_u32(p, 4u * i);
  for (u32 k = 0u; k < 4u; ++k) o[k] = (float)((t >> (8u * k)) & 255u) / 255.0f;
}
BRDFPROF_FN void tex_st_rgba8(GLOBAL u8* p, u32 i, float a, float b, float c, float d) {
  float v[4] = {a, b, c, d}; u32 t = 0u;
  for (u32 k = 0u; k < 4u; ++k) t |= (u32)m_rint(m_fmin(m_fmax(v[k], 0.0f), 1.0f) * 255.0f) << (8u * k);
  st_u32(p, 4u * i, t);
}
#endif
