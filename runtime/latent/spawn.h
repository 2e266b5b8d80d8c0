// Safe spawn search at reset (spec 4.4): the first of 20 candidates right of x = 64 whose box is free.
#pragma once

#include "runtime/kage_hd.h"
#include "runtime/kage_math.h"
#include "runtime/latent/collision.h"
#include "runtime/latent/latent_params.h"
#include "runtime/latent/layout.h"

namespace kage {

/// Integer spawn cell.
struct SpawnPoint {
  int32_t x;
  int32_t y;
};

inline constexpr int32_t kSpawnCandidates = 20;
inline constexpr int32_t kSpawnStartX = 64;
inline constexpr int32_t kSpawnFallback = 64;

/// Candidate i sits at clip(64 + i * (width + 4), hw, L - hw - 1), two rows above resting on the ground
/// of that column; if no candidate is free the result is (64, 64), possibly inside terrain (spec 11.21).
KAGE_HD SpawnPoint find_spawn(const LatentParams& p, LayoutView v) {
  for (int32_t i = 0; i < kSpawnCandidates; ++i) {
    const int32_t tx = clampi(kSpawnStartX + i * (p.char_width + 4), p.hw, p.length - p.hw - 1);
    const int32_t ty = ground_top(p, v, tx) - p.hh - 2;
    if (!collides(p, v, tx, ty)) return SpawnPoint{tx, ty};
  }
  return SpawnPoint{kSpawnFallback, kSpawnFallback};
}

}  // namespace kage
