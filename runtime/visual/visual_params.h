// Visual parameters: everything rendering and the visual state updates read, already lowered from the
// resolved config (names to ids and RGB, floats to float32). Palettes live in the schema, not here.
#pragma once

#include "runtime/kage_hd.h"

namespace kage {

/// Capacities of the fixed-size lists below. The config lowering rejects configs beyond them.
constexpr int32_t kMaxListEntries = 32;  ///< colour, shape-type and preset lists (SHAPE_COLORS alone has 21 names)
constexpr int32_t kMaxLights = 5;        ///< the original always allocates 5 light slots (spec 8.2)
constexpr int32_t kMaxStickyOffsets = 8; ///< explicit npc.sticky_x_offsets entries

/// background.mode (spec 6.2); any unknown mode string lowers to kBlack.
enum class BackgroundMode : int32_t { kBlack = 0, kImage = 1, kNoise = 2, kColor = 3 };

/// SHAPE_TYPES in the validator's order (spec 3.3); unknown names and aliases are resolved by lowering.
enum class ShapeType : int32_t {
  kCircle = 0,
  kSquare = 1,
  kLine = 2,
  kEllipse = 3,
  kTriangle = 4,
  kStar = 5,
  kPolygon = 6,
  kCross = 7,
  kDiamond = 8,
};

/// Filter presets (spec 3.4); kNone is also "no preset" (the identity).
enum class Preset : int32_t { kNone = 0, kVintage = 1, kRetro = 2, kCyberpunk = 3, kHorror = 4, kNoir = 5 };

/// An RGB colour, uint8 per channel.
struct Rgb {
  uint8_t r, g, b;
};

/// The lowered visual config of one environment batch; the members are listed in visual_params.def.
struct VisualParams {
#define KAGE_PARAM(type, name) type name;
#define KAGE_PARAM_ARRAY(type, name, count) type name[count];
#include "runtime/visual/visual_params.def"
#undef KAGE_PARAM_ARRAY
#undef KAGE_PARAM
};

static_assert(__is_trivially_copyable(VisualParams), "VisualParams must be POD");

/// An H x W config that draws only the black background, the platforms in (80,80,80) and the red
/// fallback rectangle for a 16 x 24 character, every filter at its identity and no entities or lights:
/// the base that lowering and tests change field by field.
KAGE_HD VisualParams identity_visual_params(int32_t H, int32_t W) {
  VisualParams p{};
  p.H = H;
  p.W = W;
  p.char_width = 16;
  p.char_height = 24;
  p.hw = 8;
  p.hh = 12;
  p.world_length = 16 * W;
  p.base_ground_y = 96;
  p.gravity = 0.5f;
  p.jump_velocity = -6.0f;
  p.bg_mode = BackgroundMode::kBlack;
  p.parallax_factor = 0.5f;
  p.tile_horizontal = true;
  p.fallback_color = Rgb{255, 0, 0};
  p.enable_animation = true;
  p.animation_fps = 10.0f;
  p.shape_type_count = 1;
  p.shape_types[0] = ShapeType::kCircle;
  p.shape_color_count = 1;
  p.shape_colors[0] = Rgb{255, 0, 0};
  p.shape_rotation_speed = 2.0f;
  p.layout_color_count = 1;
  p.layout_colors[0] = Rgb{80, 80, 80};
  p.npc_animation_fps = 8.0f;
  p.contrast = 1.0f;
  p.gamma = 1.0f;
  p.saturation = 1.0f;
  p.pixelate_factor = 1;
  p.radial_light_color = Rgb{255, 255, 200};
  p.point_light_intensity = 3.0f;
  p.point_light_radius = 0.1f;
  p.point_light_falloff = 2.0f;
  p.point_light_count = 1;
  for (int32_t i = 0; i < kMaxLights; ++i) p.light_colors[i] = Rgb{255, 245, 230};
  return p;
}

}  // namespace kage
