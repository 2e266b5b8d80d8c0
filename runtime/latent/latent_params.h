// Latent (dynamics) parameters: everything reset and step read, already lowered from the resolved config.
// Legacy physics aliases are resolved and floats rounded to float32 before they get here (spec 0, 1.9).
#pragma once

#include "runtime/kage_hd.h"

namespace kage {

/// Parameters of the hidden game: screen size, hitbox, layout geometry, physics, reward and episode.
/// Plain values only; a specialized build defines the same names as constexpr members.
struct LatentParams {
  // Screen (camera clamp and dead zone only; spec 1.1).
  int32_t screen_h;  ///< H
  int32_t screen_w;  ///< W
  // Hitbox (spec 5.2): hw = character.width // 2, hh = character.height // 2.
  int32_t char_width;  ///< character.width: also the spawn candidate spacing (spec 4.4)
  int32_t hw;
  int32_t hh;
  // Layout geometry (spec 1.8, 4.3).
  int32_t length;            ///< L, world width in pixels
  int32_t height_px;         ///< Hl, world height in pixels
  int32_t base_ground_y;     ///< ground-top row of height 0
  int32_t pix_per_unit;      ///< pixels per height unit
  int32_t ground_thickness;  ///< rows of the solid band
  int32_t run_width;         ///< columns per segment (> 0)
  float layout_t_flat;       ///< event threshold 1 - p_change (see layout_thresholds)
  float layout_t_up;         ///< event threshold t_flat + p_change * p_up_given_change
  int32_t min_step_height;   ///< step magnitude range, height units, inclusive
  int32_t max_step_height;
  int32_t min_height;        ///< height walk clamp, height units
  int32_t max_height;
  // Camera dead zone in screen pixels (spec 5.6).
  int32_t left_margin;
  int32_t right_margin;
  // Physics (spec 5.3), px/step and px/step^2.
  float gravity;
  float jump_velocity;
  float max_speed_x;
  float terminal_velocity;
  float ground_friction;
  float air_resistance;
  float ground_accel;
  float air_accel;
  int32_t coyote_time;       ///< steps
  int32_t ground_snap_dist;  ///< rows probed below the feet
  // Reward and episode (spec 1.1, 5.8, 5.10).
  int32_t episode_length;
  float forward_reward_scale;
  float jump_penalty;
  float timestep_penalty;
  float idle_penalty;
  float dist_to_success;
};

static_assert(__is_trivially_copyable(LatentParams), "LatentParams must be POD");
static_assert(sizeof(LatentParams) == 35 * 4, "LatentParams layout changed: update the params emitter");

/// The two event thresholds of spec 4.3 step 2: computed in double from the config's double values,
/// then rounded to float32 for the comparison with the float32 uniforms (e.g. 0.3 and 0.65 for 0.7 / 0.5).
KAGE_HD void layout_thresholds(double p_change, double p_up_given_change, float& t_flat, float& t_up) {
  const double flat = 1.0 - p_change;
  t_flat = static_cast<float>(flat);
  t_up = static_cast<float>(flat + p_change * p_up_given_change);
}

/// Number of layout segments ceil(L / run_width) (spec 4.3 step 1): the per-env layout buffer size.
KAGE_HD int32_t layout_segment_count(const LatentParams& p) { return (p.length + p.run_width - 1) / p.run_width; }

/// Whether the compact layout storage can hold every height this config produces: one byte per
/// segment stores h - min_height, so the walk range must fit in a byte. The config mapping rejects
/// the rest (and run_width <= 0, which the original also rejects).
KAGE_HD bool latent_params_supported(const LatentParams& p) {
  return p.run_width > 0 && p.length > 0 && p.height_px > 0 && p.max_height >= p.min_height &&
         p.max_height - p.min_height <= 255 && p.ground_thickness >= 0;
}

}  // namespace kage
