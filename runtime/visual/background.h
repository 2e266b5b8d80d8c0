// Background stage (spec 6.2): the background colour of one screen pixel, regenerated from the small
// state (image index, colour index or noise key) instead of a stored copy.
#pragma once

#include "runtime/kage_hd.h"
#include "runtime/kage_math.h"
#include "runtime/rng.h"
#include "runtime/visual/asset_view.h"
#include "runtime/visual/visual_params.h"
#include "runtime/visual/visual_state.h"

namespace kage {

/// Chooses the background of an episode or a switch from key k (spec 6.2 "Generation"): the image
/// index (image mode, drawn only with more than one image), the colour index (colour mode) or the
/// noise key (noise mode: the image itself is regenerated per pixel from it).
KAGE_HD void choose_background(const VisualParams& p, const AssetView& assets, Key k, VisualState& s) {
  switch (p.bg_mode) {
    case BackgroundMode::kImage:
      s.bg_index = assets.bg_count > 1 ? randint(k, 0, 0, assets.bg_count) : 0;
      break;
    case BackgroundMode::kColor:
      s.bg_index = p.bg_color_count > 0 ? randint(k, 0, 0, p.bg_color_count) : 0;
      break;
    case BackgroundMode::kNoise:
      s.bg_noise_key = k;
      break;
    default:
      break;
  }
}

/// Background RGB of screen pixel (r, c) for a camera at camera_x (spec 6.2 "Drawing"); black mode,
/// an empty colour list and a missing image stack give black.
KAGE_HD void background_pixel(const VisualParams& p, const AssetView& assets, const VisualState& s, float camera_x,
                              int32_t r, int32_t c, uint8_t* rgb) {
  rgb[0] = rgb[1] = rgb[2] = 0;
  switch (p.bg_mode) {
    case BackgroundMode::kImage: {
      if (assets.bg_count <= 0) return;
      const int32_t off = round_even_i(camera_x * p.parallax_factor);
      int32_t bc = c + off;
      bc = p.tile_horizontal ? floor_mod(bc, assets.bg_w) : clampi(bc, 0, assets.bg_w - 1);
      const int32_t br = clampi(r, 0, assets.bg_h - 1);
      const int32_t img = clampi(s.bg_index, 0, assets.bg_count - 1);
      const uint8_t* px = assets.bg + ((static_cast<int64_t>(img) * assets.bg_h + br) * assets.bg_w + bc) * 3;
      rgb[0] = px[0];
      rgb[1] = px[1];
      rgb[2] = px[2];
      return;
    }
    case BackgroundMode::kColor: {
      if (p.bg_color_count <= 0) return;
      const Rgb col = p.bg_colors[clampi(s.bg_index, 0, p.bg_color_count - 1)];
      rgb[0] = col.r;
      rgb[1] = col.g;
      rgb[2] = col.b;
      return;
    }
    case BackgroundMode::kNoise: {
      // uint8(uniform(k, (H, W, 3), 0, 256)), flat index (r*W + c)*3 + ch; static between switches.
      const uint32_t base = static_cast<uint32_t>((r * p.W + c) * 3);
      for (uint32_t ch = 0; ch < 3; ++ch) {
        rgb[ch] = static_cast<uint8_t>(uniform(s.bg_noise_key, base + ch, 0.0f, 256.0f));
      }
      return;
    }
    default:
      return;
  }
}

}  // namespace kage
