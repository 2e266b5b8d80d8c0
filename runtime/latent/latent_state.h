// Per-environment latent state (spec 4.5 without the visual fields and without the solid mask):
// the agent, the camera and the episode bookkeeping. The layout lives beside it as segment bytes.
#pragma once

#include "runtime/kage_hd.h"

namespace kage {

/// The dynamic part of one environment. Positions are integer-valued floats after every step (spec 5.4).
struct LatentState {
  float x;                 ///< agent centre, world px
  float y;
  float vx;                ///< post-collision velocity, px/step
  float vy;
  float camera_x;          ///< world x of screen column 0
  float x_max;             ///< max x reached this episode (starts at spawn x)
  float initial_x;         ///< spawn x
  float episode_return;    ///< sum of rewards
  float vx_mean;           ///< running means of post-collision vx, vy (spec 5.8)
  float vy_mean;
  int32_t coyote_timer;    ///< steps since last grounded, saturating at coyote_time + 1
  int32_t t;               ///< steps taken in this episode
  int32_t jump_count;      ///< steps with JUMP pressed
  uint32_t episode;        ///< episode index of this environment (key derivation in the batch)
  uint8_t grounded;        ///< contact at the start of the last step (spec 5.3, 11.20)
  uint8_t success_once;    ///< success reached at least once
  uint8_t pad[2];
};

static_assert(__is_trivially_copyable(LatentState), "LatentState must be POD");
static_assert(sizeof(LatentState) == 60, "LatentState layout changed");

/// What one step reports besides the next state (spec 5.8, 5.10).
struct StepOutcome {
  float reward;
  float passed_distance;  ///< x - initial_x
  float progress;         ///< passed_distance / dist_to_success, 0 if dist_to_success <= 0
  uint8_t success;        ///< passed_distance >= dist_to_success
  uint8_t terminated;     ///< always false in the original (spec 11.26)
  uint8_t truncated;      ///< t >= episode_length
};

static_assert(__is_trivially_copyable(StepOutcome), "StepOutcome must be POD");
static_assert(sizeof(StepOutcome) == 16, "StepOutcome layout changed");

}  // namespace kage
