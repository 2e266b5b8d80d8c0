// GPU batch runtime: buffer layout, asset upload and kernel launches through the driver API.
#include "runtime/cuda/device_batch.h"

#include <algorithm>
#include <atomic>
#include <climits>
#include <cstddef>
#include <cstring>
#include <vector>

#include "runtime/cuda/group_plan.h"
#include "runtime/cuda/render_plan.h"
#include "runtime/cpu/batch_state.h"
#include "runtime/latent/latent_state.h"
#include "runtime/visual/visual_state.h"

namespace kage {
namespace {

/// Rounds up to a multiple of 256 bytes (the alignment of every sub-buffer).
size_t align256(size_t n) { return (n + 255) / 256 * 256; }

/// Sub-buffer offsets of the per-env state allocation.
struct StateLayout {
  size_t seeds, latent, segments, visual, actions, reset_mask, reward, terminated, truncated, final_mask, final_latent,
      final_segments, final_visual, total;
  size_t info[kInfoFieldCount], final_info[kInfoFieldCount];
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
  l.reset_mask = take(n);
  l.reward = take(n * sizeof(float));
  l.terminated = take(n);
  l.truncated = take(n);
  l.final_mask = take(n);
  l.final_latent = take(n * sizeof(LatentState));
  l.final_segments = take(n * segment_stride);
  l.final_visual = take(n * sizeof(VisualState));
  int i = 0;
#define KAGE_INFO_FIELD(Enum, member, name, ctype, dtype, doc, value) \
  l.info[i] = take(n * sizeof(ctype));                         \
  l.final_info[i++] = take(n * sizeof(ctype));
#include "runtime/info_fields.def"
#undef KAGE_INFO_FIELD
  l.total = at;
  return l;
}

/// The info columns at `offsets` of the allocation at `base`.
InfoArrays info_arrays(CUdeviceptr base, const size_t* offsets) {
  InfoArrays a{};
  int i = 0;
#define KAGE_INFO_FIELD(Enum, member, name, ctype, dtype, doc, value) a.member = reinterpret_cast<ctype*>(base + offsets[i++]);
#include "runtime/info_fields.def"
#undef KAGE_INFO_FIELD
  return a;
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

bool upload_dynamic_params(const CudaModule& module, const LatentParams& lp, const VisualParams& vp,
                           std::string* error) {
  // The generic build reads its parameters from __constant__ memory; a specialized build has them folded.
  struct Upload {
    const char* name;
    const void* src;
    size_t bytes;
  };
  for (const Upload& u : {Upload{"kage_dynamic_latent", &lp, sizeof lp}, Upload{"kage_dynamic_visual", &vp, sizeof vp}}) {
    size_t size = 0;
    if (const CUdeviceptr p = module.global(u.name, &size); p != 0) {
      if (size != u.bytes) {
        *error = std::string("DeviceBatch: ") + u.name + " has another size in the module: rebuild it";
        return false;
      }
      if (!cu_check(cuMemcpyHtoD(p, u.src, u.bytes), "cuMemcpyHtoD(params)", error)) return false;
    }
  }
  return true;
}

std::optional<DeviceAssets> upload_assets(const AssetView& ha, std::string* error) {
  // One allocation, pointers rebased.
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
  DeviceAssets d;
  if (!cu_check(cuMemAlloc(&d.memory, std::max<size_t>(total, 256)), "cuMemAlloc(assets)", error)) return std::nullopt;
  auto upload = [&](size_t off, const void* src, size_t bytes) {
    return bytes == 0 || cu_check(cuMemcpyHtoD(d.memory + off, src, bytes), "cuMemcpyHtoD(assets)", error);
  };
  bool ok = upload(0, ha.bg, bg_bytes) && upload(o_px, ha.sprite_pixels, px_bytes) &&
            upload(o_frames, ha.frames, frames * sizeof(SpriteFrame));
  for (int i = 0; i < 3 && ok; ++i) ok = upload(set_off[i], tables[i]->sets, tables[i]->count * sizeof(SpriteSet));
  if (!ok) {
    cuMemFree(d.memory);
    return std::nullopt;
  }
  auto at = [&](size_t off) { return reinterpret_cast<const uint8_t*>(d.memory + off); };
  AssetView& da = d.view;
  da = ha;
  da.bg = bg_bytes ? at(0) : nullptr;
  da.sprite_pixels = px_bytes ? at(o_px) : nullptr;
  da.frames = frames ? reinterpret_cast<const SpriteFrame*>(at(o_frames)) : nullptr;
  SpriteSetTable* dtables[3] = {&da.agent_skins, &da.npc_types, &da.sticky_types};
  for (int i = 0; i < 3; ++i)
    dtables[i]->sets = tables[i]->count ? reinterpret_cast<const SpriteSet*>(at(set_off[i])) : nullptr;
  return d;
}

namespace {

/// The columns of `a` from environment `first` on.
InfoArrays offset_info(const InfoArrays& a, int32_t first) {
  InfoArrays o{};
#define KAGE_INFO_FIELD(Enum, member, name, ctype, dtype, doc, value) o.member = a.member + first;
#include "runtime/info_fields.def"
#undef KAGE_INFO_FIELD
  return o;
}

/// The view of environments [first, first + count) of the batch view `w`: every per-env pointer moved
/// to environment `first` (layouts `segment_stride` bytes apart, frames `frame_bytes`).
DeviceEnvs part_view(const DeviceEnvs& w, int32_t first, int32_t count, size_t frame_bytes) {
  const int64_t f = first;
  DeviceEnvs v = w;
  v.num_envs = count;
  v.seeds = w.seeds + f;
  v.latent = w.latent + f;
  v.segments = w.segments + f * w.segment_stride;
  v.visual = w.visual + f;
  v.actions.data = static_cast<const int32_t*>(w.actions.data) + f;
  v.reset_mask = nullptr;
  v.obs = w.obs + f * static_cast<int64_t>(frame_bytes);
  v.reward = w.reward + f;
  v.terminated = w.terminated + f;
  v.truncated = w.truncated + f;
  v.info = offset_info(w.info, first);
  v.final_mask = w.final_mask + f;
  v.final_latent = w.final_latent + f;
  v.final_segments = w.final_segments + f * w.segment_stride;
  v.final_visual = w.final_visual + f;
  v.final_obs = w.final_obs + f * static_cast<int64_t>(frame_bytes);
  v.final_info = offset_info(w.final_info, first);
  return v;
}

/// Why a part cannot run on the GPU, or cannot join the first part `p0` in one batch; empty if it can.
std::string part_problem(const DevicePartSource& p, const DevicePartSource& p0) {
  if (!p.module) return "no module";
  if (p.num_envs < 0) return "a negative environment count";
  if (!latent_params_supported(p.lp)) return "layout parameters not supported";
  if (!render_supported(p.vp))
    return "frame size not supported on the GPU (W <= " + std::to_string(kMaxScreenWidth) +
           "; with blur, sharpen or pixelate H * W <= " + std::to_string(kFramePassMaxThreads * kFramePassPixelsPerThread) +
           ")";
  if (layout_segment_count(p.lp) != layout_segment_count(p0.lp))
    return "its layout has " + std::to_string(layout_segment_count(p.lp)) + " segments, the first part's " +
           std::to_string(layout_segment_count(p0.lp)) + ": the parts of one batch must share one hidden game";
  if (p.vp.H != p0.vp.H || p.vp.W != p0.vp.W)
    return "its frames are " + std::to_string(p.vp.H) + "x" + std::to_string(p.vp.W) + ", the first part's " +
           std::to_string(p0.vp.H) + "x" + std::to_string(p0.vp.W) + ": the parts of one batch must share one frame size";
  return {};
}

}  // namespace

std::optional<DeviceBatch> DeviceBatch::create(const CudaModule& module, const LatentParams& lp,
                                               const VisualParams& vp, const AssetView& host_assets, int32_t num_envs,
                                               std::string* error) {
  if (num_envs <= 0) {
    *error = "DeviceBatch: the environment count must be positive";
    return std::nullopt;
  }
  return create({DevicePartSource{&module, lp, vp, host_assets, num_envs, {}}}, error);
}

std::optional<DeviceBatch> DeviceBatch::create(const std::vector<DevicePartSource>& parts, std::string* error) {
  int64_t total = 0;
  for (const DevicePartSource& p : parts) total += std::max(p.num_envs, 0);
  if (parts.empty() || total <= 0 || total > INT32_MAX) {
    *error = "DeviceBatch: give one or more parts with 1 to 2^31 - 1 environments in all";
    return std::nullopt;
  }
  for (size_t k = 0; k < parts.size(); ++k) {
    const std::string problem = part_problem(parts[k], parts.front());
    if (!problem.empty()) {
      *error = "DeviceBatch: " + (parts.size() > 1 ? "part " + std::to_string(k) + ": " : std::string()) + problem;
      return std::nullopt;
    }
    // A generic module holds its parameters in its __constant__ memory: one instance serves one part.
    size_t bytes = 0;
    for (size_t j = 0; j < k; ++j)
      if (parts[j].module == parts[k].module && parts[k].module->global("kage_dynamic_latent", &bytes) != 0) {
        *error = "DeviceBatch: parts " + std::to_string(j) + " and " + std::to_string(k) +
                 " share one module whose parameters are in its __constant__ memory: load one module per part";
        return std::nullopt;
      }
  }
  CUdevice dev;
  int multiprocessors = 0;
  if (!cu_check(cuCtxGetDevice(&dev), "cuCtxGetDevice", error) ||
      !cu_check(cuDeviceGetAttribute(&multiprocessors, CU_DEVICE_ATTRIBUTE_MULTIPROCESSOR_COUNT, dev),
             "cuDeviceGetAttribute(multiprocessors)", error))
    return std::nullopt;

  // Each part: its kernels, its parameters in its module, its launch settings and its assets. A part is
  // kept in the batch as soon as it owns device memory, so that the batch's destructor frees it on error.
  static std::atomic<uint64_t> batches_made{0};
  DeviceBatch b;
  b.serial_ = ++batches_made;
  b.multiprocessors_ = multiprocessors;
  int32_t first = 0;
  int32_t visual_extent = 0;
  for (const DevicePartSource& src : parts) {
    Part p;
    p.first = first;
    for (auto [fn, name] : {std::pair{&p.reset, "kage_reset"}, std::pair{&p.step, "kage_step"},
                            std::pair{&p.render, "kage_render"}, std::pair{&p.step_rows, "kage_step_rows"}}) {
      *fn = src.module->function(name, error);
      if (!*fn) return std::nullopt;
    }
    if (!b.sample_actions_ && !(b.sample_actions_ = src.module->function("kage_sample_actions", error)))
      return std::nullopt;
    if (!upload_dynamic_params(*src.module, src.lp, src.vp, error)) return std::nullopt;
    p.code = src.code;
    p.frame_passes = needs_frame_passes(src.vp);
    p.render_threads = render_threads(src.vp);
    p.render_smem = render_dynamic_smem_bytes(src.vp);
    p.frames_per_block = frames_per_block(src.vp, std::max(src.num_envs, 1), multiprocessors);
    if (!cu_check(cuFuncSetAttribute(p.render, CU_FUNC_ATTRIBUTE_MAX_DYNAMIC_SHARED_SIZE_BYTES, p.render_smem),
                  "cuFuncSetAttribute(dynamic shared memory)", error))
      return std::nullopt;
    std::optional<DeviceAssets> assets = upload_assets(src.host_assets, error);
    if (!assets) return std::nullopt;
    p.assets = assets->memory;
    p.envs.assets = assets->view;
    p.envs.num_envs = src.num_envs;
    p.envs.visual_extent = visual_state_extent(src.vp, src.host_assets);
    visual_extent = std::max(visual_extent, p.envs.visual_extent);
    b.parts_.push_back(p);
    first += src.num_envs;
  }

  // State and observations: one allocation each for every environment of every part.
  const DevicePartSource& p0 = parts.front();
  const size_t n = static_cast<size_t>(total);
  b.segment_count_ = layout_segment_count(p0.lp);
  const int32_t stride = segment_stride_bytes(b.segment_count_);
  const StateLayout l = state_layout(n, static_cast<size_t>(stride));
  b.obs_stride_ = static_cast<size_t>(p0.vp.H) * p0.vp.W * 3;
  if (!cu_check(cuMemAlloc(&b.state_, l.total), "cuMemAlloc(state)", error)) return std::nullopt;
  if (!cu_check(cuMemsetD8(b.state_, 0, l.total), "cuMemsetD8(state)", error)) return std::nullopt;
  if (!cu_check(cuMemAlloc(&b.obs_buf_, 2 * n * b.obs_stride_), "cuMemAlloc(observations)", error)) return std::nullopt;
  const size_t count_bytes = parts.size() * sizeof(StepCount);
  if (!cu_check(cuMemAlloc(&b.step_counts_, count_bytes), "cuMemAlloc(step counts)", error) ||
      !cu_check(cuMemsetD8(b.step_counts_, 0, count_bytes), "cuMemsetD8(step counts)", error))
    return std::nullopt;
  // One host-mapped report slot per part: a part's kernels number its environments from 0.
  void* mapped = nullptr;
  CUdeviceptr mapped_device = 0;
  const size_t report_bytes = parts.size() * sizeof(ActionError);
  if (!cu_check(cuMemHostAlloc(&mapped, report_bytes, CU_MEMHOSTALLOC_DEVICEMAP), "cuMemHostAlloc", error)) return std::nullopt;
  b.action_error_ = static_cast<ActionError*>(mapped);
  for (size_t k = 0; k < parts.size(); ++k) b.action_error_[k] = ActionError{};
  if (!cu_check(cuMemHostGetDevicePointer(&mapped_device, mapped, 0), "cuMemHostGetDevicePointer", error))
    return std::nullopt;
  auto ptr = [&](size_t off) { return reinterpret_cast<uint8_t*>(b.state_ + off); };
  DeviceEnvs& e = b.envs_;
  e.num_envs = static_cast<int32_t>(total);
  e.segment_stride = stride;
  e.visual_extent = visual_extent;
  e.seeds = reinterpret_cast<const uint64_t*>(ptr(l.seeds));
  e.latent = reinterpret_cast<LatentState*>(ptr(l.latent));
  e.segments = ptr(l.segments);
  e.visual = reinterpret_cast<VisualState*>(ptr(l.visual));
  e.actions = ActionSource{ptr(l.actions), 1, 0, reinterpret_cast<StepCount*>(b.step_counts_),
                           reinterpret_cast<ActionError*>(mapped_device)};
  e.reset_mask = nullptr;
  e.obs = reinterpret_cast<uint8_t*>(b.obs_buf_);
  e.reward = reinterpret_cast<float*>(ptr(l.reward));
  e.terminated = ptr(l.terminated);
  e.truncated = ptr(l.truncated);
  e.info = info_arrays(b.state_, l.info);
  e.final_mask = ptr(l.final_mask);
  e.final_latent = reinterpret_cast<LatentState*>(ptr(l.final_latent));
  e.final_segments = ptr(l.final_segments);
  e.final_visual = reinterpret_cast<VisualState*>(ptr(l.final_visual));
  e.final_obs = reinterpret_cast<uint8_t*>(b.obs_buf_ + n * b.obs_stride_);
  e.final_info = info_arrays(b.state_, l.final_info);
  e.assets = b.parts_.front().envs.assets;
  for (size_t k = 0; k < b.parts_.size(); ++k) {
    Part& p = b.parts_[k];
    const AssetView assets = p.envs.assets;
    const int32_t extent = p.envs.visual_extent;
    p.envs = part_view(e, p.first, p.envs.num_envs, b.obs_stride_);
    p.envs.assets = assets;
    p.envs.visual_extent = extent;
    p.envs.actions.error = reinterpret_cast<ActionError*>(mapped_device) + k;
    p.envs.actions.count = reinterpret_cast<StepCount*>(b.step_counts_) + k;
  }
  b.reset_mask_ = ptr(l.reset_mask);
  b.seeds_.assign(n, 0);
  if (b.parts_.size() > 1 && !b.create_part_streams(error)) return std::nullopt;
  return b;
}

bool DeviceBatch::create_part_streams(std::string* error) {
  if (!cu_check(cuEventCreate(&fork_, CU_EVENT_DISABLE_TIMING), "cuEventCreate", error)) return false;
  for (Part& p : parts_)
    if (!cu_check(cuStreamCreate(&p.stream, CU_STREAM_NON_BLOCKING), "cuStreamCreate", error) ||
        !cu_check(cuEventCreate(&p.stepped, CU_EVENT_DISABLE_TIMING), "cuEventCreate", error))
      return false;
  return true;
}

DeviceBatch::DeviceBatch(DeviceBatch&& o) noexcept
    : envs_(o.envs_),
      parts_(std::move(o.parts_)),
      stream_(o.stream_),
      obs_stride_(o.obs_stride_),
      segment_count_(o.segment_count_),
      state_(o.state_),
      obs_buf_(o.obs_buf_),
      step_counts_(o.step_counts_),
      reset_mask_(o.reset_mask_),
      seeds_(std::move(o.seeds_)),
      action_error_(o.action_error_),
      sample_actions_(o.sample_actions_),
      fork_(o.fork_),
      serial_(o.serial_),
      multiprocessors_(o.multiprocessors_),
      plans_(std::move(o.plans_)) {
  o.parts_.clear();
  o.state_ = o.obs_buf_ = o.step_counts_ = 0;
  o.action_error_ = nullptr;
  o.fork_ = nullptr;
}

DeviceBatch::~DeviceBatch() {
  // Frees fail only once the context is gone at exit, when the memory is released anyway.
  plans_.clear();
  for (CUdeviceptr p : {state_, obs_buf_, step_counts_})
    if (p) cuMemFree(p);
  for (const Part& p : parts_) {
    if (p.assets) cuMemFree(p.assets);
    if (p.stepped) cuEventDestroy(p.stepped);
    if (p.stream) cuStreamDestroy(p.stream);
  }
  if (fork_) cuEventDestroy(fork_);
  if (action_error_) cuMemFreeHost(action_error_);
}

bool DeviceBatch::launch_per_env(CUfunction f, const DeviceEnvs& envs, CUstream stream, std::string* error) {
  if (envs.num_envs == 0) return true;  // a mixture's part of no environments
  DeviceEnvs arg = envs;
  void* args[] = {&arg};
  const unsigned grid = static_cast<unsigned>((envs.num_envs + kPerEnvThreads - 1) / kPerEnvThreads);
  return cu_check(cuLaunchKernel(f, grid, 1, 1, kPerEnvThreads, 1, 1, 0, stream, args, nullptr), "cuLaunchKernel", error);
}

bool DeviceBatch::launch_render(const Part& p, CUstream stream, std::string* error) {
  if (p.envs.num_envs == 0) return true;
  const GroupRow* no_rows = nullptr;  // kage_render of the part's own view
  DeviceEnvs arg = p.envs;
  void* args[] = {&no_rows, &arg};
  const unsigned grid = static_cast<unsigned>((p.envs.num_envs + p.frames_per_block - 1) / p.frames_per_block);
  return cu_check(cuLaunchKernel(p.render, grid, 1, 1, static_cast<unsigned>(p.render_threads),
                              1, 1, static_cast<unsigned>(p.render_smem), stream, args, nullptr),
               "cuLaunchKernel", error);
}

bool DeviceBatch::launch_renders(std::string* error) {
  for (const Part& p : parts_)
    if (!launch_render(p, stream_, error)) return false;
  return true;
}

bool DeviceBatch::reset(const uint64_t* seeds, const uint8_t* mask, std::string* error) {
  const size_t n = static_cast<size_t>(envs_.num_envs);
  // Environments outside the mask keep their seeds: the device array is rewritten whole.
  for (size_t i = 0; i < n; ++i)
    if (!mask || mask[i]) seeds_[i] = seeds[i];
  const CUdeviceptr d = reinterpret_cast<CUdeviceptr>(envs_.seeds);
  if (!cu_check(cuMemcpyHtoDAsync(d, seeds_.data(), sizeof(uint64_t) * n, stream_), "cuMemcpyHtoDAsync(seeds)", error))
    return false;
  if (mask && !cu_check(cuMemcpyHtoDAsync(reinterpret_cast<CUdeviceptr>(reset_mask_), mask, n, stream_),
                     "cuMemcpyHtoDAsync(reset mask)", error))
    return false;
  for (const Part& p : parts_) {
    DeviceEnvs v = p.envs;
    v.reset_mask = mask ? reset_mask_ + p.first : nullptr;
    if (!launch_per_env(p.reset, v, stream_, error)) return false;
  }
  return launch_renders(error);
}

bool DeviceBatch::launch_step(const ActionSource& source, bool render, std::string* error) {
  const int64_t element = source.is_int64 ? sizeof(int64_t) : sizeof(int32_t);
  // One part steps on stream_; a mixture's parts each on their own stream, forked from stream_ and joined
  // back, since a part's few environments leave the GPU mostly idle while its kernels run.
  const bool fork = parts_.size() > 1;
  if (fork && !cu_check(cuEventRecord(fork_, stream_), "cuEventRecord", error)) return false;
  for (const Part& p : parts_) {
    DeviceEnvs v = p.envs;
    v.actions = source;
    v.actions.data = static_cast<const uint8_t*>(source.data) + p.first * source.stride * element;
    v.actions.count = p.envs.actions.count;
    v.actions.error = p.envs.actions.error;
    const CUstream stream = fork ? p.stream : stream_;
    if ((fork && !cu_check(cuStreamWaitEvent(stream, fork_, 0), "cuStreamWaitEvent", error)) ||
        !launch_per_env(p.step, v, stream, error) || (render && !launch_render(p, stream, error)))
      return false;
    if (fork && !(cu_check(cuEventRecord(p.stepped, stream), "cuEventRecord", error) &&
                  cu_check(cuStreamWaitEvent(stream_, p.stepped, 0), "cuStreamWaitEvent", error)))
      return false;
  }
  return true;
}

bool DeviceBatch::step(const int32_t* actions, std::string* error) {
  return cu_check(cuMemcpyHtoDAsync(this->actions(), actions, sizeof(int32_t) * envs_.num_envs, stream_),
               "cuMemcpyHtoDAsync(actions)", error) &&
         step_device_actions(error);
}

bool DeviceBatch::step(const DeviceActions& a, std::string* error) {
  return launch_step(ActionSource{reinterpret_cast<const void*>(a.data), a.stride, a.is_int64 ? 1 : 0, nullptr,
                                  nullptr},
                     true, error);
}

bool DeviceBatch::step_device_actions(std::string* error) { return launch_step(envs_.actions, true, error); }

bool DeviceBatch::step_no_render(std::string* error) { return launch_step(envs_.actions, false, error); }

std::optional<ActionError> DeviceBatch::take_action_error() {
  // The earliest step's report (the first part's among those of one step), with the part's first
  // environment added; the other complete reports are forgotten with it, as one part's later ones are.
  std::optional<ActionError> first;
  for (size_t k = 0; k < parts_.size(); ++k) {
    volatile ActionError* e = action_error_ + k;
    if (e->state != 2u) continue;
    const ActionError reported{2u, e->env + parts_[k].first, e->value, e->step};
    e->state = 0u;
    if (!first || reported.step < first->step) first = reported;
  }
  return first;
}

bool DeviceBatch::synchronize(std::string* error) const {
  return cu_check(cuStreamSynchronize(stream_), "cuStreamSynchronize", error);
}

bool DeviceBatch::download_obs(uint8_t* host, std::string* error) const {
  return cu_check(cuMemcpyDtoHAsync(host, obs(), obs_stride_ * static_cast<size_t>(envs_.num_envs), stream_),
               "cuMemcpyDtoHAsync(obs)", error) &&
         synchronize(error);
}

bool DeviceBatch::sample_actions(uint64_t seed, uint32_t t, std::string* error) {
  CUdeviceptr actions = this->actions();
  int32_t n = envs_.num_envs;
  void* args[] = {&actions, &n, &seed, &t};
  const unsigned grid = static_cast<unsigned>((n + kPerEnvThreads - 1) / kPerEnvThreads);
  return cu_check(cuLaunchKernel(sample_actions_, grid, 1, 1, kPerEnvThreads, 1, 1, 0, stream_, args, nullptr),
               "cuLaunchKernel(kage_sample_actions)", error);
}

namespace {

/// One section of a saved state: `bytes_per_env` bytes per environment at `device` (rows `pitch`
/// bytes apart) and at offset `blob` of the saved state (rows packed).
struct StateSection {
  CUdeviceptr device;
  size_t blob;
  size_t bytes_per_env;
  size_t pitch;
};

std::vector<StateSection> state_sections(const DeviceEnvs& e, const BatchStateLayout& l, size_t segment_bytes) {
  auto at = [](const void* p) { return reinterpret_cast<CUdeviceptr>(p); };
  std::vector<StateSection> s = {
      {at(e.seeds), l.seeds, sizeof(uint64_t), sizeof(uint64_t)},
      {at(e.latent), l.latent, sizeof(LatentState), sizeof(LatentState)},
      {at(e.segments), l.segments, segment_bytes, static_cast<size_t>(e.segment_stride)},
      {at(e.visual), l.visual, sizeof(VisualState), sizeof(VisualState)},
      {at(e.reward), l.reward, sizeof(float), sizeof(float)},
      {at(e.terminated), l.terminated, 1, 1},
      {at(e.truncated), l.truncated, 1, 1},
  };
  int i = 0;
#define KAGE_INFO_FIELD(Enum, member, name, ctype, dtype, doc, value) \
  s.push_back({at(e.info.member), l.info[i++], sizeof(ctype), sizeof(ctype)});
#include "runtime/info_fields.def"
#undef KAGE_INFO_FIELD
  return s;
}

}  // namespace

bool DeviceBatch::copy_state(uint8_t* blob, bool to_host, std::string* error) const {
  const size_t n = static_cast<size_t>(envs_.num_envs);
  const BatchStateLayout l(n, static_cast<size_t>(segment_count_));
  for (const StateSection& s : state_sections(envs_, l, static_cast<size_t>(segment_count_))) {
    CUDA_MEMCPY2D c{};
    if (to_host) {
      c.srcMemoryType = CU_MEMORYTYPE_DEVICE;
      c.srcDevice = s.device;
      c.srcPitch = s.pitch;
      c.dstMemoryType = CU_MEMORYTYPE_HOST;
      c.dstHost = blob + s.blob;
      c.dstPitch = s.bytes_per_env;
    } else {
      c.srcMemoryType = CU_MEMORYTYPE_HOST;
      c.srcHost = blob + s.blob;
      c.srcPitch = s.bytes_per_env;
      c.dstMemoryType = CU_MEMORYTYPE_DEVICE;
      c.dstDevice = s.device;
      c.dstPitch = s.pitch;
    }
    c.WidthInBytes = s.bytes_per_env;
    c.Height = n;
    if (!cu_check(cuMemcpy2DAsync(&c, stream_), "cuMemcpy2DAsync(state)", error)) return false;
  }
  return true;
}

bool DeviceBatch::save_state(const std::string& spec_hash, std::vector<uint8_t>* out, std::string* error) const {
  out->assign(BatchStateLayout(static_cast<size_t>(envs_.num_envs), static_cast<size_t>(segment_count_)).total, 0);
  write_batch_state_header(out->data(), envs_.num_envs, segment_count_, spec_hash);
  return copy_state(out->data(), true, error) && synchronize(error);
}

bool DeviceBatch::load_state(const uint8_t* data, size_t size, const std::string& spec_hash, std::string* error) {
  const std::string problem = check_batch_state(data, size, envs_.num_envs, segment_count_, spec_hash);
  if (!problem.empty()) {
    *error = problem;
    return false;
  }
  // The blob is read, never written: copy_state takes a mutable pointer for both directions.
  if (!copy_state(const_cast<uint8_t*>(data), false, error)) return false;
  const size_t n = static_cast<size_t>(envs_.num_envs);
  const BatchStateLayout l(n, static_cast<size_t>(segment_count_));
  std::memcpy(seeds_.data(), data + l.seeds, n * sizeof(uint64_t));
  // Frames are a pure function of the state: render them again instead of saving them. The copies
  // read pageable host memory, so they are complete when this returns.
  return cu_check(cuMemsetD8Async(reinterpret_cast<CUdeviceptr>(envs_.final_mask), 0, n, stream_),
               "cuMemsetD8Async(final mask)", error) &&
         launch_renders(error) && synchronize(error);
}

}  // namespace kage
