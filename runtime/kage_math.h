// Float32 and integer math helpers shared by every semantics header (host, nvcc and NVRTC).
// They pin the original's conventions: round half to even, floored modulo, clip = min(max(v, lo), hi).
#pragma once

#include "runtime/kage_hd.h"

#if !defined(__CUDACC__)
#include <cmath>
#endif

namespace kage {

// Under nvcc and NVRTC the CUDA math builtins (rintf, floorf, ...) are in the global namespace
// without any header; on the host they come from <cmath>. KAGE_MATH_FN picks the right spelling.
#if defined(__CUDACC__)
#define KAGE_MATH_FN(name) ::name##f
#else
#define KAGE_MATH_FN(name) std::name
#endif

/// Round half to even (the original's `round`, spec 0 "Rounding"); assumes the default rounding mode.
KAGE_HD float round_even(float v) { return KAGE_MATH_FN(rint)(v); }

/// round_even as int32 (the value must fit; positions and pixel indices always do).
KAGE_HD int32_t round_even_i(float v) { return static_cast<int32_t>(KAGE_MATH_FN(rint)(v)); }

KAGE_HD float floor(float v) { return KAGE_MATH_FN(floor)(v); }
KAGE_HD float ceil(float v) { return KAGE_MATH_FN(ceil)(v); }
KAGE_HD float trunc(float v) { return KAGE_MATH_FN(trunc)(v); }
KAGE_HD float fabs(float v) { return KAGE_MATH_FN(fabs)(v); }
KAGE_HD float sqrt(float v) { return KAGE_MATH_FN(sqrt)(v); }
KAGE_HD float fmod(float a, float b) { return KAGE_MATH_FN(fmod)(a, b); }

#undef KAGE_MATH_FN

// ---- transcendentals from IEEE-exact operations ----
// The library exp/log/pow/sin/cos of the host libm and of CUDA differ in the last ulp, and the noise
// samplers turn one ulp into a different sample (a GPU frame 109 codes off the CPU one). These are
// built only from +, -, *, / (correctly rounded everywhere), sqrt, floor, comparisons and bit moves,
// evaluated in a fixed order: with -ffp-contract=off on the host and --fmad=false on the device both
// compute the same bits. Accuracy: log/exp < 1 ulp (fdlibm's float algorithms), pow/sin/cos through
// double arithmetic (error ~1e-14 before the final rounding to float).

/// Reinterprets the bytes of one trivially copyable value as another of the same size
/// (std::bit_cast is not available under NVRTC).
template <class To, class From>
KAGE_HD To bit_cast_hd(From from) {
  static_assert(sizeof(To) == sizeof(From), "bit_cast_hd needs equal sizes");
  union {
    From from;
    To to;
  } v;
  v.from = from;
  return v.to;
}
KAGE_HD uint32_t float_bits(float f) { return bit_cast_hd<uint32_t>(f); }
KAGE_HD float bits_float(uint32_t u) { return bit_cast_hd<float>(u); }
KAGE_HD uint64_t double_bits(double d) { return bit_cast_hd<uint64_t>(d); }
KAGE_HD double bits_double(uint64_t u) { return bit_cast_hd<double>(u); }

#if defined(__CUDACC__)
KAGE_HD double floor_d(double v) { return ::floor(v); }
#else
KAGE_HD double floor_d(double v) { return std::floor(v); }
#endif

/// +inf (no <limits> under NVRTC).
KAGE_HD float inf_f() { return bits_float(0x7f800000u); }


/// Natural logarithm (fdlibm e_logf: x = 2^k (1 + f), log(1 + f) = f - f^2/2 + s (f^2/2 + R(s^2)),
/// s = f / (2 + f)). log(0) = -inf, log(x < 0) = NaN.
KAGE_HD float log(float x) {
  const int32_t ix0 = static_cast<int32_t>(float_bits(x));
  if ((ix0 & 0x7fffffff) == 0) return -inf_f();
  if (ix0 < 0) return (x - x) / 0.0f;
  if (ix0 >= 0x7f800000) return x + x;
  int32_t k = 0;
  int32_t ix = ix0;
  if (ix < 0x00800000) {  // subnormal: scale by 2^25
    k -= 25;
    ix = static_cast<int32_t>(float_bits(x * 33554432.0f));
  }
  k += (ix >> 23) - 127;
  ix &= 0x007fffff;
  const int32_t i = (ix + (0x95f64 << 3)) & 0x800000;  // mantissa >= sqrt(2): halve it
  const float m = bits_float(static_cast<uint32_t>(ix | (i ^ 0x3f800000)));
  k += i >> 23;
  const float f = m - 1.0f;
  const float s = f / (2.0f + f);
  const float z = s * s;
  const float w = z * z;
  const float t1 = w * (4.0000000596e-01f + w * (2.2222198546e-01f + w * 1.5313838422e-01f));
  const float t2 = z * (6.6666668653e-01f + w * (2.8571429849e-01f + w * (1.8183572590e-01f + w * 1.4798198640e-01f)));
  const float r = t2 + t1;
  const float hfsq = 0.5f * f * f;
  const float dk = static_cast<float>(k);
  return dk * 6.9313812256e-01f - ((hfsq - (s * (hfsq + r) + dk * 9.0580006145e-06f)) - f);
}

/// 2^k as a float for k in [-126, 127].
KAGE_HD float pow2i(int32_t k) { return bits_float(static_cast<uint32_t>(k + 127) << 23); }

/// Exponential (fdlibm e_expf: x = k ln2 + r with a two-part ln2, a rational approximation of e^r,
/// then scaling by 2^k in two exact steps so that subnormal results round once).
KAGE_HD float exp(float x) {
  if (x != x) return x + x;
  if (x > 8.8721679688e+01f) return inf_f();
  if (x < -1.0397208405e+02f) return 0.0f;
  const int32_t k = static_cast<int32_t>(x * 1.4426950216e+00f + (x < 0.0f ? -0.5f : 0.5f));
  const float t = static_cast<float>(k);
  const float hi = x - t * 6.9314575195e-01f;  // ln2 high part: 15 significant bits, t * it is exact
  const float lo = t * 1.4286067653e-06f;
  const float r = hi - lo;
  const float rr = r * r;
  const float c =
      r - rr * (1.6666667163e-01f +
                rr * (-2.7777778450e-03f + rr * (6.6137559770e-05f + rr * (-1.6533901999e-06f + rr * 4.1381369442e-08f))));
  const float y = 1.0f - ((lo - (r * c) / (2.0f - c)) - hi);
  const int32_t k1 = k / 2;
  return y * pow2i(k1) * pow2i(k - k1);
}

/// log(x) for a positive finite double (a float widened: always normal). Series of 2 atanh(s) with
/// s = f / (2 + f), |s| < 0.172: truncation error < 2e-14 relative.
KAGE_HD double log_d(double x) {
  const uint64_t b = double_bits(x);
  int32_t e = static_cast<int32_t>((b >> 52) & 0x7ff) - 1023;
  double m = bits_double((b & 0x000fffffffffffffull) | 0x3ff0000000000000ull);
  if (m > 1.4142135623730951) {
    m = m * 0.5;
    e += 1;
  }
  const double f = m - 1.0;
  const double s = f / (2.0 + f);
  const double z = s * s;
  const double p =
      1.0 / 3 + z * (1.0 / 5 + z * (1.0 / 7 + z * (1.0 / 9 + z * (1.0 / 11 + z * (1.0 / 13 + z * (1.0 / 15 + z * (1.0 / 17)))))));
  const double hfsq = 0.5 * f * f;
  const double de = static_cast<double>(e);
  // f - hfsq + s (hfsq + 2 z p) keeps the leading term exact (fdlibm's arrangement).
  return de * 6.93147180369123816490e-01 - ((hfsq - (s * (hfsq + 2.0 * z * p) + de * 1.90821492927058770002e-10)) - f);
}

/// e^y as a float for a double y (rounded once at the end). Taylor series to r^12 on |r| <= ln2 / 2.
KAGE_HD float exp_d_to_float(double y) {
  if (y != y) return static_cast<float>(y);
  if (y > 89.0) return inf_f();
  if (y < -104.0) return 0.0f;
  const double kd = floor_d(y * 1.44269504088896338700 + 0.5);
  const double r = (y - kd * 6.93147180369123816490e-01) - kd * 1.90821492927058770002e-10;
  double p = 1.0 / 479001600.0;  // 1/12!
  p = 1.0 / 39916800.0 + r * p;
  p = 1.0 / 3628800.0 + r * p;
  p = 1.0 / 362880.0 + r * p;
  p = 1.0 / 40320.0 + r * p;
  p = 1.0 / 5040.0 + r * p;
  p = 1.0 / 720.0 + r * p;
  p = 1.0 / 120.0 + r * p;
  p = 1.0 / 24.0 + r * p;
  p = 1.0 / 6.0 + r * p;
  p = 0.5 + r * p;
  p = 1.0 + r * p;
  p = 1.0 + r * p;
  const int64_t k = static_cast<int64_t>(kd);
  return static_cast<float>(p * bits_double(static_cast<uint64_t>(k + 1023) << 52));
}

/// Whether a float holds an integer value, and whether that integer is odd.
KAGE_HD bool is_integer(float v) { return floor(v) == v; }
KAGE_HD bool is_odd_integer(float v) { return is_integer(v) && fabs(v) < 16777216.0f && floor(v * 0.5f) != v * 0.5f; }

/// a^b = e^(b log a) in double (C's special cases for zero, one, infinities and negative bases).
KAGE_HD float pow(float a, float b) {
  if (b == 0.0f || a == 1.0f) return 1.0f;
  if (a != a || b != b) return a + b;
  float sign = 1.0f;
  if (a < 0.0f) {
    if (!is_integer(b)) return (a - a) / 0.0f;
    if (is_odd_integer(b)) sign = -1.0f;
    a = -a;
  }
  if (a == 0.0f) return b > 0.0f ? 0.0f * sign : sign * inf_f();
  if (a == inf_f()) return b > 0.0f ? sign * inf_f() : 0.0f * sign;
  if (b == inf_f()) return a > 1.0f ? inf_f() : 0.0f;
  if (b == -inf_f()) return a > 1.0f ? 0.0f : inf_f();
  return sign * exp_d_to_float(static_cast<double>(b) * log_d(static_cast<double>(a)));
}

/// sin and cos of a float in double: x = q pi/2 + r (pi/2 in two parts, the first of 33 bits, so q
/// times it is exact for |q| < 2^20), Taylor series on |r| <= pi/4 (error < 3e-14), quadrant select.
KAGE_HD void sincos(float x, float& s_out, float& c_out) {
  if (!(fabs(x) < 1.0e6f)) {  // inf / NaN / beyond the reduction's exact range
    s_out = c_out = (x - x) / 0.0f;
    if (x == x && fabs(x) != inf_f()) {  // large finite angles do not occur in the semantics
      s_out = 0.0f;
      c_out = 1.0f;
    }
    return;
  }
  const double xd = static_cast<double>(x);
  const double qd = floor_d(xd * 6.36619772367581382433e-01 + 0.5);
  const double r = (xd - qd * 1.57079632673412561417e+00) - qd * 6.07710050650619224932e-11;
  const double z = r * r;
  double sp = -1.0 / 1307674368000.0;  // -1/15!
  sp = 1.0 / 6227020800.0 + z * sp;
  sp = -1.0 / 39916800.0 + z * sp;
  sp = 1.0 / 362880.0 + z * sp;
  sp = -1.0 / 5040.0 + z * sp;
  sp = 1.0 / 120.0 + z * sp;
  sp = -1.0 / 6.0 + z * sp;
  const double sr = r + r * z * sp;
  double cp = 1.0 / 20922789888000.0;  // 1/16!
  cp = -1.0 / 87178291200.0 + z * cp;
  cp = 1.0 / 479001600.0 + z * cp;
  cp = -1.0 / 3628800.0 + z * cp;
  cp = 1.0 / 40320.0 + z * cp;
  cp = -1.0 / 720.0 + z * cp;
  cp = 1.0 / 24.0 + z * cp;
  cp = -0.5 + z * cp;
  const double cr = 1.0 + z * cp;
  const int32_t q = static_cast<int32_t>(static_cast<int64_t>(qd) & 3);
  const double sv = q == 0 ? sr : q == 1 ? cr : q == 2 ? -sr : -cr;
  const double cv = q == 0 ? cr : q == 1 ? -sr : q == 2 ? -cr : sr;
  s_out = static_cast<float>(sv);
  c_out = static_cast<float>(cv);
}

KAGE_HD float sin(float x) {
  float s, c;
  sincos(x, s, c);
  return s;
}
KAGE_HD float cos(float x) {
  float s, c;
  sincos(x, s, c);
  return c;
}

/// sin(2 pi u) and cos(2 pi u) for u in [0, 1) in float, for Box-Muller: 4u splits exactly into a
/// quadrant and a remainder in [-1/2, 1/2], so only the final product by pi/2 rounds.
KAGE_HD void sincos_2pi(float u, float& s_out, float& c_out) {
  const float t = u * 4.0f;
  const float qf = floor(t + 0.5f);
  const float x = (t - qf) * 1.57079632679489661923f;
  const float z = x * x;
  const float sr = x + x * z * (-1.6666667163e-01f + z * (8.3333337680e-03f + z * (-1.9841270114e-04f + z * 2.7557314297e-06f)));
  const float cr = 1.0f + z * (-0.5f + z * (4.1666667908e-02f + z * (-1.3888889225e-03f + z * 2.4801587642e-05f)));
  const int32_t q = static_cast<int32_t>(qf) & 3;
  s_out = q == 0 ? sr : q == 1 ? cr : q == 2 ? -sr : -cr;
  c_out = q == 0 ? cr : q == 1 ? -sr : q == 2 ? -cr : sr;
}

/// max / min written as selects (jnp.maximum/minimum on non-NaN values), identical on every target.
KAGE_HD float maxf(float a, float b) { return a > b ? a : b; }
KAGE_HD float minf(float a, float b) { return a < b ? a : b; }
KAGE_HD int32_t maxi(int32_t a, int32_t b) { return a > b ? a : b; }
KAGE_HD int32_t mini(int32_t a, int32_t b) { return a < b ? a : b; }

/// clip(v, lo, hi) = min(max(v, lo), hi) (spec 0): with lo > hi the result is hi.
KAGE_HD float clampf(float v, float lo, float hi) { return minf(maxf(v, lo), hi); }
KAGE_HD int32_t clampi(int32_t v, int32_t lo, int32_t hi) { return mini(maxi(v, lo), hi); }

/// Floored modulo for floats (result has the sign of b, like jnp.remainder / Python %).
KAGE_HD float floor_mod(float a, float b) {
  float r = fmod(a, b);
  if (r != 0.0f && ((r < 0.0f) != (b < 0.0f))) r += b;
  return r;
}

/// Floored modulo for ints (result in [0, b) for b > 0).
KAGE_HD int32_t floor_mod(int32_t a, int32_t b) {
  int32_t r = a % b;
  if (r != 0 && ((r < 0) != (b < 0))) r += b;
  return r;
}

/// Floored integer division (Python //).
KAGE_HD int32_t floor_div(int32_t a, int32_t b) {
  int32_t q = a / b;
  if ((a % b != 0) && ((a < 0) != (b < 0))) --q;
  return q;
}

/// sign(v) in {-1, 0, +1}.
KAGE_HD int32_t sign(int32_t v) { return (v > 0) - (v < 0); }

/// Float to uint8 as the original: clip to [0, 255], then truncate toward zero (spec 0).
KAGE_HD uint8_t to_u8_clipped(float v) { return static_cast<uint8_t>(clampf(v, 0.0f, 255.0f)); }

}  // namespace kage
