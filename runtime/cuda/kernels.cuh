// CUDA kernels of one configuration: reset, fused step + autoreset + render, step without rendering,
// and render only. Templates over a config type `Cfg` with `static constexpr LatentParams latent()` and
// `static constexpr VisualParams visual()` (a generated config: every parameter folds, and every stage's
// plain `if` on a parameter sees a constant, so disabled stages vanish) or over DynamicCfg (parameters
// read from __constant__ memory, one build for every config). Compiles under nvcc and NVRTC: the
// semantics headers and this file use no host headers.
//
// Observations are [N][H][W][3] uint8. One block renders one frame: thread 0 steps the environment
// in shared memory while nothing else of the block runs, then every thread composes its pixels in
// registers; neighbourhood filters exchange pixels through a float32 frame in shared memory.
#pragma once

#include "runtime/cuda/device_envs.h"
#include "runtime/cuda/render_plan.h"
#include "runtime/kage_hd.h"
#include "runtime/latent/latent_step.h"
#include "runtime/rng.h"
#include "runtime/visual/compose.h"
#include "runtime/visual/filters.h"
#include "runtime/visual/lights.h"
#include "runtime/visual/visual_update.h"

namespace kage {

// ---- parameters ----

/// A specialized config's parameters as device constants with initializers: loads at constant offsets
/// fold, indexed reads (palettes, shape lists) read the table from memory.
template <class Cfg>
__device__ constexpr LatentParams kLatentOf = Cfg::latent();
template <class Cfg>
__device__ constexpr VisualParams kVisualOf = Cfg::visual();

/// The parameters a kernel reads, as references.
template <class Cfg>
struct ParamsOf {
  static __device__ __forceinline__ const LatentParams& latent() { return kLatentOf<Cfg>; }
  static __device__ __forceinline__ const VisualParams& visual() { return kVisualOf<Cfg>; }
};

}  // namespace kage

/// The generic build's parameters, uploaded by the host (DeviceBatch) before the first launch.
extern "C" {
__constant__ kage::LatentParams kage_dynamic_latent;
__constant__ kage::VisualParams kage_dynamic_visual;
}

namespace kage {

/// The config type of the generic build.
struct DynamicCfg {};

template <>
struct ParamsOf<DynamicCfg> {
  static __device__ __forceinline__ const LatentParams& latent() { return kage_dynamic_latent; }
  static __device__ __forceinline__ const VisualParams& visual() { return kage_dynamic_visual; }
};

// ---- stepping ----

/// The episode key of environment `env` in episode `episode` (as CpuBatch::episode_key).
__device__ __forceinline__ Key device_episode_key(const DeviceEnvs& e, int32_t env, uint32_t episode) {
  return fold(seed_key(e.seeds[env]), episode);
}

/// Starts `episode` of one environment: layout, latent and visual state (spec 4.2).
__device__ __forceinline__ void device_reset_env(const LatentParams& lp, const VisualParams& vp, const AssetView& assets,
                                          Key key, uint32_t episode, uint8_t* segments, LatentState& ls,
                                          VisualState& vs) {
  latent_reset(lp, key, episode, segments, ls);
  const LayoutView layout{segments};
  visual_reset(vp, assets, key, [&](int32_t c) { return ground_top(lp, layout, c); }, vs);
}

/// Writes reward, flags and info of one step (or zeros after an explicit reset).
__device__ __forceinline__ void record_outcome(const DeviceEnvs& e, int32_t env, const LatentState& s,
                                               const StepOutcome& o) {
  e.reward[env] = o.reward;
  e.terminated[env] = o.terminated;
  e.truncated[env] = o.truncated;
  StepInfo info;
  info.x = s.x;
  info.y = s.y;
  info.vx = s.vx;
  info.vy = s.vy;
  info.passed_distance = o.passed_distance;
  info.progress = o.progress;
  info.episode_return = s.episode_return;
  info.jump_count = s.jump_count;
  info.timestep = s.t;
  info.success = o.success;
  info.success_once = s.success_once;
  info.pad[0] = info.pad[1] = 0;
  e.info[env] = info;
}

/// One step of one environment with automatic reset (the order of CpuBatch::step): the latent step,
/// its outcome, then either the next episode's reset or the visual step (spec 5.7, 5.9).
__device__ __forceinline__ void device_step_env(const LatentParams& lp, const VisualParams& vp, const DeviceEnvs& e,
                                         int32_t env, uint8_t* segments, LatentState& ls, VisualState& vs) {
  const StepOutcome o = latent_step(lp, LayoutView{segments}, ls, e.actions[env]);
  record_outcome(e, env, ls, o);
  if (o.terminated || o.truncated) {
    const uint32_t next = ls.episode + 1;
    device_reset_env(lp, vp, e.assets, device_episode_key(e, env, next), next, segments, ls, vs);
  } else {
    visual_step(vp, e.assets, device_episode_key(e, env, ls.episode), static_cast<uint32_t>(ls.t), ls.vx, vs);
  }
}

// ---- rendering ----

/// Solid rows [lo, hi) of one screen column, packed as two 16-bit values.
struct ColumnSpan {
  short lo;
  short hi;
};

/// Values shared by every pixel of one frame, computed once per block.
struct FrameSetup {
  FrameConstants f;
  AgentView agent;
  Preset episode_preset;
  FilterKeys keys;
  float jitter[9];
  ScreenBox agent_box;  ///< outside it the agent leaves pixels unchanged
  bool plain;           ///< every pixel outside agent_box is a function of solid() alone (register path)
};

/// The extremes of the solid spans of one 16-column group: a row outside [lo_min, hi_max) is empty in
/// every column of the group and a row in [lo_max, hi_min) solid in every column.
struct GroupSpan {
  short lo_min, lo_max, hi_min, hi_max;
};

/// A layout mask that is the same everywhere: composes the two colours of a plain run.
struct ConstSolid {
  bool value;
  __device__ __forceinline__ bool operator()(int32_t, int32_t) const { return value; }
};

/// The layout mask at screen row r and world column wc = c + cam through the block's column table;
/// the table was built with the clamps of solid(), and r is clamped the same way.
struct SpanSolid {
  const ColumnSpan* spans;
  int32_t cam;
  int32_t height_px;
  __device__ __forceinline__ bool operator()(int32_t r, int32_t wc) const {
    const ColumnSpan s = spans[wc - cam];
    const int32_t rr = clampi(r, 0, height_px - 1);
    return rr >= s.lo && rr < s.hi;
  }
};

constexpr short kShortMax = 32767;
constexpr short kShortMin = -32768;

/// Shared memory of a rendering block besides the optional float frame.
struct BlockShared {
  LatentState latent;
  FrameSetup setup;
  alignas(16) VisualState visual;
  alignas(16) uint8_t segments[kMaxLayoutBytes];
  ColumnSpan spans[kMaxScreenWidth];
  GroupSpan groups[kMaxScreenWidth / kPixelsPerThread];
};

/// Copies `bytes` (a multiple of 4) between two 4-byte aligned buffers with the whole block.
__device__ __forceinline__ void block_copy_words(void* dst, const void* src, int32_t bytes) {
  uint32_t* d = static_cast<uint32_t*>(dst);
  const uint32_t* s = static_cast<const uint32_t*>(src);
  for (int32_t i = static_cast<int32_t>(threadIdx.x); i < bytes / 4; i += static_cast<int32_t>(blockDim.x)) d[i] = s[i];
}

/// Per-pixel stages of the register path after composition: the episode preset (7.1 A), the main chain
/// without neighbourhood passes (B), the point lights (8.2); the same arithmetic as render_frame.
template <class Cfg>
__device__ __forceinline__ void pixel_stages(const VisualState& vs, const FrameSetup& fs, int32_t r, int32_t c,
                                             uint8_t* rgb) {
  const VisualParams& vp = ParamsOf<Cfg>::visual();
  if (fs.episode_preset != Preset::kNone) {
    float f[3] = {static_cast<float>(rgb[0]), static_cast<float>(rgb[1]), static_cast<float>(rgb[2])};
    preset_pixel_op(fs.episode_preset, f, r, c, vp.H, vp.W);
    for (int32_t ch = 0; ch < 3; ++ch) rgb[ch] = to_u8_clipped(f[ch]);
  }
  if (!filters_identity(vp)) {
    float f[3] = {static_cast<float>(rgb[0]), static_cast<float>(rgb[1]), static_cast<float>(rgb[2])};
    preset_pixel_op(vp.pop_filter, f, r, c, vp.H, vp.W);
    chain_head_pixel(vp, fs.jitter, f);
    chain_tail_pixel(vp, fs.keys, r, c, f);
    for (int32_t ch = 0; ch < 3; ++ch) rgb[ch] = to_u8_clipped(f[ch]);
  }
  if (vp.point_light_enabled) light_pixel(vp, vs, r, c, rgb);
}

/// The composited, filtered and lit pixel (r, c) of the register path.
template <class Cfg, class SolidFn>
__device__ __forceinline__ void register_pixel(const AssetView& assets, const BlockShared& sh, const SolidFn& solid,
                                               int32_t r, int32_t c, uint8_t* rgb) {
  const VisualParams& vp = ParamsOf<Cfg>::visual();
  compose_pixel(vp, assets, sh.setup.agent, solid, sh.visual, sh.setup.f, r, c, rgb);
  pixel_stages<Cfg>(sh.visual, sh.setup, r, c, rgb);
}

/// A pixel as one word: r | g << 8 | b << 16.
__device__ __forceinline__ uint32_t pack_rgb(const uint8_t* rgb) {
  return static_cast<uint32_t>(rgb[0]) | (static_cast<uint32_t>(rgb[1]) << 8) | (static_cast<uint32_t>(rgb[2]) << 16);
}

/// Four packed pixels (12 bytes) as three words: p0 p0 p0 p1 | p1 p1 p2 p2 | p2 p3 p3 p3.
__device__ __forceinline__ void pack_quad(uint32_t a, uint32_t b, uint32_t c, uint32_t d, uint32_t* w) {
  w[0] = a | (b << 24);
  w[1] = (b >> 8) | (c << 16);
  w[2] = (c >> 16) | (d << 8);
}

/// The pixel (r, c) of a plain run (outside the agent box) with the layout mask fixed to `solid`.
template <class Cfg>
__device__ __forceinline__ uint32_t plain_pixel(const AssetView& assets, const BlockShared& sh, bool solid, int32_t r,
                                                int32_t c) {
  uint8_t rgb[3];
  register_pixel<Cfg>(assets, sh, ConstSolid{solid}, r, c, rgb);
  return pack_rgb(rgb);
}

/// Register path: each thread renders runs of 16 pixels of one row and stores each as three 16-byte
/// words (rows whose width is not a multiple of 16 are stored byte by byte). A plain run (nothing but
/// the background and the layout, see compose_layout_only) composes one pixel per layout colour and
/// selects per pixel through the column spans, or, when the group's span extremes show that the row
/// is all solid or all empty, stores one colour; this takes simplest from ~75 instructions per pixel
/// to a few. Other runs compose every pixel, four at a time into three words.
template <class Cfg>
__device__ __forceinline__ void render_register_path(const AssetView& assets, const BlockShared& sh,
                                                     const SpanSolid& solid, uint8_t* out) {
  const VisualParams& vp = ParamsOf<Cfg>::visual();
  if (register_path_vectorized(vp)) {
    const FrameSetup& fs = sh.setup;
    const bool plain = fs.plain;
    const ScreenBox box = fs.agent_box;
    const int32_t runs_per_row = vp.W / kPixelsPerThread;
    for (int32_t run = static_cast<int32_t>(threadIdx.x); run < vp.H * runs_per_row;
         run += static_cast<int32_t>(blockDim.x)) {
      const int32_t r = run / runs_per_row;
      const int32_t g = run - r * runs_per_row;
      const int32_t c0 = g * kPixelsPerThread;
      uint8_t* dst = out + (r * vp.W + c0) * 3;
      const bool agent_run = r >= box.y0 && r <= box.y1 && c0 <= box.x1 && c0 + kPixelsPerThread - 1 >= box.x0;
      if (plain && !agent_run) {
        const GroupSpan gs = sh.groups[g];
        const int32_t rr = clampi(r, 0, solid.height_px - 1);
        const bool none = rr < gs.lo_min || rr >= gs.hi_max;
        const bool all = rr >= gs.lo_max && rr < gs.hi_min;
        uint32_t w[12];
        if (none || all) {
          const uint32_t p = plain_pixel<Cfg>(assets, sh, all, r, c0);
          pack_quad(p, p, p, p, w);
#pragma unroll
          for (int32_t q = 1; q < 4; ++q) w[3 * q] = w[0], w[3 * q + 1] = w[1], w[3 * q + 2] = w[2];
        } else {
          const uint32_t on = plain_pixel<Cfg>(assets, sh, true, r, c0);
          const uint32_t off = plain_pixel<Cfg>(assets, sh, false, r, c0);
          uint32_t px[kPixelsPerThread];
#pragma unroll
          for (int32_t j = 0; j < kPixelsPerThread; ++j) px[j] = solid(r, c0 + j + solid.cam) ? on : off;
#pragma unroll
          for (int32_t q = 0; q < 4; ++q) pack_quad(px[4 * q], px[4 * q + 1], px[4 * q + 2], px[4 * q + 3], w + 3 * q);
        }
        uint4* d4 = reinterpret_cast<uint4*>(dst);
        d4[0] = make_uint4(w[0], w[1], w[2], w[3]);
        d4[1] = make_uint4(w[4], w[5], w[6], w[7]);
        d4[2] = make_uint4(w[8], w[9], w[10], w[11]);
      } else {
        // Four pixels at a time (three 4-byte stores): the whole chain is inlined four times, not 16.
#pragma unroll 1
        for (int32_t q = 0; q < 4; ++q) {
          uint32_t px[4];
#pragma unroll
          for (int32_t k = 0; k < 4; ++k) {
            uint8_t rgb[3];
            register_pixel<Cfg>(assets, sh, solid, r, c0 + 4 * q + k, rgb);
            px[k] = pack_rgb(rgb);
          }
          uint32_t w[3];
          pack_quad(px[0], px[1], px[2], px[3], w);
          uint32_t* d = reinterpret_cast<uint32_t*>(dst + 12 * q);
          d[0] = w[0];
          d[1] = w[1];
          d[2] = w[2];
        }
      }
    }
  } else {
    for (int32_t i = static_cast<int32_t>(threadIdx.x); i < vp.H * vp.W; i += static_cast<int32_t>(blockDim.x)) {
      uint8_t rgb[3];
      register_pixel<Cfg>(assets, sh, solid, i / vp.W, i % vp.W, rgb);
      for (int32_t ch = 0; ch < 3; ++ch) out[i * 3 + ch] = rgb[ch];
    }
  }
}

/// Frame-pass path: the frame lives in shared memory as float32 (H x W x 3); thread t owns pixels
/// t, t + blockDim, ... (at most 16). Per-pixel stages update the thread's own pixels in place (no
/// barrier between them); a neighbourhood pass waits until every thread has finished its pixels,
/// computes the owned pixels' new values into registers, waits until every thread has read the frame,
/// writes them, and waits again.
template <class Cfg>
struct FramePass {
  float* frame;

  __device__ __forceinline__ static int32_t pixel(int32_t k) {
    return static_cast<int32_t>(threadIdx.x) + k * static_cast<int32_t>(blockDim.x);
  }
  __device__ __forceinline__ static bool owned(int32_t k) {
    const VisualParams& vp = ParamsOf<Cfg>::visual();
    return pixel(k) < vp.H * vp.W;
  }

  /// Whether run_banded applies: the block covers whole rows (pixel k of every thread lies in rows
  /// [kB, kB + B), B = blockDim / W >= 1), so a pass reading one row up and down can go band by band.
  __device__ __forceinline__ static bool banded() {
    const VisualParams& vp = ParamsOf<Cfg>::visual();
    return static_cast<int32_t>(blockDim.x) % vp.W == 0;
  }

  /// As run for passes that read at most one row above and below (blur, sharpen): band k is read while
  /// band k - 1 still holds its old values, and band k - 1 is written after the barrier that follows
  /// band k's reads (band k + 1 reads nothing of band k - 1). Each thread holds 2 x 3 values instead of
  /// 16 x 3, which is what made the 1024-thread frame-pass kernel spill.
  template <class Sample>
  __device__ __forceinline__ void run_banded(const Sample& sample) const {
    const VisualParams& vp = ParamsOf<Cfg>::visual();
    __syncthreads();
    float prev[3] = {0.0f, 0.0f, 0.0f};
#pragma unroll 1
    for (int32_t k = 0; k < kFramePassPixelsPerThread; ++k) {
      float cur[3];
      const bool own = owned(k);
      if (own) {
        const int32_t i = pixel(k);
#pragma unroll
        for (int32_t ch = 0; ch < 3; ++ch) cur[ch] = sample(i / vp.W, i % vp.W, ch);
      }
      __syncthreads();
      if (k > 0 && owned(k - 1))
#pragma unroll
        for (int32_t ch = 0; ch < 3; ++ch) frame[pixel(k - 1) * 3 + ch] = prev[ch];
      if (own)
#pragma unroll
        for (int32_t ch = 0; ch < 3; ++ch) prev[ch] = cur[ch];
    }
    if (owned(kFramePassPixelsPerThread - 1))
#pragma unroll
      for (int32_t ch = 0; ch < 3; ++ch) frame[pixel(kFramePassPixelsPerThread - 1) * 3 + ch] = prev[ch];
    __syncthreads();
  }

  /// Runs sample(frame, r, c, ch) for every owned value, then replaces the frame with the results.
  template <class Sample>
  __device__ __forceinline__ void run(const Sample& sample) const {
    const VisualParams& vp = ParamsOf<Cfg>::visual();
    // The per-pixel stages before a pass write each thread's own pixels; the pass reads its
    // neighbours' pixels, so every thread must have finished them first (without this barrier rows
    // owned by other warps were read half-updated: 0.3-0.5 % of the hardest frames' values differed
    // from the CPU reference, up to 109 codes).
    __syncthreads();
    // Not unrolled: nv lives in local memory instead of taking 96 registers from every other stage
    // (only the fallback of pixelate uses this).
    float nv[kFramePassPixelsPerThread][3];
#pragma unroll 1
    for (int32_t k = 0; k < kFramePassPixelsPerThread; ++k)
      if (owned(k)) {
        const int32_t i = pixel(k);
#pragma unroll
        for (int32_t ch = 0; ch < 3; ++ch) nv[k][ch] = sample(i / vp.W, i % vp.W, ch);
      }
    __syncthreads();
#pragma unroll 1
    for (int32_t k = 0; k < kFramePassPixelsPerThread; ++k)
      if (owned(k))
#pragma unroll
        for (int32_t ch = 0; ch < 3; ++ch) frame[pixel(k) * 3 + ch] = nv[k][ch];
    __syncthreads();
  }

  /// Blur (7.1 step 8): (1 - b)*F + b*Box3(F), as blur_pass.
  __device__ __forceinline__ void blur(float sigma) const {
    const VisualParams& vp = ParamsOf<Cfg>::visual();
    const float b = blur_weight(sigma);
    const float* f = frame;
    const auto sample = [&](int32_t r, int32_t c, int32_t ch) { return blur_at(f, vp.H, vp.W, r, c, ch, b); };
    if (banded()) run_banded(sample);
    else run(sample);
  }

  /// Sharpen (7.1 step 9): clip(F + amount*(F - blur1(F)), 0, 255), as sharpen_pass.
  __device__ __forceinline__ void sharpen(float amount) const {
    const VisualParams& vp = ParamsOf<Cfg>::visual();
    const float b = blur_weight(1.0f);
    const float* f = frame;
    const auto sample = [&](int32_t r, int32_t c, int32_t ch) {
      const float src = f[(r * vp.W + c) * 3 + ch];
      return clampf(src + amount * (src - blur_at(f, vp.H, vp.W, r, c, ch, b)), 0.0f, 255.0f);
    };
    if (banded()) run_banded(sample);
    else run(sample);
  }

  /// Pixelate (7.1 step 10): F[pix(r)][pix(c)], as pixelate_pass.
  __device__ __forceinline__ void pixelate(int32_t factor) const {
    const VisualParams& vp = ParamsOf<Cfg>::visual();
    const float* f = frame;
    // When every source pixel is its own source (pix(pix(i)) = pix(i) for the owned rows and columns),
    // no source changes value, so each pixel can be read and written in place in one sweep.
    bool fixed = true;
    for (int32_t k = 0; k < kFramePassPixelsPerThread; ++k)
      if (owned(k)) {
        const int32_t i = pixel(k), r = pixelate_index(i / vp.W, vp.H, factor), c = pixelate_index(i % vp.W, vp.W, factor);
        fixed = fixed && pixelate_index(r, vp.H, factor) == r && pixelate_index(c, vp.W, factor) == c;
      }
    if (__syncthreads_and(fixed)) {
#pragma unroll 1
      for (int32_t k = 0; k < kFramePassPixelsPerThread; ++k)
        if (owned(k)) {
          const int32_t i = pixel(k);
          const int32_t src = pixelate_index(i / vp.W, vp.H, factor) * vp.W + pixelate_index(i % vp.W, vp.W, factor);
          for (int32_t ch = 0; ch < 3; ++ch) frame[i * 3 + ch] = f[src * 3 + ch];
        }
      __syncthreads();
      return;
    }
    run([&](int32_t r, int32_t c, int32_t ch) {
      return f[(pixelate_index(r, vp.H, factor) * vp.W + pixelate_index(c, vp.W, factor)) * 3 + ch];
    });
  }
};

/// Frame-pass path in apply_filters' order: compose and the episode preset's pixel stages, its
/// sharpen and the truncation to uint8 (7.1 A); the main chain with the pop_filter preset, head,
/// blur, sharpen, pixelate, tail (B); then the lights (8.2). The bytes are staged in the frame's
/// memory and stored with 16-byte words.
template <class Cfg>
__device__ __forceinline__ void render_frame_pass_path(const AssetView& assets, const BlockShared& sh,
                                                       const SpanSolid& solid, float* frame, uint8_t* out) {
  const VisualParams& vp = ParamsOf<Cfg>::visual();
  const FrameSetup& fs = sh.setup;
  const FramePass<Cfg> pass{frame};
  const int32_t n = vp.H * vp.W;
  const int32_t first = static_cast<int32_t>(threadIdx.x), stride = static_cast<int32_t>(blockDim.x);
  const Preset ep = fs.episode_preset;
#pragma unroll 1
  for (int32_t i = first; i < n; i += stride) {
    uint8_t rgb[3];
    compose_pixel(vp, assets, fs.agent, solid, sh.visual, fs.f, i / vp.W, i % vp.W, rgb);
    float* f = frame + i * 3;
    for (int32_t ch = 0; ch < 3; ++ch) f[ch] = static_cast<float>(rgb[ch]);
    if (ep != Preset::kNone) preset_pixel_op(ep, f, i / vp.W, i % vp.W, vp.H, vp.W);
  }
  if (ep != Preset::kNone) {
    const float amount = preset_sharpen_amount(ep);
    if (amount > 0.0f) pass.sharpen(amount);
#pragma unroll 1
    for (int32_t i = first; i < n; i += stride)
      for (int32_t ch = 0; ch < 3; ++ch) frame[i * 3 + ch] = static_cast<float>(to_u8_clipped(frame[i * 3 + ch]));
  }
  if (!filters_identity(vp)) {
    const float preset_sharpen = preset_sharpen_amount(vp.pop_filter);
#pragma unroll 1
    for (int32_t i = first; i < n; i += stride) {
      preset_pixel_op(vp.pop_filter, frame + i * 3, i / vp.W, i % vp.W, vp.H, vp.W);
      if (preset_sharpen == 0.0f) chain_head_pixel(vp, fs.jitter, frame + i * 3);
    }
    if (preset_sharpen > 0.0f) {
      pass.sharpen(preset_sharpen);
#pragma unroll 1
      for (int32_t i = first; i < n; i += stride) chain_head_pixel(vp, fs.jitter, frame + i * 3);
    }
    if (vp.blur_sigma > 0.0f) pass.blur(vp.blur_sigma);
    if (vp.sharpen_amount > 0.0f) pass.sharpen(vp.sharpen_amount);
    if (vp.pixelate_factor > 1) pass.pixelate(vp.pixelate_factor);
#pragma unroll 1
    for (int32_t i = first; i < n; i += stride) chain_tail_pixel(vp, fs.keys, i / vp.W, i % vp.W, frame + i * 3);
  }
  // Truncate and light the owned pixels into registers, then stage the bytes over the frame.
  uint32_t px[kFramePassPixelsPerThread];
#pragma unroll
  for (int32_t k = 0; k < kFramePassPixelsPerThread; ++k)
    if (pass.owned(k)) {
      const int32_t i = pass.pixel(k);
      uint8_t rgb[3];
      for (int32_t ch = 0; ch < 3; ++ch) rgb[ch] = to_u8_clipped(frame[i * 3 + ch]);
      if (vp.point_light_enabled) light_pixel(vp, sh.visual, i / vp.W, i % vp.W, rgb);
      px[k] = static_cast<uint32_t>(rgb[0]) | (static_cast<uint32_t>(rgb[1]) << 8) |
              (static_cast<uint32_t>(rgb[2]) << 16);
    }
  __syncthreads();
  uint8_t* staged = reinterpret_cast<uint8_t*>(frame);
#pragma unroll
  for (int32_t k = 0; k < kFramePassPixelsPerThread; ++k)
    if (pass.owned(k))
      for (int32_t ch = 0; ch < 3; ++ch) staged[pass.pixel(k) * 3 + ch] = static_cast<uint8_t>(px[k] >> (8 * ch));
  __syncthreads();
  const int32_t bytes = n * 3;
  if (bytes % 16 == 0) {
    const uint4* src = reinterpret_cast<const uint4*>(staged);
    uint4* dst = reinterpret_cast<uint4*>(out);
    for (int32_t i = first; i < bytes / 16; i += stride) dst[i] = src[i];
  } else {
    for (int32_t i = first; i < bytes; i += stride) out[i] = staged[i];
  }
}

/// Renders the state held in `sh` into `out` with the whole block: frame setup by thread 0, the
/// column table, then the pixels. Entered by every thread; the state in `sh` must be complete.
/// `frame` is the dynamic shared memory: the float frame (frame-pass path) or the staging slots.
template <class Cfg>
__device__ __forceinline__ void render_block(const DeviceEnvs& e, int32_t env, BlockShared& sh, float* frame,
                                             uint8_t* out) {
  const LatentParams& lp = ParamsOf<Cfg>::latent();
  const VisualParams& vp = ParamsOf<Cfg>::visual();
  if (threadIdx.x == 0) {
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
  // The distractors' per-frame shape values (up to 20 sin/cos each) on the second warp, beside thread 0.
  const int32_t dist_first = blockDim.x > 32 ? 32 : 0;
  if (static_cast<int32_t>(threadIdx.x) >= dist_first)
    for (int32_t i = static_cast<int32_t>(threadIdx.x) - dist_first; i < distractor_slots(vp);
         i += static_cast<int32_t>(blockDim.x) - dist_first)
      sh.setup.f.dist[i] = distractor_frame(vp, sh.visual, i);
  __syncthreads();
  const int32_t cam = sh.setup.f.cam;
  const LayoutView layout{sh.segments};
  for (int32_t c = static_cast<int32_t>(threadIdx.x); c < vp.W; c += static_cast<int32_t>(blockDim.x)) {
    const SolidSpan s = solid_span(lp, layout, clampi(c + cam, 0, lp.length - 1));
    sh.spans[c] = ColumnSpan{static_cast<short>(s.lo), static_cast<short>(s.hi)};
  }
  __syncthreads();
  if (sh.setup.plain) {
    for (int32_t g = static_cast<int32_t>(threadIdx.x); g < vp.W / kPixelsPerThread; g += static_cast<int32_t>(blockDim.x)) {
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
    __syncthreads();
  }
  const SpanSolid solid{sh.spans, cam, lp.height_px};
  if (needs_frame_passes(vp)) {
    render_frame_pass_path<Cfg>(e.assets, sh, solid, frame, out);
  } else {
    render_register_path<Cfg>(e.assets, sh, solid, out);
  }
}

/// Loads one environment's state into shared memory with the whole block.
template <class Cfg>
__device__ __forceinline__ void load_state(const DeviceEnvs& e, int32_t env, BlockShared& sh) {
  block_copy_words(&sh.latent, e.latent + env, static_cast<int32_t>(sizeof(LatentState)));
  block_copy_words(sh.segments, e.segments + static_cast<int64_t>(env) * e.segment_stride, e.segment_stride);
  block_copy_words(&sh.visual, e.visual + env, e.visual_extent);
  __syncthreads();
}

/// Stores one environment's state from shared memory with the whole block (after a barrier).
template <class Cfg>
__device__ __forceinline__ void store_state(const DeviceEnvs& e, int32_t env, const BlockShared& sh) {
  block_copy_words(e.latent + env, &sh.latent, static_cast<int32_t>(sizeof(LatentState)));
  block_copy_words(e.segments + static_cast<int64_t>(env) * e.segment_stride, sh.segments, e.segment_stride);
  block_copy_words(e.visual + env, &sh.visual, e.visual_extent);
}

/// The frame of environment env.
template <class Cfg>
__device__ __forceinline__ uint8_t* frame_of(const DeviceEnvs& e, int32_t env) {
  const VisualParams& vp = ParamsOf<Cfg>::visual();
  return e.obs + static_cast<int64_t>(env) * vp.H * vp.W * 3;
}

/// Launch bounds of the rendering kernels: at most a frame-pass block; a config that certainly takes
/// the register path (no neighbourhood filter, no preset: tested on constants, as needs_frame_passes is
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

/// Reset: one thread per environment starts episode 0 (no rendering; see render_body).
template <class Cfg>
__device__ __forceinline__ void reset_body(const DeviceEnvs& e) {
  const int32_t env = static_cast<int32_t>(blockIdx.x * blockDim.x + threadIdx.x);
  if (env >= e.num_envs) return;
  LatentState ls;
  device_reset_env(ParamsOf<Cfg>::latent(), ParamsOf<Cfg>::visual(), e.assets, device_episode_key(e, env, 0), 0,
            e.segments + static_cast<int64_t>(env) * e.segment_stride, ls, e.visual[env]);
  e.latent[env] = ls;
  record_outcome(e, env, ls, StepOutcome{});
}

/// Step without rendering: one thread per environment (the original's state-only measurement).
template <class Cfg>
__device__ __forceinline__ void step_only_body(const DeviceEnvs& e) {
  const int32_t env = static_cast<int32_t>(blockIdx.x * blockDim.x + threadIdx.x);
  if (env >= e.num_envs) return;
  LatentState ls = e.latent[env];
  device_step_env(ParamsOf<Cfg>::latent(), ParamsOf<Cfg>::visual(), e, env,
           e.segments + static_cast<int64_t>(env) * e.segment_stride, ls, e.visual[env]);
  e.latent[env] = ls;
}

/// Fused step + autoreset + render: one block per environment (grid-stride over environments).
template <class Cfg>
__device__ __forceinline__ void step_render_body(const DeviceEnvs& e, BlockShared& sh, float* frame) {
  for (int32_t env = static_cast<int32_t>(blockIdx.x); env < e.num_envs; env += static_cast<int32_t>(gridDim.x)) {
    load_state<Cfg>(e, env, sh);
    if (threadIdx.x == 0) device_step_env(ParamsOf<Cfg>::latent(), ParamsOf<Cfg>::visual(), e, env, sh.segments, sh.latent, sh.visual);
    __syncthreads();
    store_state<Cfg>(e, env, sh);
    render_block<Cfg>(e, env, sh, frame, frame_of<Cfg>(e, env));
    __syncthreads();
  }
}

/// Render only: one block per environment renders its current state (after reset, or for timing).
template <class Cfg>
__device__ __forceinline__ void render_body(const DeviceEnvs& e, BlockShared& sh, float* frame) {
  for (int32_t env = static_cast<int32_t>(blockIdx.x); env < e.num_envs; env += static_cast<int32_t>(gridDim.x)) {
    load_state<Cfg>(e, env, sh);
    render_block<Cfg>(e, env, sh, frame, frame_of<Cfg>(e, env));
    __syncthreads();
  }
}

/// Uniform random actions in [0, 8) for step t (benchmarks), from their own key.
__device__ __forceinline__ void sample_actions_body(int32_t* actions, int32_t n, uint64_t seed, uint32_t t) {
  const int32_t i = static_cast<int32_t>(blockIdx.x * blockDim.x + threadIdx.x);
  if (i < n) actions[i] = randint(fold(seed_key(seed), t), static_cast<uint32_t>(i), 0, 8);
}

}  // namespace kage

/// Emits the entry points of one config with fixed unmangled names, so that a loader finds them in any
/// compiled config: kage_reset and kage_step_only (one thread per environment; any block size),
/// kage_step_render and kage_render (one block per environment, render_threads() threads and
/// render_dynamic_smem_bytes() bytes of dynamic shared memory), kage_sample_actions. Use once per module.
#define KAGE_INSTANTIATE_KERNELS(CFG)                                                                     \
  extern "C" __global__ void kage_reset(const kage::DeviceEnvs e) { kage::reset_body<CFG>(e); }           \
  extern "C" __global__ void kage_step_only(const kage::DeviceEnvs e) { kage::step_only_body<CFG>(e); }   \
  extern "C" __global__ void __launch_bounds__(kage::RenderBounds<CFG>::kThreads,                          \
                                               kage::RenderBounds<CFG>::kMinBlocks) kage_step_render(const kage::DeviceEnvs e) {         \
    __shared__ kage::BlockShared sh;                                                                      \
    extern __shared__ float4 kage_frame[];                                                                \
    kage::step_render_body<CFG>(e, sh, reinterpret_cast<float*>(kage_frame));                             \
  }                                                                                                       \
  extern "C" __global__ void __launch_bounds__(kage::RenderBounds<CFG>::kThreads,                          \
                                               kage::RenderBounds<CFG>::kMinBlocks) kage_render(const kage::DeviceEnvs e) {              \
    __shared__ kage::BlockShared sh;                                                                      \
    extern __shared__ float4 kage_frame[];                                                                \
    kage::render_body<CFG>(e, sh, reinterpret_cast<float*>(kage_frame));                                  \
  }                                                                                                       \
  extern "C" __global__ void kage_sample_actions(int32_t* actions, int32_t n, uint64_t seed, uint32_t t) {  \
    kage::sample_actions_body(actions, n, seed, t);                                                       \
  }
