// Filter primitives (spec 7.1-7.5, 3.4) as per-pixel float32 operations on one RGB triple in [0, 255],
// in the original's arithmetic order. Neighbourhood filters are frame passes (filter_passes.h).
#pragma once

#include "runtime/kage_hd.h"
#include "runtime/kage_math.h"
#include "runtime/visual/approx_division.h"
#include "runtime/visual/visual_math.h"
#include "runtime/visual/visual_params.h"

namespace kage {

/// 7.1 step 2: F = clip(F + 100*b, 0, 255).
KAGE_HD void brightness_op(float* f, float b) {
  for (int32_t ch = 0; ch < 3; ++ch) f[ch] = clampf(f[ch] + 100.0f * b, 0.0f, 255.0f);
}

/// 7.1 step 3: F = clip((F - 128)*k + 128, 0, 255).
KAGE_HD void contrast_op(float* f, float k) {
  for (int32_t ch = 0; ch < 3; ++ch) f[ch] = clampf((f[ch] - 128.0f) * k + 128.0f, 0.0f, 255.0f);
}

/// 7.1 step 4: F = 255*(F/255)^gamma, no clip.
KAGE_HD void gamma_op(float* f, float g) {
  for (int32_t ch = 0; ch < 3; ++ch) f[ch] = 255.0f * pow(f[ch] * kInv255, g);
}

/// 7.2: one HSV round trip with saturation multiplier `sat` and hue offset `hue_shift` (degrees);
/// the later hue rules override the earlier ones, so saturation 0 gives max(R, G, B) greys (11.42).
/// The divisions by dl and mx are the GPU's approximate ones (approx_division.h): with correctly rounded
/// divisions 1-5 % of the values of a saturation or hue change end 1 code off the goldens; with the
/// original's compiled arithmetic (no FMA contraction anywhere in this op, checked against XLA's output
/// on an H200) the goldens are reproduced. kInv255 is approx_rcp(255).
KAGE_HD void hsv_op(float* f, float sat, float hue_shift) {
  const float r = f[0] * kInv255, g = f[1] * kInv255, b = f[2] * kInv255;
  const float mx = maxf(maxf(r, g), b);
  const float mn = minf(minf(r, g), b);
  const float dl = mx - mn;
  float hue = 0.0f;
  if (mx == r && dl > 0.0f) hue = 60.0f * floor_mod(approx_div(g - b, dl), 6.0f);
  if (mx == g && dl > 0.0f) hue = 60.0f * (approx_div(b - r, dl) + 2.0f);
  if (mx == b && dl > 0.0f) hue = 60.0f * (approx_div(r - g, dl) + 4.0f);
  float s = mx > 0.0f ? approx_div(dl, mx) : 0.0f;
  const float v = mx;
  if (sat != 1.0f) s = clampf(s * sat, 0.0f, 1.0f);
  if (hue_shift != 0.0f) hue = floor_mod(hue + hue_shift, 360.0f);
  // XLA turns the division by the constant 60 into a product with its float32 reciprocal.
  const float hp = hue * (1.0f / 60.0f);
  const float C = v * s;
  const float X = C * (1.0f - fabs(floor_mod(hp, 2.0f) - 1.0f));
  const float m = v - C;
  const int32_t i = floor_mod(static_cast<int32_t>(floor(hp)), 6);
  float o[3];
  switch (i) {
    case 0: o[0] = C; o[1] = X; o[2] = 0.0f; break;
    case 1: o[0] = X; o[1] = C; o[2] = 0.0f; break;
    case 2: o[0] = 0.0f; o[1] = C; o[2] = X; break;
    case 3: o[0] = 0.0f; o[1] = X; o[2] = C; break;
    case 4: o[0] = X; o[1] = 0.0f; o[2] = C; break;
    default: o[0] = C; o[1] = 0.0f; o[2] = X; break;
  }
  for (int32_t ch = 0; ch < 3; ++ch) f[ch] = clampf(255.0f * (o[ch] + m), 0.0f, 255.0f);
}

/// 7.1 step 6: warm (+R, -B) for T > 0, cool (+B, -R) for T < 0, then clip.
KAGE_HD void color_temp_op(float* f, float t) {
  const float w = maxf(0.0f, t);
  const float c = maxf(0.0f, -t);
  f[0] = f[0] + 30.0f * w;
  f[2] = f[2] - 15.0f * w;
  f[2] = f[2] + 30.0f * c;
  f[0] = f[0] - 15.0f * c;
  for (int32_t ch = 0; ch < 3; ++ch) f[ch] = clampf(f[ch], 0.0f, 255.0f);
}

/// 7.3 colour jitter: F' = M F (M row-normalised, built by jitter_matrix), then clip.
KAGE_HD void matrix_op(float* f, const float* m) {
  float o[3];
  for (int32_t ch = 0; ch < 3; ++ch) o[ch] = m[ch * 3] * f[0] + m[ch * 3 + 1] * f[1] + m[ch * 3 + 2] * f[2];
  for (int32_t ch = 0; ch < 3; ++ch) f[ch] = clampf(o[ch], 0.0f, 255.0f);
}

/// 7.5: normalised distance of pixel (r, c) from (H/2, W/2), integer indices (half a pixel off, 11.44).
KAGE_HD float centre_distance(int32_t r, int32_t c, int32_t H, int32_t W) {
  const float hc = static_cast<float>(H) / 2.0f;
  const float wc = static_cast<float>(W) / 2.0f;
  const float dy = static_cast<float>(r) - hc;
  const float dx = static_cast<float>(c) - wc;
  return sqrt(dy * dy + dx * dx) / sqrt(hc * hc + wc * wc);
}

/// 7.5 vignette: F *= clip(1 - s*d^2, 0, 1).
KAGE_HD void vignette_op(float* f, float strength, float d) {
  const float k = clampf(1.0f - strength * (d * d), 0.0f, 1.0f);
  for (int32_t ch = 0; ch < 3; ++ch) f[ch] = f[ch] * k;
}

/// 7.5 radial light: F = clip(F + s*clip(1 - d^1.5, 0, 1)*colour, 0, 255).
KAGE_HD void radial_op(float* f, float strength, Rgb color, float d) {
  const float m = strength * clampf(1.0f - pow(d, 1.5f), 0.0f, 1.0f);
  const float col[3] = {static_cast<float>(color.r), static_cast<float>(color.g), static_cast<float>(color.b)};
  for (int32_t ch = 0; ch < 3; ++ch) f[ch] = clampf(f[ch] + m * col[ch], 0.0f, 255.0f);
}

/// The per-pixel part of a preset (spec 3.4), in its fixed order. Cyberpunk ends with a sharpen
/// (a frame pass, see preset_sharpen_amount); everything else is per-pixel.
KAGE_HD void preset_pixel_op(Preset preset, float* f, int32_t r, int32_t c, int32_t H, int32_t W) {
  switch (preset) {
    case Preset::kVintage:
      hsv_op(f, 0.7f, 0.0f);
      color_temp_op(f, 0.3f);
      vignette_op(f, 0.3f, centre_distance(r, c, H, W));
      contrast_op(f, 1.1f);
      break;
    case Preset::kHorror:
      hsv_op(f, 0.3f, 0.0f);
      color_temp_op(f, -0.4f);
      brightness_op(f, -0.2f);
      vignette_op(f, 0.6f, centre_distance(r, c, H, W));
      contrast_op(f, 1.4f);
      break;
    case Preset::kRetro:
      // Saturation and hue are separate round trips inside presets (3.4).
      hsv_op(f, 1.5f, 0.0f);
      hsv_op(f, 1.0f, 15.0f);
      brightness_op(f, 0.1f);
      contrast_op(f, 0.9f);
      break;
    case Preset::kCyberpunk:
      hsv_op(f, 1.8f, 0.0f);
      color_temp_op(f, -0.2f);
      contrast_op(f, 1.3f);
      break;
    case Preset::kNoir:
      hsv_op(f, 0.0f, 0.0f);
      contrast_op(f, 1.6f);
      vignette_op(f, 0.4f, centre_distance(r, c, H, W));
      break;
    default:
      break;
  }
}

/// The sharpen amount that ends a preset (cyberpunk: 0.5), 0 for the others.
KAGE_HD float preset_sharpen_amount(Preset preset) { return preset == Preset::kCyberpunk ? 0.5f : 0.0f; }

}  // namespace kage
