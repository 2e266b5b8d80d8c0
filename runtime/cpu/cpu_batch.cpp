// CPU batch runtime: static partition of the environments over std::threads; every environment is
// independent, so the results are the same for any thread count.
#include "runtime/cpu/cpu_batch.h"

#include <algorithm>
#include <thread>

#include "runtime/episode.h"

namespace kage {

std::optional<CpuBatch> CpuBatch::create(const LatentParams& p, int32_t num_envs, const CpuBatchOptions& options) {
  if (!latent_params_supported(p) || num_envs <= 0 || options.num_threads <= 0) return std::nullopt;
  return CpuBatch(p, num_envs, options);
}

CpuBatch::CpuBatch(const LatentParams& p, int32_t num_envs, const CpuBatchOptions& options)
    : params_(p),
      num_envs_(num_envs),
      options_(options),
      stride_(static_cast<size_t>(layout_segment_count(p))),
      obs_stride_(static_cast<size_t>(p.screen_h) * p.screen_w * 3),
      seeds_(num_envs, 0),
      states_(num_envs, LatentState{}),
      segments_(stride_ * num_envs, 0),
      obs_(obs_stride_ * num_envs, 0) {
  info_.resize(static_cast<size_t>(num_envs));
}

Key CpuBatch::episode_key(int32_t env) const { return fold(seed_key(seeds_[env]), states_[env].episode); }

template <class Fn>
void CpuBatch::parallel_for(const Fn& fn) {
  const int32_t threads = std::min(options_.num_threads, num_envs_);
  auto range = [&](int32_t i) { fn(static_cast<int32_t>(int64_t{num_envs_} * i / threads),
                                   static_cast<int32_t>(int64_t{num_envs_} * (i + 1) / threads)); };
  std::vector<std::thread> workers;
  workers.reserve(threads - 1);
  for (int32_t i = 1; i < threads; ++i) workers.emplace_back(range, i);
  range(0);
  for (std::thread& w : workers) w.join();
}

namespace {

/// The episode driver's outputs for the hidden game: info rows, and the render hook on each step, before
/// an automatic reset (on_final) and after it (on_reset).
struct LatentStepOut {
  const LatentParams& p;
  const RenderHook& hook;
  BatchInfo& info;
  Key seed;  ///< seed_key of the environment's seed
  int32_t env;
  bool autoreset;
  uint8_t* obs;

  Key episode_key(uint32_t episode) const { return fold(seed, episode); }
  void record(const LatentState& s, const StepOutcome& o) const { info.record(env, s, o); }
  bool stepped(bool done, const uint8_t* segments, const LatentState& s, const VisualState*) const {
    const LayoutView layout{segments};
    if (autoreset && done) {
      if (hook.on_final) hook.on_final(hook.user, env, episode_key(s.episode), p, layout, s);
      return true;
    }
    if (hook.on_step) hook.on_step(hook.user, env, episode_key(s.episode), p, layout, s, obs);
    return false;
  }
  void restarted(const uint8_t* segments, const LatentState& s, const VisualState*) const {
    if (hook.on_reset) hook.on_reset(hook.user, env, episode_key(s.episode), p, LayoutView{segments}, s, obs);
  }
};

}  // namespace

void CpuBatch::reset_env(int32_t env, uint32_t episode) {
  const LatentStepOut out{params_, hook_, info_, seed_key(seeds_[env]), env, options_.autoreset, obs(env)};
  uint8_t* segments = segments_.data() + static_cast<size_t>(env) * stride_;
  episode_reset(LatentOnlyParams{&params_}, AssetView{}, out.episode_key(episode), episode, segments, states_[env],
                nullptr);
  out.restarted(segments, states_[env], nullptr);
}

void CpuBatch::reset(const uint64_t* seeds) {
  std::copy(seeds, seeds + num_envs_, seeds_.begin());
  parallel_for([&](int32_t first, int32_t last) {
    for (int32_t env = first; env < last; ++env) {
      reset_env(env, 0);
      // A fresh episode reports zero reward and metrics at its spawn point.
      info_.record(env, states_[env], StepOutcome{});
    }
  });
}

void CpuBatch::step(const int32_t* actions) {
  parallel_for([&](int32_t first, int32_t last) {
    for (int32_t env = first; env < last; ++env) {
      LatentStepOut out{params_, hook_, info_, seed_key(seeds_[env]), env, options_.autoreset, obs(env)};
      episode_step(LatentOnlyParams{&params_}, AssetView{}, actions[env],
                   segments_.data() + static_cast<size_t>(env) * stride_, states_[env], nullptr, out);
    }
  });
}

}  // namespace kage
