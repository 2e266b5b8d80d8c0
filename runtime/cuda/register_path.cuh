// Register path of the GPU renderer: frames without neighbourhood filters, composed, filtered and lit
// in registers by the threads of a block (BlockGroup): plain frames as 16-byte words, others as
// 16-pixel runs per thread.
#pragma once

#include "runtime/cuda/kernel_step.cuh"
#include "runtime/cuda/render_plan.h"
#include "runtime/visual/compose.h"
#include "runtime/visual/filters.h"
#include "runtime/visual/lights.h"

namespace kage {

/// A layout mask that is the same everywhere: composes the two colours of a plain frame.
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

/// The threads that render one frame together: the whole block.
struct BlockGroup {
  __device__ __forceinline__ static int32_t rank() { return static_cast<int32_t>(threadIdx.x); }
  __device__ __forceinline__ static int32_t size() { return static_cast<int32_t>(blockDim.x); }
  __device__ __forceinline__ static void sync() { __syncthreads(); }
};

/// Copies `bytes` (a multiple of 4) between two 4-byte aligned buffers with the threads of `Group`.
template <class Group>
__device__ __forceinline__ void group_copy_words(void* dst, const void* src, int32_t bytes) {
  uint32_t* d = static_cast<uint32_t*>(dst);
  const uint32_t* s = static_cast<const uint32_t*>(src);
  for (int32_t i = Group::rank(); i < bytes / 4; i += Group::size()) d[i] = s[i];
}

/// The register path's frame for walk_filters: one pixel, in registers. Without neighbourhood passes
/// (the path is chosen only when needs_frame_passes is false).
struct PixelFrame {
  static constexpr bool kPasses = false;
  uint8_t* rgb;
  int32_t r, c;
  float f[3];
  bool loaded = false;  ///< f holds the current values (else rgb does)

  template <class Fn>
  __device__ __forceinline__ void pixels(const Fn& fn) {
    if (!loaded)
      for (int32_t ch = 0; ch < 3; ++ch) f[ch] = static_cast<float>(rgb[ch]);
    loaded = true;
    fn(f, r, c);
  }
  template <class Fn>
  __device__ __forceinline__ void last_pixels(const Fn& fn) {
    pixels(fn);
    truncate();
  }
  __device__ __forceinline__ void truncate() {
    for (int32_t ch = 0; ch < 3; ++ch) rgb[ch] = to_u8_clipped(f[ch]);
    loaded = false;
  }
};

/// Per-pixel stages of the register path after composition: the filter chain (walk_filters), then the
/// point lights (8.2); the same arithmetic as render_frame.
template <class Cfg>
__device__ __forceinline__ void pixel_stages(const VisualState& vs, const FrameSetup& fs, int32_t r, int32_t c,
                                             uint8_t* rgb) {
  const VisualParams& vp = ParamsOf<Cfg>::visual();
  PixelFrame frame{rgb, r, c};
  walk_filters(vp, fs.episode_preset, fs.jitter, fs.keys, frame);
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

/// The three words of a 12-byte repeat of pixel p (r | g << 8 | b << 16): bytes whose offset is
/// 0, 1 and 2 mod 3 start them.
struct PixelPattern {
  uint32_t w[3];
  __device__ __forceinline__ explicit PixelPattern(uint32_t p)
      : w{p | (p << 24), (p >> 8) | (p << 16), (p >> 16) | (p << 8)} {}
  /// The 16 bytes of a row of p starting at a byte offset that is `phase` mod 3 (4 = 1 mod 3).
  __device__ __forceinline__ uint4 word(int32_t phase) const {
    const uint32_t a = phase == 0 ? w[0] : phase == 1 ? w[1] : w[2];
    const uint32_t b = phase == 0 ? w[1] : phase == 1 ? w[2] : w[0];
    const uint32_t c = phase == 0 ? w[2] : phase == 1 ? w[0] : w[1];
    return make_uint4(a, b, c, a);
  }
};

/// The 16 bytes starting `skip` (0..2) bytes into six consecutive packed pixels.
__device__ __forceinline__ uint4 six_pixels_word(const uint32_t* px, int32_t skip) {
  uint32_t q[5];
  pack_quad(px[0], px[1], px[2], px[3], q);
  q[3] = px[4] | (px[5] << 24);
  q[4] = px[5] >> 8;
  const uint32_t shift = 8u * static_cast<uint32_t>(skip);
  return make_uint4(__funnelshift_r(q[0], q[1], shift), __funnelshift_r(q[1], q[2], shift),
                    __funnelshift_r(q[2], q[3], shift), __funnelshift_r(q[3], q[4], shift));
}

/// A plain frame (FrameSetup::plain; rows a multiple of 16 pixels): the scene is one of two colours at
/// every pixel outside the agent box, chosen by the layout mask. Pass 1 writes the whole frame as
/// 16-byte words, consecutive threads on consecutive words (every warp store covers 512 contiguous
/// bytes): word j of a row lies in the 16-column group j / 3 at byte phase j % 3, and is one colour
/// when the group's span extremes say so, else six masked pixels. Pass 2 composes the agent box one
/// pixel per thread and overwrites it, so the agent's few hundred pixels are spread over the group
/// instead of serialising the threads whose words it touches.
template <class Cfg, class Group, class Slot>
__device__ __forceinline__ void render_plain_frame(const AssetView& assets, const Slot& sh, const SpanSolid& solid,
                                                   uint8_t* out) {
  const VisualParams& vp = ParamsOf<Cfg>::visual();
  const FrameSetup& fs = sh.setup;
  uint8_t rgb[3];
  scene_pixel(vp, assets, fs.agent, ConstSolid{true}, sh.visual, fs.f, 0, 0, rgb);
  const uint32_t on = pack_rgb(rgb);
  scene_pixel(vp, assets, fs.agent, ConstSolid{false}, sh.visual, fs.f, 0, 0, rgb);
  const uint32_t off = pack_rgb(rgb);
  const PixelPattern on_words(on), off_words(off);
  const int32_t words_per_row = vp.W * 3 / 16;
  uint4* words = reinterpret_cast<uint4*>(out);
  for (int32_t k = Group::rank(); k < vp.H * words_per_row; k += Group::size()) {
    const int32_t r = k / words_per_row;
    const int32_t j = k - r * words_per_row;
    const int32_t g = j / 3;
    const int32_t phase = j - 3 * g;
    const GroupSpan gs = sh.groups[g];
    const int32_t rr = clampi(r, 0, solid.height_px - 1);
    if (rr < gs.lo_min || rr >= gs.hi_max) {
      words[k] = off_words.word(phase);
    } else if (rr >= gs.lo_max && rr < gs.hi_min) {
      words[k] = on_words.word(phase);
    } else {
      // Bytes 16 * phase .. + 15 of the group's 48 start `phase` bytes into its pixel 5 * phase.
      const int32_t c0 = g * kPixelsPerThread + 5 * phase;
      uint32_t px[6];
#pragma unroll
      for (int32_t t = 0; t < 6; ++t) px[t] = solid(r, c0 + t + solid.cam) ? on : off;
      words[k] = six_pixels_word(px, phase);
    }
  }
  Group::sync();
  const ScreenBox& box = fs.agent_box;
  const int32_t x0 = maxi(box.x0, 0), x1 = mini(box.x1, vp.W - 1);
  const int32_t y0 = maxi(box.y0, 0), y1 = mini(box.y1, vp.H - 1);
  const int32_t box_w = x1 - x0 + 1;
  if (box_w <= 0 || y1 < y0) return;
  for (int32_t i = Group::rank(); i < box_w * (y1 - y0 + 1); i += Group::size()) {
    const int32_t r = y0 + i / box_w;
    const int32_t c = x0 + i % box_w;
    register_pixel<Cfg>(assets, sh, solid, r, c, rgb);
    uint8_t* dst = out + (r * vp.W + c) * 3;
    dst[0] = rgb[0];
    dst[1] = rgb[1];
    dst[2] = rgb[2];
  }
}

/// Register path: a plain frame by render_plain_frame; otherwise each thread composes runs of 16
/// pixels of one row and stores each run as three 16-byte words (rows whose width is not a multiple of
/// 16 are stored byte by byte): four pixels at a time into three words where the chain is specialized,
/// one at a time in the generic build (its chain inlined four times under the register cap was 4x
/// slower on hardest without neighbourhood filters: 93 k -> 23.5 k steps/s).
template <class Cfg, class Group, class Slot>
__device__ __forceinline__ void render_register_path(const AssetView& assets, const Slot& sh,
                                                     const SpanSolid& solid, uint8_t* out) {
  const VisualParams& vp = ParamsOf<Cfg>::visual();
  if (register_path_vectorized(vp)) {
    if (sh.setup.plain) return render_plain_frame<Cfg, Group>(assets, sh, solid, out);
    const int32_t runs_per_row = vp.W / kPixelsPerThread;
    for (int32_t run = Group::rank(); run < vp.H * runs_per_row; run += Group::size()) {
      const int32_t r = run / runs_per_row;
      const int32_t c0 = (run - r * runs_per_row) * kPixelsPerThread;
      uint8_t* dst = out + (r * vp.W + c0) * 3;
      if constexpr (kGenericBuild<Cfg>) {
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
