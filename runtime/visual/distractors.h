// Distractors (spec 9.3): spawn at reset and the per-step bounce and spin, in screen coordinates.
// Purely visual; the drawing is in compose.h.
#pragma once

#include "runtime/kage_hd.h"
#include "runtime/kage_math.h"
#include "runtime/rng.h"
#include "runtime/visual/visual_params.h"
#include "runtime/visual/visual_state.h"

namespace kage {

/// Screen margin of the distractor box [15, W - 15] x [15, H - 15].
constexpr float kDistractorMargin = 15.0f;

/// Distractor count actually simulated and drawn.
KAGE_HD int32_t distractor_slots(const VisualParams& p) {
  return p.distractors_enabled ? clampi(p.distractor_count, 0, kMaxDistractors) : 0;
}

/// Spawn (9.3): one sub-key per property, one counter per distractor. Unlike the original, can_move
/// and can_rotate do not re-randomise the other properties (11.16): distributions match, bits differ.
KAGE_HD void spawn_distractors(const VisualParams& p, Key k, VisualState& s) {
  const float W = static_cast<float>(p.W), H = static_cast<float>(p.H);
  for (int32_t i = 0; i < distractor_slots(p); ++i) {
    const uint32_t u = static_cast<uint32_t>(i);
    s.dist_x[i] = uniform(fold(k, 0u), u, kDistractorMargin, W - kDistractorMargin);
    s.dist_y[i] = uniform(fold(k, 1u), u, kDistractorMargin, H - kDistractorMargin);
    const float v = p.distractor_max_speed;
    s.dist_vx[i] = p.distractor_can_move ? uniform(fold(k, 2u), u, -v, v) : 0.0f;
    s.dist_vy[i] = p.distractor_can_move ? uniform(fold(k, 3u), u, -v, v) : 0.0f;
    s.dist_angle[i] = uniform(fold(k, 4u), u, 0.0f, 360.0f);
    s.dist_rot[i] = p.distractor_can_rotate
                        ? uniform(fold(k, 5u), u, p.distractor_min_rotation, p.distractor_max_rotation)
                        : 0.0f;
    s.dist_shape[i] = randint(fold(k, 6u), u, 0, p.distractor_shape_count);
    s.dist_color[i] = randint(fold(k, 7u), u, 0, p.distractor_color_count);
    s.dist_size[i] = randint(fold(k, 8u), u, p.distractor_min_size, p.distractor_max_size + 1);
  }
}

/// Per-step motion (9.3): reflect a velocity when the unclamped new position reaches the margin, clamp
/// the position, advance the angle modulo 360.
KAGE_HD void step_distractors(const VisualParams& p, VisualState& s) {
  const float hi_x = static_cast<float>(p.W) - kDistractorMargin;
  const float hi_y = static_cast<float>(p.H) - kDistractorMargin;
  for (int32_t i = 0; i < distractor_slots(p); ++i) {
    const float nx = s.dist_x[i] + s.dist_vx[i];
    const float ny = s.dist_y[i] + s.dist_vy[i];
    if (nx <= kDistractorMargin || nx >= hi_x) s.dist_vx[i] = -s.dist_vx[i];
    if (ny <= kDistractorMargin || ny >= hi_y) s.dist_vy[i] = -s.dist_vy[i];
    s.dist_x[i] = clampf(nx, kDistractorMargin, hi_x);
    s.dist_y[i] = clampf(ny, kDistractorMargin, hi_y);
    s.dist_angle[i] = floor_mod(s.dist_angle[i] + s.dist_rot[i], 360.0f);
  }
}

}  // namespace kage
