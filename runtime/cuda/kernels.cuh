// CUDA kernels of one configuration: reset, step (with autoreset, one thread per environment), render,
// and random actions for benchmarks. Templates over a config type `Cfg` with `static constexpr
// LatentParams latent()` and `static constexpr VisualParams visual()` (a generated config: every
// parameter folds, and every stage's plain `if` on a parameter sees a constant, so disabled stages
// vanish) or over DynamicCfg (parameters read from __constant__ memory, one build for every config).
// Compiles under nvcc and NVRTC: the semantics headers and these files use no host headers.
//
// A step with observations is the step kernel, then the render kernel: the step is serial per
// environment and runs 32 environments per warp; the render is parallel per pixel and runs one frame
// per block at a time. (A fused kernel that stepped inside the rendering block was slower: its serial
// step and per-frame setup held up the frame's pixels.) Observations are [N][H][W][3] uint8. Frames
// without neighbourhood filters take the register path (register_path.cuh; up to 8 frames per block,
// one after the other); frames with blur, sharpen or pixelate take the frame-pass path, a
// float32 frame in shared memory (frame_pass.cuh).
#pragma once

#include "runtime/cuda/frame_pass.cuh"
#include "runtime/cuda/kernel_step.cuh"
#include "runtime/cuda/register_path.cuh"

namespace kage {

/// Renders the state held in `sh` into `out` with the threads of `Group`: frame setup by its first
/// thread, the column table from the layout at `segments`, then the pixels. Entered by every thread of
/// the group; the state in `sh` must be complete. `frame` is the float frame of the frame-pass path.
template <class Cfg, class Group, class Slot>
__device__ __forceinline__ void group_render_frame(const DeviceEnvs& e, int32_t env, Slot& sh, const uint8_t* segments,
                                                   float* frame, uint8_t* out) {
  const LatentParams& lp = ParamsOf<Cfg>::latent();
  const VisualParams& vp = ParamsOf<Cfg>::visual();
  if (Group::rank() == 0) {
    FrameSetup& fs = sh.setup;
    fs.agent = AgentView{sh.latent.x, sh.latent.y, sh.latent.camera_x};
    agent_frame_constants(vp, fs.agent, sh.visual, fs.f);
    fs.episode_preset = episode_preset(vp, sh.visual);
    fs.agent_box = agent_box(vp, e.assets, sh.visual, fs.f);
    fs.plain = !needs_frame_passes(vp) && compose_layout_only(vp, e.assets) && fs.episode_preset == Preset::kNone &&
               filters_identity(vp) && !vp.point_light_enabled;
    for (int32_t i = 0; i < 9; ++i) fs.jitter[i] = (i % 4 == 0) ? 1.0f : 0.0f;
    if (vp.color_jitter_std > 0.0f || vp.gaussian_noise_std > 0.0f || vp.poisson_noise_scale > 0.0f) {
      fs.keys = filter_keys(device_episode_key(e, env, sh.latent.episode), static_cast<uint32_t>(sh.latent.t));
      if (vp.color_jitter_std > 0.0f) jitter_matrix(fs.keys.jitter, vp.color_jitter_std, fs.jitter);
    }
  }
  // The distractors' per-frame shape values (up to 20 sin/cos each) beside the first thread: on the
  // block's second warp (on the first warp's other lanes when the block is a single warp).
  const int32_t dist_first = Group::size() > 32 ? 32 : 1;
  if (Group::rank() >= dist_first)
    for (int32_t i = Group::rank() - dist_first; i < distractor_slots(vp); i += Group::size() - dist_first)
      sh.setup.f.dist[i] = distractor_frame(vp, sh.visual, i);
  Group::sync();
  const int32_t cam = sh.setup.f.cam;
  const LayoutView layout{segments};
  for (int32_t c = Group::rank(); c < vp.W; c += Group::size()) {
    const SolidSpan s = solid_span(lp, layout, clampi(c + cam, 0, lp.length - 1));
    sh.spans[c] = ColumnSpan{static_cast<short>(s.lo), static_cast<short>(s.hi)};
  }
  Group::sync();
  if (sh.setup.plain) {
    for (int32_t g = Group::rank(); g < vp.W / kPixelsPerThread; g += Group::size()) {
      GroupSpan gs{kShortMax, kShortMin, kShortMax, kShortMin};
      for (int32_t j = 0; j < kPixelsPerThread; ++j) {
        const ColumnSpan s = sh.spans[g * kPixelsPerThread + j];
        gs.lo_min = s.lo < gs.lo_min ? s.lo : gs.lo_min;
        gs.lo_max = s.lo > gs.lo_max ? s.lo : gs.lo_max;
        gs.hi_min = s.hi < gs.hi_min ? s.hi : gs.hi_min;
        gs.hi_max = s.hi > gs.hi_max ? s.hi : gs.hi_max;
      }
      sh.groups[g] = gs;
    }
    Group::sync();
  }
  const SpanSolid solid{sh.spans, cam, lp.height_px};
  if (needs_frame_passes(vp)) return render_frame_pass_path<Cfg>(e.assets, sh, solid, frame, out);
  render_register_path<Cfg, Group>(e.assets, sh, solid, out);
}

/// The frame of environment env in `frames` (obs or final_obs).
template <class Cfg>
__device__ __forceinline__ uint8_t* frame_of(uint8_t* frames, int32_t env) {
  const VisualParams& vp = ParamsOf<Cfg>::visual();
  return frames + static_cast<int64_t>(env) * vp.H * vp.W * 3;
}

/// Launch bounds of the render kernel: at most a frame-pass block; a config that certainly takes the
/// register path (no neighbourhood filter, no preset: tested on constants, as needs_frame_passes is
/// not constexpr) asks for two such blocks' worth, i.e. four 256-thread blocks per SM (64 registers).
template <class Cfg>
struct RenderBounds {
  static constexpr VisualParams kVisual = Cfg::visual();
  static constexpr bool kMayPass = kVisual.blur_sigma > 0.0f || kVisual.sharpen_amount > 0.0f ||
                                   kVisual.pixelate_factor > 1 || kVisual.pop_filter != Preset::kNone ||
                                   kVisual.pop_filter_count > 0;
  static constexpr int32_t kThreads = kFramePassMaxThreads;
  static constexpr int32_t kMinBlocks = kMayPass ? 1 : 2;
};
template <>
struct RenderBounds<DynamicCfg> {
  static constexpr int32_t kThreads = kFramePassMaxThreads;
  static constexpr int32_t kMinBlocks = 1;
};

// ---- kernel bodies (the extern "C" entry points are emitted by KAGE_INSTANTIATE_KERNELS) ----

/// Reset: one thread per environment starts episode 0 where reset_mask says so (every environment when
/// it is null); no environment is final afterwards. No rendering (see render_body).
template <class Cfg>
__device__ __forceinline__ void reset_body(const DeviceEnvs& e) {
  const int32_t env = static_cast<int32_t>(blockIdx.x * blockDim.x + threadIdx.x);
  if (env >= e.num_envs) return;
  e.final_mask[env] = 0;
  if (e.reset_mask && !e.reset_mask[env]) return;
  LatentState ls;
  episode_reset(ParamsOf<Cfg>{}, e.assets, device_episode_key(e, env, 0), 0,
                e.segments + static_cast<int64_t>(env) * e.segment_stride, ls, &e.visual[env]);
  e.latent[env] = ls;
  record_outcome(e, env, ls, StepOutcome{});
}

/// Step with autoreset: one thread per environment; the render kernel then draws the observations
/// (run alone, the state-only measurement of the original's own benchmark).
template <class Cfg>
__device__ __forceinline__ void step_body(const DeviceEnvs& e) {
  const int32_t env = static_cast<int32_t>(blockIdx.x * blockDim.x + threadIdx.x);
  if (env >= e.num_envs) return;
  LatentState ls = e.latent[env];
  // Both addresses before the action's load, the order the PTX had before the episode driver.
  uint8_t* segments = e.segments + static_cast<int64_t>(env) * e.segment_stride;
  VisualState* vs = &e.visual[env];
  DeviceStepOut out{e, env};
  episode_step(ParamsOf<Cfg>{}, e.assets, load_action(e.actions, env), segments, ls, vs, out);
  e.latent[env] = ls;
}

/// Render: the current states (after reset or step), and the final states of environments whose episode
/// the step ended. Block b renders environments [b * k, b * k + k)
/// one after the other with the whole block, k = ceil(num_envs / gridDim) (the launch picks the grid
/// from frames_per_block); the layout is read from global memory (only its column table is per pixel).
template <class Cfg>
__device__ __forceinline__ void render_body(const DeviceEnvs& e, BlockShared& sh, float* frame) {
  const int32_t k = (e.num_envs + static_cast<int32_t>(gridDim.x) - 1) / static_cast<int32_t>(gridDim.x);
  const int32_t first = static_cast<int32_t>(blockIdx.x) * k;
  const int32_t last = first + k < e.num_envs ? first + k : e.num_envs;
  for (int32_t env = first; env < last; ++env) {
    group_copy_words<BlockGroup>(&sh.latent, e.latent + env, static_cast<int32_t>(sizeof(LatentState)));
    group_copy_words<BlockGroup>(&sh.visual, e.visual + env, e.visual_extent);
    __syncthreads();
    group_render_frame<Cfg, BlockGroup>(e, env, sh, e.segments + static_cast<int64_t>(env) * e.segment_stride, frame,
                                  frame_of<Cfg>(e.obs, env));
    __syncthreads();
    if (e.final_mask[env]) {
      // The finished episode's last frame, from the state and layout the step kernel kept.
      group_copy_words<BlockGroup>(&sh.latent, e.final_latent + env, static_cast<int32_t>(sizeof(LatentState)));
      group_copy_words<BlockGroup>(&sh.visual, e.final_visual + env, e.visual_extent);
      __syncthreads();
      group_render_frame<Cfg, BlockGroup>(e, env, sh, e.final_segments + static_cast<int64_t>(env) * e.segment_stride,
                                    frame, frame_of<Cfg>(e.final_obs, env));
      __syncthreads();
    }
  }
}

/// A grouped step's row (blockIdx.y): copies the row into shared memory, points its actions at the batch's row
/// of the call's array, then steps as step_body does and counts the launch in the part's own StepCount.
template <class Cfg>
__device__ __forceinline__ void step_row_body(const GroupRow* rows, const ActionRows& a, GroupRow& row) {
  group_copy_words<BlockGroup>(&row, rows + blockIdx.y, static_cast<int32_t>(sizeof(GroupRow)));
  __syncthreads();
  if (threadIdx.x == 0) {
    const int64_t element = a.is_int64 ? 8 : 4;
    const int64_t at = row.batch * a.row_stride + row.first * a.stride;
    row.envs.actions.data = static_cast<const uint8_t*>(a.data) + at * element;
    row.envs.actions.stride = a.stride;
    row.envs.actions.is_int64 = a.is_int64;
  }
  __syncthreads();
  step_body<Cfg>(row.envs);
  count_step(row.envs.actions, row.envs.num_envs);
}

/// The render kernel's body: render_body over `one`, or, when `rows` is not null, over row blockIdx.y of a
/// grouped launch; either view is copied into shared memory first. One entry point serves both, since each
/// inlined copy of render_body costs as much NVRTC and nvcc time as the rest of the module.
template <class Cfg>
__device__ __forceinline__ void render_entry_body(const GroupRow* rows, const DeviceEnvs& one, GroupRow& row,
                                                  BlockShared& sh, float* frame) {
  if (rows)
    group_copy_words<BlockGroup>(&row, rows + blockIdx.y, static_cast<int32_t>(sizeof(GroupRow)));
  else if (threadIdx.x == 0)
    row.envs = one;
  __syncthreads();
  render_body<Cfg>(row.envs, sh, frame);
}

/// Uniform random actions in [0, 8) for step t (benchmarks), from their own key.
__device__ __forceinline__ void sample_actions_body(int32_t* actions, int32_t n, uint64_t seed, uint32_t t) {
  const int32_t i = static_cast<int32_t>(blockIdx.x * blockDim.x + threadIdx.x);
  if (i < n) actions[i] = benchmark_action(seed, t, static_cast<uint32_t>(i));
}

}  // namespace kage

/// Emits the entry points of one config with fixed unmangled names, so that a loader finds them in any
/// compiled config: kage_reset and kage_step (one thread per environment; any block size); kage_step_rows,
/// whose block row y steps rows[y] (GroupRow): several batches' parts of this config in one launch;
/// kage_render (render_threads() threads and render_dynamic_smem_bytes() bytes of dynamic shared memory
/// per block, ceil(num_envs / gridDim.x) environments per block) of `one`, or with `rows` not null of
/// rows[blockIdx.y]; kage_sample_actions. Use once per module.
#define KAGE_INSTANTIATE_KERNELS(CFG)                                                                     \
  extern "C" __global__ void kage_reset(const kage::DeviceEnvs e) { kage::reset_body<CFG>(e); }           \
  extern "C" __global__ void kage_step(const kage::DeviceEnvs e) {                                        \
    kage::step_body<CFG>(e);                                                                              \
    kage::count_step(e.actions, e.num_envs);                                                              \
  }                                                                                                       \
  extern "C" __global__ void kage_step_rows(const kage::GroupRow* rows, const kage::ActionRows actions) {   \
    __shared__ kage::GroupRow row;                                                                        \
    kage::step_row_body<CFG>(rows, actions, row);                                                         \
  }                                                                                                       \
  extern "C" __global__ void __launch_bounds__(kage::RenderBounds<CFG>::kThreads,                          \
                                               kage::RenderBounds<CFG>::kMinBlocks)                       \
      kage_render(const kage::GroupRow* rows, const kage::DeviceEnvs one) {                               \
    __shared__ kage::BlockShared sh;                                                                      \
    __shared__ kage::GroupRow row;                                                                        \
    extern __shared__ float4 kage_frame[];                                                                \
    kage::render_entry_body<CFG>(rows, one, row, sh, reinterpret_cast<float*>(kage_frame));               \
  }                                                                                                       \
  extern "C" __global__ void kage_sample_actions(int32_t* actions, int32_t n, uint64_t seed, uint32_t t) {  \
    kage::sample_actions_body(actions, n, seed, t);                                                       \
  }
