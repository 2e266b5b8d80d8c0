// Parameters and stepping of the CUDA kernels (kernels.cuh): a config type's parameters as device
// constants (specialized) or __constant__ memory (DynamicCfg), and the outputs of one environment's
// step for the episode driver (runtime/episode.h). Compiles under nvcc and NVRTC (no host headers).
#pragma once

#include "runtime/cuda/device_envs.h"
#include "runtime/episode.h"
#include "runtime/kage_hd.h"
#include "runtime/rng.h"

namespace kage {

// ---- parameters ----

/// A specialized config's parameters as device constants with initializers: loads at constant offsets
/// fold, indexed reads (palettes, shape lists) read the table from memory.
template <class Cfg>
__device__ constexpr LatentParams kLatentOf = Cfg::latent();
template <class Cfg>
__device__ constexpr VisualParams kVisualOf = Cfg::visual();

/// The parameters a kernel reads, as references (a parameter provider of runtime/episode.h).
template <class Cfg>
struct ParamsOf {
  static constexpr bool kVisual = true;
  static __device__ __forceinline__ const LatentParams& latent() { return kLatentOf<Cfg>; }
  static __device__ __forceinline__ const VisualParams& visual() { return kVisualOf<Cfg>; }
};

}  // namespace kage

/// The generic build's parameters, uploaded by the host (DeviceBatch) before the first launch.
extern "C" {
__constant__ kage::LatentParams kage_dynamic_latent;
__constant__ kage::VisualParams kage_dynamic_visual;
}

namespace kage {

/// The config type of the generic build.
struct DynamicCfg {};

/// Whether Cfg is the generic build (its stage chain is not folded; NVRTC has no <type_traits>).
template <class Cfg>
constexpr bool kGenericBuild = false;
template <>
constexpr bool kGenericBuild<DynamicCfg> = true;

template <>
struct ParamsOf<DynamicCfg> {
  static constexpr bool kVisual = true;
  static __device__ __forceinline__ const LatentParams& latent() { return kage_dynamic_latent; }
  static __device__ __forceinline__ const VisualParams& visual() { return kage_dynamic_visual; }
};

// ---- stepping ----

/// The episode key of environment `env` in episode `episode` (as CpuBatch::episode_key).
__device__ __forceinline__ Key device_episode_key(const DeviceEnvs& e, int32_t env, uint32_t episode) {
  return fold(seed_key(e.seeds[env]), episode);
}

/// Writes reward, flags and info of one step (or zeros after an explicit reset).
__device__ __forceinline__ void record_outcome(const DeviceEnvs& e, int32_t env, const LatentState& s,
                                               const StepOutcome& o) {
  e.reward[env] = o.reward;
  e.terminated[env] = o.terminated;
  e.truncated[env] = o.truncated;
  record_info(e.info, env, s, o);
}

/// Copies `bytes` (a multiple of 4) from `src` to `dst` a word at a time.
__device__ __forceinline__ void copy_words(void* dst, const void* src, int32_t bytes) {
  for (int32_t i = 0; i < bytes / 4; ++i) static_cast<uint32_t*>(dst)[i] = static_cast<const uint32_t*>(src)[i];
}

/// The action of environment `env`. A value outside 0..7 is reported to the host (the first one per
/// launch wins) and then masked like any other (spec 3.2).
__device__ __forceinline__ int32_t load_action(const ActionSource& a, int32_t env) {
  const int64_t i = static_cast<int64_t>(env) * a.stride;
  const int64_t v = a.is_int64 ? static_cast<const int64_t*>(a.data)[i] : static_cast<const int32_t*>(a.data)[i];
  if ((v < 0 || v > 7) && a.error && atomicCAS(&a.error->state, 0u, 1u) == 0u) {
    a.error->env = env;
    a.error->value = v;
    a.error->step = a.count ? a.count->steps + 1 : 0;
    __threadfence_system();
    atomicExch(&a.error->state, 2u);
  }
  return static_cast<int32_t>(v);
}

/// Counts a finished step launch in `a.count` (StepCount): called by every thread of the launch after its
/// environment's step (and so after any report of its action read the count). One atomic per warp; the warp
/// that completes the launch's `num_envs` environments resets `done` for the next launch on the stream.
__device__ __forceinline__ void count_step(const ActionSource& a, int32_t num_envs) {
  if (!a.count) return;
  const int32_t env = static_cast<int32_t>(blockIdx.x * blockDim.x + threadIdx.x);
  const uint32_t together = __activemask();
  const uint32_t stepped = __ballot_sync(together, env < num_envs);
  if (static_cast<int32_t>(threadIdx.x % 32) != __ffs(static_cast<int>(together)) - 1 || stepped == 0) return;
  const uint32_t n = static_cast<uint32_t>(__popc(static_cast<int>(stepped)));
  if (atomicAdd(&a.count->done, n) + n == static_cast<uint32_t>(num_envs)) {
    a.count->done = 0;
    a.count->steps += 1;
  }
}

/// Where the episode driver puts one environment's step: reward, flags and info in the batch's
/// columns; a finished episode's last state goes to the final_* buffers (the render kernel draws it)
/// before the next episode starts, which then reports its spawn point's info.
struct DeviceStepOut {
  const DeviceEnvs& e;
  int32_t env;

  __device__ __forceinline__ Key episode_key(uint32_t episode) const { return device_episode_key(e, env, episode); }
  __device__ __forceinline__ void record(const LatentState& ls, const StepOutcome& o) const {
    record_outcome(e, env, ls, o);
  }
  __device__ __forceinline__ bool stepped(bool done, const uint8_t* segments, const LatentState& ls,
                                          const VisualState* vs) const {
    e.final_mask[env] = done ? 1 : 0;
    if (!done) return false;
    e.final_latent[env] = ls;
    copy_words(e.final_segments + static_cast<int64_t>(env) * e.segment_stride, segments, e.segment_stride);
    copy_words(e.final_visual + env, vs, e.visual_extent);
    copy_info_row(e.final_info, e.info, env);
    return true;
  }
  __device__ __forceinline__ void restarted(const uint8_t*, const LatentState& ls, const VisualState*) const {
    record_info(e.info, env, ls, StepOutcome{});
  }
};

}  // namespace kage
