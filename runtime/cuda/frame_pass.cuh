// Frame-pass path of the GPU renderer: blur, sharpen and pixelate read neighbouring pixels, so the
// whole block keeps the frame as float32 in shared memory and runs the stages as passes over it.
#pragma once

#include "runtime/cuda/register_path.cuh"

namespace kage {

/// Frame-pass path: the frame lives in shared memory as float32 (H x W x 3); thread t owns pixels
/// t, t + blockDim, ... (at most 16). Per-pixel stages update the thread's own pixels in place (no
/// barrier between them); a neighbourhood pass waits until every thread has finished its pixels,
/// computes the owned pixels' new values into registers, waits until every thread has read the frame,
/// writes them, and waits again.
template <class Cfg>
struct FramePass {
  static constexpr bool kPasses = true;
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

  /// fn(rgb, r, c) at every owned pixel, in place (walk_filters' per-pixel stages).
  template <class Fn>
  __device__ __forceinline__ void pixels(const Fn& fn) const {
    const VisualParams& vp = ParamsOf<Cfg>::visual();
#pragma unroll 1
    for (int32_t i = static_cast<int32_t>(threadIdx.x); i < vp.H * vp.W; i += static_cast<int32_t>(blockDim.x))
      fn(frame + i * 3, i / vp.W, i % vp.W);
  }
  /// The final per-pixel stage: the output staging truncates the values afterwards.
  template <class Fn>
  __device__ __forceinline__ void last_pixels(const Fn& fn) const {
    pixels(fn);
  }
  /// Rounds the owned values to uint8 and back (7.1 A).
  __device__ __forceinline__ void truncate() const {
    pixels([](float* rgb, int32_t, int32_t) {
      for (int32_t ch = 0; ch < 3; ++ch) rgb[ch] = static_cast<float>(to_u8_clipped(rgb[ch]));
    });
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

/// Frame-pass path: compose into the float frame, the filter chain (walk_filters), then the lights
/// (8.2). The bytes are staged in the frame's memory and stored with 16-byte words.
template <class Cfg>
__device__ __forceinline__ void render_frame_pass_path(const AssetView& assets, const BlockShared& sh,
                                                       const SpanSolid& solid, float* frame, uint8_t* out) {
  const VisualParams& vp = ParamsOf<Cfg>::visual();
  const FrameSetup& fs = sh.setup;
  FramePass<Cfg> pass{frame};
  const int32_t n = vp.H * vp.W;
  const int32_t first = static_cast<int32_t>(threadIdx.x), stride = static_cast<int32_t>(blockDim.x);
#pragma unroll 1
  for (int32_t i = first; i < n; i += stride) {
    uint8_t rgb[3];
    compose_pixel(vp, assets, fs.agent, solid, sh.visual, fs.f, i / vp.W, i % vp.W, rgb);
    for (int32_t ch = 0; ch < 3; ++ch) frame[i * 3 + ch] = static_cast<float>(rgb[ch]);
  }
  walk_filters(vp, fs.episode_preset, fs.jitter, fs.keys, pass);
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
}  // namespace kage
