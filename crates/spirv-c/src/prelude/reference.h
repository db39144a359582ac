// ---- brdfprof prelude: the f64 reference. The CUDA C++ text of the translation compiled for the CPU by g++,
// every f32 and f16 value a pair (v, e): v the value the kernel's own operations give in double precision
// (its f32 constants as they are), e a bound on how far an implementation that follows the Vulkan precision
// rules may be from v (Vulkan 1.3, appendix "Vulkan Environment for SPIR-V", "Precision and Operation of
// SPIR-V Instructions", tables "Precision of core SPIR-V Instructions" and "Precision of GLSL.std.450
// Instructions"). Each operation adds what its inputs' bounds can move its result (first-order, or over the
// interval where the function is monotone) to its own allowance:
//   add, subtract, multiply, conversions: correctly rounded, rounding mode unspecified (1 ULP);
//   division: 2.5 ULP for |y| in [2^-126, 2^126] (half: [2^-14, 2^14]); outside, no bound;
//   exp, exp2: 3 + 2|x| ULP (half: 1 + 2|x|);
//   log, log2: 3 ULP outside [0.5, 2], absolute error 2^-21 inside (half: 2^-7);
//   inversesqrt: 2 ULP; sqrt inherited from 1 / inversesqrt (2 x 2 + 2.5 = 6.5 ULP);
//   pow inherited from exp2(y log2 x); sin, cos: absolute 2^-11 inside [-pi, pi] (half: 2^-7), no bound
//   outside; tan inherited from sin / cos; atan, atan2: 4096 ULP (half: 5); asin, acos, sinh, cosh, tanh,
//   asinh, acosh, atanh, fma, mix, length, normalize, reflect, ... inherited from their formulas (the
//   translation writes them as those formulas, so the bound follows them operation by operation);
//   floor, ceil, trunc, round, fract, min, max, clamp, fabs: correctly rounded (exact).
// ULP is the rule's ulp(x) for the format (f32: 23 mantissa bits; f16: 10); a result a denormal may be
// flushed (any value below the smallest normal may become 0). Where the rules give no bound (a division by
// a divisor that may be 0, a logarithm of a range reaching 0, sin past pi), the bound is infinite. A
// comparison whose operands are within their bounds of each other, a conversion to an integer or a floor
// whose argument's range crosses an integer, and a bit cast of an inexact value can go either way in a
// conforming implementation: the invocation is marked unbounded, and every value it stores has an infinite
// bound (not judged). Stores of writable bindings write (v, e) pairs at four times the offset (see host.rs).
typedef unsigned char u8;
typedef unsigned short u16;
typedef unsigned int u32;
typedef int i32;
typedef unsigned long long u64;
#define GLOBAL
#define BRDFPROF_FN static inline
#define BRDFPROF_LOOP_LIMIT(env) (++(env)->loop_iterations > (1u << 20) && ((env)->flags |= 1u))
#define BRDFPROF_OWN_HALF_MATHS 1
#define BRDFPROF_OWN_TEXELS 1

static const double BRDFPROF_INF = __builtin_huge_val();
static bool brdfprof_unbounded = false;
#define BRDFPROF_INVOCATION_BEGIN() (brdfprof_unbounded = false)
BRDFPROF_FN void unbounded() { brdfprof_unbounded = true; }

// The precision rules of one format (P = 32: single precision; 16: half).
template <int P> struct Rules;
template <> struct Rules<32> {
  static constexpr int mantissa = 23, min_exponent = -126;
  static constexpr double exp_base = 3.0, log_inside = 0x1p-21, sin_cos = 0x1p-11, atan = 4096.0, div_lo = 0x1p-126, div_hi = 0x1p126;
};
template <> struct Rules<16> {
  static constexpr int mantissa = 10, min_exponent = -14;
  static constexpr double exp_base = 1.0, log_inside = 0x1p-7, sin_cos = 0x1p-7, atan = 5.0, div_lo = 0x1p-14, div_hi = 0x1p14;
};

// ulp(m) of the format at magnitude m (the spacing of the format's numbers there; at 0, the smallest).
template <int P> BRDFPROF_FN double ulp_at(double m) {
  if (!(m < BRDFPROF_INF)) return BRDFPROF_INF;
  int ex = 0;
  hm::frexp(m, &ex);
  int e = (m == 0.0 || ex - 1 < Rules<P>::min_exponent) ? Rules<P>::min_exponent : ex - 1;
  return hm::ldexp(1.0, e - Rules<P>::mantissa);
}
// n ULP at the magnitude of a result r whose operands' bounds move it by p, plus what flushing may take where
// the range reaches below the smallest normal (a result there may be flushed to 0). An exact infinity (from
// exact infinities) has no allowance.
template <int P> BRDFPROF_FN double allow(double n, double r, double p) {
  double m = hm::fabs(r) + p, smallest = hm::ldexp(1.0, Rules<P>::min_exponent);
  if (hm::isinf(m)) return 0.0;
  return n * ulp_at<P>(m) + (hm::fabs(r) - p < smallest ? hm::fmin(m, smallest) : 0.0);
}
// A correctly rounded operation: exact where its result is exact and representable, else one ULP (the rounding
// mode is unspecified: either neighbour) and the flush allowance.
template <int P> BRDFPROF_FN bool representable(double r);
template <> inline bool representable<32>(double r) { return (double)(float)r == r; }
template <> inline bool representable<16>(double r) { return (double)(_Float16)r == r; }
template <int P> BRDFPROF_FN double rounded(double r, double p) {
  return (p == 0.0 && representable<P>(r) && !(r != 0.0 && hm::fabs(r) < hm::ldexp(1.0, Rules<P>::min_exponent))) ? 0.0 : allow<P>(1.0, r, p);
}
// |x| e, with 0 where e is 0 (an exact operand moves nothing, even next to an infinity).
BRDFPROF_FN double moved(double x, double e) { return e == 0.0 ? 0.0 : hm::fabs(x) * e; }

template <int P> struct E {
  double v, e;
  E() = default;
  E(float x) : v(x), e(0.0) {}
  // A conversion from double or from an integer: correctly rounded.
  E(double x) : v(x), e(rounded<P>(x, 0.0)) {}
  E(int x) : v(x), e(hm::fabs((double)x) < hm::ldexp(1.0, Rules<P>::mantissa + 1) ? 0.0 : rounded<P>(x, 0.0)) {}
  E(unsigned x) : v(x), e((double)x < hm::ldexp(1.0, Rules<P>::mantissa + 1) ? 0.0 : rounded<P>(x, 0.0)) {}
  static E of(double v, double e) { E r; r.v = v; r.e = e; return r; }
  explicit operator double() const { if (e > 0.0) unbounded(); return v; }
  explicit operator int() const { return (int)to_integer(-2147483648.0, 2147483647.0); }
  explicit operator unsigned() const { return (unsigned)to_integer(0.0, 4294967295.0); }
  // A conversion to an integer truncates: it goes either way where the range crosses an integer.
  double to_integer(double lo, double hi) const {
    if (e > 0.0 && hm::trunc(v - e) != hm::trunc(v + e)) unbounded();
    if (!(v >= lo && v <= hi)) { unbounded(); return v != v ? 0.0 : (v < lo ? lo : hi); }
    return hm::trunc(v);
  }
  friend E operator+(E a, E b) { double r = a.v + b.v, p = a.e + b.e; return of(r, p + rounded<P>(r, p)); }
  friend E operator-(E a, E b) { double r = a.v - b.v, p = a.e + b.e; return of(r, p + rounded<P>(r, p)); }
  friend E operator-(E a) { return of(-a.v, a.e); }
  friend E operator*(E a, E b) {
    double r = a.v * b.v, p = moved(a.v, b.e) + moved(b.v, a.e) + a.e * b.e;
    return of(r, p + rounded<P>(r, p));
  }
  // Operands within their bounds of each other compare either way in a conforming implementation.
  static void near(E a, E b) { double s = a.e + b.e; if (s > 0.0 && !(hm::fabs(a.v - b.v) > s)) unbounded(); }
  friend bool operator<(E a, E b) { near(a, b); return a.v < b.v; }
  friend bool operator<=(E a, E b) { near(a, b); return a.v <= b.v; }
  friend bool operator>(E a, E b) { near(a, b); return a.v > b.v; }
  friend bool operator>=(E a, E b) { near(a, b); return a.v >= b.v; }
  friend bool operator==(E a, E b) { near(a, b); return a.v == b.v; }
  friend bool operator!=(E a, E b) { near(a, b); return a.v != b.v; }
};
typedef E<32> Ef;
typedef E<16> half_t;

// A monotone function's move over [v - e, v + e] (the larger side), for the bound of its result.
template <typename F> BRDFPROF_FN double monotone_move(F f, double v, double e, double lo_limit) {
  if (e == 0.0) return 0.0;
  double lo = v - e < lo_limit ? lo_limit : v - e;
  return hm::fmax(hm::fabs(f(v + e) - f(v)), hm::fabs(f(v) - f(lo)));
}

template <int P> BRDFPROF_FN E<P> t_div(E<P> a, E<P> b) {
  double r = a.v / b.v, lo = hm::fabs(b.v) - b.e, hi = hm::fabs(b.v) + b.e;
  if (!(lo >= Rules<P>::div_lo && hi <= Rules<P>::div_hi)) return E<P>::of(r, BRDFPROF_INF);
  double p = (a.e + moved(r, b.e)) / lo;
  return E<P>::of(r, p + allow<P>(2.5, r, p));
}
template <int P> BRDFPROF_FN E<P> t_exp2(E<P> x, bool natural) {
  auto f = [natural](double t) { return natural ? hm::exp(t) : hm::exp2(t); };
  double r = f(x.v);
  if (x.e == 0.0 && hm::isinf(x.v)) return E<P>::of(r, 0.0);  // exp(-inf) = 0, exp(inf) = inf: exact
  double p = monotone_move(f, x.v, x.e, -BRDFPROF_INF);
  return E<P>::of(r, p + allow<P>(Rules<P>::exp_base + 2.0 * (hm::fabs(x.v) + x.e), r, p));
}
template <int P> BRDFPROF_FN E<P> t_log2(E<P> x, bool natural) {
  auto f = [natural](double t) { return natural ? hm::log(t) : hm::log2(t); };
  double r = f(x.v), lo = x.v - x.e, hi = x.v + x.e;
  if (x.e == 0.0 && !(x.v > 0.0)) return E<P>::of(r, 0.0);  // log(0) = -inf and log of a negative: exact
  if (!(lo > 0.0)) return E<P>::of(r, hi < 0.0 ? 0.0 : BRDFPROF_INF);
  double p = monotone_move(f, x.v, x.e, 0.0), rule = 0.0;
  if (hi >= 0.5 && lo <= 2.0) rule = Rules<P>::log_inside;
  if (lo < 0.5 || hi > 2.0) rule = hm::fmax(rule, allow<P>(3.0, r, p));
  return E<P>::of(r, p + rule);
}
template <int P> BRDFPROF_FN E<P> t_rsqrt(E<P> x) {
  auto f = [](double t) { return 1.0 / hm::sqrt(t); };
  double r = f(x.v);
  if (x.e == 0.0 && !(x.v > 0.0)) return E<P>::of(r, 0.0);
  if (!(x.v - x.e > 0.0)) return E<P>::of(r, x.v + x.e < 0.0 ? 0.0 : BRDFPROF_INF);
  double p = monotone_move(f, x.v, x.e, 0.0);
  return E<P>::of(r, p + allow<P>(2.0, r, p));
}
template <int P> BRDFPROF_FN E<P> t_sqrt(E<P> x) {
  double r = hm::sqrt(x.v);
  if (x.v < 0.0 && x.v + x.e >= 0.0) { unbounded(); return E<P>::of(r, BRDFPROF_INF); }
  double p = monotone_move([](double t) { return hm::sqrt(t); }, x.v, x.e, 0.0);
  return E<P>::of(r, p + allow<P>(6.5, r, p));
}
template <int P> BRDFPROF_FN E<P> t_sin_cos(E<P> x, bool cosine) {
  double r = cosine ? hm::cos(x.v) : hm::sin(x.v);
  if (!(hm::fabs(x.v) + x.e <= 3.14159265358979323846)) return E<P>::of(r, BRDFPROF_INF);
  return E<P>::of(r, x.e + Rules<P>::sin_cos);
}
template <int P> BRDFPROF_FN E<P> t_atan2(E<P> y, E<P> x) {
  double r = hm::atan2(y.v, x.v), s = x.e + y.e, rho = hm::hypot(x.v, y.v);
  if (s > 0.0 && !(rho > s)) return E<P>::of(r, BRDFPROF_INF);
  if (y.e > 0.0 && hm::fabs(y.v) <= y.e && x.v - x.e < 0.0) unbounded();  // the branch cut at +-pi
  double p = s > 0.0 ? s / (rho - s) : 0.0;
  return E<P>::of(r, p + allow<P>(Rules<P>::atan, r, p));
}
// pow: inherited from exp2(y log2 x). Where the base's range reaches 0 and the exponent is positive (a clamped
// cosine to a power), the formula's log2 has no bound but pow has: it is 0 at an exact 0, and anywhere in
// [0, pow(hi, y)] over the range, plus the rule's rounding at its top.
template <int P> BRDFPROF_FN E<P> t_pow(E<P> x, E<P> y) {
  if (!(x.v - x.e <= 0.0 && x.v >= 0.0 && y.v - y.e > 0.0)) return t_exp2(y * t_log2(x, false), false);
  double r = hm::pow(x.v, y.v), top = x.v + x.e;
  if (top == 0.0) return E<P>::of(r, 0.0);
  double hi = hm::fmax(hm::pow(top, y.v - y.e), hm::pow(top, y.v + y.e));
  double n = Rules<P>::exp_base + 2.0 * hm::fabs((y.v + y.e) * hm::log2(top));
  return E<P>::of(r, hm::fmax(hi - r, r) + allow<P>(n, r, hi));
}
// floor, ceil, trunc, round, rint: exact, but a range across a step goes either way.
template <int P, typename F> BRDFPROF_FN E<P> t_step(E<P> x, F f) {
  if (x.e > 0.0 && f(x.v - x.e) != f(x.v + x.e)) unbounded();
  return E<P>::of(f(x.v), 0.0);
}
// min and max are exact: where one operand's range lies wholly below the other's, the result is that operand
// with its own bound; else the larger bound.
template <int P> BRDFPROF_FN E<P> t_fmin(E<P> a, E<P> b) {
  if (a.v + a.e < b.v - b.e) return a;
  if (b.v + b.e < a.v - a.e) return b;
  return E<P>::of(hm::fmin(a.v, b.v), hm::fmax(a.e, b.e));
}
template <int P> BRDFPROF_FN E<P> t_fmax(E<P> a, E<P> b) {
  if (a.v - a.e > b.v + b.e) return a;
  if (b.v - b.e > a.v + a.e) return b;
  return E<P>::of(hm::fmax(a.v, b.v), hm::fmax(a.e, b.e));
}

#define BRDFPROF_BOTH1(name, body) \
  BRDFPROF_FN Ef name(Ef x) { typedef Ef T; body } \
  BRDFPROF_FN half_t name##_h(half_t x) { typedef half_t T; body }
#define BRDFPROF_BOTH2(name, body) \
  BRDFPROF_FN Ef name(Ef x, Ef y) { typedef Ef T; body } \
  BRDFPROF_FN half_t name##_h(half_t x, half_t y) { typedef half_t T; body }
BRDFPROF_BOTH2(m_fdiv, return t_div(x, y);)
BRDFPROF_BOTH1(m_exp, return t_exp2(x, true);)
BRDFPROF_BOTH1(m_exp2, return t_exp2(x, false);)
BRDFPROF_BOTH1(m_log, return t_log2(x, true);)
BRDFPROF_BOTH1(m_log2, return t_log2(x, false);)
BRDFPROF_BOTH2(m_pow, return t_pow(x, y);)
BRDFPROF_BOTH1(m_rsqrt, return t_rsqrt(x);)
BRDFPROF_BOTH1(m_sqrt, return t_sqrt(x);)
BRDFPROF_BOTH1(m_sin, return t_sin_cos(x, false);)
BRDFPROF_BOTH1(m_cos, return t_sin_cos(x, true);)
BRDFPROF_BOTH1(m_tan, return t_div(t_sin_cos(x, false), t_sin_cos(x, true));)
BRDFPROF_BOTH2(m_atan2, return t_atan2(x, y);)
BRDFPROF_BOTH1(m_atan, return t_atan2(x, T(1.0f));)
BRDFPROF_BOTH1(m_asin, return t_atan2(x, t_sqrt(T(1.0f) - x * x));)
BRDFPROF_BOTH1(m_acos, return t_atan2(t_sqrt(T(1.0f) - x * x), x);)
BRDFPROF_BOTH1(m_sinh, return (t_exp2(x, true) - t_exp2(-x, true)) * T(0.5f);)
BRDFPROF_BOTH1(m_cosh, return (t_exp2(x, true) + t_exp2(-x, true)) * T(0.5f);)
BRDFPROF_BOTH1(m_tanh, T a = t_exp2(x, true); T b = t_exp2(-x, true); return t_div((a - b) * T(0.5f), (a + b) * T(0.5f));)
BRDFPROF_BOTH1(m_asinh, return t_log2(x + t_sqrt(x * x + T(1.0f)), true);)
BRDFPROF_BOTH1(m_acosh, return t_log2(x + t_sqrt(x * x - T(1.0f)), true);)
BRDFPROF_BOTH1(m_atanh, return t_log2(t_div(T(1.0f) + x, T(1.0f) - x), true) * T(0.5f);)
BRDFPROF_BOTH1(m_floor, return t_step(x, [](double t) { return hm::floor(t); });)
BRDFPROF_BOTH1(m_ceil, return t_step(x, [](double t) { return hm::ceil(t); });)
BRDFPROF_BOTH1(m_trunc, return t_step(x, [](double t) { return hm::trunc(t); });)
BRDFPROF_BOTH1(m_round, return t_step(x, [](double t) { return hm::round(t); });)
BRDFPROF_BOTH1(m_rint, return t_step(x, [](double t) { return hm::rint(t); });)
BRDFPROF_BOTH1(m_fabs, return T::of(hm::fabs(x.v), x.e);)
BRDFPROF_BOTH2(m_fmin, return t_fmin(x, y);)
BRDFPROF_BOTH2(m_fmax, return t_fmax(x, y);)
BRDFPROF_FN Ef m_fma(Ef a, Ef b, Ef c) { return a * b + c; }
BRDFPROF_FN Ef m_ldexp(Ef x, i32 n) { double r = hm::ldexp(x.v, n); return Ef::of(r, hm::ldexp(x.e, n) + rounded<32>(r, hm::ldexp(x.e, n))); }
BRDFPROF_FN half_t m_ldexp_h(half_t x, i32 n) { double r = hm::ldexp(x.v, n); return half_t::of(r, hm::ldexp(x.e, n) + rounded<16>(r, hm::ldexp(x.e, n))); }
// OpFRem: inherited from x - y trunc(x / y).
BRDFPROF_FN Ef m_fmod(Ef x, Ef y) { return x - y * m_trunc(m_fdiv(x, y)); }
BRDFPROF_FN bool m_isnan(Ef x) { return hm::isnan(x.v); }
BRDFPROF_FN bool m_isinf(Ef x) { return hm::isinf(x.v); }

// Halves: h_ operations under half precision's rules; conversions from f32 round (1 ULP of half).
BRDFPROF_FN half_t h_from_bits(u32 b) { u16 x = (u16)b; _Float16 h; memcpy(&h, &x, 2); return half_t((float)h); }
BRDFPROF_FN u32 h_bits(half_t h) { if (h.e > 0.0) unbounded(); _Float16 f = (_Float16)h.v; u16 x; memcpy(&x, &f, 2); return x; }
BRDFPROF_FN Ef h_to_f32(half_t h) { return Ef::of(h.v, h.e); }
BRDFPROF_FN half_t h_from_f32(Ef f) { return half_t::of(f.v, f.e + rounded<16>(f.v, f.e)); }
BRDFPROF_FN half_t h_add(half_t a, half_t b) { return a + b; }
BRDFPROF_FN half_t h_sub(half_t a, half_t b) { return a - b; }
BRDFPROF_FN half_t h_mul(half_t a, half_t b) { return a * b; }
BRDFPROF_FN half_t h_fma(half_t a, half_t b, half_t c) { return a * b + c; }
BRDFPROF_FN half_t h_neg(half_t a) { return -a; }
BRDFPROF_FN half_t h_div(half_t a, half_t b) { return t_div(a, b); }
BRDFPROF_FN bool h_lt(half_t a, half_t b) { return a < b; }
BRDFPROF_FN bool h_le(half_t a, half_t b) { return a <= b; }
BRDFPROF_FN bool h_gt(half_t a, half_t b) { return a > b; }
BRDFPROF_FN bool h_ge(half_t a, half_t b) { return a >= b; }
BRDFPROF_FN bool h_eq(half_t a, half_t b) { return a == b; }
BRDFPROF_FN half_t h_min(half_t a, half_t b) { return t_fmin(a, b); }
BRDFPROF_FN half_t h_max(half_t a, half_t b) { return t_fmax(a, b); }

// Bits: an inexact value's bits are any of its range's, so a bit cast of one is unbounded.
BRDFPROF_FN u32 f32_bits(Ef x) { if (x.e > 0.0) unbounded(); float f = (float)x.v; u32 b; memcpy(&b, &f, 4); return b; }
BRDFPROF_FN Ef f32_from_bits(u32 b) { float x; memcpy(&x, &b, 4); return Ef(x); }
BRDFPROF_FN double f64_from_bits(u64 b) { double x; memcpy(&x, &b, 8); return x; }

// Memory. Read-only and constant bindings hold the kernel's input bytes; a writable binding holds 16 bytes
// for every 4 of the Vulkan kernel's (a float as its value and bound in double, an integer as its 4 bytes).
BRDFPROF_FN double stored_bound(double e) { return brdfprof_unbounded ? BRDFPROF_INF : e; }
BRDFPROF_FN Ef input_f32(float x) { return Ef::of(x, (x != 0.0f && hm::fabs(x) < 0x1p-126f) ? hm::fabs((double)x) : 0.0); }
BRDFPROF_FN u32 ldro_u32(const u8* p, u32 off) { u32 v; memcpy(&v, p + off, 4); return v; }
BRDFPROF_FN i32 ldro_i32(const u8* p, u32 off) { i32 v; memcpy(&v, p + off, 4); return v; }
BRDFPROF_FN Ef ldro_f32(const u8* p, u32 off) { float v; memcpy(&v, p + off, 4); return input_f32(v); }
BRDFPROF_FN half_t ldro_f16(const u8* p, u32 off) { u16 v; memcpy(&v, p + off, 2); return h_from_bits(v); }
BRDFPROF_FN double ldro_f64(const u8* p, u32 off) { double v; memcpy(&v, p + off, 8); return v; }
BRDFPROF_FN void ldro4_f32(const u8* p, u32 off, Ef* o) { for (u32 k = 0u; k < 4u; ++k) o[k] = ldro_f32(p, off + 4u * k); }
BRDFPROF_FN void ldro4_u32(const u8* p, u32 off, u32* o) { memcpy(o, p + off, 16); }
#define ldc_u32 ldro_u32
#define ldc_i32 ldro_i32
#define ldc_f32 ldro_f32
#define ldc_f16 ldro_f16
#define ldc_f64 ldro_f64
#define ldc4_f32 ldro4_f32
#define ldc4_u32 ldro4_u32
BRDFPROF_FN Ef pair_ld(const u8* p) { double x[2]; memcpy(x, p, 16); return Ef::of(x[0], x[1]); }
BRDFPROF_FN void pair_st(u8* p, double v, double e) { double x[2] = {v, stored_bound(e)}; memcpy(p, x, 16); }
BRDFPROF_FN u32 ld_u32(u8* p, u32 off) { u32 v; memcpy(&v, p + 4u * off, 4); return v; }
BRDFPROF_FN i32 ld_i32(u8* p, u32 off) { i32 v; memcpy(&v, p + 4u * off, 4); return v; }
BRDFPROF_FN Ef ld_f32(u8* p, u32 off) { return pair_ld(p + 4u * off); }
BRDFPROF_FN half_t ld_f16(u8* p, u32 off) { Ef x = pair_ld(p + 4u * off); return half_t::of(x.v, x.e); }
BRDFPROF_FN double ld_f64(u8* p, u32 off) { double v; memcpy(&v, p + 4u * off, 8); return v; }
BRDFPROF_FN void ld4_f32(u8* p, u32 off, Ef* o) { for (u32 k = 0u; k < 4u; ++k) o[k] = ld_f32(p, off + 4u * k); }
BRDFPROF_FN void ld4_u32(u8* p, u32 off, u32* o) { for (u32 k = 0u; k < 4u; ++k) o[k] = ld_u32(p, off + 4u * k); }
BRDFPROF_FN void st_u32(u8* p, u32 off, u32 v) { memcpy(p + 4u * off, &v, 4); }
BRDFPROF_FN void st_i32(u8* p, u32 off, i32 v) { memcpy(p + 4u * off, &v, 4); }
BRDFPROF_FN void st_f32(u8* p, u32 off, Ef v) { pair_st(p + 4u * off, v.v, v.e); }
BRDFPROF_FN void st_f16(u8* p, u32 off, half_t v) { pair_st(p + 4u * off, v.v, v.e); }
BRDFPROF_FN void st_f64(u8* p, u32 off, double v) { memcpy(p + 4u * off, &v, 8); }
BRDFPROF_FN void st4_f32(u8* p, u32 off, Ef a, Ef b, Ef c, Ef d) { st_f32(p, off, a); st_f32(p, off + 4u, b); st_f32(p, off + 8u, c); st_f32(p, off + 12u, d); }
BRDFPROF_FN void st4_u32(u8* p, u32 off, u32 a, u32 b, u32 c, u32 d) { st_u32(p, off, a); st_u32(p, off + 4u, b); st_u32(p, off + 8u, c); st_u32(p, off + 12u, d); }
#define BRDFPROF_CONSTANT_BLOCK(name, bytes)
#define BRDFPROF_CONSTANT_FIELD(name) const u8* name;
#define BRDFPROF_CONSTANT_REF(env, name) ((env)->name)
#define BRDFPROF_SURFACE_FIELD(name) u8* name;

// From here on the kernel's (and the common prelude's) f32 values are bounded pairs.
#define float Ef
