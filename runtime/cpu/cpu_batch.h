// CPU batch runtime: N environments stepped with the KAGE_HD latent semantics, split over threads.
// Observations come from a render hook; without one the batch runs the hidden game only.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "runtime/episode_info.h"
#include "runtime/latent/latent_params.h"
#include "runtime/latent/latent_state.h"
#include "runtime/latent/layout.h"
#include "runtime/rng.h"

namespace kage {

/// Fills one environment's observation (H x W x 3 uint8, row-major) from its latent state. Called from
/// worker threads, at most once per environment per reset/step and never twice at once for the same env.
struct RenderHook {
  void* user = nullptr;
  /// After a reset (explicit or automatic) of `env`: the new episode's key, state (t = 0) and layout.
  void (*on_reset)(void* user, int32_t env, Key episode_key, const LatentParams& p, LayoutView layout,
                   const LatentState& s, uint8_t* obs) = nullptr;
  /// After a step that did not end in an automatic reset, on the post-step state.
  void (*on_step)(void* user, int32_t env, Key episode_key, const LatentParams& p, LayoutView layout,
                  const LatentState& s, uint8_t* obs) = nullptr;
  /// After a step that ends the episode, before its automatic reset, on the finished episode's last
  /// state (the final observation goes to the hook's own buffer; `obs` is then overwritten by on_reset).
  void (*on_final)(void* user, int32_t env, Key episode_key, const LatentParams& p, LayoutView layout,
                   const LatentState& s) = nullptr;
};

struct CpuBatchOptions {
  int32_t num_threads = 1;  ///< worker count (>= 1); results do not depend on it
  bool autoreset = true;    ///< reset a finished episode at once with the next episode key
};

/// The info columns of runtime/info_fields.def for N environments (structure of arrays).
struct InfoTable {
#define KAGE_INFO_FIELD(Enum, member, name, ctype, dtype, doc, value) std::vector<ctype> member;
#include "runtime/info_fields.def"
#undef KAGE_INFO_FIELD

  /// Sizes every column for n environments, zeroed.
  void resize(size_t n) {
#define KAGE_INFO_FIELD(Enum, member, name, ctype, dtype, doc, value) member.assign(n, ctype{});
#include "runtime/info_fields.def"
#undef KAGE_INFO_FIELD
  }

  /// The columns as pointers (valid until the next resize).
  InfoArrays columns() {
    InfoArrays a;
#define KAGE_INFO_FIELD(Enum, member, name, ctype, dtype, doc, value) a.member = member.data();
#include "runtime/info_fields.def"
#undef KAGE_INFO_FIELD
    return a;
  }
};

/// Per-environment results of the last reset or step: reward, flags and the info columns.
struct BatchInfo : InfoTable {
  std::vector<float> reward;
  std::vector<uint8_t> terminated;
  std::vector<uint8_t> truncated;

  /// Sizes every column for n environments, zeroed.
  void resize(size_t n) {
    InfoTable::resize(n);
    reward.assign(n, 0.0f);
    terminated.assign(n, 0);
    truncated.assign(n, 0);
  }

  /// Writes environment env's row from its state after a step (or a reset, with a zero outcome).
  /// Inline: generated host libraries (kernels_host.so) use it without linking the runtime.
  void record(int32_t env, const LatentState& s, const StepOutcome& o) {
    reward[env] = o.reward;
    terminated[env] = o.terminated;
    truncated[env] = o.truncated;
    record_info(columns(), env, s, o);
  }
};

/// N environments of one latent configuration. Episode e of the environment given seed s uses the key
/// fold(seed_key(s), e); reset(seeds) starts episode 0.
class CpuBatch {
 public:
  /// A batch of `num_envs` environments, or nothing if the parameters are unsupported
  /// (latent_params_supported) or num_envs / num_threads are not positive.
  [[nodiscard]] static std::optional<CpuBatch> create(const LatentParams& p, int32_t num_envs,
                                                      const CpuBatchOptions& options);

  /// Installs the observation hook; the observation buffer stays zero without one.
  void set_render_hook(const RenderHook& hook) { hook_ = hook; }

  /// Starts episode 0 of every environment; `seeds` has size() entries.
  void reset(const uint64_t* seeds);

  /// Advances every environment by one action (size() entries, any int32: spec 3.2 masks them).
  void step(const int32_t* actions);

  int32_t size() const { return num_envs_; }
  const LatentParams& params() const { return params_; }
  /// Reward, flags and info of the last reset or step; after an automatic reset, of the finished
  /// episode's last step.
  const BatchInfo& info() const { return info_; }
  /// Observations [N][H][W][3] of the last reset or step (the new episode's after an automatic reset).
  const uint8_t* observations() const { return obs_.data(); }
  const LatentState& state(int32_t env) const { return states_[env]; }
  LayoutView layout(int32_t env) const { return LayoutView{segments_.data() + static_cast<size_t>(env) * stride_}; }
  /// The key of the episode environment `env` is in now.
  Key episode_key(int32_t env) const;

 private:
  CpuBatch(const LatentParams& p, int32_t num_envs, const CpuBatchOptions& options);

  /// Runs fn(first, last) over a static partition of the environments, one range per thread.
  template <class Fn>
  void parallel_for(const Fn& fn);
  void reset_env(int32_t env, uint32_t episode);
  uint8_t* obs(int32_t env) { return obs_.data() + static_cast<size_t>(env) * obs_stride_; }

  LatentParams params_;
  int32_t num_envs_;
  CpuBatchOptions options_;
  size_t stride_;      ///< layout bytes per environment
  size_t obs_stride_;  ///< H * W * 3
  RenderHook hook_;
  std::vector<uint64_t> seeds_;
  std::vector<LatentState> states_;
  std::vector<uint8_t> segments_;
  std::vector<uint8_t> obs_;
  BatchInfo info_;
};

}  // namespace kage
