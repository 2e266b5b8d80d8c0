// Math helpers only the visual stages need (kage_math.h holds the shared ones).
#pragma once

#include "runtime/kage_hd.h"
#include "runtime/kage_math.h"

namespace kage {

constexpr float kPi = 3.14159265358979323846f;

/// In the recorded goldens, colour / 255 behaves as a product with the float32 value one ulp below
/// 1/255 (the original's GPU division is approximate): saturation 0 gives max(R, G, B) - 1 and gamma
/// maps 255 to 254. Divisions of colour values by 255 use this constant to reproduce that.
constexpr float kInv255 = 0.0039215684f;  // nextafter(float(1/255), 0)

/// x^n for an integer n >= 1 by binary exponentiation, the multiplication order of JAX's
/// integer_pow (x^4 = (x*x)*(x*x), x^3 = x*(x*x)): the original's power for an integer exponent (8.2).
KAGE_HD float int_pow(float x, int32_t n) {
  float acc = 1.0f;
  bool have = false;
  while (n > 0) {
    if (n & 1) {
      acc = have ? acc * x : x;
      have = true;
    }
    n >>= 1;
    if (n > 0) x = x * x;
  }
  return acc;
}

/// Float32 erfinv, the single-precision approximation XLA uses (Giles 2010), spec A.4.
KAGE_HD float erfinv_f32(float x) {
  float w = -log((1.0f - x) * (1.0f + x));
  float p;
  if (w < 5.0f) {
    w = w - 2.5f;
    p = 2.81022636e-08f;
    p = 3.43273939e-07f + p * w;
    p = -3.5233877e-06f + p * w;
    p = -4.39150654e-06f + p * w;
    p = 0.00021858087f + p * w;
    p = -0.00125372503f + p * w;
    p = -0.00417768164f + p * w;
    p = 0.246640727f + p * w;
    p = 1.50140941f + p * w;
  } else {
    w = sqrt(w) - 3.0f;
    p = -0.000200214257f;
    p = 0.000100950558f + p * w;
    p = 0.00134934322f + p * w;
    p = -0.00367342844f + p * w;
    p = 0.00573950773f + p * w;
    p = -0.0076224613f + p * w;
    p = 0.00943887047f + p * w;
    p = 1.00167406f + p * w;
    p = 2.83297682f + p * w;
  }
  return p * x;
}

/// log(Gamma(x)) for x >= 1 in float32 (Stirling series with a shift to x >= 8), for the Poisson
/// rejection test; the library lgammaf is not thread-safe on every host libc.
KAGE_HD float lgamma_f32(float x) {
  float shift = 0.0f;
  while (x < 8.0f) {
    shift -= log(x);
    x += 1.0f;
  }
  const float inv = 1.0f / x;
  const float inv2 = inv * inv;
  const float series = inv * (1.0f / 12.0f - inv2 * (1.0f / 360.0f - inv2 * (1.0f / 1260.0f)));
  return shift + (x - 0.5f) * log(x) - x + 0.918938533f + series;
}

}  // namespace kage
