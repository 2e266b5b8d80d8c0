// Register path of the GPU renderer: the per-frame values (FrameSetup), the layout's column table and
// the 16-pixel runs that a thread composes, filters and lights in registers. Used by kernels.cuh with
// a whole block (BlockGroup) or one warp (WarpGroup) per frame.
#pragma once

#include "runtime/cuda/kernel_step.cuh"
#include "runtime/cuda/render_plan.h"
#include "runtime/visual/compose.h"
#include "runtime/visual/filters.h"
#include "runtime/visual/lights.h"

namespace kage {

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

/// The threads that render one frame together: a whole block (frame-pass path, wide frames) or one
/// warp (register path: eight independent frames per 256-thread block, so that one lane's serial step
/// and frame setup overlap the other warps' pixels instead of stalling a whole block).
struct BlockGroup {
  static constexpr bool kWholeBlock = true;
  __device__ __forceinline__ static int32_t rank() { return static_cast<int32_t>(threadIdx.x); }
  __device__ __forceinline__ static int32_t size() { return static_cast<int32_t>(blockDim.x); }
  __device__ __forceinline__ static void sync() { __syncthreads(); }
};
struct WarpGroup {
  static constexpr bool kWholeBlock = false;
  __device__ __forceinline__ static int32_t rank() { return static_cast<int32_t>(threadIdx.x % 32); }
  __device__ __forceinline__ static int32_t size() { return 32; }
  // __syncwarp also orders the lanes' shared and global memory accesses (the step's writes).
  __device__ __forceinline__ static void sync() { __syncwarp(); }
};

/// Copies `bytes` (a multiple of 4) between two 4-byte aligned buffers with the threads of `Group`.
template <class Group>
__device__ __forceinline__ void group_copy_words(void* dst, const void* src, int32_t bytes) {
  uint32_t* d = static_cast<uint32_t*>(dst);
  const uint32_t* s = static_cast<const uint32_t*>(src);
  for (int32_t i = Group::rank(); i < bytes / 4; i += Group::size()) d[i] = s[i];
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
template <class Cfg, class Slot, class SolidFn>
__device__ __forceinline__ void register_pixel(const AssetView& assets, const Slot& sh, const SolidFn& solid,
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
template <class Cfg, class Slot>
__device__ __forceinline__ uint32_t plain_pixel(const AssetView& assets, const Slot& sh, bool solid, int32_t r,
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
/// to a few. Other runs compose every pixel: four at a time into three words where the chain is
/// specialized, one at a time in the generic build (its chain inlined four times under the register
/// cap was 4x slower on hardest without neighbourhood filters: 93 k -> 23.5 k steps/s).
template <class Cfg, class Group, class Slot>
__device__ __forceinline__ void render_register_path(const AssetView& assets, const Slot& sh,
                                                     const SpanSolid& solid, uint8_t* out) {
  const VisualParams& vp = ParamsOf<Cfg>::visual();
  if (register_path_vectorized(vp)) {
    const FrameSetup& fs = sh.setup;
    const bool plain = fs.plain;
    const ScreenBox box = fs.agent_box;
    const int32_t runs_per_row = vp.W / kPixelsPerThread;
    for (int32_t run = Group::rank(); run < vp.H * runs_per_row; run += Group::size()) {
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
      } else if constexpr (kGenericBuild<Cfg>) {
#pragma unroll 1
        for (int32_t j = 0; j < kPixelsPerThread; ++j) {
          uint8_t rgb[3];
          register_pixel<Cfg>(assets, sh, solid, r, c0 + j, rgb);
          for (int32_t ch = 0; ch < 3; ++ch) dst[3 * j + ch] = rgb[ch];
        }
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
    for (int32_t i = Group::rank(); i < vp.H * vp.W; i += Group::size()) {
      uint8_t rgb[3];
      register_pixel<Cfg>(assets, sh, solid, i / vp.W, i % vp.W, rgb);
      for (int32_t ch = 0; ch < 3; ++ch) out[i * 3 + ch] = rgb[ch];
    }
  }
}

}  // namespace kage
