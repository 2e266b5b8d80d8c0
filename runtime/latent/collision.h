// Collision: the agent's box test and the axis-separated resolution of a proposed move (spec 5.4).
// Positions leave here as rounded integers whether or not anything collided (spec 11.18).
#pragma once

#include "runtime/kage_hd.h"
#include "runtime/kage_math.h"
#include "runtime/latent/latent_params.h"
#include "runtime/latent/layout.h"

namespace kage {

/// Whether the (2hw+1) x (2hh+1) box centred on integer (cx, cy) touches solid terrain, indices
/// clamped into the world (spec 4.4).
KAGE_HD bool collides(const LatentParams& p, LayoutView v, int32_t cx, int32_t cy) {
  return any_solid(p, v, cx - p.hw, cx + p.hw, cy - p.hh, cy + p.hh);
}

/// Resolved position and velocity of one step.
struct Resolved {
  float x;
  float y;
  float vx;
  float vy;
};

/// Resolves the move (x, y) -> (x_new, y_new): horizontal pass at the old row, then vertical pass at
/// the resolved column, each stepping back one pixel at a time towards the old position and zeroing
/// its velocity component if it moved back at all (spec 5.4, exactly the original's loops).
KAGE_HD Resolved resolve_collision(const LatentParams& p, LayoutView v, float x, float y, float x_new, float y_new,
                                   float vx, float vy) {
  const int32_t cx0 = round_even_i(x);
  const int32_t cy0 = round_even_i(y);
  const int32_t cx1 = round_even_i(x_new);
  const int32_t cy1 = round_even_i(y_new);

  int32_t cxr = cx1;
  if (collides(p, v, cx1, cy0)) {
    while (cxr != cx0 && collides(p, v, cxr, cy0)) cxr -= sign(cxr - cx0);
  }
  if (cxr != cx1) vx = 0.0f;

  int32_t cyr = cy1;
  if (collides(p, v, cxr, cy1)) {
    while (cyr != cy0 && collides(p, v, cxr, cyr)) cyr -= sign(cyr - cy0);
  }
  if (cyr != cy1) vy = 0.0f;

  return Resolved{static_cast<float>(cxr), static_cast<float>(cyr), vx, vy};
}

}  // namespace kage
