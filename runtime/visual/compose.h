// Scene composition (spec 6.1 steps 1-7) as a per-pixel function: background, distractors, platforms,
// world NPCs, sticky NPCs and the agent, each tested at one pixel, so only the selected branch is drawn.
#pragma once

#include "runtime/kage_hd.h"
#include "runtime/kage_math.h"
#include "runtime/visual/asset_view.h"
#include "runtime/visual/background.h"
#include "runtime/visual/distractors.h"
#include "runtime/visual/shapes.h"
#include "runtime/visual/visual_math.h"
#include "runtime/visual/visual_params.h"
#include "runtime/visual/visual_state.h"

namespace kage {

/// The latent quantities rendering reads besides the layout: the agent centre and the camera.
struct AgentView {
  float x;
  float y;
  float camera_x;
};

/// Per-frame values of one distractor: its centre pixel and its shape's angle values.
struct DistractorFrame {
  int32_t cx;
  int32_t cy;
  ShapeFrame shape;
};

/// Per-frame values shared by every pixel of a frame (computed once by frame_constants).
struct FrameConstants {
  int32_t agent_cx;  ///< agent anchor round(x - camera_x) (6.5)
  int32_t agent_cy;  ///< round(y + 1)
  int32_t cam;       ///< round(camera_x), for platforms and world NPCs (6.3, 9.1)
  ShapeFrame agent_shape;  ///< the agent shape's angle values (shape mode only)
  DistractorFrame dist[kMaxDistractors];  ///< the first distractor_slots(p) entries
};

/// The agent part of frame_constants: anchor, camera and shape.
KAGE_HD void agent_frame_constants(const VisualParams& p, const AgentView& agent, const VisualState& s,
                                   FrameConstants& f) {
  f.agent_cx = round_even_i(agent.x - agent.camera_x);
  f.agent_cy = round_even_i(agent.y + 1.0f);
  f.cam = round_even_i(agent.camera_x);
  f.agent_shape = ShapeFrame{1.0f, 0.0f, 0, {}, {}};
  if (!p.use_sprites && p.use_shape) {
    const ShapeType type = p.shape_types[clampi(s.shape_type_idx, 0, p.shape_type_count - 1)];
    const float radius = 0.5f * static_cast<float>(mini(p.char_width, p.char_height));
    f.agent_shape = shape_frame(type, f.agent_cx, f.agent_cy, radius, s.shape_angle * kPi / 180.0f);
  }
}

/// The shape type of distractor i (circle when the list is empty).
KAGE_HD ShapeType distractor_type(const VisualParams& p, const VisualState& s, int32_t i) {
  return p.distractor_shape_count > 0 ? p.distractor_shapes[clampi(s.dist_shape[i], 0, p.distractor_shape_count - 1)]
                                      : ShapeType::kCircle;
}

/// The distractor part of frame_constants: slot i < distractor_slots(p). Its angle is used as
/// radians (11.34).
KAGE_HD DistractorFrame distractor_frame(const VisualParams& p, const VisualState& s, int32_t i) {
  DistractorFrame d;
  d.cx = round_even_i(s.dist_x[i]);
  d.cy = round_even_i(s.dist_y[i]);
  d.shape = shape_frame(distractor_type(p, s, i), d.cx, d.cy, static_cast<float>(s.dist_size[i]) / 2.0f,
                        s.dist_angle[i]);
  return d;
}

KAGE_HD FrameConstants frame_constants(const VisualParams& p, const AgentView& agent, const VisualState& s) {
  FrameConstants f;
  agent_frame_constants(p, agent, s, f);
  for (int32_t i = 0; i < distractor_slots(p); ++i) f.dist[i] = distractor_frame(p, s, i);
  return f;
}

KAGE_HD void set_rgb(uint8_t* rgb, Rgb col) {
  rgb[0] = col.r;
  rgb[1] = col.g;
  rgb[2] = col.b;
}

/// Composites frame `fr` anchored at (cx, cy) over pixel (r, c) if the frame covers it (spec 6.4):
/// x0 = cx - sw // 2, y0 = cy + hh - sh; out = a*S + (1 - a)*img in float32, clipped and truncated.
KAGE_HD void blend_sprite_pixel(const AssetView& assets, const SpriteFrame& fr, int32_t cx, int32_t cy, int32_t hh,
                                int32_t r, int32_t c, uint8_t* rgb) {
  const int32_t x0 = cx - fr.width / 2;
  const int32_t y0 = cy + hh - fr.height;
  const int32_t j = c - x0;
  const int32_t i = r - y0;
  if (i < 0 || j < 0 || i >= fr.height || j >= fr.width) return;
  const uint8_t* px = assets.sprite_pixels + fr.offset + (i * fr.width + j) * 4;
  const float a = static_cast<float>(px[3]) / 255.0f;
  for (int32_t ch = 0; ch < 3; ++ch) {
    const float out = a * static_cast<float>(px[ch]) + (1.0f - a) * static_cast<float>(rgb[ch]);
    rgb[ch] = to_u8_clipped(out);
  }
}

/// Draws the distractors over pixel (r, c) (spec 9.4): each is confined to the 32 x 32 window with
/// top-left (cy - 16, cx - 16).
KAGE_HD void distractors_pixel(const VisualParams& p, const VisualState& s, const FrameConstants& f, int32_t r,
                               int32_t c, uint8_t* rgb) {
  for (int32_t i = 0; i < distractor_slots(p); ++i) {
    const DistractorFrame& d = f.dist[i];
    if (c < d.cx - 16 || c >= d.cx + 16 || r < d.cy - 16 || r >= d.cy + 16) continue;
    if (!inside_distractor(distractor_type(p, s, i), d.cx, d.cy, static_cast<float>(s.dist_size[i]), d.shape, c, r)) {
      continue;
    }
    const Rgb red = {255, 0, 0};
    set_rgb(rgb, p.distractor_color_count > 0
                     ? p.distractor_colors[clampi(s.dist_color[i], 0, p.distractor_color_count - 1)]
                     : red);
  }
}

/// Draws the world NPCs over pixel (r, c) in slot order (spec 9.1).
KAGE_HD void npcs_pixel(const VisualParams& p, const AssetView& assets, const VisualState& s,
                        const FrameConstants& f, int32_t r, int32_t c, uint8_t* rgb) {
  for (int32_t i = 0; i < s.npc_count; ++i) {
    const int32_t sx = s.npc_x[i] - f.cam;
    if (!(sx >= -p.char_width && sx < p.W + p.char_width && s.npc_x[i] > 0)) continue;
    const SpriteFrame& fr = sprite_frame_at(assets, sprite_set_at(assets.npc_types, s.npc_type[i]), s.npc_frame);
    blend_sprite_pixel(assets, fr, sx, s.npc_y[i], p.hh, r, c, rgb);
  }
}

/// Draws the first sticky_count sticky NPCs over pixel (r, c) (spec 9.2), following the agent.
KAGE_HD void sticky_pixel(const VisualParams& p, const AssetView& assets, const VisualState& s,
                          const FrameConstants& f, int32_t r, int32_t c, uint8_t* rgb) {
  for (int32_t i = 0; i < s.sticky_count; ++i) {
    const SpriteFrame& fr =
        sprite_frame_at(assets, sprite_set_at(assets.sticky_types, s.sticky_type[i]), s.sticky_frame);
    blend_sprite_pixel(assets, fr, f.agent_cx + s.sticky_offset[i], s.sticky_y[i], p.hh, r, c, rgb);
  }
}

/// Draws the agent over pixel (r, c) (spec 6.5): sprite, else shape, else the fallback rectangle.
KAGE_HD void agent_pixel(const VisualParams& p, const AssetView& assets, const VisualState& s,
                         const FrameConstants& f, int32_t r, int32_t c, uint8_t* rgb) {
  if (p.use_sprites) {
    if (assets.agent_skins.count <= 0) return;  // invisible agent (11.9)
    const SpriteFrame& fr = sprite_frame_at(assets, sprite_set_at(assets.agent_skins, s.skin_idx), s.sprite_idx);
    blend_sprite_pixel(assets, fr, f.agent_cx, f.agent_cy, p.hh, r, c, rgb);
    return;
  }
  if (p.use_shape) {
    // The original tests every pixel; every shape fits in max(w, h) pixels of the centre, so only
    // that box is tested (same result).
    const int32_t e = maxi(p.char_width, p.char_height);
    if (c < f.agent_cx - e || c > f.agent_cx + e || r < f.agent_cy - e || r > f.agent_cy + e) return;
    const ShapeType type = p.shape_types[clampi(s.shape_type_idx, 0, p.shape_type_count - 1)];
    if (inside_agent_shape(type, f.agent_cx, f.agent_cy, p.char_width, p.char_height, f.agent_shape, c, r)) {
      set_rgb(rgb, p.shape_colors[clampi(s.shape_color_idx, 0, p.shape_color_count - 1)]);
    }
    return;
  }
  if (c >= f.agent_cx - p.hw && c <= f.agent_cx + p.hw && r >= f.agent_cy - p.hh && r <= f.agent_cy + p.hh) {
    set_rgb(rgb, p.fallback_color);
  }
}

/// Inclusive screen box outside which agent_pixel leaves a pixel unchanged (empty when x1 < x0).
struct ScreenBox {
  int32_t x0, x1, y0, y1;
};

/// The box of agent_pixel's three cases: the sprite frame, the shape's reach, the rectangle.
KAGE_HD ScreenBox agent_box(const VisualParams& p, const AssetView& assets, const VisualState& s,
                            const FrameConstants& f) {
  if (p.use_sprites) {
    if (assets.agent_skins.count <= 0) return ScreenBox{0, -1, 0, -1};
    const SpriteFrame& fr = sprite_frame_at(assets, sprite_set_at(assets.agent_skins, s.skin_idx), s.sprite_idx);
    const int32_t x0 = f.agent_cx - fr.width / 2, y0 = f.agent_cy + p.hh - fr.height;
    return ScreenBox{x0, x0 + fr.width - 1, y0, y0 + fr.height - 1};
  }
  if (p.use_shape) {
    const ShapeType type = p.shape_types[clampi(s.shape_type_idx, 0, p.shape_type_count - 1)];
    const int32_t e = agent_shape_reach(type, p.char_width, p.char_height);
    return ScreenBox{f.agent_cx - e, f.agent_cx + e, f.agent_cy - e, f.agent_cy + e};
  }
  return ScreenBox{f.agent_cx - p.hw, f.agent_cx + p.hw, f.agent_cy - p.hh, f.agent_cy + p.hh};
}

/// Whether compose_pixel depends only on solid(r, c) at every pixel outside agent_box: the background
/// is one colour (black, colour mode, or image mode without images) and nothing but the agent is drawn
/// over the layout. Renderers then compose one pixel per colour and select per pixel.
KAGE_HD bool compose_layout_only(const VisualParams& p, const AssetView& assets) {
  const bool uniform_bg = p.bg_mode == BackgroundMode::kBlack || p.bg_mode == BackgroundMode::kColor ||
                          (p.bg_mode == BackgroundMode::kImage && assets.bg_count <= 0);
  return uniform_bg && distractor_slots(p) == 0 && !(p.npc_enabled && assets.npc_types.count > 0) &&
         !(p.sticky_enabled && assets.sticky_types.count > 0);
}

/// The scene under the agent at pixel (r, c) (spec 6.1 steps 1-6): background, distractors, layout,
/// NPCs. `solid(r, wc)` is the layout's mask at screen row r and world column wc; it clamps both like
/// the original's gathers (6.3).
template <class SolidFn>
KAGE_HD void scene_pixel(const VisualParams& p, const AssetView& assets, const AgentView& agent, const SolidFn& solid,
                         const VisualState& s, const FrameConstants& f, int32_t r, int32_t c, uint8_t* rgb) {
  background_pixel(p, assets, s, agent.camera_x, r, c, rgb);
  distractors_pixel(p, s, f, r, c, rgb);
  if (solid(r, c + f.cam)) set_rgb(rgb, p.layout_colors[clampi(s.layout_color_idx, 0, p.layout_color_count - 1)]);
  if (p.npc_enabled && assets.npc_types.count > 0) npcs_pixel(p, assets, s, f, r, c, rgb);
  if (p.sticky_enabled && assets.sticky_types.count > 0) sticky_pixel(p, assets, s, f, r, c, rgb);
}

/// The composited scene at pixel (r, c) before filters (spec 6.1 steps 1-7).
template <class SolidFn>
KAGE_HD void compose_pixel(const VisualParams& p, const AssetView& assets, const AgentView& agent, const SolidFn& solid,
                           const VisualState& s, const FrameConstants& f, int32_t r, int32_t c, uint8_t* rgb) {
  scene_pixel(p, assets, agent, solid, s, f, r, c, rgb);
  agent_pixel(p, assets, s, f, r, c, rgb);
}

}  // namespace kage
