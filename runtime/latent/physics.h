// Physics update of one step before collision (spec 5.3): ground contact, coyote time, jump,
// friction then acceleration, gravity, speed clamps and the world-bounds clamp of the position.
#pragma once

#include "runtime/kage_hd.h"
#include "runtime/kage_math.h"
#include "runtime/latent/latent_params.h"
#include "runtime/latent/layout.h"

namespace kage {

/// The decoded action (spec 3.2): bit0 LEFT, bit1 RIGHT, bit2 JUMP of the int32 value; higher bits are
/// ignored and negative values use their two's-complement low bits.
struct ActionInput {
  int32_t action_x;  ///< [RIGHT] - [LEFT] in {-1, 0, +1}
  bool jump_pressed;
};

KAGE_HD ActionInput decode_action(int32_t action) {
  const int32_t left = (action & 1) != 0 ? 1 : 0;
  const int32_t right = (action & 2) != 0 ? 1 : 0;
  return ActionInput{right - left, (action & 4) != 0};
}

/// Result of the physics update: the proposed position and the state's new velocity and contact flags.
struct PhysicsOut {
  float x_new;
  float y_new;
  float vx;
  float vy;
  bool grounded;
  int32_t coyote_timer;
};

/// Whether the rows cy+hh+1 .. cy+hh+ground_snap_dist under the box touch terrain (spec 5.5).
KAGE_HD bool ground_contact(const LatentParams& p, LayoutView v, int32_t cx, int32_t cy) {
  return any_solid(p, v, cx - p.hw, cx + p.hw, cy + p.hh + 1, cy + p.hh + p.ground_snap_dist);
}

/// apply_physics of spec 5.3, float32 in the original's order. `grounded` and `coyote_timer` describe
/// contact at the start of the step; the stored grounded flag is not read (spec 11.20).
KAGE_HD PhysicsOut apply_physics(const LatentParams& p, LayoutView v, float x, float y, float vx, float vy,
                                 int32_t coyote_timer, ActionInput in) {
  const bool contact = ground_contact(p, v, round_even_i(x), round_even_i(y));
  bool grounded = contact && (vy >= 0.0f);
  int32_t ct = grounded ? 0 : mini(coyote_timer + 1, p.coyote_time + 1);
  const bool can_jump = ct <= p.coyote_time;
  if (in.jump_pressed && can_jump) {
    vy = p.jump_velocity;
    grounded = false;
    ct = p.coyote_time + 1;
  }
  const float friction = grounded ? p.ground_friction : p.air_resistance;
  const float accel = grounded ? p.ground_accel : p.air_accel;
  vx = clampf(vx * friction + accel * static_cast<float>(in.action_x), -p.max_speed_x, p.max_speed_x);
  vy = clampf(vy + p.gravity, -100.0f, p.terminal_velocity);
  // The world-bounds clamp is not a collision: it does not zero the velocity (spec 11.29).
  const float x_new = clampf(x + vx, static_cast<float>(p.hw), static_cast<float>(p.length - 1 - p.hw));
  const float y_new = clampf(y + vy, static_cast<float>(p.hh), static_cast<float>(p.height_px - 1 - p.hh));
  return PhysicsOut{x_new, y_new, vx, vy, grounded, ct};
}

}  // namespace kage
