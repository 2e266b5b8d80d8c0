// Camera: horizontal dead-zone follow with a clamp to the world (spec 5.6) and its reset position (4.2).
#pragma once

#include "runtime/kage_hd.h"
#include "runtime/kage_math.h"
#include "runtime/latent/latent_params.h"

namespace kage {

/// camera_x at reset: clip(x - W // 2, 0, L - W), float32 (spec 4.2 step 4).
KAGE_HD float reset_camera(const LatentParams& p, float x) {
  return clampf(x - static_cast<float>(floor_div(p.screen_w, 2)), 0.0f, static_cast<float>(p.length - p.screen_w));
}

/// Moves the camera so that the agent's screen x stays in [left_margin, W - right_margin] (spec 5.6).
KAGE_HD float update_camera(const LatentParams& p, float camera_x, float x_new) {
  const float s = x_new - camera_x;
  const float lo = static_cast<float>(p.left_margin);
  const float hi = static_cast<float>(p.screen_w - p.right_margin);
  if (s < lo) {
    camera_x -= (lo - s);
  } else if (s > hi) {
    camera_x += (s - hi);
  }
  return clampf(camera_x, 0.0f, static_cast<float>(p.length - p.screen_w));
}

}  // namespace kage
