// The episode driver, written once for every backend: reset (layout, latent state, visual state) and
// step (latent step, record, visual step, then the same-step automatic reset of a finished episode,
// spec 10.2). Host and device (nvcc, NVRTC).
//
// It is a template over a parameter provider `P` and a backend's outputs `Out`, in the way CuTe takes
// static or dynamic values: p.latent() and p.visual() return the parameters, either a generated config's
// constants (which fold, so disabled stages vanish) or run-time values (the generic path); P::kVisual
// says whether the environment has a visual half (false: the hidden game only).
//
// `Out` says where results go and when to restart:
//   Key episode_key(uint32_t episode)           the key of one of the environment's episodes
//   void record(const LatentState&, const StepOutcome&)  after the latent step
//   bool stepped(bool done, const uint8_t* segments, const LatentState&, const VisualState*)
//       after the visual step; true starts the next episode (done, and the backend autoresets)
//   void restarted(const uint8_t* segments, const LatentState&, const VisualState*)  after that reset
#pragma once

#include "runtime/kage_hd.h"
#include "runtime/latent/latent_step.h"
#include "runtime/rng.h"
#include "runtime/visual/asset_view.h"
#include "runtime/visual/visual_state.h"
#include "runtime/visual/visual_update.h"

namespace kage {

/// Run-time parameters of a full environment (the generic path).
struct RuntimeParams {
  static constexpr bool kVisual = true;
  const LatentParams* latent_params;
  const VisualParams* visual_params;
  KAGE_HD const LatentParams& latent() const { return *latent_params; }
  KAGE_HD const VisualParams& visual() const { return *visual_params; }
};

/// Run-time parameters of the hidden game alone (no visual state, no frames).
struct LatentOnlyParams {
  static constexpr bool kVisual = false;
  const LatentParams* latent_params;
  KAGE_HD const LatentParams& latent() const { return *latent_params; }
};

/// Starts `episode` (key `key`) of one environment: layout and latent state, then the visual state
/// (spec 4.2). `vs` is unused when P has no visual half.
template <class P>
KAGE_HD void episode_reset(const P& p, const AssetView& assets, Key key, uint32_t episode, uint8_t* segments,
                           LatentState& ls, VisualState* vs) {
  latent_reset(p.latent(), key, episode, segments, ls);
  if constexpr (P::kVisual) {
    const LayoutView layout{segments};
    visual_reset(p.visual(), assets, key, [&](int32_t c) { return ground_top(p.latent(), layout, c); }, *vs);
  }
}

/// One step of one environment with `action` (any int32: spec 3.2 masks it); returns the step's outcome
/// (after an automatic reset still the finished episode's).
template <class P, class Out>
KAGE_HD StepOutcome episode_step(const P& p, const AssetView& assets, int32_t action, uint8_t* segments,
                                 LatentState& ls, VisualState* vs, Out& out) {
  const StepOutcome o = latent_step(p.latent(), LayoutView{segments}, ls, action);
  out.record(ls, o);
  if constexpr (P::kVisual)
    visual_step(p.visual(), assets, out.episode_key(ls.episode), static_cast<uint32_t>(ls.t), ls.vx, *vs);
  if (!out.stepped(o.terminated || o.truncated, segments, ls, vs)) return o;
  const uint32_t next = ls.episode + 1;
  episode_reset(p, assets, out.episode_key(next), next, segments, ls, vs);
  out.restarted(segments, ls, vs);
  return o;
}

}  // namespace kage
