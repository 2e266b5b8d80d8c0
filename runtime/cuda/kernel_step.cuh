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
  StepInfo info;
  info.x = s.x;
  info.y = s.y;
  info.vx = s.vx;
  info.vy = s.vy;
  info.passed_distance = o.passed_distance;
  info.progress = o.progress;
  info.episode_return = s.episode_return;
  info.jump_count = s.jump_count;
  info.timestep = s.t;
  info.success = o.success;
  info.success_once = s.success_once;
  info.pad[0] = info.pad[1] = 0;
  e.info[env] = info;
}

/// One step of one environment with automatic reset (the order of CpuBatch::step): the latent step,
/// its outcome, then either the next episode's reset or the visual step (spec 5.7, 5.9).
__device__ __forceinline__ void device_step_env(const LatentParams& lp, const VisualParams& vp, const DeviceEnvs& e,
                                         int32_t env, uint8_t* segments, LatentState& ls, VisualState& vs) {
  const StepOutcome o = latent_step(lp, LayoutView{segments}, ls, e.actions[env]);
  record_outcome(e, env, ls, o);
  if (o.terminated || o.truncated) {
    const uint32_t next = ls.episode + 1;
    device_reset_env(lp, vp, e.assets, device_episode_key(e, env, next), next, segments, ls, vs);
  } else {
    visual_step(vp, e.assets, device_episode_key(e, env, ls.episode), static_cast<uint32_t>(ls.t), ls.vx, vs);
  }
}

}  // namespace kage
