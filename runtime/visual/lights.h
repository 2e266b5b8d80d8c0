// Effects (spec 8): per-episode light positions and the additive point-light pass, per pixel.
#pragma once

#include "runtime/kage_hd.h"
#include "runtime/kage_math.h"
#include "runtime/rng.h"
#include "runtime/visual/visual_math.h"
#include "runtime/visual/visual_params.h"
#include "runtime/visual/visual_state.h"

namespace kage {

/// Light positions of an episode (8.1): (x, y) uniform in [0.15, 0.85) for all 5 slots, drawn even
/// with lights disabled. The radii and intensities the original also draws are never used, so they
/// are not drawn.
KAGE_HD void reset_lights(Key lights_key, VisualState& s) {
  for (int32_t i = 0; i < kMaxLights; ++i) {
    s.light_x[i] = uniform(lights_key, static_cast<uint32_t>(2 * i), 0.15f, 0.85f);
    s.light_y[i] = uniform(lights_key, static_cast<uint32_t>(2 * i + 1), 0.15f, 0.85f);
  }
}

/// The point-light pass at pixel (r, c) (8.2): adds each active light's colour * intensity weighted by
/// clip(1 / (1 + nd^falloff), 0, 1) (config radius and intensity, not the per-episode ones), then clips.
/// An integer falloff is powered by repeated multiplication, a fractional one by powf.
KAGE_HD void light_pixel(const VisualParams& p, const VisualState& s, int32_t r, int32_t c, uint8_t* rgb) {
  const int32_t n = mini(p.point_light_count, kMaxLights);
  const float H = static_cast<float>(p.H), W = static_cast<float>(p.W);
  const float reach = sqrt(H * H + W * W) * p.point_light_radius;
  float acc[3] = {0.0f, 0.0f, 0.0f};
  for (int32_t i = 0; i < n; ++i) {
    const float dx = static_cast<float>(c) - s.light_x[i] * W;
    const float dy = static_cast<float>(r) - s.light_y[i] * H;
    const float nd = sqrt(dx * dx + dy * dy) / reach;
    const float pw = p.point_light_falloff_int > 0 ? int_pow(nd, p.point_light_falloff_int)
                                                   : pow(nd, p.point_light_falloff);
    const float mask = clampf(1.0f / (1.0f + pw), 0.0f, 1.0f);
    const Rgb col = p.light_colors[i];
    acc[0] += mask * static_cast<float>(col.r) * p.point_light_intensity;
    acc[1] += mask * static_cast<float>(col.g) * p.point_light_intensity;
    acc[2] += mask * static_cast<float>(col.b) * p.point_light_intensity;
  }
  for (int32_t ch = 0; ch < 3; ++ch) rgb[ch] = to_u8_clipped(static_cast<float>(rgb[ch]) + acc[ch]);
}

}  // namespace kage
