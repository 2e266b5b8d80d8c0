// The per-environment info of a reset or step as columns (structure of arrays), written from the latent
// state and the step's outcome. Host and device (nvcc, NVRTC): the CPU batches and the GPU kernels
// record through the same function, so both report the same values.
#pragma once

#include "runtime/kage_hd.h"
#include "runtime/latent/latent_state.h"

namespace kage {

/// The number of info fields.
constexpr int32_t kInfoFieldCount = 0
#define KAGE_INFO_FIELD(Enum, member, name, ctype, dtype, doc) +1
#include "runtime/info_fields.def"
#undef KAGE_INFO_FIELD
    ;

/// Pointers to the [N] columns of every info field (runtime/info_fields.def).
struct InfoArrays {
#define KAGE_INFO_FIELD(Enum, member, name, ctype, dtype, doc) ctype* member;
#include "runtime/info_fields.def"
#undef KAGE_INFO_FIELD
};

/// Writes row `env` from the state `s` after a step with outcome `o` (after a reset: a zero outcome, so
/// the metrics of the new episode's spawn point).
KAGE_HD void record_info(const InfoArrays& a, int32_t env, const LatentState& s, const StepOutcome& o) {
  a.x[env] = s.x;
  a.y[env] = s.y;
  a.vx[env] = s.vx;
  a.vy[env] = s.vy;
  a.vx_mean[env] = s.vx_mean;
  a.vy_mean[env] = s.vy_mean;
  a.timestep[env] = s.t;
  a.passed_distance[env] = o.passed_distance;
  a.progress[env] = o.progress;
  a.success[env] = o.success;
  a.success_once[env] = s.success_once;
  a.jump_count[env] = s.jump_count;
  a.episode_return[env] = s.episode_return;
  a.episode_length[env] = s.t;
}

/// Copies row `env` of every column from `src` to `dst`.
KAGE_HD void copy_info_row(const InfoArrays& dst, const InfoArrays& src, int32_t env) {
#define KAGE_INFO_FIELD(Enum, member, name, ctype, dtype, doc) dst.member[env] = src.member[env];
#include "runtime/info_fields.def"
#undef KAGE_INFO_FIELD
}

}  // namespace kage
