// The device-side view of a batch of environments: plain pointers into device memory, passed by value
// as the one argument of every kernel (kernels.cuh). Host and device (nvcc, NVRTC), no std headers.
#pragma once

#include "runtime/episode_info.h"
#include "runtime/kage_hd.h"
#include "runtime/latent/latent_state.h"
#include "runtime/visual/asset_view.h"
#include "runtime/visual/visual_state.h"

namespace kage {

/// The first out-of-range action a step kernel saw (in host-mapped memory, so the host reads it without
/// a copy). `state` is 0 until then, 1 while the reporting thread writes, 2 once the fields are complete.
struct ActionError {
  uint32_t state;
  int32_t env;
  int64_t value;
  uint64_t step;   ///< the launch's number: StepCount::steps + 1 when it ran
};

/// A batch part's step launches, counted on the device (so that a launch replayed from a CUDA graph is
/// numbered as a fresh one would be): the warps that finished their environments' step add to `done`;
/// the last one resets it and adds 1 to `steps`.
struct StepCount {
  uint64_t steps;
  uint32_t done;
};

/// Where a step kernel reads its actions: element `env * stride` of an int32 or int64 device array.
struct ActionSource {
  const void* data;
  int64_t stride;        ///< in elements
  int32_t is_int64;      ///< 0: int32 elements, 1: int64
  StepCount* count;      ///< device memory; null: launches not counted (no report either)
  ActionError* error;    ///< host-mapped; values outside 0..7 are reported here (then masked, spec 3.2)
};

/// Every buffer of a device batch (structure of arrays over environments; the latent and visual
/// states are arrays of structs, copied whole into shared memory by the block that renders them).
/// Environment i's layout is `segments + i * segment_stride`; its observation `obs + i * H * W * 3`.
struct DeviceEnvs {
  int32_t num_envs;
  int32_t segment_stride;      ///< bytes per layout, layout_segment_count rounded up to 4
  int32_t visual_extent;       ///< leading VisualState bytes the config uses (visual_state_extent)
  const uint64_t* seeds;       ///< [N] user seeds; episode e uses fold(seed_key(seed), e)
  LatentState* latent;         ///< [N]
  uint8_t* segments;           ///< [N][segment_stride]
  VisualState* visual;         ///< [N]
  ActionSource actions;        ///< read by the step kernel
  const uint8_t* reset_mask;   ///< [N] for the reset kernel: reset where 1 (null: every environment)
  uint8_t* obs;                ///< [N][H][W][3]
  float* reward;               ///< [N]
  uint8_t* terminated;         ///< [N]
  uint8_t* truncated;          ///< [N]
  InfoArrays info;             ///< [N] each: the state after the call (a new episode's after autoreset)
  // Same-step autoreset: a step that ends an episode keeps its last state here and the render kernel
  // draws it into final_obs.
  uint8_t* final_mask;         ///< [N] 0/1: the last step ended the episode
  LatentState* final_latent;   ///< [N]
  uint8_t* final_segments;     ///< [N][segment_stride]
  VisualState* final_visual;   ///< [N]
  uint8_t* final_obs;          ///< [N][H][W][3]
  InfoArrays final_info;       ///< [N] each
  AssetView assets;            ///< pointers rebased to device memory
};

static_assert(__is_trivially_copyable(DeviceEnvs), "DeviceEnvs is a kernel argument");

/// One row of a grouped launch (DeviceBatch::step_together): a batch part that runs the launch's config.
/// Block row blockIdx.y of kage_step_rows, and of kage_render given rows, works on rows[blockIdx.y].
struct GroupRow {
  DeviceEnvs envs;  ///< the part's view, as its own launches see it (its count and report slots included)
  int32_t batch;    ///< the row of the call's actions that holds this part's batch
  int32_t first;    ///< the part's first environment in its batch
};

/// The actions of a grouped step: batch b's environment i reads element b * row_stride + i * stride.
struct ActionRows {
  const void* data;
  int64_t row_stride;  ///< in elements
  int64_t stride;      ///< in elements
  int32_t is_int64;    ///< 0: int32 elements, 1: int64
};

/// Bytes of one environment's layout buffer: the segment count rounded up to whole 32-bit words.
KAGE_HD int32_t segment_stride_bytes(int32_t segment_count) { return (segment_count + 3) / 4 * 4; }

}  // namespace kage
