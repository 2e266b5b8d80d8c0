// The per-environment info of a reset or step as columns (structure of arrays), written from the latent
// state and the step's outcome. Host and device (nvcc, NVRTC): the CPU batches and the GPU kernels
// record through the same function, so both report the same values.
#pragma once

#include "runtime/kage_hd.h"
#include "runtime/latent/latent_state.h"

namespace kage {

/// The number of info fields.
constexpr int32_t kInfoFieldCount = 0
#define KAGE_INFO_FIELD(Enum, member, name, ctype, dtype, doc, value) +1
#include "runtime/info_fields.def"
#undef KAGE_INFO_FIELD
    ;

/// Pointers to the [N] columns of every info field (runtime/info_fields.def).
struct InfoArrays {
#define KAGE_INFO_FIELD(Enum, member, name, ctype, dtype, doc, value) ctype* member;
#include "runtime/info_fields.def"
#undef KAGE_INFO_FIELD
};

/// Writes row `env` from the state `s` after a step with outcome `o` (after a reset: a zero outcome, so
/// the metrics of the new episode's spawn point).
KAGE_HD void record_info(const InfoArrays& a, int32_t env, const LatentState& s, const StepOutcome& o) {
#define KAGE_INFO_FIELD(Enum, member, name, ctype, dtype, doc, value) a.member[env] = value;
#include "runtime/info_fields.def"
#undef KAGE_INFO_FIELD
}

/// Copies row `env` of every column from `src` to `dst`.
KAGE_HD void copy_info_row(const InfoArrays& dst, const InfoArrays& src, int32_t env) {
#define KAGE_INFO_FIELD(Enum, member, name, ctype, dtype, doc, value) dst.member[env] = src.member[env];
#include "runtime/info_fields.def"
#undef KAGE_INFO_FIELD
}

}  // namespace kage
