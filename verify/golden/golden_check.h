// Golden replay and comparison (../shared/golden/README.md): physics trajectories, rendered frames, filter
// and light passes, each measured the way the README states its tolerance. Used by `kagec golden check`.
#pragma once

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "fileio/image_io.h"
#include "runtime/latent/latent_params.h"
#include "runtime/visual/asset_view.h"
#include "runtime/visual/image_diff.h"
#include "runtime/visual/visual_params.h"
#include "runtime/visual/visual_state.h"

namespace kage {

/// One line of a golden report: the worst deviation of one field or image against its limit.
struct GoldenLine {
  std::string name;     ///< e.g. "physics_default.json x" or "render_shape_black/seed0_t10.png"
  std::string measure;  ///< what `worst` is, e.g. "max |diff|"
  double worst = 0;
  std::string limit;    ///< the README's tolerance, as text
  bool pass = false;
  std::string detail;   ///< first failing place, or the other measures
};

/// Image tolerances of the README: per-channel maximum, share of equal values, mean absolute difference.
struct ImageTolerance {
  int32_t max_abs;
  double min_equal;
  double max_mean;
};

inline constexpr ImageTolerance kExactImage{0, 1.0, 0.0};
inline constexpr ImageTolerance kImageBackground{4, 0.0, 0.2};  ///< JPEG backgrounds (render goldens)
inline constexpr ImageTolerance kFilterImage{2, 0.99, 255.0};   ///< filters and effects

/// Compares `got` (H x W x 3) with an expected image under `tol`.
GoldenLine compare_image(const std::string& name, const uint8_t* got, const Image& expected, const ImageTolerance& tol);

/// Replays every episode of a physics_*.json file on its recorded ground_top with `p`: the layout round
/// trip and solid mask, the reset state, then every step's fields. One line per field (plus "layout" and
/// "initial"), the worst deviation over all episodes.
std::vector<GoldenLine> check_physics(const std::string& name, const LatentParams& p, const nlohmann::json& file);

/// Replays a render_*/ directory: each listed frame rendered from its recorded state on the recorded
/// ground_top, compared with its PNG; and the state of our replay of the actions against the recording.
std::vector<GoldenLine> check_render(const std::string& dir, const LatentParams& lp, const VisualParams& vp,
                                     const AssetView& assets, const ImageTolerance& tol);

/// The filter chain of `p` (no per-episode preset, key (0, 0), t = 0) applied to `image` in place.
void apply_filter_chain(const VisualParams& p, Image& image);

/// The point-light pass of `p` with the light positions `xy` (kMaxLights pairs, normalised) in place.
void apply_point_lights(const VisualParams& p, const float (&x)[kMaxLights], const float (&y)[kMaxLights], Image& image);

}  // namespace kage
