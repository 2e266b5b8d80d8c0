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

/// The lowered visual config of one environment batch.
struct VisualParams {
  int32_t H;  ///< observation height
  int32_t W;  ///< observation width

  // Latent values the visuals also read (spec 11.15); copies of the latent config, never written back.
  int32_t char_width;      ///< character.width: NPC visibility margin (9.1), shape size (6.6)
  int32_t char_height;     ///< character.height: shape size (6.6)
  int32_t hw;              ///< character.width // 2: fallback rectangle (6.5)
  int32_t hh;              ///< character.height // 2: sprite bottom anchor of agent and NPCs (6.4)
  int32_t world_length;    ///< layout.length L: world NPC spawn range (9.1)
  int32_t base_ground_y;   ///< layout.base_ground_y: sticky NPC base line (9.2)
  float gravity;           ///< physics.gravity, reused by sticky NPC jumps (9.2)
  float jump_velocity;     ///< physics.jump_velocity, reused by sticky NPC jumps (9.2)

  // Background (spec 1.2, 6.2, 5.9).
  BackgroundMode bg_mode;
  float parallax_factor;
  bool tile_horizontal;
  float switch_frequency;      ///< per-step switch probability in [0, 1]
  int32_t bg_color_count;      ///< entries of bg_colors (COLOR_PALETTE values); 0 draws black
  Rgb bg_colors[kMaxListEntries];

  // Agent (spec 1.3, 5.7, 6.5, 6.6).
  bool use_sprites;             ///< wins over use_shape; no skins loaded = invisible agent (11.9)
  bool use_shape;
  Rgb fallback_color;           ///< rectangle colour when neither sprites nor shapes are used
  bool enable_animation;
  float animation_fps;          ///< > 0 (the lowering rejects 0, spec 11.8)
  int32_t idle_sprite_idx;
  int32_t shape_type_count;     ///< >= 1 when use_shape
  ShapeType shape_types[kMaxListEntries];
  int32_t shape_color_count;    ///< >= 1 when use_shape
  Rgb shape_colors[kMaxListEntries];  ///< SHAPE_COLORS values, fallback (255,0,0)
  bool shape_rotate;
  float shape_rotation_speed;   ///< degrees per step (11.32)

  // Layout colour (spec 4.1 step 3, 11.11): SHAPE_COLORS values, fallback (80,80,80).
  int32_t layout_color_count;   ///< >= 1
  Rgb layout_colors[kMaxListEntries];

  // World NPCs (spec 9.1); active iff npc_enabled and world sprite types were loaded.
  bool npc_enabled;
  int32_t min_npc_count;
  int32_t max_npc_count;        ///< <= kMaxNpcs (visual_state.h)
  int32_t npc_spawn_y_offset;
  float npc_animation_fps;      ///< also drives sticky NPCs; > 0

  // Sticky NPCs (spec 9.2); active iff sticky_enabled and sticky types were loaded.
  bool sticky_enabled;
  int32_t min_sticky_count;
  int32_t max_sticky_count;     ///< <= kMaxSticky (visual_state.h)
  bool sticky_can_jump;
  float sticky_jump_probability;
  bool sticky_y_randomize;
  int32_t sticky_y_min_offset;
  int32_t sticky_y_max_offset;
  int32_t sticky_x_offset_count;  ///< 0: use the bounds below (if set) or the linspace spread
  int32_t sticky_x_offsets[kMaxStickyOffsets];
  bool sticky_x_bounds_set;       ///< both sticky_x_min and sticky_x_max are non-null
  int32_t sticky_x_min;
  int32_t sticky_x_max;

  // Distractors (spec 9.3, 9.4).
  bool distractors_enabled;
  int32_t distractor_count;     ///< <= kMaxDistractors (visual_state.h)
  int32_t distractor_shape_count;
  ShapeType distractor_shapes[kMaxListEntries];
  int32_t distractor_color_count;
  Rgb distractor_colors[kMaxListEntries];  ///< SHAPE_COLORS values, fallback (255,0,0)
  bool distractor_can_move;
  float distractor_max_speed;   ///< min_speed is unused by the original (11.35)
  bool distractor_can_rotate;
  float distractor_min_rotation;  ///< radians per step in effect (11.34)
  float distractor_max_rotation;
  int32_t distractor_min_size;
  int32_t distractor_max_size;

  // Filters (section 7); identity values disable a stage.
  float brightness;
  float contrast;
  float gamma;
  float saturation;
  float hue_shift;              ///< degrees
  float color_temp;
  float color_jitter_std;
  float gaussian_noise_std;
  float poisson_noise_scale;
  float blur_sigma;
  float sharpen_amount;
  int32_t pixelate_factor;
  float vignette_strength;
  float radial_light_strength;
  Rgb radial_light_color;
  Preset pop_filter;            ///< single preset inside the main chain; kNone = null (7.1 step 1)
  int32_t pop_filter_count;     ///< entries of pop_filter_list; 0 = no per-episode preset
  Preset pop_filter_list[kMaxListEntries];

  // Point lights (spec 8.2).
  bool point_light_enabled;
  float point_light_intensity;
  float point_light_radius;     ///< fraction of the image diagonal
  float point_light_falloff;    ///< exponent, used through powf when point_light_falloff_int == 0
  int32_t point_light_falloff_int;  ///< > 0: the YAML gave an integer, powered by repeated multiplication
  int32_t point_light_count;    ///< 1..5
  Rgb light_colors[kMaxLights]; ///< slot i = LIGHT_COLORS[names[i mod len]], fallback (255,255,255)
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
