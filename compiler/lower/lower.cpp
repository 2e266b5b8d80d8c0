// Lowering of a resolved Spec into LatentParams, VisualParams and the asset sources (spec 1, 3.1, 11.11).
#include "compiler/lower/lower.h"

#include <algorithm>
#include <cmath>

#include "compiler/generated/spec_fields.h"
#include "compiler/sema/capacity.h"
#include "compiler/sema/schema.h"
#include "runtime/visual/visual_state.h"

namespace kage {

namespace {

// The bounds capacity_errors checks are the runtime's own.
static_assert(RuntimeCapacity::kNpcSlots == kMaxNpcs && RuntimeCapacity::kStickySlots == kMaxSticky &&
              RuntimeCapacity::kDistractorSlots == kMaxDistractors &&
              RuntimeCapacity::kStickyOffsets == kMaxStickyOffsets && RuntimeCapacity::kListEntries == kMaxListEntries);

/// A config name and the runtime value it lowers to.
template <class E>
struct NamedValue {
  const char* name;
  E value;
};

// The schema's name tables (compiler/generated/spec_fields.h), matched to the runtime's enums by name,
// so the schema's order cannot disagree with the runtime's values (spec 3.3, 3.4, 6.2).
#define KAGE_SHAPE(Id, name) {name, ShapeType::k##Id},
#define KAGE_PRESET(Id, name) {name, Preset::k##Id},
#define KAGE_MODE(Id, name) {name, BackgroundMode::k##Id},
constexpr NamedValue<ShapeType> kShapes[] = {KAGE_SCHEMA_SHAPE_TYPES(KAGE_SHAPE)};
constexpr NamedValue<Preset> kPresets[] = {KAGE_SCHEMA_PRESETS(KAGE_PRESET)};
constexpr NamedValue<BackgroundMode> kModes[] = {KAGE_SCHEMA_BACKGROUND_MODES(KAGE_MODE)};
#undef KAGE_SHAPE
#undef KAGE_PRESET
#undef KAGE_MODE

/// The value named `name`; `fallback` for a name the table lacks.
template <class E, size_t N>
E value_of(const NamedValue<E> (&table)[N], const std::string& name, E fallback) {
  for (const NamedValue<E>& v : table)
    if (name == v.name) return v.value;
  return fallback;
}

/// The name of `value`; "?" for a value the table lacks.
template <class E, size_t N>
const char* name_of(const NamedValue<E> (&table)[N], E value) {
  for (const NamedValue<E>& v : table)
    if (v.value == value) return v.name;
  return "?";
}

Rgb rgb_of(const std::array<int64_t, 3>& c) {
  auto ch = [](int64_t v) { return static_cast<uint8_t>(std::clamp<int64_t>(v, 0, 255)); };
  return Rgb{ch(c[0]), ch(c[1]), ch(c[2])};
}

/// `name` looked up in a schema colour table, `fallback` when it is not there.
Rgb table_color(const char* table, const std::string& name, Rgb fallback) {
  const NameTable* t = config_schema().table(table);
  if (!t) return fallback;
  const auto it = t->rgb.find(name);
  if (it == t->rgb.end()) return fallback;
  return Rgb{static_cast<uint8_t>(it->second[0]), static_cast<uint8_t>(it->second[1]),
             static_cast<uint8_t>(it->second[2])};
}

/// Fills a fixed colour list from names; returns the count (capacity_errors bounds it).
int32_t fill_colors(const std::vector<std::string>& names, const char* table, Rgb fallback, Rgb* out) {
  const int32_t n = std::min<int32_t>(static_cast<int32_t>(names.size()), kMaxListEntries);
  for (int32_t i = 0; i < n; ++i) out[i] = table_color(table, names[i], fallback);
  return n;
}

int32_t fill_shapes(const std::vector<std::string>& names, ShapeType* out) {
  const int32_t n = std::min<int32_t>(static_cast<int32_t>(names.size()), kMaxListEntries);
  for (int32_t i = 0; i < n; ++i) out[i] = value_of(kShapes, names[i], ShapeType::kCircle);
  return n;
}

Preset preset_of(const std::string& name) { return value_of(kPresets, name, Preset::kNone); }

int32_t floor_half(int64_t v) { return static_cast<int32_t>(v >= 0 ? v / 2 : -((-v + 1) / 2)); }

LatentParams lower_latent(const spec_fields::Config& c) {
  LatentParams p{};
  p.screen_h = static_cast<int32_t>(c.H);
  p.screen_w = static_cast<int32_t>(c.W);
  p.char_width = static_cast<int32_t>(c.character.width);
  p.hw = floor_half(c.character.width);
  p.hh = floor_half(c.character.height);
  p.length = static_cast<int32_t>(c.layout.length);
  p.height_px = static_cast<int32_t>(c.layout.height_px);
  p.base_ground_y = static_cast<int32_t>(c.layout.base_ground_y);
  p.pix_per_unit = static_cast<int32_t>(c.layout.pix_per_unit);
  p.ground_thickness = static_cast<int32_t>(c.layout.ground_thickness);
  p.run_width = static_cast<int32_t>(c.layout.run_width);
  layout_thresholds(c.layout.p_change, c.layout.p_up_given_change, p.layout_t_flat, p.layout_t_up);
  p.min_step_height = static_cast<int32_t>(c.layout.min_step_height);
  p.max_step_height = static_cast<int32_t>(c.layout.max_step_height);
  p.min_height = static_cast<int32_t>(c.layout.min_height);
  p.max_height = static_cast<int32_t>(c.layout.max_height);
  p.left_margin = static_cast<int32_t>(c.camera.left_margin);
  p.right_margin = static_cast<int32_t>(c.camera.right_margin);
  p.gravity = static_cast<float>(c.physics.gravity);
  p.jump_velocity = static_cast<float>(c.physics.jump_velocity);
  p.max_speed_x = static_cast<float>(c.physics.max_speed_x);
  p.terminal_velocity = static_cast<float>(c.physics.terminal_velocity);
  p.ground_friction = static_cast<float>(c.physics.ground_friction);
  p.air_resistance = static_cast<float>(c.physics.air_resistance);
  p.ground_accel = static_cast<float>(c.physics.ground_accel);
  p.air_accel = static_cast<float>(c.physics.air_accel);
  p.coyote_time = static_cast<int32_t>(c.physics.coyote_time);
  p.ground_snap_dist = static_cast<int32_t>(c.physics.ground_snap_dist);
  p.episode_length = static_cast<int32_t>(c.episode_length);
  p.forward_reward_scale = static_cast<float>(c.forward_reward_scale);
  p.jump_penalty = static_cast<float>(c.jump_penalty);
  p.timestep_penalty = static_cast<float>(c.timestep_penalty);
  p.idle_penalty = static_cast<float>(c.idle_penalty);
  p.dist_to_success = static_cast<float>(c.dist_to_success);
  return p;
}

void lower_scene(const spec_fields::Config& c, const LatentParams& lp, VisualParams& p) {
  p.char_width = lp.char_width;
  p.char_height = static_cast<int32_t>(c.character.height);
  p.hw = lp.hw;
  p.hh = lp.hh;
  p.world_length = lp.length;
  p.base_ground_y = lp.base_ground_y;
  p.gravity = lp.gravity;
  p.jump_velocity = lp.jump_velocity;

  const auto& bg = c.background;
  p.bg_mode = value_of(kModes, bg.mode, BackgroundMode::kBlack);
  p.parallax_factor = static_cast<float>(bg.parallax_factor);
  p.tile_horizontal = bg.tile_horizontal;
  p.switch_frequency = static_cast<float>(bg.switch_frequency);
  p.bg_color_count = fill_colors(bg.color_names, "colorPaletteName", Rgb{0, 0, 0}, p.bg_colors);

  const auto& ch = c.character;
  p.use_sprites = ch.use_sprites;
  p.use_shape = ch.use_shape;
  p.fallback_color = rgb_of(ch.fallback_color);
  p.enable_animation = ch.enable_animation;
  p.animation_fps = static_cast<float>(ch.animation_fps);
  p.idle_sprite_idx = static_cast<int32_t>(ch.idle_sprite_idx);
  p.shape_type_count = fill_shapes(ch.shape_types, p.shape_types);
  p.shape_color_count = fill_colors(ch.shape_colors, "shapeColorName", Rgb{255, 0, 0}, p.shape_colors);
  p.shape_rotate = ch.shape_rotate;
  p.shape_rotation_speed = static_cast<float>(ch.shape_rotation_speed);

  p.layout_color_count = fill_colors(c.layout.layout_colors, "shapeColorName", Rgb{80, 80, 80}, p.layout_colors);
  if (p.layout_color_count == 0) {  // the original's default "gray" draws (80,80,80)
    p.layout_colors[0] = Rgb{80, 80, 80};
    p.layout_color_count = 1;
  }
}

void lower_entities(const spec_fields::Config& c, VisualParams& p) {
  const auto& n = c.npc;
  p.npc_enabled = n.enabled;
  p.min_npc_count = static_cast<int32_t>(n.min_npc_count);
  p.max_npc_count = static_cast<int32_t>(std::min<int64_t>(n.max_npc_count, kMaxNpcs));
  p.npc_spawn_y_offset = static_cast<int32_t>(n.spawn_y_offset);
  p.npc_animation_fps = static_cast<float>(n.animation_fps);
  p.sticky_enabled = n.sticky_enabled;
  p.min_sticky_count = static_cast<int32_t>(n.min_sticky_count);
  p.max_sticky_count = static_cast<int32_t>(std::min<int64_t>(n.max_sticky_count, kMaxSticky));
  p.sticky_can_jump = n.sticky_can_jump;
  p.sticky_jump_probability = static_cast<float>(n.sticky_jump_probability);
  p.sticky_y_randomize = n.sticky_y_randomize;
  p.sticky_y_min_offset = static_cast<int32_t>(n.sticky_y_min_offset);
  p.sticky_y_max_offset = static_cast<int32_t>(n.sticky_y_max_offset);
  p.sticky_x_offset_count = std::min<int32_t>(static_cast<int32_t>(n.sticky_x_offsets.size()), kMaxStickyOffsets);
  for (int32_t i = 0; i < p.sticky_x_offset_count; ++i) p.sticky_x_offsets[i] = static_cast<int32_t>(n.sticky_x_offsets[i]);
  p.sticky_x_bounds_set = n.sticky_x_min.has_value() && n.sticky_x_max.has_value();
  p.sticky_x_min = static_cast<int32_t>(n.sticky_x_min.value_or(0));
  p.sticky_x_max = static_cast<int32_t>(n.sticky_x_max.value_or(0));

  const auto& d = c.distractors;
  p.distractors_enabled = d.enabled;
  p.distractor_count = static_cast<int32_t>(std::clamp<int64_t>(d.count, 0, kMaxDistractors));
  p.distractor_shape_count = fill_shapes(d.shape_types, p.distractor_shapes);
  p.distractor_color_count = fill_colors(d.shape_colors, "shapeColorName", Rgb{255, 0, 0}, p.distractor_colors);
  p.distractor_can_move = d.can_move;
  p.distractor_max_speed = static_cast<float>(d.max_speed);
  p.distractor_can_rotate = d.can_rotate;
  p.distractor_min_rotation = static_cast<float>(d.min_rotation_speed);
  p.distractor_max_rotation = static_cast<float>(d.max_rotation_speed);
  p.distractor_min_size = static_cast<int32_t>(d.min_size);
  p.distractor_max_size = static_cast<int32_t>(d.max_size);
}

void lower_filters_and_lights(const spec_fields::Config& c, VisualParams& p) {
  const auto& f = c.filters;
  p.brightness = static_cast<float>(f.brightness);
  p.contrast = static_cast<float>(f.contrast);
  p.gamma = static_cast<float>(f.gamma);
  p.saturation = static_cast<float>(f.saturation);
  p.hue_shift = static_cast<float>(f.hue_shift);
  p.color_temp = static_cast<float>(f.color_temp);
  p.color_jitter_std = static_cast<float>(f.color_jitter_std);
  p.gaussian_noise_std = static_cast<float>(f.gaussian_noise_std);
  p.poisson_noise_scale = static_cast<float>(f.poisson_noise_scale);
  p.blur_sigma = static_cast<float>(f.blur_sigma);
  p.sharpen_amount = static_cast<float>(f.sharpen_amount);
  p.pixelate_factor = static_cast<int32_t>(f.pixelate_factor);
  p.vignette_strength = static_cast<float>(f.vignette_strength);
  p.radial_light_strength = static_cast<float>(f.radial_light_strength);
  p.radial_light_color = rgb_of(f.radial_light_color);
  p.pop_filter = f.pop_filter ? preset_of(*f.pop_filter) : Preset::kNone;
  p.pop_filter_count = std::min<int32_t>(static_cast<int32_t>(f.pop_filter_list.size()), kMaxListEntries);
  for (int32_t i = 0; i < p.pop_filter_count; ++i) p.pop_filter_list[i] = preset_of(f.pop_filter_list[i]);

  const auto& e = c.effects;
  p.point_light_enabled = e.point_light_enabled;
  p.point_light_intensity = static_cast<float>(e.point_light_intensity);
  p.point_light_radius = static_cast<float>(e.point_light_radius);
  p.point_light_falloff = static_cast<float>(e.point_light_falloff);
  // An integral exponent is powered by repeated multiplication, as the original does for a YAML int (8.2).
  const double falloff = e.point_light_falloff;
  p.point_light_falloff_int = falloff >= 1 && falloff <= 64 && std::floor(falloff) == falloff ? static_cast<int32_t>(falloff) : 0;
  p.point_light_count = static_cast<int32_t>(std::clamp<int64_t>(e.point_light_count, 1, kMaxLights));
  const auto& names = e.point_light_color_names;
  for (int32_t i = 0; i < kMaxLights; ++i) {
    p.light_colors[i] = names.empty() ? Rgb{255, 255, 255}
                                      : table_color("lightColorName", names[i % names.size()], Rgb{255, 255, 255});
  }
}

AssetSources lower_assets(const Spec& spec, int32_t H) {
  AssetSources s;
  s.height = H;
  for (const AssetFile& f : spec.assets.backgrounds) s.backgrounds.push_back(f.file);
  for (const AssetSet& set : spec.assets.agent_skins) s.agent_skins.push_back(set.dir);
  for (const AssetSet& set : spec.assets.npc_types) s.npc_types.push_back(set.dir);
  for (const AssetSet& set : spec.assets.sticky_types) s.sticky_types.push_back(set.dir);
  return s;
}

}  // namespace

std::string LowerResult::error_text() const {
  std::string out;
  for (const CapacityError& e : errors) out += "'" + e.path + "' " + e.message + "\n";
  return out;
}

LowerResult lower_spec(const Spec& spec) {
  LowerResult result;
  result.errors = capacity_errors(spec);
  if (!result.errors.empty()) return result;
  const spec_fields::Config c = spec_fields::from_json(spec.values);
  LoweredConfig out;
  out.latent = lower_latent(c);
  if (!latent_params_supported(out.latent)) {
    // capacity_errors covers every condition of latent_params_supported; reaching here means an inert mark
    // hid one, so name the layout as a whole.
    result.errors.push_back(CapacityError{"layout", "the layout geometry is outside what the runtime can store"});
    return result;
  }
  out.visual = identity_visual_params(out.latent.screen_h, out.latent.screen_w);
  lower_scene(c, out.latent, out.visual);
  lower_entities(c, out.visual);
  lower_filters_and_lights(c, out.visual);
  out.assets = lower_assets(spec, out.latent.screen_h);
  result.config = std::move(out);
  return result;
}

const char* config_name(BackgroundMode mode) { return name_of(kModes, mode); }
const char* config_name(ShapeType shape) { return name_of(kShapes, shape); }
const char* config_name(Preset preset) { return name_of(kPresets, preset); }

}  // namespace kage
