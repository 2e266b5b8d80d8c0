// Float32 and integer math helpers shared by every semantics header (host, nvcc and NVRTC).
// They pin the original's conventions: round half to even, floored modulo, clip = min(max(v, lo), hi).
#pragma once

#include "kage_hd.h"

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
KAGE_HD float exp(float v) { return KAGE_MATH_FN(exp)(v); }
KAGE_HD float log(float v) { return KAGE_MATH_FN(log)(v); }
KAGE_HD float pow(float a, float b) { return KAGE_MATH_FN(pow)(a, b); }
KAGE_HD float sin(float v) { return KAGE_MATH_FN(sin)(v); }
KAGE_HD float cos(float v) { return KAGE_MATH_FN(cos)(v); }
KAGE_HD float atan2(float y, float x) { return KAGE_MATH_FN(atan2)(y, x); }
KAGE_HD float fmod(float a, float b) { return KAGE_MATH_FN(fmod)(a, b); }

#undef KAGE_MATH_FN

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
