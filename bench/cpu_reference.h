// CPU reference of the GPU batch for the benchmark's correctness check: the same KAGE_HD semantics in
// the same order as the kernels (kernels.cuh), one environment at a time.
#pragma once

#include <cstdint>
#include <vector>

#include "runtime/latent/latent_params.h"
#include "runtime/latent/latent_state.h"
#include "runtime/visual/asset_view.h"
#include "runtime/visual/visual_params.h"
#include "runtime/visual/visual_state.h"

namespace kage::bench {

/// N environments with their layouts and visual states.
class CpuReference {
 public:
  CpuReference(const LatentParams& lp, const VisualParams& vp, const AssetView& assets, int32_t num_envs);
  /// Episode 0 of every environment.
  void reset(const std::vector<uint64_t>& seeds);
  /// One step with automatic reset (the order of the step kernel).
  void step(const std::vector<int32_t>& actions);
  /// Renders every environment's current state into `obs` ([N][H][W][3]) with `threads` workers.
  void render(std::vector<uint8_t>& obs, int32_t threads) const;
  /// The actions kage_sample_actions draws for step t.
  std::vector<int32_t> sample_actions(uint64_t seed, uint32_t t) const;

  const std::vector<LatentState>& latent() const { return latent_; }
  const std::vector<VisualState>& visual() const { return visual_; }
  const std::vector<uint8_t>& segments() const { return segments_; }
  int32_t segment_stride() const { return stride_; }
  const std::vector<float>& reward() const { return reward_; }

 private:
  void reset_env(int32_t env, uint32_t episode);
  LatentParams lp_;
  VisualParams vp_;
  AssetView assets_;
  int32_t n_;
  int32_t stride_;
  std::vector<uint64_t> seeds_;
  std::vector<LatentState> latent_;
  std::vector<VisualState> visual_;
  std::vector<uint8_t> segments_;
  std::vector<float> reward_;
};

}  // namespace kage::bench
