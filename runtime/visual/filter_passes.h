// Neighbourhood filters (spec 7.1 steps 8-10): 3x3 box blend, unsharp mask and pixelation, as frame
// passes from one float32 H x W x 3 buffer into another (on the GPU: from shared memory).
#pragma once

#include "runtime/kage_hd.h"
#include "runtime/kage_math.h"

namespace kage {

/// Blend weight of the box blur: b = clip(sigma / 2.5, 0, 1) (7.1 step 8; sharpen uses sigma = 1).
KAGE_HD float blur_weight(float sigma) { return clampf(sigma / 2.5f, 0.0f, 1.0f); }

/// Box3(F) at (r, c, ch): the mean of the 3 x 3 neighbourhood with edge replication.
KAGE_HD float box3_at(const float* f, int32_t H, int32_t W, int32_t r, int32_t c, int32_t ch) {
  float sum = 0.0f;
  for (int32_t dy = -1; dy <= 1; ++dy) {
    const int32_t rr = clampi(r + dy, 0, H - 1);
    for (int32_t dx = -1; dx <= 1; ++dx) {
      const int32_t cc = clampi(c + dx, 0, W - 1);
      sum += f[(rr * W + cc) * 3 + ch];
    }
  }
  return sum / 9.0f;
}

/// (1 - b)*F + b*Box3(F) at one sample.
KAGE_HD float blur_at(const float* f, int32_t H, int32_t W, int32_t r, int32_t c, int32_t ch, float b) {
  return (1.0f - b) * f[(r * W + c) * 3 + ch] + b * box3_at(f, H, W, r, c, ch);
}

/// Blur pass (7.1 step 8): dst = (1 - b)*src + b*Box3(src).
KAGE_HD void blur_pass(const float* src, float* dst, int32_t H, int32_t W, float sigma) {
  const float b = blur_weight(sigma);
  for (int32_t r = 0; r < H; ++r)
    for (int32_t c = 0; c < W; ++c)
      for (int32_t ch = 0; ch < 3; ++ch) dst[(r * W + c) * 3 + ch] = blur_at(src, H, W, r, c, ch, b);
}

/// Sharpen pass (7.1 step 9): B = blur with sigma 1; dst = clip(src + amount*(src - B), 0, 255).
KAGE_HD void sharpen_pass(const float* src, float* dst, int32_t H, int32_t W, float amount) {
  const float b = blur_weight(1.0f);
  for (int32_t r = 0; r < H; ++r)
    for (int32_t c = 0; c < W; ++c)
      for (int32_t ch = 0; ch < 3; ++ch) {
        const int32_t i = (r * W + c) * 3 + ch;
        dst[i] = clampf(src[i] + amount * (src[i] - blur_at(src, H, W, r, c, ch, b)), 0.0f, 255.0f);
      }
}

/// Nearest resampling index (7.4): floor(float32((i + 0.5) * m / n)), clamped into [0, m).
KAGE_HD int32_t nearest_index(int32_t i, int32_t m, int32_t n) {
  const float v = (static_cast<float>(i) + 0.5f) * static_cast<float>(m) / static_cast<float>(n);
  return clampi(static_cast<int32_t>(floor(v)), 0, m - 1);
}

/// Source index of output index i after downsampling n -> n // f and upsampling back (7.4).
KAGE_HD int32_t pixelate_index(int32_t i, int32_t n, int32_t factor) {
  const int32_t small = maxi(n / factor, 1);
  return nearest_index(nearest_index(i, small, n), n, small);
}

/// Pixelate pass (7.1 step 10, 7.4; quirk 11.43): dst[r][c] = src[pix(r)][pix(c)].
KAGE_HD void pixelate_pass(const float* src, float* dst, int32_t H, int32_t W, int32_t factor) {
  for (int32_t r = 0; r < H; ++r) {
    const int32_t sr = pixelate_index(r, H, factor);
    for (int32_t c = 0; c < W; ++c) {
      const int32_t sc = pixelate_index(c, W, factor);
      for (int32_t ch = 0; ch < 3; ++ch) dst[(r * W + c) * 3 + ch] = src[(sr * W + sc) * 3 + ch];
    }
  }
}

}  // namespace kage
