// Reset and step of the hidden game (spec 4.2 latent parts, 5.1): the only entry points a backend calls.
// Reads LatentParams only; rendering consumes the resulting state (design.md "Latent and visual are separated").
#pragma once

#include "runtime/kage_hd.h"
#include "runtime/latent/camera.h"
#include "runtime/latent/collision.h"
#include "runtime/latent/latent_params.h"
#include "runtime/latent/latent_state.h"
#include "runtime/latent/layout.h"
#include "runtime/latent/physics.h"
#include "runtime/latent/reward.h"
#include "runtime/latent/spawn.h"
#include "runtime/rng.h"

namespace kage {

/// Starts an episode on an existing layout: spawn (4.4), camera (4.2 step 4), zero velocity and
/// contact flags (step 5) and the bookkeeping of step 13. `episode` is recorded in the state.
KAGE_HD void latent_reset_on_layout(const LatentParams& p, LayoutView v, uint32_t episode, LatentState& s) {
  const SpawnPoint sp = find_spawn(p, v);
  s = LatentState{};
  s.x = static_cast<float>(sp.x);
  s.y = static_cast<float>(sp.y);
  s.camera_x = reset_camera(p, s.x);
  s.x_max = s.x;
  s.initial_x = s.x;
  s.episode = episode;
}

/// Full latent reset: generates the layout of `episode_key` into `segments` (layout_segment_count(p)
/// bytes) from the Layout stream, then starts the episode on it.
KAGE_HD void latent_reset(const LatentParams& p, Key episode_key, uint32_t episode, uint8_t* segments,
                          LatentState& s) {
  generate_layout(p, stream_key(episode_key, Stream::Layout), segments);
  latent_reset_on_layout(p, LayoutView{segments}, episode, s);
}

/// One step of the hidden game in the order of spec 5.1: decode (3.2), physics (5.3), collision (5.4),
/// camera (5.6), t + 1, reward and metrics (5.8), truncation (5.10). The agent dynamics draw no
/// random numbers (spec 5.9).
KAGE_HD StepOutcome latent_step(const LatentParams& p, LayoutView v, LatentState& s, int32_t action) {
  const ActionInput in = decode_action(action);
  const PhysicsOut ph = apply_physics(p, v, s.x, s.y, s.vx, s.vy, s.coyote_timer, in);
  const Resolved r = resolve_collision(p, v, s.x, s.y, ph.x_new, ph.y_new, ph.vx, ph.vy);
  const float x_prev = s.x;
  s.x = r.x;
  s.y = r.y;
  s.vx = r.vx;
  s.vy = r.vy;
  s.grounded = ph.grounded ? 1 : 0;
  s.coyote_timer = ph.coyote_timer;
  s.camera_x = update_camera(p, s.camera_x, s.x);
  s.t += 1;
  return update_reward(p, s, x_prev, in.jump_pressed);
}

}  // namespace kage
