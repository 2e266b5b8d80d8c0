// Full CPU environment over run-time parameters: a HostBatch on the generic path whose info() keeps a
// finished episode's last step (the AutoResetWrapper's final observation kept too, spec 10.2).
#pragma once

#include <cstdint>
#include <memory>

#include "runtime/cpu/host_batch.h"
#include "runtime/visual/asset_view.h"
#include "runtime/visual/visual_params.h"
#include "runtime/visual/visual_state.h"

namespace kage {

/// N environments of one configuration that render an observation on every reset and step.
/// Results do not depend on the thread count.
class CpuEnv {
 public:
  /// A batch over `assets` (which must outlive it), or nothing when the latent parameters are unsupported,
  /// the screen sizes of `latent` and `visual` differ, or `num_envs` / `num_threads` are not positive.
  static std::unique_ptr<CpuEnv> create(const LatentParams& latent, const VisualParams& visual, const AssetView& assets,
                                        int32_t num_envs, int32_t num_threads);

  CpuEnv(const CpuEnv&) = delete;
  CpuEnv& operator=(const CpuEnv&) = delete;

  /// Starts episode 0 of every environment (`seeds`: size() entries) and renders its first frame.
  void reset(const uint64_t* seeds);
  /// One action per environment (spec 3.2); an environment whose episode ends is reset at once.
  void step(const int32_t* actions);

  int32_t size() const { return batch_.size(); }
  int32_t height() const { return batch_.visual_params().H; }
  int32_t width() const { return batch_.visual_params().W; }
  /// Observations [N][H][W][3] of the last reset or step (the new episode's after an automatic reset).
  const uint8_t* observations() const { return batch_.observations(); }
  const uint8_t* observation(int32_t env) const { return batch_.observation(env); }
  /// Reward, flags and info of the last reset or step. For an environment with done(env) these are the
  /// finished episode's last step (its final info); the state is already the new episode's.
  const BatchInfo& info() const { return batch_.info(); }
  /// Whether the last step ended the environment's episode (and reset it).
  bool done(int32_t env) const { return batch_.done(env); }
  /// The finished episode's last frame, for an environment with done(env) (H x W x 3).
  const uint8_t* final_observation(int32_t env) const { return batch_.final_observation(env); }
  const LatentState& latent_state(int32_t env) const { return batch_.latent_state(env); }
  const VisualState& visual_state(int32_t env) const { return batch_.visual_state(env); }
  const LatentParams& latent_params() const { return batch_.latent_params(); }
  const VisualParams& visual_params() const { return batch_.visual_params(); }
  size_t frame_bytes() const { return batch_.frame_bytes(); }

 private:
  CpuEnv(const LatentParams& latent, const VisualParams& visual, const AssetView& assets, int32_t num_envs,
         int32_t num_threads);

  HostBatch batch_;
};

}  // namespace kage
