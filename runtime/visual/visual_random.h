// Float32 samplers the visual stages draw from (spec A.4): normal and Poisson over counter-based keys.
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

/// Iteration caps of the Poisson sampler. Knuth needs about lam + 1 < 11 uniforms on average and
/// exceeds 64 with probability far below 1e-20; the rejection loop accepts >= 85 % of proposals.
constexpr uint32_t kKnuthMaxDraws = 64;
constexpr uint32_t kRejectionMaxTries = 32;

/// A Poisson(lam) draw from its own key `k` (one key per sample): Knuth's method for lam < 10,
/// Hoermann's transformed rejection (PTRS) otherwise, 0 for lam <= 0 (spec A.4).
KAGE_HD int32_t poisson(Key k, float lam) {
  if (!(lam > 0.0f)) return 0;
  if (lam < 10.0f) {
    float log_sum = 0.0f;
    uint32_t count = 0;
    while (count < kKnuthMaxDraws) {
      log_sum += log(uniform(k, count, 0.0f, 1.0f));
      ++count;
      if (!(log_sum > -lam)) break;
    }
    return static_cast<int32_t>(count) - 1;
  }
  const float log_lam = log(lam);
  const float b = 0.931f + 2.53f * sqrt(lam);
  const float a = -0.059f + 0.02483f * b;
  const float inv_alpha = 1.1239f + 1.1328f / (b - 3.4f);
  const float v_r = 0.9277f - 3.6224f / (b - 2.0f);
  for (uint32_t it = 0; it < kRejectionMaxTries; ++it) {
    const float u = uniform(k, 2 * it, 0.0f, 1.0f) - 0.5f;
    const float v = uniform(k, 2 * it + 1, 0.0f, 1.0f);
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

}  // namespace kage
