// Full CPU environment: a CpuBatch for the hidden game plus the visual half (visual state, rendering),
// with the AutoResetWrapper's final observation kept (spec 10.2).
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "runtime/host/cpu_batch.h"
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

  int32_t size() const { return batch_->size(); }
  int32_t height() const { return visual_.H; }
  int32_t width() const { return visual_.W; }
  /// Observations [N][H][W][3] of the last reset or step (the new episode's after an automatic reset).
  const uint8_t* observations() const { return batch_->observations(); }
  const uint8_t* observation(int32_t env) const { return observations() + static_cast<size_t>(env) * frame_bytes(); }
  /// Reward, flags and info of the last reset or step. For an environment with done(env) these are the
  /// finished episode's last step (its final info); the state is already the new episode's.
  const BatchInfo& info() const { return batch_->info(); }
  /// Whether the last step ended the environment's episode (and reset it).
  bool done(int32_t env) const { return done_[env] != 0; }
  /// The finished episode's last frame, for an environment with done(env) (H x W x 3).
  const uint8_t* final_observation(int32_t env) const { return final_obs_.data() + static_cast<size_t>(env) * frame_bytes(); }
  const LatentState& latent_state(int32_t env) const { return batch_->state(env); }
  const VisualState& visual_state(int32_t env) const { return visual_states_[env]; }
  const LatentParams& latent_params() const { return batch_->params(); }
  const VisualParams& visual_params() const { return visual_; }
  size_t frame_bytes() const { return static_cast<size_t>(visual_.H) * visual_.W * 3; }

 private:
  CpuEnv(CpuBatch batch, const VisualParams& visual, const AssetView& assets);
  static void on_reset(void* user, int32_t env, Key key, const LatentParams& p, LayoutView layout, const LatentState& s,
                       uint8_t* obs);
  static void on_step(void* user, int32_t env, Key key, const LatentParams& p, LayoutView layout, const LatentState& s,
                      uint8_t* obs);
  static void on_final(void* user, int32_t env, Key key, const LatentParams& p, LayoutView layout, const LatentState& s);
  /// Renders the current visual state of `env` for the latent state `s` into `out`.
  void render(int32_t env, Key key, const LatentParams& p, LayoutView layout, const LatentState& s, uint8_t* out) const;

  std::unique_ptr<CpuBatch> batch_;
  VisualParams visual_;
  AssetView assets_;
  std::vector<VisualState> visual_states_;
  std::vector<uint8_t> final_obs_;
  std::vector<uint8_t> done_;
};

}  // namespace kage
