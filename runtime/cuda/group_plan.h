// The launches of DeviceBatch::step_together over one list of batches, made at the list's first call and
// kept by its first batch: the GroupRow table in device memory, one launch pair per code, and the streams
// and events that order them.
#pragma once

#include <cuda.h>

#include <cstdint>
#include <vector>

namespace kage {

/// One code's launch pair: kage_step_rows and kage_render over rows [first_row, first_row + row_count).
struct GroupLaunch {
  CUfunction step_rows = nullptr;
  CUfunction render = nullptr;
  int32_t first_row = 0;
  int32_t row_count = 0;
  int32_t max_envs = 0;           ///< the largest row: the grid's width
  int32_t frames_per_block = 1;   ///< planned over the rows' environments together
  int32_t render_threads = 0;
  int32_t render_smem = 0;
  CUstream stream = nullptr;      ///< owned, when the plan has several launch pairs: where this pair runs
  CUevent done = nullptr;         ///< owned, with `stream`: recorded after the pair, joined by the lead stream
};

struct GroupPlan {
  std::vector<uint64_t> serials;    ///< the batches' serial numbers, in call order
  CUdeviceptr rows = 0;             ///< owned: the GroupRow of every part with environments, code by code
  std::vector<GroupLaunch> launches;
  CUevent entered = nullptr;        ///< owned: the lead stream on entry, waited for by the others' streams
  CUevent fork = nullptr;           ///< owned: recorded on the lead stream, waited for by the launches' streams
  std::vector<CUevent> queued;      ///< owned, one per batch: its stream's work before the step
  CUevent stepped = nullptr;        ///< owned: the step's end on the lead stream, waited for by the others

  GroupPlan() = default;
  GroupPlan(const GroupPlan&) = delete;
  GroupPlan& operator=(const GroupPlan&) = delete;
  ~GroupPlan();
};

}  // namespace kage
