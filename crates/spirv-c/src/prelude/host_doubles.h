// ---- brdfprof prelude, both host builds (the translation's host check and the f64 reference): double
// precision maths (host_maths.h), and integer division without the CPU's trap. ----
BRDFPROF_FN double m_sqrt_d(double x) { return hm::sqrt(x); }
BRDFPROF_FN double m_rsqrt_d(double x) { return 1.0 / hm::sqrt(x); }
BRDFPROF_FN double m_exp_d(double x) { return hm::exp(x); }
BRDFPROF_FN double m_exp2_d(double x) { return hm::exp2(x); }
BRDFPROF_FN double m_log_d(double x) { return hm::log(x); }
BRDFPROF_FN double m_log2_d(double x) { return hm::log2(x); }
BRDFPROF_FN double m_pow_d(double x, double y) { return hm::pow(x, y); }
BRDFPROF_FN double m_sin_d(double x) { return hm::sin(x); }
BRDFPROF_FN double m_cos_d(double x) { return hm::cos(x); }
BRDFPROF_FN double m_tan_d(double x) { return hm::tan(x); }
BRDFPROF_FN double m_asin_d(double x) { return hm::asin(x); }
BRDFPROF_FN double m_acos_d(double x) { return hm::acos(x); }
BRDFPROF_FN double m_atan_d(double x) { return hm::atan(x); }
BRDFPROF_FN double m_atan2_d(double y, double x) { return hm::atan2(y, x); }
BRDFPROF_FN double m_floor_d(double x) { return hm::floor(x); }
BRDFPROF_FN double m_ceil_d(double x) { return hm::ceil(x); }
BRDFPROF_FN double m_trunc_d(double x) { return hm::trunc(x); }
BRDFPROF_FN double m_round_d(double x) { return hm::round(x); }
BRDFPROF_FN double m_rint_d(double x) { return hm::rint(x); }
BRDFPROF_FN double m_fabs_d(double x) { return hm::fabs(x); }
BRDFPROF_FN double m_fmin_d(double a, double b) { return hm::fmin(a, b); }
BRDFPROF_FN double m_fmax_d(double a, double b) { return hm::fmax(a, b); }
BRDFPROF_FN double m_fma_d(double a, double b, double c) { return hm::fma(a, b, c); }

// Integer division without the CPU's trap: a zero divisor gives what NVIDIA's hardware gives (all ones for
// unsigned, -1 or 1 for signed), INT_MIN / -1 wraps.
BRDFPROF_FN u32 m_udiv(u32 a, u32 b) { return b == 0u ? 0xffffffffu : a / b; }
BRDFPROF_FN u32 m_umod(u32 a, u32 b) { return b == 0u ? a : a % b; }
BRDFPROF_FN i32 m_sdiv(i32 a, i32 b) { return b == 0 ? (a < 0 ? 1 : -1) : (b == -1 ? (i32)(0u - (u32)a) : a / b); }
BRDFPROF_FN i32 m_srem(i32 a, i32 b) { return (b == 0 || b == -1) ? (b == 0 ? a : 0) : a % b; }
