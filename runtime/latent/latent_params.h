// Latent (dynamics) parameters: everything reset and step read, already lowered from the resolved config.
// Legacy physics aliases are resolved and floats rounded to float32 before they get here (spec 0, 1.9).
#pragma once

#include "runtime/kage_hd.h"

namespace kage {

/// Parameters of the hidden game: screen size, hitbox, layout geometry, physics, reward and episode.
/// Plain values only; the members are listed in latent_params.def.
struct LatentParams {
#define KAGE_PARAM(type, name) type name;
#include "runtime/latent/latent_params.def"
#undef KAGE_PARAM
};

static_assert(__is_trivially_copyable(LatentParams), "LatentParams must be POD");
static_assert(sizeof(LatentParams) == 35 * 4, "LatentParams layout changed: update the params emitter");

/// The two event thresholds of spec 4.3 step 2: computed in double from the config's double values,
/// then rounded to float32 for the comparison with the float32 uniforms (e.g. 0.3 and 0.65 for 0.7 / 0.5).
KAGE_HD void layout_thresholds(double p_change, double p_up_given_change, float& t_flat, float& t_up) {
  const double flat = 1.0 - p_change;
  t_flat = static_cast<float>(flat);
  t_up = static_cast<float>(flat + p_change * p_up_given_change);
}

/// Number of layout segments ceil(L / run_width) (spec 4.3 step 1): the per-env layout buffer size.
KAGE_HD int32_t layout_segment_count(const LatentParams& p) { return (p.length + p.run_width - 1) / p.run_width; }

/// Whether the compact layout storage can hold every height this config produces: one byte per
/// segment stores h - min_height, so the walk range must fit in a byte. The config mapping rejects
/// the rest (and run_width <= 0, which the original also rejects).
KAGE_HD bool latent_params_supported(const LatentParams& p) {
  return p.run_width > 0 && p.length > 0 && p.height_px > 0 && p.max_height >= p.min_height &&
         p.max_height - p.min_height <= 255 && p.ground_thickness >= 0;
}

}  // namespace kage
