// The filter chain (spec 7.1): the per-episode preset, then the main chain, as per-pixel head and tail
// stages around the neighbourhood passes. The order of the stages is written once, in walk_filters;
// each renderer (apply_filters here, the GPU's frame-pass and register paths) walks it over its own
// frame. Stochastic stages draw from the frame's FilterNoise key.
#pragma once

#include "runtime/kage_hd.h"
#include "runtime/kage_math.h"
#include "runtime/rng.h"
#include "runtime/visual/filter_ops.h"
#include "runtime/visual/filter_passes.h"
#include "runtime/visual/visual_params.h"
#include "runtime/visual/visual_random.h"
#include "runtime/visual/visual_state.h"

namespace kage {

/// The main chain's fast path (7.1 B): every stage at its identity and no pop_filter.
KAGE_HD bool filters_identity(const VisualParams& p) {
  return p.brightness == 0.0f && p.contrast == 1.0f && p.gamma == 1.0f && p.saturation == 1.0f &&
         p.hue_shift == 0.0f && p.color_temp == 0.0f && p.blur_sigma == 0.0f && p.sharpen_amount == 0.0f &&
         p.pixelate_factor <= 1 && p.vignette_strength == 0.0f && p.radial_light_strength == 0.0f &&
         p.color_jitter_std == 0.0f && p.gaussian_noise_std == 0.0f && p.poisson_noise_scale == 0.0f &&
         p.pop_filter == Preset::kNone;
}

/// The per-episode preset from pop_filter_list (7.1 A), kNone when the list is empty.
KAGE_HD Preset episode_preset(const VisualParams& p, const VisualState& s) {
  if (p.pop_filter_count <= 0) return Preset::kNone;
  return p.pop_filter_list[clampi(s.filter_preset_idx, 0, p.pop_filter_count - 1)];
}

/// Keys of one frame's stochastic filters (7.3): one sub-key per filter, derived from (episode, t).
struct FilterKeys {
  Key jitter;
  Key gaussian;
  Key poisson;
};

KAGE_HD FilterKeys filter_keys(Key episode, uint32_t t) {
  const Key k = fold(stream_key(episode, Stream::FilterNoise), t);
  return FilterKeys{fold(k, 0u), fold(k, 1u), fold(k, 2u)};
}

/// The colour-jitter matrix of a frame (7.3): M = I + std*N(3x3), each row divided by the sum of the
/// absolute values of that row.
KAGE_HD void jitter_matrix(Key k, float std_dev, float* m) {
  for (int32_t i = 0; i < 3; ++i) {
    for (int32_t j = 0; j < 3; ++j) {
      m[i * 3 + j] = (i == j ? 1.0f : 0.0f) + std_dev * normal(k, static_cast<uint32_t>(i * 3 + j));
    }
    const float norm = fabs(m[i * 3]) + fabs(m[i * 3 + 1]) + fabs(m[i * 3 + 2]);
    for (int32_t j = 0; j < 3; ++j) m[i * 3 + j] = m[i * 3 + j] / norm;
  }
}

/// Main-chain steps 2-7 at one pixel (brightness, contrast, gamma, HSV, colour temperature, jitter).
KAGE_HD void chain_head_pixel(const VisualParams& p, const float* jitter_m, float* f) {
  if (p.brightness != 0.0f) brightness_op(f, p.brightness);
  if (p.contrast != 1.0f) contrast_op(f, p.contrast);
  if (p.gamma != 1.0f) gamma_op(f, p.gamma);
  if (p.saturation != 1.0f || p.hue_shift != 0.0f) hsv_op(f, p.saturation, p.hue_shift);
  if (p.color_temp != 0.0f) color_temp_op(f, p.color_temp);
  if (p.color_jitter_std > 0.0f) matrix_op(f, jitter_m);
}

/// Main-chain steps 11-14 at pixel (r, c) (gaussian and Poisson noise, vignette, radial light).
KAGE_HD void chain_tail_pixel(const VisualParams& p, const FilterKeys& keys, int32_t r, int32_t c, float* f) {
  const uint32_t pixel = static_cast<uint32_t>(r * p.W + c);
  if (p.gaussian_noise_std > 0.0f) {
    float z[3];
    pixel_normals3(keys.gaussian, pixel, z);
    for (uint32_t ch = 0; ch < 3; ++ch) f[ch] = clampf(f[ch] + p.gaussian_noise_std * z[ch], 0.0f, 255.0f);
  }
  if (p.poisson_noise_scale > 0.0f) {
    for (uint32_t ch = 0; ch < 3; ++ch) {
      const int32_t n = poisson(keys.poisson, pixel * 3 + ch, f[ch] * p.poisson_noise_scale);
      f[ch] = clampf(static_cast<float>(n) / p.poisson_noise_scale, 0.0f, 255.0f);
    }
  }
  if (p.vignette_strength > 0.0f || p.radial_light_strength > 0.0f) {
    const float d = centre_distance(r, c, p.H, p.W);
    if (p.vignette_strength > 0.0f) vignette_op(f, p.vignette_strength, d);
    if (p.radial_light_strength > 0.0f) radial_op(f, p.radial_light_strength, p.radial_light_color, d);
  }
}

/// The filter stages in spec 7.1 order over a renderer's frame, which runs them:
///   frame.pixels(fn)        fn(float* rgb, int32_t r, int32_t c) at every pixel; the first call of a
///                           group loads the frame's uint8 values
///   frame.last_pixels(fn)   the same for the final per-pixel stage; the frame's values are final after it
///   frame.truncate()        rounds the values to uint8 and back (7.1 A's truncation)
///   frame.sharpen(amount), frame.blur(sigma), frame.pixelate(factor)   the neighbourhood passes
/// Frame::kPasses is false for a frame that never takes them (the GPU's register path: chosen only
/// when needs_frame_passes is false), so their calls are not even compiled there.
template <class Frame>
KAGE_HD void walk_filters(const VisualParams& p, Preset episode, const float* jitter_m, const FilterKeys& keys,
                          Frame& frame) {
  // A: the per-episode preset, truncated back to uint8 (7.1 A, 11.41).
  if (episode != Preset::kNone) {
    frame.pixels([&](float* px, int32_t r, int32_t c) { preset_pixel_op(episode, px, r, c, p.H, p.W); });
    if constexpr (Frame::kPasses) {
      const float sharpen = preset_sharpen_amount(episode);
      if (sharpen > 0.0f) frame.sharpen(sharpen);
    }
    frame.truncate();
  }
  if (filters_identity(p)) return;
  // B: the main chain. The pop_filter preset's sharpen sits between its pixel stages and step 2.
  float preset_sharpen = 0.0f;
  if constexpr (Frame::kPasses) preset_sharpen = preset_sharpen_amount(p.pop_filter);
  frame.pixels([&](float* px, int32_t r, int32_t c) {
    preset_pixel_op(p.pop_filter, px, r, c, p.H, p.W);
    if (preset_sharpen == 0.0f) chain_head_pixel(p, jitter_m, px);
  });
  if constexpr (Frame::kPasses) {
    if (preset_sharpen > 0.0f) {
      frame.sharpen(preset_sharpen);
      frame.pixels([&](float* px, int32_t, int32_t) { chain_head_pixel(p, jitter_m, px); });
    }
    if (p.blur_sigma > 0.0f) frame.blur(p.blur_sigma);
    if (p.sharpen_amount > 0.0f) frame.sharpen(p.sharpen_amount);
    if (p.pixelate_factor > 1) frame.pixelate(p.pixelate_factor);
  }
  frame.last_pixels([&](float* px, int32_t r, int32_t c) { chain_tail_pixel(p, keys, r, c, px); });
}

/// The CPU's frame for walk_filters: a uint8 image (H x W x 3) and two float buffers of H*W*3 values,
/// each pass writing the other one.
struct CpuFilterFrame {
  static constexpr bool kPasses = true;
  int32_t H, W;
  uint8_t* img;
  float* f;
  float* tmp;
  bool loaded = false;  ///< f holds the current values (else img does)

  template <class Fn>
  KAGE_HD void pixels(const Fn& fn) {
    for (int32_t i = 0; i < H * W; ++i) {
      float* px = f + i * 3;
      if (!loaded)
        for (int32_t ch = 0; ch < 3; ++ch) px[ch] = static_cast<float>(img[i * 3 + ch]);
      fn(px, i / W, i % W);
    }
    loaded = true;
  }
  template <class Fn>
  KAGE_HD void last_pixels(const Fn& fn) {
    for (int32_t i = 0; i < H * W; ++i) {
      float* px = f + i * 3;
      fn(px, i / W, i % W);
      for (int32_t ch = 0; ch < 3; ++ch) img[i * 3 + ch] = to_u8_clipped(px[ch]);
    }
    loaded = false;
  }
  KAGE_HD void truncate() {
    for (int32_t i = 0; i < H * W * 3; ++i) img[i] = to_u8_clipped(f[i]);
    loaded = false;
  }
  KAGE_HD void sharpen(float amount) {
    sharpen_pass(f, tmp, H, W, amount);
    swap();
  }
  KAGE_HD void blur(float sigma) {
    blur_pass(f, tmp, H, W, sigma);
    swap();
  }
  KAGE_HD void pixelate(int32_t factor) {
    pixelate_pass(f, tmp, H, W, factor);
    swap();
  }
  /// The output of a pass becomes the input of the next.
  KAGE_HD void swap() {
    float* t = f;
    f = tmp;
    tmp = t;
  }
};

/// The whole chain over a uint8 frame `img` (H x W x 3), in place. `f` and `tmp` are caller-provided
/// float buffers of H*W*3 values each (no heap in semantics code).
KAGE_HD void apply_filters(const VisualParams& p, Preset episode, const FilterKeys& keys, uint8_t* img, float* f,
                           float* tmp) {
  float jitter_m[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  if (p.color_jitter_std > 0.0f) jitter_matrix(keys.jitter, p.color_jitter_std, jitter_m);
  CpuFilterFrame frame{p.H, p.W, img, f, tmp};
  walk_filters(p, episode, jitter_m, keys, frame);
}

}  // namespace kage
