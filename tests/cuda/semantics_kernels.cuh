// Kernels that instantiate the whole semantics library for the GPU: latent reset/step, visual
// reset/step, render_frame (composition, filter chain, lights) and the filter passes on their own.
// Compiled by nvcc (semantics_nvcc_check.cu) and by NVRTC (nvrtc_check.cpp), so that a header that
// stops compiling for either device path fails the build or the tests. Never launched: CI has no GPU.
#pragma once

#include "runtime/kage_hd.h"
#include "runtime/latent/latent_step.h"
#include "runtime/visual/filter_passes.h"
#include "runtime/visual/filters.h"
#include "runtime/visual/render.h"
#include "runtime/visual/visual_update.h"

namespace kage_check {

/// Layout mask lookup with clamped indices (the contract of render_frame's SolidFn).
struct MaskSolid {
  const uint8_t* mask;
  int32_t h;
  int32_t w;
  KAGE_HD bool operator()(int32_t r, int32_t wc) const {
    return mask[kage::clampi(r, 0, h - 1) * w + kage::clampi(wc, 0, w - 1)] != 0;
  }
};

/// Ground-top row per world column (the contract of visual_reset's GroundTopFn).
struct ColumnGroundTop {
  const int32_t* top;
  int32_t w;
  KAGE_HD int32_t operator()(int32_t c) const { return top[kage::clampi(c, 0, w - 1)]; }
};

}  // namespace kage_check

extern "C" __global__ void kage_check_latent(const kage::LatentParams* p, uint8_t* segments, kage::LatentState* s,
                                             const int32_t* actions, kage::StepOutcome* out, int32_t n) {
  const int32_t i = static_cast<int32_t>(blockIdx.x * blockDim.x + threadIdx.x);
  if (i >= n) return;
  uint8_t* seg = segments + i * kage::layout_segment_count(*p);
  kage::latent_reset(*p, kage::Key{1u, static_cast<uint32_t>(i)}, 0u, seg, s[i]);
  out[i] = kage::latent_step(*p, kage::LayoutView{seg}, s[i], actions[i]);
}

extern "C" __global__ void kage_check_visual(const kage::VisualParams* p, const kage::AssetView* assets,
                                             const int32_t* ground_top, int32_t width, const float* vx,
                                             kage::VisualState* s, int32_t n) {
  const int32_t i = static_cast<int32_t>(blockIdx.x * blockDim.x + threadIdx.x);
  if (i >= n) return;
  const kage::Key episode{2u, static_cast<uint32_t>(i)};
  kage::visual_reset(*p, *assets, episode, kage_check::ColumnGroundTop{ground_top, width}, s[i]);
  kage::visual_step(*p, *assets, episode, 1u, vx[i], s[i]);
}

extern "C" __global__ void kage_check_render(const kage::VisualParams* p, const kage::AssetView* assets,
                                             const kage::AgentView* agents, const uint8_t* mask, int32_t mask_h,
                                             int32_t mask_w, const kage::VisualState* s, uint8_t* frames,
                                             float* scratch, int32_t n) {
  const int32_t i = static_cast<int32_t>(blockIdx.x * blockDim.x + threadIdx.x);
  if (i >= n) return;
  const int32_t pixels = p->H * p->W * 3;
  kage::render_frame(*p, *assets, agents[i], kage_check::MaskSolid{mask, mask_h, mask_w}, s[i],
                     kage::Key{3u, static_cast<uint32_t>(i)}, 1u, frames + i * pixels,
                     scratch + i * kage::render_scratch_floats(*p));
}

extern "C" __global__ void kage_check_filter_passes(const kage::VisualParams* p, uint8_t* frames, float* a, float* b,
                                                    int32_t n) {
  const int32_t i = static_cast<int32_t>(blockIdx.x * blockDim.x + threadIdx.x);
  if (i >= n) return;
  const int32_t H = p->H, W = p->W, pixels = H * W * 3;
  float* src = a + i * pixels;
  float* dst = b + i * pixels;
  kage::blur_pass(src, dst, H, W, p->blur_sigma);
  kage::sharpen_pass(dst, src, H, W, p->sharpen_amount);
  kage::pixelate_pass(src, dst, H, W, p->pixelate_factor);
  float px[3] = {dst[0], dst[1], dst[2]};
  kage::hsv_op(px, p->saturation, p->hue_shift);
  kage::preset_pixel_op(p->pop_filter, px, 0, 0, H, W);
  kage::apply_filters(*p, p->pop_filter, kage::filter_keys(kage::Key{4u, 5u}, 6u), frames + i * pixels, src, dst);
}
