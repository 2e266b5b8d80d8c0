// Rendering (spec 6): one observation from the latent view and the visual state: composition per
// pixel, the filter chain, then the point lights.
#pragma once

#include "runtime/kage_hd.h"
#include "runtime/rng.h"
#include "runtime/visual/asset_view.h"
#include "runtime/visual/compose.h"
#include "runtime/visual/filters.h"
#include "runtime/visual/lights.h"
#include "runtime/visual/visual_params.h"
#include "runtime/visual/visual_state.h"

namespace kage {

/// Float scratch values render_frame needs: two H x W x 3 buffers for the filter passes.
KAGE_HD int32_t render_scratch_floats(const VisualParams& p) { return 2 * p.H * p.W * 3; }

/// Renders the observation of step t (0 = reset) of the episode with key `episode` into `out`
/// (H x W x 3 uint8, row-major), one pixel after the other (the GPU's group_render_frame in
/// runtime/cuda/kernels.cuh draws the same frame with the threads of a block). `solid(r, wc)` answers the layout mask at row r and world column wc,
/// clamping both (spec 6.3). `scratch` holds render_scratch_floats(p) floats; it is only touched when
/// a filter is active.
template <class SolidFn>
KAGE_HD void render_frame(const VisualParams& p, const AssetView& assets, const AgentView& agent, const SolidFn& solid,
                          const VisualState& s, Key episode, uint32_t t, uint8_t* out, float* scratch) {
  const FrameConstants f = frame_constants(p, agent, s);
  for (int32_t r = 0; r < p.H; ++r) {
    for (int32_t c = 0; c < p.W; ++c) compose_pixel(p, assets, agent, solid, s, f, r, c, out + (r * p.W + c) * 3);
  }
  const Preset episode_filter = episode_preset(p, s);
  if (episode_filter != Preset::kNone || !filters_identity(p)) {
    const int32_t n = p.H * p.W * 3;
    apply_filters(p, episode_filter, filter_keys(episode, t), out, scratch, scratch + n);
  }
  if (p.point_light_enabled) {
    for (int32_t r = 0; r < p.H; ++r) {
      for (int32_t c = 0; c < p.W; ++c) light_pixel(p, s, r, c, out + (r * p.W + c) * 3);
    }
  }
}

}  // namespace kage
