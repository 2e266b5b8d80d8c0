// The buffers of kage.jax's two XLA FFI calls, checked against the config and turned into the runtime's
// pointers. One layout for the CPU and the CUDA handlers, in the order python/kage/jax/_ffi.py passes
// them (K = the info fields of runtime/info_fields.def, in that order):
//
//   kage_reset  args: seeds u32 [..., N, 2] (each environment's uint64 seed as low word, high word)
//               rets: latent, segments, visual, obs, reward, terminated, truncated, final_mask, info x K
//   kage_step   args: seeds, latent, segments, visual, final_obs, actions s32 [..., N], final_info x K
//               rets: latent, segments, visual, final_obs, obs, reward, terminated, truncated, final_mask,
//                     final_latent, final_segments, final_visual, final_info x K, info x K
//
// The step's rets 0-3 alias args 1-4 and its final_info rets alias its final_info args (the state, updated
// in place); final_latent, final_segments and final_visual are scratch the GPU's render kernel reads the
// finished episodes from. Leading axes (vmap's, with vmap_method="broadcast_all") are more environments:
// every environment is independent, so [B, N] is one batch of B * N.
#pragma once

#include <cstddef>
#include <cstdint>

#include "api/jax/jax_config.h"
#include "runtime/episode_info.h"
#include "runtime/latent/latent_state.h"
#include "runtime/visual/visual_state.h"
#include "xla/ffi/api/ffi.h"

namespace kage::jax {

/// An in-place pair (a step argument and the result aliasing it) that XLA gave two buffers: the result must
/// start as the argument, so the handler copies it over before the kernels run.
struct InPlaceCopy {
  void* to = nullptr;
  const void* from = nullptr;
  size_t bytes = 0;
};

/// The step's in-place pairs: the state (4) and the final_info columns.
inline constexpr size_t kInPlacePairs = 4 + kInfoFieldCount;

/// Environment rows of one call. The step-only members are null for a reset.
struct EnvBuffers {
  int64_t n = 0;  ///< environments, every leading axis included
  const uint64_t* seeds = nullptr;
  LatentState* latent = nullptr;
  uint8_t* segments = nullptr;  ///< rows of JaxConfig::segment_stride bytes
  VisualState* visual = nullptr;
  uint8_t* obs = nullptr;
  float* reward = nullptr;
  uint8_t* terminated = nullptr;
  uint8_t* truncated = nullptr;
  uint8_t* final_mask = nullptr;
  InfoArrays info{};
  const int32_t* actions = nullptr;
  uint8_t* final_obs = nullptr;
  InfoArrays final_info{};
  LatentState* final_latent = nullptr;
  uint8_t* final_segments = nullptr;
  VisualState* final_visual = nullptr;
  InPlaceCopy copies[kInPlacePairs] = {};  ///< the first `copy_count` are needed (usually none)
  size_t copy_count = 0;
};

/// The reset's buffers, or an error naming the one that does not fit the config.
xla::ffi::ErrorOr<EnvBuffers> reset_buffers(const JaxConfig& config, const xla::ffi::RemainingArgs& args,
                                            const xla::ffi::RemainingRets& rets);
/// The step's buffers, or an error naming the one that does not fit the config.
xla::ffi::ErrorOr<EnvBuffers> step_buffers(const JaxConfig& config, const xla::ffi::RemainingArgs& args,
                                           const xla::ffi::RemainingRets& rets);

/// The text of every handler error: "kage.jax: <call>: <what>".
xla::ffi::Error handler_error(const char* call, const std::string& what);

}  // namespace kage::jax
