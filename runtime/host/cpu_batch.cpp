// CPU batch runtime: static partition of the environments over std::threads; every environment is
// independent, so the results are the same for any thread count.
#include "runtime/host/cpu_batch.h"

#include <algorithm>
#include <thread>

#include "runtime/latent/latent_step.h"

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

void CpuBatch::reset_env(int32_t env, uint32_t episode) {
  const Key key = fold(seed_key(seeds_[env]), episode);
  uint8_t* segments = segments_.data() + static_cast<size_t>(env) * stride_;
  latent_reset(params_, key, episode, segments, states_[env]);
  if (hook_.on_reset) hook_.on_reset(hook_.user, env, key, params_, LayoutView{segments}, states_[env], obs(env));
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
      const LayoutView layout = this->layout(env);
      const StepOutcome o = latent_step(params_, layout, states_[env], actions[env]);
      info_.record(env, states_[env], o);
      if (options_.autoreset && (o.terminated || o.truncated)) {
        if (hook_.on_final) hook_.on_final(hook_.user, env, episode_key(env), params_, layout, states_[env]);
        reset_env(env, states_[env].episode + 1);
      } else if (hook_.on_step) {
        hook_.on_step(hook_.user, env, episode_key(env), params_, layout, states_[env], obs(env));
      }
    }
  });
}

}  // namespace kage
