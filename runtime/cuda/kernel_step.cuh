// Parameters and stepping of the CUDA kernels (kernels.cuh): a config type's parameters as device
// constants (specialized) or __constant__ memory (DynamicCfg), and one environment's step with
// automatic reset, as CpuBatch::step. Compiles under nvcc and NVRTC (no host headers).
#pragma once

#include "runtime/cuda/device_envs.h"
#include "runtime/kage_hd.h"
#include "runtime/latent/latent_step.h"
#include "runtime/rng.h"
#include "runtime/visual/visual_update.h"

namespace kage {

// ---- parameters ----

/// A specialized config's parameters as device constants with initializers: loads at constant offsets
/// fold, indexed reads (palettes, shape lists) read the table from memory.
template <class Cfg>
__device__ constexpr LatentParams kLatentOf = Cfg::latent();
template <class Cfg>
__device__ constexpr VisualParams kVisualOf = Cfg::visual();

/// The parameters a kernel reads, as references.
template <class Cfg>
struct ParamsOf {
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
  static __device__ __forceinline__ const LatentParams& latent() { return kage_dynamic_latent; }
  static __device__ __forceinline__ const VisualParams& visual() { return kage_dynamic_visual; }
};

// ---- stepping ----

/// The episode key of environment `env` in episode `episode` (as CpuBatch::episode_key).
__device__ __forceinline__ Key device_episode_key(const DeviceEnvs& e, int32_t env, uint32_t episode) {
  return fold(seed_key(e.seeds[env]), episode);
}

/// Starts `episode` of one environment: layout, latent and visual state (spec 4.2).
__device__ __forceinline__ void device_reset_env(const LatentParams& lp, const VisualParams& vp, const AssetView& assets,
                                          Key key, uint32_t episode, uint8_t* segments, LatentState& ls,
                                          VisualState& vs) {
  latent_reset(lp, key, episode, segments, ls);
  const LayoutView layout{segments};
  visual_reset(vp, assets, key, [&](int32_t c) { return ground_top(lp, layout, c); }, vs);
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
    a.error->step = a.step;
    __threadfence_system();
    atomicExch(&a.error->state, 2u);
  }
  return static_cast<int32_t>(v);
}

/// One step of one environment with same-step automatic reset (the order of HostBatch::step): the
/// latent step and its outcome; then the visual step of the new t; if the episode ended, its last
/// state goes to the final_* buffers (the render kernel draws it) and the next episode starts.
__device__ __forceinline__ void device_step_env(const LatentParams& lp, const VisualParams& vp, const DeviceEnvs& e,
                                                int32_t env, uint8_t* segments, LatentState& ls, VisualState& vs) {
  const StepOutcome o = latent_step(lp, LayoutView{segments}, ls, load_action(e.actions, env));
  record_outcome(e, env, ls, o);
  visual_step(vp, e.assets, device_episode_key(e, env, ls.episode), static_cast<uint32_t>(ls.t), ls.vx, vs);
  const bool done = o.terminated || o.truncated;
  e.final_mask[env] = done ? 1 : 0;
  if (!done) return;
  e.final_latent[env] = ls;
  copy_words(e.final_segments + static_cast<int64_t>(env) * e.segment_stride, segments, e.segment_stride);
  copy_words(e.final_visual + env, &vs, e.visual_extent);
  copy_info_row(e.final_info, e.info, env);
  const uint32_t next = ls.episode + 1;
  device_reset_env(lp, vp, e.assets, device_episode_key(e, env, next), next, segments, ls, vs);
  record_info(e.info, env, ls, StepOutcome{});
}

}  // namespace kage
