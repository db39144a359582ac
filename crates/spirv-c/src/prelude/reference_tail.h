// ---- the f64 reference, after the common prelude: what needs its functions. ----
BRDFPROF_FN half_t m_smoothstep_h(half_t e0, half_t e1, half_t x) {
  half_t t = h_min(h_max(h_div(h_sub(x, e0), h_sub(e1, e0)), half_t(0.0f)), half_t(1.0f));
  return h_mul(h_mul(t, t), h_sub(half_t(3.0f), h_mul(half_t(2.0f), t)));
}
// Texel buffers: a sampled (const) one holds the kernel's input texels; a writable one 64 bytes per texel, a
// (value, bound) pair per component (an integer component as its 4 bytes in the pair's place). The conversion of a stored value to its format (R11G11B10F's
// rounding, RGBA8's quantisation) is the caller's to allow for: the pair is the value before it.
BRDFPROF_FN void texel_pairs_ld(u8* p, u32 i, u32 n, float* o) { for (u32 k = 0u; k < n; ++k) o[k] = pair_ld(p + 64u * i + 16u * k); }
BRDFPROF_FN void texel_pairs_st(u8* p, u32 i, u32 n, const float* v) { for (u32 k = 0u; k < n; ++k) pair_st(p + 64u * i + 16u * k, v[k].v, v[k].e); }
BRDFPROF_FN void texel_u32_ld(u8* p, u32 i, u32 n, u32* o) { for (u32 k = 0u; k < n; ++k) memcpy(&o[k], p + 64u * i + 16u * k, 4); }
BRDFPROF_FN void texel_u32_st(u8* p, u32 i, u32 n, const u32* v) { for (u32 k = 0u; k < n; ++k) memcpy(p + 64u * i + 16u * k, &v[k], 4); }
BRDFPROF_FN void tex_ld_r11g11b10f(const u8* p, u32 i, float* o) { uf_decode3(ldro_u32(p, 4u * i), o); }
BRDFPROF_FN void tex_ld_r11g11b10f(u8* p, u32 i, float* o) { texel_pairs_ld(p, i, 3u, o); }
BRDFPROF_FN void tex_st_r11g11b10f(u8* p, u32 i, float r, float g, float b) { float v[3] = {r, g, b}; texel_pairs_st(p, i, 3u, v); }
BRDFPROF_FN void tex_ld_rgba32ui(const u8* p, u32 i, u32* o) { ldro4_u32(p, 16u * i, o); }
BRDFPROF_FN void tex_ld_rgba32ui(u8* p, u32 i, u32* o) { texel_u32_ld(p, i, 4u, o); }
BRDFPROF_FN void tex_st_rgba32ui(u8* p, u32 i, u32 a, u32 b, u32 c, u32 d) { u32 v[4] = {a, b, c, d}; texel_u32_st(p, i, 4u, v); }
BRDFPROF_FN void tex_ld_rgba32f(const u8* p, u32 i, float* o) { ldro4_f32(p, 16u * i, o); }
BRDFPROF_FN void tex_ld_rgba32f(u8* p, u32 i, float* o) { texel_pairs_ld(p, i, 4u, o); }
BRDFPROF_FN void tex_st_rgba32f(u8* p, u32 i, float a, float b, float c, float d) { float v[4] = {a, b, c, d}; texel_pairs_st(p, i, 4u, v); }
BRDFPROF_FN void tex_ld_r32ui(const u8* p, u32 i, u32* o) { o[0] = ldro_u32(p, 4u * i); }
BRDFPROF_FN void tex_ld_r32ui(u8* p, u32 i, u32* o) { texel_u32_ld(p, i, 1u, o); }
BRDFPROF_FN void tex_st_r32ui(u8* p, u32 i, u32 a) { texel_u32_st(p, i, 1u, &a); }
BRDFPROF_FN void tex_ld_r32f(const u8* p, u32 i, float* o) { o[0] = ldro_f32(p, 4u * i); }
BRDFPROF_FN void tex_ld_r32f(u8* p, u32 i, float* o) { texel_pairs_ld(p, i, 1u, o); }
BRDFPROF_FN void tex_st_r32f(u8* p, u32 i, float a) { texel_pairs_st(p, i, 1u, &a); }
BRDFPROF_FN void tex_ld_rgba8(const u8* p, u32 i, float* o) {
  u32 t = ldro_u32(p, 4u * i);
  for (u32 k = 0u; k < 4u; ++k) o[k] = m_fdiv((float)((t >> (8u * k)) & 255u), 255.0f);
}
BRDFPROF_FN void tex_ld_rgba8(u8* p, u32 i, float* o) { texel_pairs_ld(p, i, 4u, o); }
BRDFPROF_FN void tex_st_rgba8(u8* p, u32 i, float a, float b, float c, float d) { float v[4] = {a, b, c, d}; texel_pairs_st(p, i, 4u, v); }
