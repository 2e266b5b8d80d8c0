// CPU environment: visual reset/step and rendering run from CpuBatch's render hook, on its worker threads.
#include "runtime/host/cpu_env.h"

#include <algorithm>

#include "runtime/latent/layout.h"
#include "runtime/visual/render.h"
#include "runtime/visual/visual_update.h"

namespace kage {

std::unique_ptr<CpuEnv> CpuEnv::create(const LatentParams& latent, const VisualParams& visual, const AssetView& assets,
                                       int32_t num_envs, int32_t num_threads) {
  if (latent.screen_h != visual.H || latent.screen_w != visual.W) return nullptr;
  CpuBatchOptions options;
  options.num_threads = num_threads;
  options.autoreset = true;
  std::optional<CpuBatch> batch = CpuBatch::create(latent, num_envs, options);
  if (!batch) return nullptr;
  return std::unique_ptr<CpuEnv>(new CpuEnv(std::move(*batch), visual, assets));
}

CpuEnv::CpuEnv(CpuBatch batch, const VisualParams& visual, const AssetView& assets)
    : batch_(std::make_unique<CpuBatch>(std::move(batch))),
      visual_(visual),
      assets_(assets),
      visual_states_(batch_->size(), VisualState{}),
      final_obs_(static_cast<size_t>(batch_->size()) * frame_bytes(), 0),
      done_(batch_->size(), 0) {
  RenderHook hook;
  hook.user = this;
  hook.on_reset = &CpuEnv::on_reset;
  hook.on_step = &CpuEnv::on_step;
  hook.on_final = &CpuEnv::on_final;
  batch_->set_render_hook(hook);
}

void CpuEnv::reset(const uint64_t* seeds) {
  std::fill(done_.begin(), done_.end(), 0);
  batch_->reset(seeds);
}

void CpuEnv::step(const int32_t* actions) {
  std::fill(done_.begin(), done_.end(), 0);
  batch_->step(actions);
}

void CpuEnv::render(int32_t env, Key key, const LatentParams& p, LayoutView layout, const LatentState& s,
                    uint8_t* out) const {
  // One scratch per worker thread: only filters touch it, and one frame is rendered at a time per thread.
  thread_local std::vector<float> scratch;
  const size_t need = static_cast<size_t>(render_scratch_floats(visual_));
  if (scratch.size() < need) scratch.resize(need);
  const AgentView agent{s.x, s.y, s.camera_x};
  auto solid_at = [&](int32_t r, int32_t c) { return solid(p, layout, r, c); };
  render_frame(visual_, assets_, agent, solid_at, visual_states_[env], key, static_cast<uint32_t>(s.t), out,
               scratch.data());
}

void CpuEnv::on_reset(void* user, int32_t env, Key key, const LatentParams& p, LayoutView layout, const LatentState& s,
                      uint8_t* obs) {
  CpuEnv& self = *static_cast<CpuEnv*>(user);
  auto ground_top_at = [&](int32_t c) { return ground_top(p, layout, c); };
  visual_reset(self.visual_, self.assets_, key, ground_top_at, self.visual_states_[env]);
  self.render(env, key, p, layout, s, obs);
}

void CpuEnv::on_step(void* user, int32_t env, Key key, const LatentParams& p, LayoutView layout, const LatentState& s,
                     uint8_t* obs) {
  CpuEnv& self = *static_cast<CpuEnv*>(user);
  visual_step(self.visual_, self.assets_, key, static_cast<uint32_t>(s.t), s.vx, self.visual_states_[env]);
  self.render(env, key, p, layout, s, obs);
}

void CpuEnv::on_final(void* user, int32_t env, Key key, const LatentParams& p, LayoutView layout,
                      const LatentState& s) {
  CpuEnv& self = *static_cast<CpuEnv*>(user);
  visual_step(self.visual_, self.assets_, key, static_cast<uint32_t>(s.t), s.vx, self.visual_states_[env]);
  self.render(env, key, p, layout, s, self.final_obs_.data() + static_cast<size_t>(env) * self.frame_bytes());
  self.done_[env] = 1;
}

}  // namespace kage
