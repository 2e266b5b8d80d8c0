// Visual state of one environment: indices, seeds and small entity arrays, never an image.
// Written by visual_reset / visual_step (visual_update.h), read by render_frame (render.h).
#pragma once

#include "runtime/kage_hd.h"
#include "runtime/rng.h"
#include "runtime/visual/visual_params.h"

namespace kage {

/// Entity capacities. The original sizes its arrays by the config (max_npc_count, max_sticky_count,
/// distractors.count, spec 4.5); the benchmark uses at most 20 / 5 / 5. The lowering rejects more.
constexpr int32_t kMaxNpcs = 32;
constexpr int32_t kMaxSticky = 8;
constexpr int32_t kMaxDistractors = 16;

/// Per-environment visual state (spec 4.5, minus the background copy and the filter key: the background
/// is an index, a colour index or a noise key; per-step keys are derived from (episode key, t)).
struct VisualState {
  // Background (6.2): image index (image mode), colour index (colour mode) or the noise key (noise mode).
  int32_t bg_index;
  Key bg_noise_key;

  // Agent look (4.1, 5.7).
  int32_t skin_idx;
  int32_t sprite_idx;
  float animation_timer;       ///< seconds toward the next frame
  int32_t shape_type_idx;      ///< index into VisualParams::shape_types
  int32_t shape_color_idx;     ///< index into VisualParams::shape_colors
  float shape_angle;           ///< degrees
  int32_t layout_color_idx;    ///< index into VisualParams::layout_colors
  int32_t filter_preset_idx;   ///< index into VisualParams::pop_filter_list

  float light_x[kMaxLights];   ///< normalised light positions (8.1), in [0.15, 0.85)
  float light_y[kMaxLights];

  // World NPCs (9.1). All slots animate in lockstep (they start together), so one frame/timer pair
  // stands for the original's per-slot arrays. Empty slots have npc_x = 0 and are never drawn.
  int32_t npc_count;
  int32_t npc_frame;
  float npc_timer;
  int32_t npc_x[kMaxNpcs];
  int32_t npc_y[kMaxNpcs];
  int32_t npc_type[kMaxNpcs];

  // Sticky NPCs (9.2): all max_sticky_count slots are simulated, the first sticky_count drawn.
  int32_t sticky_count;
  int32_t sticky_frame;
  float sticky_timer;
  int32_t sticky_offset[kMaxSticky];  ///< screen-x offset from the agent
  int32_t sticky_y[kMaxSticky];
  int32_t sticky_home_y[kMaxSticky];
  float sticky_vy[kMaxSticky];
  bool sticky_on_ground[kMaxSticky];
  int32_t sticky_type[kMaxSticky];

  // Distractors (9.3), screen coordinates; angles are used as radians when drawn (11.34).
  float dist_x[kMaxDistractors];
  float dist_y[kMaxDistractors];
  float dist_vx[kMaxDistractors];
  float dist_vy[kMaxDistractors];
  float dist_angle[kMaxDistractors];
  float dist_rot[kMaxDistractors];
  int32_t dist_shape[kMaxDistractors];
  int32_t dist_color[kMaxDistractors];
  int32_t dist_size[kMaxDistractors];
};

static_assert(__is_trivially_copyable(VisualState), "VisualState must be POD");
static_assert(sizeof(VisualState) <= 1280, "VisualState must stay small (design.md 'State is small')");

}  // namespace kage
