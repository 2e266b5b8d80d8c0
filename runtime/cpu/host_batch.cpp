// CPU batch: the two HostKernels and the batch (threads, explicit reset, saved state); the episode
// driver (runtime/episode.h) steps each environment.
#include "runtime/cpu/host_batch.h"

#include <algorithm>
#include <cstring>
#include <thread>

#include "runtime/cpu/batch_state.h"

namespace kage {
namespace {

class GenericHostKernels final : public HostKernels {
 public:
  GenericHostKernels(const LatentParams& l, const VisualParams& v) : latent_(l), visual_(v) {}
  const LatentParams& latent() const override { return latent_; }
  const VisualParams& visual() const override { return visual_; }
  void reset_env(const AssetView& a, Key k, uint32_t episode, const EnvSlot& e) const override {
    env_reset(params(), a, k, episode, e);
  }
  void step_env(const AssetView& a, Key seed, int32_t action, const EnvSlot& e, const StepRows& rows) const override {
    env_step(params(), a, seed, action, e, rows);
  }
  void render_env(const AssetView& a, Key k, const EnvSlot& e) const override { env_render(params(), a, k, e); }

 private:
  RuntimeParams params() const { return {&latent_, &visual_}; }
  LatentParams latent_;
  VisualParams visual_;
};

class GeneratedHostKernels final : public HostKernels {
 public:
  explicit GeneratedHostKernels(const HostEntryPoints& ep) : ep_(ep) { ep_.params(&latent_, &visual_); }
  const LatentParams& latent() const override { return latent_; }
  const VisualParams& visual() const override { return visual_; }
  void reset_env(const AssetView& a, Key k, uint32_t episode, const EnvSlot& e) const override {
    ep_.reset_env(&a, k, episode, &e);
  }
  void step_env(const AssetView& a, Key seed, int32_t action, const EnvSlot& e, const StepRows& rows) const override {
    ep_.step_env(&a, seed, action, &e, &rows);
  }
  void render_env(const AssetView& a, Key k, const EnvSlot& e) const override { ep_.render_env(&a, k, &e); }

 private:
  HostEntryPoints ep_;
  LatentParams latent_{};
  VisualParams visual_{};
};

}  // namespace

std::unique_ptr<HostKernels> generic_host_kernels(const LatentParams& latent, const VisualParams& visual) {
  return std::make_unique<GenericHostKernels>(latent, visual);
}

std::unique_ptr<HostKernels> generated_host_kernels(const HostEntryPoints& entry_points) {
  return std::make_unique<GeneratedHostKernels>(entry_points);
}

namespace {

std::vector<HostPart> one_part(std::unique_ptr<HostKernels> kernels, const AssetView& assets, int32_t num_envs) {
  std::vector<HostPart> parts;
  parts.push_back(HostPart{std::move(kernels), assets, num_envs});
  return parts;
}

size_t frame_bytes_of(const HostKernels& k) { return static_cast<size_t>(k.visual().H) * k.visual().W * 3; }

}  // namespace

HostBatch::HostBatch(std::unique_ptr<HostKernels> kernels, const AssetView& assets, int32_t num_envs,
                     int32_t num_threads, bool info_shows_new_episode)
    : HostBatch(one_part(std::move(kernels), assets, num_envs), num_threads, info_shows_new_episode) {}

HostBatch::HostBatch(std::vector<HostPart> parts, int32_t num_threads, bool info_shows_new_episode)
    : parts_(std::move(parts)),
      n_(0),
      threads_(std::max(1, num_threads)),
      info_shows_new_episode_(info_shows_new_episode) {
  for (size_t k = 0; k < parts_.size(); ++k) part_.insert(part_.end(), parts_[k].num_envs, static_cast<int32_t>(k));
  n_ = static_cast<int32_t>(part_.size());
  seg_bytes_ = static_cast<size_t>(layout_segment_count(latent_params()));
  frame_ = frame_bytes_of(*parts_.front().kernels);
  const size_t n = static_cast<size_t>(n_);
  seeds_.assign(n, 0);
  latent_.assign(n, LatentState{});
  visual_.assign(n, VisualState{});
  segments_.assign(n * seg_bytes_, 0);
  obs_.assign(n * frame_, 0);
  final_obs_.assign(n * frame_, 0);
  final_mask_.assign(n, 0);
  info_.resize(n);
  final_info_.resize(n);
}

std::string HostBatch::parts_problem(const std::vector<const HostKernels*>& kernels) {
  for (size_t k = 1; k < kernels.size(); ++k) {
    const HostKernels& first = *kernels.front();
    const HostKernels& other = *kernels[k];
    if (frame_bytes_of(other) != frame_bytes_of(first))
      return "part " + std::to_string(k) + " renders " + std::to_string(other.visual().H) + "x" +
             std::to_string(other.visual().W) + " frames, part 0 " + std::to_string(first.visual().H) + "x" +
             std::to_string(first.visual().W);
    if (layout_segment_count(other.latent()) != layout_segment_count(first.latent()))
      return "part " + std::to_string(k) + "'s layout has another size than part 0's";
  }
  return {};
}

template <class Fn>
void HostBatch::parallel_for(const Fn& fn) {
  const int32_t threads = std::min(threads_, n_);
  size_t scratch_floats = 0;
  for (const HostPart& p : parts_)
    scratch_floats = std::max(scratch_floats, static_cast<size_t>(render_scratch_floats(p.kernels->visual())));
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

void HostBatch::reset_env(int32_t env, uint32_t episode, float* scratch) {
  const HostPart& p = part(env);
  p.kernels->reset_env(p.assets, fold(seed_key(seeds_[env]), episode), episode, slot(env, scratch));
}

void HostBatch::reset(const uint64_t* seeds, const uint8_t* mask) {
  parallel_for([&](int32_t env, float* scratch) {
    final_mask_[env] = 0;
    if (mask && !mask[env]) return;
    seeds_[env] = seeds[env];
    reset_env(env, 0, scratch);
    info_.record(env, latent_[env], StepOutcome{});
  });
}

void HostBatch::step(const int32_t* actions) {
  StepRows rows{0, info_.reward.data(), info_.terminated.data(), info_.truncated.data(), info_.columns(),
                final_mask_.data(), final_info_.columns(), nullptr, info_shows_new_episode_ ? 1 : 0};
  parallel_for([&](int32_t env, float* scratch) {
    StepRows row = rows;
    row.env = env;
    row.final_obs = final_obs_.data() + env * frame_;
    const HostPart& p = part(env);
    p.kernels->step_env(p.assets, seed_key(seeds_[env]), actions[env], slot(env, scratch), row);
  });
}

std::vector<uint8_t> HostBatch::save_state(const std::string& spec_hash) const {
  const size_t n = static_cast<size_t>(n_);
  const BatchStateLayout l(n, seg_bytes_);
  std::vector<uint8_t> out(l.total, 0);
  write_batch_state_header(out.data(), n_, static_cast<int32_t>(seg_bytes_), spec_hash);
  auto put = [&](size_t off, const void* src, size_t bytes) { std::memcpy(out.data() + off, src, bytes); };
  put(l.seeds, seeds_.data(), n * sizeof(uint64_t));
  put(l.latent, latent_.data(), n * sizeof(LatentState));
  put(l.segments, segments_.data(), n * seg_bytes_);
  put(l.visual, visual_.data(), n * sizeof(VisualState));
  put(l.reward, info_.reward.data(), n * sizeof(float));
  put(l.terminated, info_.terminated.data(), n);
  put(l.truncated, info_.truncated.data(), n);
  int i = 0;
#define KAGE_INFO_FIELD(Enum, member, name, ctype, dtype, doc, value) put(l.info[i++], info_.member.data(), n * sizeof(ctype));
#include "runtime/info_fields.def"
#undef KAGE_INFO_FIELD
  return out;
}

std::string HostBatch::load_state(const uint8_t* data, size_t size, const std::string& spec_hash) {
  const std::string problem = check_batch_state(data, size, n_, static_cast<int32_t>(seg_bytes_), spec_hash);
  if (!problem.empty()) return problem;
  const size_t n = static_cast<size_t>(n_);
  const BatchStateLayout l(n, seg_bytes_);
  auto get = [&](void* dst, size_t off, size_t bytes) { std::memcpy(dst, data + off, bytes); };
  get(seeds_.data(), l.seeds, n * sizeof(uint64_t));
  get(latent_.data(), l.latent, n * sizeof(LatentState));
  get(segments_.data(), l.segments, n * seg_bytes_);
  get(visual_.data(), l.visual, n * sizeof(VisualState));
  get(info_.reward.data(), l.reward, n * sizeof(float));
  get(info_.terminated.data(), l.terminated, n);
  get(info_.truncated.data(), l.truncated, n);
  int i = 0;
#define KAGE_INFO_FIELD(Enum, member, name, ctype, dtype, doc, value) get(info_.member.data(), l.info[i++], n * sizeof(ctype));
#include "runtime/info_fields.def"
#undef KAGE_INFO_FIELD
  // Frames are a pure function of the state: render them again instead of saving them.
  parallel_for([&](int32_t env, float* scratch) {
    final_mask_[env] = 0;
    const HostPart& p = part(env);
    p.kernels->render_env(p.assets, episode_key(env), slot(env, scratch));
  });
  return {};
}

}  // namespace kage
