// World and sticky NPCs (spec 9.1, 9.2): spawn at reset and the per-step animation and sticky jumps.
// Purely visual; the drawing is in compose.h.
#pragma once

#include "runtime/kage_hd.h"
#include "runtime/kage_math.h"
#include "runtime/rng.h"
#include "runtime/visual/asset_view.h"
#include "runtime/visual/visual_params.h"
#include "runtime/visual/visual_state.h"

namespace kage {

/// Fixed step duration of the animations (spec 5.7): float32(1/60) seconds.
constexpr float kAnimationDt = 1.0f / 60.0f;

/// One animation tick: timer += dt; at >= 1/fps the frame advances modulo `frames` (5.7, 9.1).
KAGE_HD void animation_tick(float fps, int32_t frames, int32_t& frame, float& timer) {
  timer = timer + kAnimationDt;
  const float period = 1.0f / fps;
  if (timer >= period) {
    frame = floor_mod(frame + 1, maxi(frames, 1));
    timer = timer - period;
  }
}

KAGE_HD bool world_npcs_active(const VisualParams& p, const AssetView& a) { return p.npc_enabled && a.npc_types.count > 0; }
KAGE_HD bool sticky_npcs_active(const VisualParams& p, const AssetView& a) {
  return p.sticky_enabled && a.sticky_types.count > 0;
}

/// World NPC spawn (9.1): count uniform in [min, max]; x uniform in [200, max(300, L - 200)) clipped to
/// [0, L); y = ground_top[x] - hh - 2 - spawn_y_offset (floating 2 px, 11.37); type uniform.
/// `ground_top(c)` is the layout's ground-top row of column c.
template <class GroundTopFn>
KAGE_HD void spawn_world_npcs(const VisualParams& p, const AssetView& a, Key k, const GroundTopFn& ground_top,
                              VisualState& s) {
  s.npc_count = 0;
  s.npc_frame = 0;
  s.npc_timer = 0.0f;
  if (!world_npcs_active(p, a)) return;
  const int32_t cap = mini(p.max_npc_count, kMaxNpcs);
  s.npc_count = mini(randint(fold(k, 0u), 0, p.min_npc_count, p.max_npc_count + 1), cap);
  const Key kx = fold(k, 1u), kt = fold(k, 2u);
  const int32_t L = p.world_length;
  for (int32_t i = 0; i < s.npc_count; ++i) {
    const int32_t x = clampi(randint(kx, static_cast<uint32_t>(i), 200, maxi(300, L - 200)), 0, L - 1);
    s.npc_x[i] = x;
    s.npc_y[i] = ground_top(x) - p.hh - 2 - p.npc_spawn_y_offset;
    s.npc_type[i] = randint(kt, static_cast<uint32_t>(i), 0, a.npc_types.count);
  }
}

/// Number of simulated sticky slots: max_sticky_count (9.2).
KAGE_HD int32_t sticky_slots(const VisualParams& p) { return clampi(p.max_sticky_count, 0, kMaxSticky); }

/// Sticky NPC spawn (9.2): count, x offsets (explicit list cycled, else uniform in [x_min, x_max], else
/// floor(linspace(-60, 60, Ns))), home rows G + offset, types.
KAGE_HD void spawn_sticky_npcs(const VisualParams& p, const AssetView& a, Key k, VisualState& s) {
  s.sticky_count = 0;
  s.sticky_frame = 0;
  s.sticky_timer = 0.0f;
  if (!sticky_npcs_active(p, a)) return;
  const int32_t ns = sticky_slots(p);
  s.sticky_count = mini(randint(fold(k, 0u), 0, p.min_sticky_count, p.max_sticky_count + 1), ns);
  const Key kx = fold(k, 1u), ky = fold(k, 2u), kt = fold(k, 3u);
  const int32_t base = p.base_ground_y - p.npc_spawn_y_offset;
  for (int32_t i = 0; i < ns; ++i) {
    const uint32_t u = static_cast<uint32_t>(i);
    if (p.sticky_x_offset_count > 0) {
      s.sticky_offset[i] = p.sticky_x_offsets[i % p.sticky_x_offset_count];
    } else if (p.sticky_x_bounds_set) {
      s.sticky_offset[i] = randint(kx, u, p.sticky_x_min, p.sticky_x_max + 1);
    } else {
      const float step = ns > 1 ? 120.0f / static_cast<float>(ns - 1) : 0.0f;
      s.sticky_offset[i] = static_cast<int32_t>(floor(-60.0f + step * static_cast<float>(i)));
    }
    const int32_t off = p.sticky_y_randomize ? randint(ky, u, p.sticky_y_min_offset, p.sticky_y_max_offset + 1)
                                             : p.sticky_y_min_offset;
    s.sticky_home_y[i] = base + off;
    s.sticky_y[i] = s.sticky_home_y[i];
    s.sticky_vy[i] = 0.0f;
    s.sticky_on_ground[i] = true;
    s.sticky_type[i] = randint(kt, u, 0, a.sticky_types.count);
  }
}

/// Per-step NPC update (9.1, 9.2): animations, and the sticky jumps from the step's StickyJump key.
/// Sticky NPCs reuse the agent's gravity and jump velocity without a fall clamp and truncate y (11.38).
KAGE_HD void step_npcs(const VisualParams& p, const AssetView& a, Key episode, uint32_t t, VisualState& s) {
  if (world_npcs_active(p, a)) animation_tick(p.npc_animation_fps, a.npc_types.max_frames, s.npc_frame, s.npc_timer);
  if (!sticky_npcs_active(p, a)) return;
  const Key kj = fold(stream_key(episode, Stream::StickyJump), t);
  for (int32_t i = 0; i < sticky_slots(p); ++i) {
    const bool jump = p.sticky_can_jump && s.sticky_on_ground[i] &&
                      uniform(kj, static_cast<uint32_t>(i), 0.0f, 1.0f) < p.sticky_jump_probability;
    float vy = jump ? p.jump_velocity : s.sticky_vy[i];
    vy = vy + p.gravity;
    float yf = static_cast<float>(s.sticky_y[i]) + vy;
    const float home = static_cast<float>(s.sticky_home_y[i]);
    if (yf >= home) {
      yf = home;
      vy = 0.0f;
      s.sticky_on_ground[i] = true;
    } else {
      s.sticky_on_ground[i] = false;
    }
    s.sticky_vy[i] = vy;
    s.sticky_y[i] = static_cast<int32_t>(yf);
  }
  animation_tick(p.npc_animation_fps, a.sticky_types.max_frames, s.sticky_frame, s.sticky_timer);
}

}  // namespace kage
