// ---- brdfprof prelude, both host builds (the translation's host check and the f64 reference): double
// precision maths through <cmath>, and integer division without the CPU's trap. ----
BRDFPROF_FN double m_sqrt_d(double x) { return std::sqrt(x); }
BRDFPROF_FN double m_rsqrt_d(double x) { return 1.0 / std::sqrt(x); }
BRDFPROF_FN double m_exp_d(double x) { return std::exp(x); }
BRDFPROF_FN double m_exp2_d(double x) { return std::exp2(x); }
BRDFPROF_FN double m_log_d(double x) { return std::log(x); }
BRDFPROF_FN double m_log2_d(double x) { return std::log2(x); }
BRDFPROF_FN double m_pow_d(double x, double y) { return std::pow(x, y); }
BRDFPROF_FN double m_sin_d(double x) { return std::sin(x); }
BRDFPROF_FN double m_cos_d(double x) { return std::cos(x); }
BRDFPROF_FN double m_tan_d(double x) { return std::tan(x); }
BRDFPROF_FN double m_asin_d(double x) { return std::asin(x); }
BRDFPROF_FN double m_acos_d(double x) { return std::acos(x); }
BRDFPROF_FN double m_atan_d(double x) { return std::atan(x); }
BRDFPROF_FN double m_atan2_d(double y, double x) { return std::atan2(y, x); }
BRDFPROF_FN double m_floor_d(double x) { return std::floor(x); }
BRDFPROF_FN double m_ceil_d(double x) { return std::ceil(x); }
BRDFPROF_FN double m_trunc_d(double x) { return std::trunc(x); }
BRDFPROF_FN double m_round_d(double x) { return std::round(x); }
BRDFPROF_FN double m_rint_d(double x) { return std::rint(x); }
BRDFPROF_FN double m_fabs_d(double x) { return std::fabs(x); }
BRDFPROF_FN double m_fmin_d(double a, double b) { return std::fmin(a, b); }
BRDFPROF_FN double m_fmax_d(double a, double b) { return std::fmax(a, b); }
BRDFPROF_FN double m_fma_d(double a, double b, double c) { return std::fma(a, b, c); }

// Integer division without the CPU's trap: a zero divisor gives what NVIDIA's hardware gives (all ones for
// unsigned, -1 or 1 for signed), INT_MIN / -1 wraps.
BRDFPROF_FN u32 m_udiv(u32 a, u32 b) { return b == 0u ? 0xffffffffu : a / b; }
BRDFPROF_FN u32 m_umod(u32 a, u32 b) { return b == 0u ? a : a % b; }
BRDFPROF_FN i32 m_sdiv(i32 a, i32 b) { return b == 0 ? (a < 0 ? 1 : -1) : (b == -1 ? (i32)(0u - (u32)a) : a / b); }
BRDFPROF_FN i32 m_srem(i32 a, i32 b) { return (b == 0 || b == -1) ? (b == 0 ? a : 0) : a % b; }
