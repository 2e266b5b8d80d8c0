// The CPU batch of the public API: N environments of one configuration (or of several: a mixture, each
// config's environments a part) stepped through a HostKernels (a generated kernels_host.so, or the generic
// path over run-time parameters) and split over threads, with same-step automatic reset that keeps the
// finished episode's final frame and info.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "runtime/cpu/cpu_batch.h"
#include "runtime/cpu/specialized_env.h"

namespace kage {

/// One environment's reset, step and render for one configuration.
class HostKernels {
 public:
  virtual ~HostKernels() = default;
  virtual const LatentParams& latent() const = 0;
  virtual const VisualParams& visual() const = 0;
  /// Starts `episode` (key `episode_key`) and renders its first frame into e.obs.
  virtual void reset_env(const AssetView& assets, Key episode_key, uint32_t episode, const EnvSlot& e) const = 0;
  /// One step through the episode driver (`seed`: seed_key of the environment's seed) into `rows`:
  /// renders the new state into e.obs and, when the episode ends, starts the next one.
  virtual void step_env(const AssetView& assets, Key seed, int32_t action, const EnvSlot& e,
                        const StepRows& rows) const = 0;
  /// Renders the current state into e.obs.
  virtual void render_env(const AssetView& assets, Key episode_key, const EnvSlot& e) const = 0;
};

/// The generic path: the semantics over run-time parameters.
std::unique_ptr<HostKernels> generic_host_kernels(const LatentParams& latent, const VisualParams& visual);
/// A generated library's entry points (every one non-null, ABI checked by the caller).
std::unique_ptr<HostKernels> generated_host_kernels(const HostEntryPoints& entry_points);

/// The environments of one config in a batch. A batch over several (a mixture) numbers them part by part:
/// the first part's environments first.
struct HostPart {
  std::unique_ptr<HostKernels> kernels;
  AssetView assets;  ///< must outlive the batch
  int32_t num_envs = 0;
};

class HostBatch {
 public:
  /// `assets` must outlive the batch; `num_envs` and `num_threads` > 0. Results do not depend on the
  /// thread count. `info_shows_new_episode`: after an automatic reset, info() shows the new episode's
  /// spawn point (else the finished step's; final_info() has that either way).
  HostBatch(std::unique_ptr<HostKernels> kernels, const AssetView& assets, int32_t num_envs, int32_t num_threads,
            bool info_shows_new_episode = true);
  /// One batch over several parts (at least one environment in all; parts_problem() of their kernels empty),
  /// each environment stepped and rendered by its part's kernels into its row of the one set of outputs: the
  /// batch equals its parts run alone, row for row.
  HostBatch(std::vector<HostPart> parts, int32_t num_threads, bool info_shows_new_episode = true);
  /// Why parts with these kernels cannot make one batch (a frame or layout size unlike the first part's: they
  /// must share one observation shape and one hidden game), or empty.
  static std::string parts_problem(const std::vector<const HostKernels*>& kernels);

  /// Starts episode 0 of the environments with mask[env] != 0 (every one when `mask` is null) with the
  /// new seeds[env]; the others keep their state and outputs. No environment is final afterwards.
  void reset(const uint64_t* seeds, const uint8_t* mask);
  /// One action per environment, actions[env] (any int32: spec 3.2 masks them). An environment whose
  /// episode ends is final: its last frame and info go to final_observations() and final_info(), and
  /// it starts its next episode at once (observations() show the new episode, and so does info()
  /// when info_shows_new_episode; reward and flags stay the finishing step's).
  void step(const int32_t* actions);

  /// The saved state (runtime/cpu/batch_state.h) under `spec_hash`.
  std::vector<uint8_t> save_state(const std::string& spec_hash) const;
  /// Restores a saved state and renders its observations; the reason when it cannot, else empty.
  std::string load_state(const uint8_t* data, size_t size, const std::string& spec_hash);

  int32_t size() const { return n_; }
  /// The first part's parameters (every part has the same frame and layout sizes).
  const LatentParams& latent_params() const { return parts_.front().kernels->latent(); }
  const VisualParams& visual_params() const { return parts_.front().kernels->visual(); }
  /// [N]: each environment's part (0 for a batch of one part).
  const int32_t* part_index() const { return part_.data(); }
  size_t frame_bytes() const { return frame_; }
  const uint8_t* observations() const { return obs_.data(); }
  const uint8_t* observation(int32_t env) const { return obs_.data() + env * frame_; }
  /// [N] 0/1: the last step ended the environment's episode.
  const uint8_t* final_mask() const { return final_mask_.data(); }
  bool done(int32_t env) const { return final_mask_[env] != 0; }
  const uint8_t* final_observations() const { return final_obs_.data(); }
  const uint8_t* final_observation(int32_t env) const { return final_obs_.data() + env * frame_; }
  const BatchInfo& info() const { return info_; }
  /// Valid in the rows of final environments.
  const InfoTable& final_info() const { return final_info_; }
  const LatentState& latent_state(int32_t env) const { return latent_[env]; }
  const VisualState& visual_state(int32_t env) const { return visual_[env]; }
  /// The layout of environment `env` (layout_segment_count bytes).
  const uint8_t* segments(int32_t env) const { return segments_.data() + env * seg_bytes_; }
  Key episode_key(int32_t env) const { return fold(seed_key(seeds_[env]), latent_[env].episode); }

 private:
  const HostPart& part(int32_t env) const { return parts_[static_cast<size_t>(part_[env])]; }
  EnvSlot slot(int32_t env, float* scratch) {
    return {&latent_[env], &visual_[env], segments_.data() + env * seg_bytes_, obs_.data() + env * frame_, scratch};
  }
  void reset_env(int32_t env, uint32_t episode, float* scratch);
  /// fn(env, scratch) over a static partition of the environments, one range and scratch per thread.
  template <class Fn>
  void parallel_for(const Fn& fn);

  std::vector<HostPart> parts_;
  std::vector<int32_t> part_;  ///< [N] each environment's part
  int32_t n_;
  int32_t threads_;
  bool info_shows_new_episode_;
  size_t seg_bytes_;
  size_t frame_;
  std::vector<uint64_t> seeds_;
  std::vector<LatentState> latent_;
  std::vector<VisualState> visual_;
  std::vector<uint8_t> segments_, obs_, final_obs_, final_mask_;
  std::vector<float> scratch_;
  BatchInfo info_;
  InfoTable final_info_;
};

}  // namespace kage
