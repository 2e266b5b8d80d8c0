// Visual state transitions: visual_reset (spec 4.1, 4.2) and visual_step (5.7, 5.9, 9.1-9.3).
// Every draw comes from the consumer's own stream (streams.def), never from a latent one.
#pragma once

#include "runtime/kage_hd.h"
#include "runtime/kage_math.h"
#include "runtime/rng.h"
#include "runtime/visual/asset_view.h"
#include "runtime/visual/background.h"
#include "runtime/visual/distractors.h"
#include "runtime/visual/lights.h"
#include "runtime/visual/npcs.h"
#include "runtime/visual/visual_params.h"
#include "runtime/visual/visual_state.h"

namespace kage {

/// Initial visual state of the episode with key `episode` (spec 4.2 steps 6-12). `ground_top(c)` is
/// the layout's ground-top row of world column c (read only by world NPC spawn, 9.1).
template <class GroundTopFn>
KAGE_HD void visual_reset(const VisualParams& p, const AssetView& assets, Key episode, const GroundTopFn& ground_top,
                          VisualState& s) {
  s = VisualState{};
  choose_background(p, assets, stream_key(episode, Stream::Background), s);
  if (p.pop_filter_count > 0) s.filter_preset_idx = randint(stream_key(episode, Stream::FilterPreset), 0, 0, p.pop_filter_count);
  reset_lights(stream_key(episode, Stream::Lights), s);
  s.sprite_idx = p.idle_sprite_idx;
  if (assets.agent_skins.count > 1) s.skin_idx = randint(stream_key(episode, Stream::AgentSkin), 0, 0, assets.agent_skins.count);
  const Key k_shape_type = fold(stream_key(episode, Stream::AgentShape), 0u);
  if (p.use_shape) {
    s.shape_type_idx = randint(k_shape_type, 0, 0, p.shape_type_count);
    s.shape_color_idx = randint(fold(stream_key(episode, Stream::AgentShape), 1u), 0, 0, p.shape_color_count);
  }
  spawn_world_npcs(p, assets, stream_key(episode, Stream::Npc), ground_top, s);
  spawn_sticky_npcs(p, assets, stream_key(episode, Stream::Sticky), s);
  spawn_distractors(p, stream_key(episode, Stream::Distractors), s);
  // The original draws the layout colour from the very key of the shape type when use_shape is on, so
  // the two indices are correlated (4.1 step 3, 11.13); the joint distribution is kept.
  const Key k_layout = p.use_shape ? k_shape_type : stream_key(episode, Stream::LayoutColor);
  s.layout_color_idx = randint(k_layout, 0, 0, p.layout_color_count);
}

/// Visual update of step t (t >= 1, the already incremented step counter), after collision; `vx` is
/// the post-collision horizontal velocity (spec 5.7).
KAGE_HD void visual_step(const VisualParams& p, const AssetView& assets, Key episode, uint32_t t, float vx,
                         VisualState& s) {
  // 5.7: the cycle length is the first skin's frame count (11.31).
  const bool moving = fabs(vx) > 0.1f;
  if (p.enable_animation && moving) {
    const int32_t frames = assets.agent_skins.count > 0 ? assets.agent_skins.sets[0].frame_count : 1;
    animation_tick(p.animation_fps, frames, s.sprite_idx, s.animation_timer);
  } else {
    s.sprite_idx = p.idle_sprite_idx;
    s.animation_timer = 0.0f;
  }
  if (p.use_shape && p.shape_rotate) s.shape_angle = floor_mod(s.shape_angle + p.shape_rotation_speed, 360.0f);
  // 5.9: the switch roll is drawn in every mode; a switch regenerates the background as at reset.
  const Key k_switch = fold(stream_key(episode, Stream::BackgroundSwitch), t);
  if (uniform(k_switch, 0, 0.0f, 1.0f) < p.switch_frequency) choose_background(p, assets, fold(k_switch, 1u), s);
  step_npcs(p, assets, episode, t, s);
  step_distractors(p, s);
}

}  // namespace kage
