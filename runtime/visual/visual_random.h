// Float32 samplers the visual stages draw from (spec A.4): normal and Poisson over counter-based keys
// (Threefry for per-frame draws, Philox-4x32 for the per-pixel noise).
// Same distributions as the original; the bits differ (design.md "Randomness is counter-based").
#pragma once

#include "runtime/kage_hd.h"
#include "runtime/kage_math.h"
#include "runtime/rng.h"
#include "runtime/visual/visual_math.h"

namespace kage {

/// Standard normal number `i` of key k: sqrt(2) * erfinv(u), u uniform on (-1, 1) (spec A.4).
KAGE_HD float normal(Key k, uint32_t i) {
  const float u = uniform(k, i, -0.99999994f, 1.0f);  // nextafter(-1, 0)
  return 1.41421356f * erfinv_f32(u);
}

/// Uniform float in (0, 1] from the top 24 bits (exact), for logarithms that must stay finite.
KAGE_HD float unit_float_open0(uint32_t bits) { return static_cast<float>((bits >> 8) + 1u) * 5.9604644775390625e-08f; }

/// Box-Muller: two independent standard normals from two words (radius sqrt(-2 log u1), angle 2 pi u2).
/// The smallest u1 is 2^-24, so |z| <= 5.77: the tail beyond has probability 8e-9.
KAGE_HD void box_muller(uint32_t a, uint32_t b, float& z0, float& z1) {
  const float rad = sqrt(-2.0f * log(unit_float_open0(a)));
  float s, c;
  sincos_2pi(unit_float(b), s, c);
  z0 = rad * c;
  z1 = rad * s;
}

/// The three standard normals of one pixel's gaussian noise (7.3): one Philox block (counter = pixel
/// index), two Box-Muller pairs, the fourth normal unused.
KAGE_HD void pixel_normals3(Key k, uint32_t pixel, float* z) {
  const Words4 w = philox4x32(k, pixel, 0u);
  float unused;
  box_muller(w.w[0], w.w[1], z[0], z[1]);
  box_muller(w.w[2], w.w[3], z[2], unused);
}

/// Iteration caps of the Poisson sampler. Inversion for lam < 10 needs about lam + 1 steps and more
/// than 64 with probability far below 1e-20; the rejection loop accepts >= 85 % of proposals.
constexpr uint32_t kInversionMaxSteps = 64;
constexpr uint32_t kRejectionMaxTries = 32;

/// Poisson(lam) sample number `i` of key k (spec A.4's distribution): 0 for lam <= 0; inversion of the
/// CDF with one uniform for lam < 10; Hoermann's transformed rejection (PTRS) otherwise, two tries per
/// Philox block (counter (i, block)). About one block per sample instead of a key fold plus two
/// Threefry blocks per try.
KAGE_HD int32_t poisson(Key k, uint32_t i, float lam) {
  if (!(lam > 0.0f)) return 0;
  Words4 w = philox4x32(k, i, 0u);
  if (lam < 10.0f) {
    const float u = unit_float(w.w[0]);
    float p = exp(-lam);
    float cdf = p;
    uint32_t n = 0;
    while (u >= cdf && n < kInversionMaxSteps) {
      ++n;
      p = p * lam / static_cast<float>(n);
      cdf += p;
    }
    return static_cast<int32_t>(n);
  }
  const float log_lam = log(lam);
  const float b = 0.931f + 2.53f * sqrt(lam);
  const float a = -0.059f + 0.02483f * b;
  const float inv_alpha = 1.1239f + 1.1328f / (b - 3.4f);
  const float v_r = 0.9277f - 3.6224f / (b - 2.0f);
  for (uint32_t it = 0; it < kRejectionMaxTries; ++it) {
    if (it > 0 && (it & 1u) == 0) w = philox4x32(k, i, it / 2);
    const uint32_t j = (it & 1u) * 2;
    const float u = unit_float(w.w[j]) - 0.5f;
    const float v = unit_float(w.w[j + 1]);
    const float us = 0.5f - fabs(u);
    const float kf = floor((2.0f * a / us + b) * u + lam + 0.43f);
    if (us >= 0.07f && v <= v_r) return static_cast<int32_t>(kf);
    if (kf < 0.0f || (us < 0.013f && v > us)) continue;
    const float s = log(v * inv_alpha / (a / (us * us) + b));
    const float t = -lam + kf * log_lam - lgamma_f32(kf + 1.0f);
    if (s <= t) return static_cast<int32_t>(kf);
  }
  return static_cast<int32_t>(round_even(lam));  // unreachable in practice (see kRejectionMaxTries)
}

/// A Poisson(lam) draw from its own key (sample 0 of k).
KAGE_HD int32_t poisson(Key k, float lam) { return poisson(k, 0u, lam); }

}  // namespace kage
