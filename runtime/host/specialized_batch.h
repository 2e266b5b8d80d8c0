// CPU backend over generated host code: N environments driven through a config's HostEntryPoints
// (from a generated kernels_host.so or compiled in), in CpuEnv's order, so both give the same bytes.
#pragma once

#include <algorithm>
#include <cstring>
#include <thread>
#include <vector>

#include "runtime/host/cpu_batch.h"
#include "runtime/host/specialized_env.h"

namespace kage {

class SpecializedCpuBatch {
 public:
  /// `assets` must outlive the batch. `num_envs`, `num_threads` > 0.
  SpecializedCpuBatch(const HostEntryPoints& ep, const AssetView& assets, int32_t num_envs, int32_t num_threads)
      : ep_(ep), assets_(assets), n_(num_envs), threads_(std::max(1, num_threads)) {
    ep_.params(&latent_params_, &visual_params_);
    seg_bytes_ = static_cast<size_t>(layout_segment_count(latent_params_));
    frame_ = static_cast<size_t>(visual_params_.H) * visual_params_.W * 3;
    const size_t n = static_cast<size_t>(n_);
    seeds_.assign(n, 0);
    latent_.assign(n, LatentState{});
    visual_.assign(n, VisualState{});
    segments_.assign(n * seg_bytes_, 0);
    obs_.assign(n * frame_, 0);
    final_obs_.assign(n * frame_, 0);
    done_.assign(n, 0);
    info_.resize(n);
  }

  /// Starts episode 0 of every environment (`seeds`: size() entries) and renders its first frame.
  void reset(const uint64_t* seeds) {
    std::copy(seeds, seeds + n_, seeds_.begin());
    parallel_for([&](int32_t env, float* scratch) {
      done_[env] = 0;
      reset_env(env, 0, scratch);
      record(env, StepOutcome{});
    });
  }

  /// One action per environment; a finished episode keeps its last frame in final_observation and
  /// starts the next one at once.
  void step(const int32_t* actions) {
    parallel_for([&](int32_t env, float* scratch) {
      const EnvSlot s = slot(env, obs_.data() + env * frame_, scratch);
      StepOutcome o{};
      ep_.step_env(&assets_, episode_key(env), actions[env], 1, &s, &o);
      record(env, o);
      done_[env] = (o.terminated || o.truncated) ? 1 : 0;
      if (done_[env]) {
        std::memcpy(final_obs_.data() + env * frame_, obs_.data() + env * frame_, frame_);
        reset_env(env, latent_[env].episode + 1, scratch);
      }
    });
  }

  int32_t size() const { return n_; }
  const LatentParams& latent_params() const { return latent_params_; }
  const VisualParams& visual_params() const { return visual_params_; }
  const uint8_t* observations() const { return obs_.data(); }
  const uint8_t* observation(int32_t env) const { return obs_.data() + env * frame_; }
  const uint8_t* final_observation(int32_t env) const { return final_obs_.data() + env * frame_; }
  bool done(int32_t env) const { return done_[env] != 0; }
  const BatchInfo& info() const { return info_; }
  const LatentState& latent_state(int32_t env) const { return latent_[env]; }
  const VisualState& visual_state(int32_t env) const { return visual_[env]; }
  size_t frame_bytes() const { return frame_; }
  Key episode_key(int32_t env) const { return fold(seed_key(seeds_[env]), latent_[env].episode); }

 private:
  EnvSlot slot(int32_t env, uint8_t* out, float* scratch) {
    return {&latent_[env], &visual_[env], segments_.data() + env * seg_bytes_, out, scratch};
  }
  void reset_env(int32_t env, uint32_t episode, float* scratch) {
    const EnvSlot s = slot(env, obs_.data() + env * frame_, scratch);
    ep_.reset_env(&assets_, fold(seed_key(seeds_[env]), episode), episode, &s);
  }
  void record(int32_t env, const StepOutcome& o) { info_.record(env, latent_[env], o); }
  /// fn(env, scratch) over a static partition of the environments, one range and scratch per thread.
  template <class Fn>
  void parallel_for(const Fn& fn) {
    const int32_t threads = std::min(threads_, n_);
    const size_t scratch_floats = static_cast<size_t>(render_scratch_floats(visual_params_));
    if (scratch_.size() < scratch_floats * threads) scratch_.resize(scratch_floats * threads);
    auto range = [&](int32_t i) {
      float* scratch = scratch_.data() + scratch_floats * i;
      for (int32_t env = static_cast<int32_t>(int64_t{n_} * i / threads);
           env < static_cast<int32_t>(int64_t{n_} * (i + 1) / threads); ++env)
        fn(env, scratch);
    };
    std::vector<std::thread> workers;
    for (int32_t i = 1; i < threads; ++i) workers.emplace_back(range, i);
    range(0);
    for (std::thread& w : workers) w.join();
  }

  HostEntryPoints ep_;
  AssetView assets_;
  int32_t n_;
  int32_t threads_;
  LatentParams latent_params_{};
  VisualParams visual_params_{};
  size_t seg_bytes_ = 0;
  size_t frame_ = 0;
  std::vector<uint64_t> seeds_;
  std::vector<LatentState> latent_;
  std::vector<VisualState> visual_;
  std::vector<uint8_t> segments_, obs_, final_obs_, done_;
  std::vector<float> scratch_;
  BatchInfo info_;
};

}  // namespace kage
