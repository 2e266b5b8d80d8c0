// The device-side view of a batch of environments: plain pointers into device memory, passed by value
// as the one argument of every kernel (kernels.cuh). Host and device (nvcc, NVRTC), no std headers.
#pragma once

#include "runtime/kage_hd.h"
#include "runtime/latent/latent_state.h"
#include "runtime/visual/asset_view.h"
#include "runtime/visual/visual_state.h"

namespace kage {

/// Per-environment results of the last reset or step besides reward and the two flags (the info of
/// spec 5.8). After an automatic reset they describe the finished episode's last step.
struct StepInfo {
  float x;
  float y;
  float vx;
  float vy;
  float passed_distance;
  float progress;
  float episode_return;
  int32_t jump_count;
  int32_t timestep;
  uint8_t success;
  uint8_t success_once;
  uint8_t pad[2];
};

static_assert(__is_trivially_copyable(StepInfo), "StepInfo must be POD");
static_assert(sizeof(StepInfo) == 40, "StepInfo layout changed");

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
  const int32_t* actions;      ///< [N], read by the step kernels
  uint8_t* obs;                ///< [N][H][W][3]
  float* reward;               ///< [N]
  uint8_t* terminated;         ///< [N]
  uint8_t* truncated;          ///< [N]
  StepInfo* info;              ///< [N]
  AssetView assets;            ///< pointers rebased to device memory
};

static_assert(__is_trivially_copyable(DeviceEnvs), "DeviceEnvs is a kernel argument");

/// Bytes of one environment's layout buffer: the segment count rounded up to whole 32-bit words.
KAGE_HD int32_t segment_stride_bytes(int32_t segment_count) { return (segment_count + 3) / 4 * 4; }

}  // namespace kage
