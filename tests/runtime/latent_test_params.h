// Test fixtures: the latent parameters of the golden recordings' "default" and "variant" configs,
// written out from ../shared/golden/README.md and the dataclass defaults of spec 1.10.
#pragma once

#include <string>

#include "runtime/latent/latent_params.h"

namespace kage::test {

/// The YAML physics, layout and reward (golden "default"): 128 x 128 screen, 16 x 24 agent.
inline LatentParams golden_default_params() {
  LatentParams p{};
  p.screen_h = 128;
  p.screen_w = 128;
  p.char_width = 16;
  p.hw = 8;
  p.hh = 12;
  p.length = 2048;
  p.height_px = 128;
  p.base_ground_y = 96;
  p.pix_per_unit = 2;
  p.ground_thickness = 2;
  p.run_width = 25;
  layout_thresholds(0.7, 0.5, p.layout_t_flat, p.layout_t_up);
  p.min_step_height = 5;
  p.max_step_height = 17;
  p.min_height = 0;
  p.max_height = 20;
  p.left_margin = 40;
  p.right_margin = 40;
  p.gravity = 0.75f;
  p.jump_velocity = -7.5f;
  p.max_speed_x = 1.0f;  // move_speed, the legacy name of max_speed_x
  p.terminal_velocity = 8.0f;
  p.ground_friction = 0.8f;
  p.air_resistance = 0.95f;
  p.ground_accel = 1.0f;
  p.air_accel = 0.4f;
  p.coyote_time = 3;
  p.ground_snap_dist = 2;
  p.episode_length = 500;
  p.forward_reward_scale = 0.2f;
  p.jump_penalty = 10.0f;
  p.timestep_penalty = 0.1f;
  p.idle_penalty = 5.0f;
  p.dist_to_success = 490.0f;
  return p;
}

/// The golden "variant": default with the reward, physics and layout overrides of golden/README.md.
inline LatentParams golden_variant_params() {
  LatentParams p = golden_default_params();
  p.episode_length = 300;
  p.forward_reward_scale = 0.5f;
  p.jump_penalty = 1.0f;
  p.timestep_penalty = 0.05f;
  p.idle_penalty = 0.5f;
  p.dist_to_success = 300.0f;
  p.gravity = 0.5f;
  p.max_speed_x = 2.0f;
  p.jump_velocity = -9.0f;
  p.ground_friction = 0.6f;
  p.air_resistance = 0.9f;
  p.terminal_velocity = 6.0f;
  p.base_ground_y = 100;
  p.pix_per_unit = 3;
  p.ground_thickness = 4;
  p.run_width = 12;
  layout_thresholds(0.9, 0.6, p.layout_t_flat, p.layout_t_up);
  p.min_step_height = 3;
  p.max_step_height = 9;
  return p;
}

/// Params of a golden file's "config" name.
inline LatentParams golden_params(const std::string& config) {
  return config == "variant" ? golden_variant_params() : golden_default_params();
}

}  // namespace kage::test
