// How a config's frames are rendered on the GPU: per pixel in registers, or with the neighbourhood
// filters (blur, sharpen, pixelate, cyberpunk's sharpen) from a float32 frame in shared memory.
// Read by the kernels (a constant in a specialized build) and by the host that sizes the launch, with
// the shared-memory slots of one frame.
#pragma once

#include "runtime/kage_hd.h"
#include "runtime/latent/latent_state.h"
#include "runtime/visual/compose.h"
#include "runtime/visual/filter_ops.h"
#include "runtime/visual/filters.h"
#include "runtime/visual/visual_params.h"
#include "runtime/visual/visual_state.h"

namespace kage {

/// Capacity of a rendering block's column table (BlockShared below): screen columns. DeviceBatch
/// rejects configs beyond it.
constexpr int32_t kMaxScreenWidth = 1024;

/// Pixels of a 48-byte run of a row (three 16-byte words) in the register path.
constexpr int32_t kPixelsPerThread = 16;
/// Threads of a register-path block, and the most frames it renders one after the other.
constexpr int32_t kRegisterPathThreads = 256;
constexpr int32_t kRegisterPathFramesPerBlock = 8;
/// Pixels per thread of the frame-pass path (strided), and its largest block: every pixel of the frame
/// belongs to one of its threads. 512 threads of 32 pixels rather than 1024 of 16: the register cap
/// of a 512-thread block is 128 instead of 64 (the 1024-thread kernel spilled 2.2 KB per thread), and
/// the banded passes keep only two pixels' results in registers whatever the pixel count.
constexpr int32_t kFramePassPixelsPerThread = 32;
constexpr int32_t kFramePassMaxThreads = 512;

/// Solid rows [lo, hi) of one screen column, packed as two 16-bit values.
struct ColumnSpan {
  short lo;
  short hi;
};

/// Values shared by every pixel of one frame, computed once per frame.
struct FrameSetup {
  FrameConstants f;
  AgentView agent;
  Preset episode_preset;
  FilterKeys keys;
  float jitter[9];
  ScreenBox agent_box;  ///< outside it the agent leaves pixels unchanged
  bool plain;           ///< every pixel outside agent_box is a function of solid() alone (register path)
};

/// The extremes of the solid spans of one 16-column group: a row outside [lo_min, hi_max) is empty in
/// every column of the group and a row in [lo_max, hi_min) solid in every column.
struct GroupSpan {
  short lo_min, lo_max, hi_min, hi_max;
};

/// Shared memory of a rendering block besides the optional float frame.
struct BlockShared {
  LatentState latent;
  FrameSetup setup;
  alignas(16) VisualState visual;
  ColumnSpan spans[kMaxScreenWidth];
  GroupSpan groups[kMaxScreenWidth / kPixelsPerThread];
};

/// Whether any frame pass can run: a sharpening preset in pop_filter_list or pop_filter, blur,
/// sharpen or pixelate (spec 7.1 steps A, 8-10).
KAGE_HD bool needs_frame_passes(const VisualParams& p) {
  bool preset_sharpen = preset_sharpen_amount(p.pop_filter) > 0.0f;
  for (int32_t i = 0; i < p.pop_filter_count && i < kMaxListEntries; ++i) {
    preset_sharpen = preset_sharpen || preset_sharpen_amount(p.pop_filter_list[i]) > 0.0f;
  }
  return preset_sharpen || p.blur_sigma > 0.0f || p.sharpen_amount > 0.0f || p.pixelate_factor > 1;
}

/// Whether the register path can store whole 16-pixel runs (each row a multiple of 16 pixels).
KAGE_HD bool register_path_vectorized(const VisualParams& p) { return p.W % kPixelsPerThread == 0; }

/// Frames a rendering block renders, one after the other, for num_envs environments on
/// `multiprocessors` SMs: one for the frame-pass path; on the register path up to
/// kRegisterPathFramesPerBlock, fewer when the batch would then leave SMs short of resident blocks.
/// `frame_passes`: needs_frame_passes of the config (frames_per_block below); a grouped launch
/// (DeviceBatch::step_together) plans its several batches' environments as one batch.
constexpr int32_t kRegisterPathBlocksPerSm = 16;
KAGE_HD int32_t frames_per_block(bool frame_passes, int32_t num_envs, int32_t multiprocessors) {
  if (frame_passes) return 1;
  const int32_t fill = num_envs / maxi(1, multiprocessors * kRegisterPathBlocksPerSm);
  return mini(kRegisterPathFramesPerBlock, maxi(1, fill));
}
KAGE_HD int32_t frames_per_block(const VisualParams& p, int32_t num_envs, int32_t multiprocessors) {
  return frames_per_block(needs_frame_passes(p), num_envs, multiprocessors);
}

/// Threads per rendering block.
KAGE_HD int32_t render_threads(const VisualParams& p) {
  if (!needs_frame_passes(p)) return kRegisterPathThreads;
  const int32_t per = (p.H * p.W + kFramePassPixelsPerThread - 1) / kFramePassPixelsPerThread;
  return (per + 31) / 32 * 32;
}

/// Dynamic shared memory of a rendering block: the float32 frame of the frame-pass path; the register
/// path packs its pixels in registers and needs none.
KAGE_HD int32_t render_dynamic_smem_bytes(const VisualParams& p) {
  return needs_frame_passes(p) ? p.H * p.W * 3 * static_cast<int32_t>(sizeof(float)) : 0;
}

/// Whether the GPU kernels support this frame size: the frame-pass path holds one frame per block.
KAGE_HD bool render_supported(const VisualParams& p) {
  return p.H > 0 && p.W > 0 && p.W <= kMaxScreenWidth && (!needs_frame_passes(p) || render_threads(p) <= kFramePassMaxThreads);
}

}  // namespace kage
