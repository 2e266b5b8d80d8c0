// GPU batch runtime: buffer layout, asset upload and kernel launches through the driver API.
#include "runtime/cuda/device_batch.h"

#include <algorithm>
#include <cstddef>
#include <vector>

#include "runtime/cuda/render_plan.h"
#include "runtime/latent/latent_state.h"
#include "runtime/visual/visual_state.h"

namespace kage {
namespace {

constexpr int32_t kPerEnvThreads = 256;

/// Rounds up to a multiple of 256 bytes (the alignment of every sub-buffer).
size_t align256(size_t n) { return (n + 255) / 256 * 256; }

bool check(CUresult r, const char* what, std::string* error) {
  if (r == CUDA_SUCCESS) return true;
  *error = cu_error_text(r, what);
  return false;
}

/// Sub-buffer offsets of the per-env state allocation.
struct StateLayout {
  size_t seeds, latent, segments, visual, actions, reward, terminated, truncated, info, total;
};

StateLayout state_layout(size_t n, size_t segment_stride) {
  StateLayout l{};
  size_t at = 0;
  auto take = [&](size_t bytes) {
    const size_t off = at;
    at += align256(bytes);
    return off;
  };
  l.seeds = take(n * sizeof(uint64_t));
  l.latent = take(n * sizeof(LatentState));
  l.segments = take(n * segment_stride);
  l.visual = take(n * sizeof(VisualState));
  l.actions = take(n * sizeof(int32_t));
  l.reward = take(n * sizeof(float));
  l.terminated = take(n);
  l.truncated = take(n);
  l.info = take(n * sizeof(StepInfo));
  l.total = at;
  return l;
}

int32_t frame_count(const AssetView& a) {
  int32_t n = 0;
  for (const SpriteSetTable* t : {&a.agent_skins, &a.npc_types, &a.sticky_types})
    for (int32_t i = 0; i < t->count; ++i) n = std::max(n, t->sets[i].first_frame + t->sets[i].frame_count);
  return n;
}

size_t sprite_bytes(const AssetView& a, int32_t frames) {
  size_t n = 0;
  for (int32_t i = 0; i < frames; ++i)
    n = std::max(n, static_cast<size_t>(a.frames[i].offset) + static_cast<size_t>(a.frames[i].width) * a.frames[i].height * 4);
  return n;
}

}  // namespace

int32_t visual_state_extent(const VisualParams& p, const AssetView& a) {
  if (p.distractors_enabled && p.distractor_count > 0) return static_cast<int32_t>(sizeof(VisualState));
  if (p.sticky_enabled && a.sticky_types.count > 0) return static_cast<int32_t>(offsetof(VisualState, dist_x));
  if (p.npc_enabled && a.npc_types.count > 0) return static_cast<int32_t>(offsetof(VisualState, sticky_count));
  return static_cast<int32_t>(offsetof(VisualState, npc_x));
}

size_t device_state_bytes_per_env(const LatentParams& lp) {
  return sizeof(uint64_t) + sizeof(LatentState) + static_cast<size_t>(segment_stride_bytes(layout_segment_count(lp))) +
         sizeof(VisualState) + sizeof(int32_t) + sizeof(float) + 2 + sizeof(StepInfo);
}

std::optional<DeviceBatch> DeviceBatch::create(const CudaModule& module, const LatentParams& lp,
                                               const VisualParams& vp, const AssetView& host_assets, int32_t num_envs,
                                               std::string* error) {
  if (num_envs <= 0) {
    *error = "DeviceBatch: the environment count must be positive";
    return std::nullopt;
  }
  if (!latent_params_supported(lp)) {
    *error = "DeviceBatch: layout parameters not supported";
    return std::nullopt;
  }
  if (!render_supported(vp)) {
    *error = "DeviceBatch: frame size not supported on the GPU (W <= " + std::to_string(kMaxScreenWidth) +
             "; with blur, sharpen or pixelate H * W <= " + std::to_string(kFramePassMaxThreads * kFramePassPixelsPerThread) + ")";
    return std::nullopt;
  }
  DeviceBatch b;
  for (auto [fn, name] : {std::pair{&b.reset_, "kage_reset"}, std::pair{&b.step_, "kage_step"}, std::pair{&b.render_, "kage_render"},
                          std::pair{&b.sample_actions_, "kage_sample_actions"}}) {
    *fn = module.function(name, error);
    if (!*fn) return std::nullopt;
  }
  // The generic build reads its parameters from __constant__ memory; a specialized build has them folded.
  struct Upload {
    const char* name;
    const void* src;
    size_t bytes;
  };
  for (const Upload& u : {Upload{"kage_dynamic_latent", &lp, sizeof lp}, Upload{"kage_dynamic_visual", &vp, sizeof vp}}) {
    const char* name = u.name;
    const void* src = u.src;
    const size_t bytes = u.bytes;
    size_t size = 0;
    if (const CUdeviceptr p = module.global(name, &size); p != 0) {
      if (size != bytes) {
        *error = std::string("DeviceBatch: ") + name + " has another size in the module: rebuild it";
        return std::nullopt;
      }
      if (!check(cuMemcpyHtoD(p, src, bytes), "cuMemcpyHtoD(params)", error)) return std::nullopt;
    }
  }
  b.render_threads_ = render_threads(vp);
  b.render_smem_ = render_dynamic_smem_bytes(vp);
  CUdevice dev;
  int multiprocessors = 0;
  if (!check(cuCtxGetDevice(&dev), "cuCtxGetDevice", error) ||
      !check(cuDeviceGetAttribute(&multiprocessors, CU_DEVICE_ATTRIBUTE_MULTIPROCESSOR_COUNT, dev),
             "cuDeviceGetAttribute(multiprocessors)", error))
    return std::nullopt;
  b.frames_per_block_ = frames_per_block(vp, num_envs, multiprocessors);
  if (!check(cuFuncSetAttribute(b.render_, CU_FUNC_ATTRIBUTE_MAX_DYNAMIC_SHARED_SIZE_BYTES, b.render_smem_),
             "cuFuncSetAttribute(dynamic shared memory)", error))
    return std::nullopt;

  // Assets: one allocation, pointers rebased.
  const AssetView& ha = host_assets;
  const int32_t frames = frame_count(ha);
  const size_t bg_bytes = static_cast<size_t>(ha.bg_count) * ha.bg_h * ha.bg_w * 3;
  const size_t px_bytes = sprite_bytes(ha, frames);
  const size_t o_px = align256(bg_bytes);
  const size_t o_frames = o_px + align256(px_bytes);
  const size_t o_sets = o_frames + align256(frames * sizeof(SpriteFrame));
  size_t total = o_sets;
  size_t set_off[3];
  const SpriteSetTable* tables[3] = {&ha.agent_skins, &ha.npc_types, &ha.sticky_types};
  for (int i = 0; i < 3; ++i) {
    set_off[i] = total;
    total += align256(tables[i]->count * sizeof(SpriteSet));
  }
  if (!check(cuMemAlloc(&b.assets_, std::max<size_t>(total, 256)), "cuMemAlloc(assets)", error)) return std::nullopt;
  auto upload = [&](size_t off, const void* src, size_t bytes) {
    return bytes == 0 || check(cuMemcpyHtoD(b.assets_ + off, src, bytes), "cuMemcpyHtoD(assets)", error);
  };
  if (!upload(0, ha.bg, bg_bytes) || !upload(o_px, ha.sprite_pixels, px_bytes) ||
      !upload(o_frames, ha.frames, frames * sizeof(SpriteFrame)))
    return std::nullopt;
  for (int i = 0; i < 3; ++i)
    if (!upload(set_off[i], tables[i]->sets, tables[i]->count * sizeof(SpriteSet))) return std::nullopt;
  auto at = [&](size_t off) { return reinterpret_cast<const uint8_t*>(b.assets_ + off); };
  AssetView& da = b.envs_.assets;
  da = ha;
  da.bg = bg_bytes ? at(0) : nullptr;
  da.sprite_pixels = px_bytes ? at(o_px) : nullptr;
  da.frames = frames ? reinterpret_cast<const SpriteFrame*>(at(o_frames)) : nullptr;
  SpriteSetTable* dtables[3] = {&da.agent_skins, &da.npc_types, &da.sticky_types};
  for (int i = 0; i < 3; ++i)
    dtables[i]->sets = tables[i]->count ? reinterpret_cast<const SpriteSet*>(at(set_off[i])) : nullptr;

  // State and observations.
  const size_t n = static_cast<size_t>(num_envs);
  const int32_t stride = segment_stride_bytes(layout_segment_count(lp));
  const StateLayout l = state_layout(n, static_cast<size_t>(stride));
  b.obs_stride_ = static_cast<size_t>(vp.H) * vp.W * 3;
  if (!check(cuMemAlloc(&b.state_, l.total), "cuMemAlloc(state)", error)) return std::nullopt;
  if (!check(cuMemsetD8(b.state_, 0, l.total), "cuMemsetD8(state)", error)) return std::nullopt;
  if (!check(cuMemAlloc(&b.obs_buf_, n * b.obs_stride_), "cuMemAlloc(observations)", error)) return std::nullopt;
  auto ptr = [&](size_t off) { return reinterpret_cast<uint8_t*>(b.state_ + off); };
  DeviceEnvs& e = b.envs_;
  e.num_envs = num_envs;
  e.segment_stride = stride;
  e.visual_extent = visual_state_extent(vp, ha);
  e.seeds = reinterpret_cast<const uint64_t*>(ptr(l.seeds));
  e.latent = reinterpret_cast<LatentState*>(ptr(l.latent));
  e.segments = ptr(l.segments);
  e.visual = reinterpret_cast<VisualState*>(ptr(l.visual));
  e.actions = reinterpret_cast<const int32_t*>(ptr(l.actions));
  e.obs = reinterpret_cast<uint8_t*>(b.obs_buf_);
  e.reward = reinterpret_cast<float*>(ptr(l.reward));
  e.terminated = ptr(l.terminated);
  e.truncated = ptr(l.truncated);
  e.info = reinterpret_cast<StepInfo*>(ptr(l.info));
  return b;
}

DeviceBatch::DeviceBatch(DeviceBatch&& o) noexcept
    : envs_(o.envs_),
      obs_stride_(o.obs_stride_),
      render_threads_(o.render_threads_),
      render_smem_(o.render_smem_),
      frames_per_block_(o.frames_per_block_),
      state_(o.state_),
      obs_buf_(o.obs_buf_),
      assets_(o.assets_),
      reset_(o.reset_),
      step_(o.step_),
      render_(o.render_),
      sample_actions_(o.sample_actions_) {
  o.state_ = o.obs_buf_ = o.assets_ = 0;
}

DeviceBatch::~DeviceBatch() {
  // Frees fail only once the context is gone at exit, when the memory is released anyway.
  for (CUdeviceptr p : {state_, obs_buf_, assets_})
    if (p) cuMemFree(p);
}

bool DeviceBatch::launch_per_env(CUfunction f, std::string* error) {
  void* args[] = {&envs_};
  const unsigned grid = static_cast<unsigned>((envs_.num_envs + kPerEnvThreads - 1) / kPerEnvThreads);
  return check(cuLaunchKernel(f, grid, 1, 1, kPerEnvThreads, 1, 1, 0, nullptr, args, nullptr), "cuLaunchKernel", error);
}

bool DeviceBatch::launch_render(std::string* error) {
  void* args[] = {&envs_};
  const unsigned grid = static_cast<unsigned>((envs_.num_envs + frames_per_block_ - 1) / frames_per_block_);
  return check(cuLaunchKernel(render_, grid, 1, 1, static_cast<unsigned>(render_threads_),
                              1, 1, static_cast<unsigned>(render_smem_), nullptr, args, nullptr),
               "cuLaunchKernel", error);
}

bool DeviceBatch::reset(const uint64_t* seeds, std::string* error) {
  const CUdeviceptr d = reinterpret_cast<CUdeviceptr>(envs_.seeds);
  return check(cuMemcpyHtoD(d, seeds, sizeof(uint64_t) * envs_.num_envs), "cuMemcpyHtoD(seeds)", error) &&
         launch_per_env(reset_, error) && launch_render(error);
}

bool DeviceBatch::step(const int32_t* actions, std::string* error) {
  return check(cuMemcpyHtoD(this->actions(), actions, sizeof(int32_t) * envs_.num_envs), "cuMemcpyHtoD(actions)",
               error) &&
         step_device_actions(error);
}

bool DeviceBatch::step_device_actions(std::string* error) { return step_no_render(error) && launch_render(error); }

bool DeviceBatch::step_no_render(std::string* error) { return launch_per_env(step_, error); }

bool DeviceBatch::download_obs(uint8_t* host, std::string* error) const {
  return check(cuMemcpyDtoH(host, obs(), obs_stride_ * static_cast<size_t>(envs_.num_envs)), "cuMemcpyDtoH(obs)", error);
}

bool DeviceBatch::sample_actions(uint64_t seed, uint32_t t, std::string* error) {
  int32_t* actions = const_cast<int32_t*>(envs_.actions);
  int32_t n = envs_.num_envs;
  void* args[] = {&actions, &n, &seed, &t};
  const unsigned grid = static_cast<unsigned>((n + kPerEnvThreads - 1) / kPerEnvThreads);
  return check(cuLaunchKernel(sample_actions_, grid, 1, 1, kPerEnvThreads, 1, 1, 0, nullptr, args, nullptr),
               "cuLaunchKernel(kage_sample_actions)", error);
}

}  // namespace kage
