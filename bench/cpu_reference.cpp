// CPU reference of the GPU batch (see cpu_reference.h).
#include "bench/cpu_reference.h"

#include <thread>

#include "runtime/cuda/device_envs.h"
#include "runtime/latent/latent_step.h"
#include "runtime/visual/render.h"
#include "runtime/visual/visual_update.h"

namespace kage::bench {

CpuReference::CpuReference(const LatentParams& lp, const VisualParams& vp, const AssetView& assets, int32_t num_envs)
    : lp_(lp),
      vp_(vp),
      assets_(assets),
      n_(num_envs),
      stride_(segment_stride_bytes(layout_segment_count(lp))),
      seeds_(num_envs),
      latent_(num_envs),
      visual_(num_envs),
      segments_(static_cast<size_t>(num_envs) * stride_, 0),
      reward_(num_envs, 0.0f) {}

void CpuReference::reset_env(int32_t env, uint32_t episode) {
  const Key key = fold(seed_key(seeds_[env]), episode);
  uint8_t* seg = segments_.data() + static_cast<size_t>(env) * stride_;
  latent_reset(lp_, key, episode, seg, latent_[env]);
  const LayoutView layout{seg};
  visual_reset(vp_, assets_, key, [&](int32_t c) { return ground_top(lp_, layout, c); }, visual_[env]);
}

void CpuReference::reset(const std::vector<uint64_t>& seeds) {
  seeds_ = seeds;
  for (int32_t i = 0; i < n_; ++i) {
    reset_env(i, 0);
    reward_[i] = 0.0f;
  }
}

void CpuReference::step(const std::vector<int32_t>& actions) {
  for (int32_t i = 0; i < n_; ++i) {
    LatentState& s = latent_[i];
    const StepOutcome o = latent_step(lp_, LayoutView{segments_.data() + static_cast<size_t>(i) * stride_}, s, actions[i]);
    reward_[i] = o.reward;
    visual_step(vp_, assets_, fold(seed_key(seeds_[i]), s.episode), static_cast<uint32_t>(s.t), s.vx, visual_[i]);
    if (o.terminated || o.truncated) reset_env(i, s.episode + 1);
  }
}

void CpuReference::render(std::vector<uint8_t>& obs, int32_t threads) const {
  const size_t frame = static_cast<size_t>(vp_.H) * vp_.W * 3;
  obs.assign(frame * n_, 0);
  auto work = [&](int32_t first, int32_t last) {
    std::vector<float> scratch(static_cast<size_t>(render_scratch_floats(vp_)));
    for (int32_t i = first; i < last; ++i) {
      const LatentState& s = latent_[i];
      const LayoutView layout{segments_.data() + static_cast<size_t>(i) * stride_};
      const auto solid_fn = [&](int32_t r, int32_t wc) { return solid(lp_, layout, r, wc); };
      render_frame(vp_, assets_, AgentView{s.x, s.y, s.camera_x}, solid_fn, visual_[i],
                   fold(seed_key(seeds_[i]), s.episode), static_cast<uint32_t>(s.t), obs.data() + frame * i,
                   scratch.data());
    }
  };
  std::vector<std::thread> pool;
  for (int32_t t = 0; t < threads; ++t) pool.emplace_back(work, n_ * t / threads, n_ * (t + 1) / threads);
  for (std::thread& th : pool) th.join();
}

std::vector<int32_t> CpuReference::sample_actions(uint64_t seed, uint32_t t) const {
  std::vector<int32_t> a(n_);
  for (int32_t i = 0; i < n_; ++i) a[i] = randint(fold(seed_key(seed), t), static_cast<uint32_t>(i), 0, 8);
  return a;
}

}  // namespace kage::bench
