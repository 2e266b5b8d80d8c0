// Generated from schemas/kage-config.schema.json by kage_schemagen; do not edit.
// The typed view of a resolved Spec's values: one member per key (legacy aliases
// are resolved into their modern key and do not appear), then the schema's name tables.
#pragma once

#include <array>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

namespace kage::spec_fields {

struct Background {
  std::vector<std::string> color_names{};
  std::optional<std::string> image_dir{};
  std::optional<std::string> image_path{};
  std::vector<std::string> image_paths{};
  std::string mode{};
  double parallax_factor{};
  double switch_frequency{};
  bool tile_horizontal{};
};

struct Camera {
  int64_t left_margin{};
  int64_t right_margin{};
};

struct Character {
  double animation_fps{};
  bool enable_animation{};
  std::array<int64_t, 3> fallback_color{};
  int64_t height{};
  int64_t idle_sprite_idx{};
  std::vector<std::string> shape_colors{};
  bool shape_rotate{};
  double shape_rotation_speed{};
  std::vector<std::string> shape_types{};
  std::optional<std::string> sprite_dir{};
  std::optional<std::string> sprite_path{};
  std::vector<std::string> sprite_paths{};
  bool use_shape{};
  bool use_sprites{};
  int64_t width{};
};

struct Distractors {
  bool can_move{};
  bool can_rotate{};
  int64_t count{};
  bool enabled{};
  double max_rotation_speed{};
  int64_t max_size{};
  double max_speed{};
  double min_rotation_speed{};
  int64_t min_size{};
  double min_speed{};
  std::vector<std::string> shape_colors{};
  std::vector<std::string> shape_types{};
};

struct Effects {
  std::vector<std::string> point_light_color_names{};
  int64_t point_light_count{};
  bool point_light_enabled{};
  double point_light_falloff{};
  double point_light_intensity{};
  double point_light_radius{};
};

struct Filters {
  double blur_sigma{};
  double brightness{};
  double color_jitter_std{};
  double color_temp{};
  double contrast{};
  double gamma{};
  double gaussian_noise_std{};
  double hue_shift{};
  std::optional<double> jpeg_quality{};
  int64_t pixelate_factor{};
  double poisson_noise_scale{};
  std::optional<std::string> pop_filter{};
  std::vector<std::string> pop_filter_list{};
  std::array<int64_t, 3> radial_light_color{};
  double radial_light_strength{};
  double saturation{};
  std::optional<int64_t> seed{};
  double sharpen_amount{};
  double vignette_strength{};
};

struct Layout {
  int64_t base_ground_y{};
  int64_t ground_thickness{};
  int64_t height_px{};
  std::vector<std::string> layout_colors{};
  int64_t length{};
  int64_t max_height{};
  int64_t max_step_height{};
  int64_t min_height{};
  int64_t min_step_height{};
  double p_change{};
  double p_up_given_change{};
  int64_t pix_per_unit{};
  int64_t run_width{};
};

struct Npc {
  double animation_fps{};
  bool enabled{};
  int64_t max_npc_count{};
  int64_t max_sticky_count{};
  int64_t min_npc_count{};
  int64_t min_sticky_count{};
  int64_t spawn_y_offset{};
  std::optional<std::string> sprite_dir{};
  std::optional<std::string> sprite_path{};
  std::vector<std::string> sprite_paths{};
  bool sticky_can_jump{};
  bool sticky_enabled{};
  double sticky_jump_probability{};
  std::optional<std::string> sticky_sprite_dir{};
  std::vector<std::string> sticky_sprite_dirs{};
  std::optional<std::string> sticky_sprite_path{};
  std::optional<int64_t> sticky_x_max{};
  std::optional<int64_t> sticky_x_min{};
  std::vector<int64_t> sticky_x_offsets{};
  int64_t sticky_y_max_offset{};
  int64_t sticky_y_min_offset{};
  bool sticky_y_randomize{};
};

struct Physics {
  double air_accel{};
  double air_resistance{};
  int64_t coyote_time{};
  double gravity{};
  double ground_accel{};
  double ground_friction{};
  int64_t ground_snap_dist{};
  double jump_velocity{};
  double max_speed_x{};
  double terminal_velocity{};
};

struct Config {
  int64_t H{};
  int64_t W{};
  double dist_to_success{};
  int64_t episode_length{};
  double forward_reward_scale{};
  double idle_penalty{};
  double jump_penalty{};
  double timestep_penalty{};
  Background background;
  Camera camera;
  Character character;
  Distractors distractors;
  Effects effects;
  Filters filters;
  Layout layout;
  Npc npc;
  Physics physics;
};

/// Number of keys in a Spec.
inline constexpr size_t kFieldCount = 115;

template <class T>
void read_field(const nlohmann::json& j, const char* key, T& out) {
  const nlohmann::json& v = j.at(key);
  if (!v.is_null()) out = v.get<T>();
}

template <class T>
void read_field(const nlohmann::json& j, const char* key, std::optional<T>& out) {
  const nlohmann::json& v = j.at(key);
  if (!v.is_null()) out = v.get<T>();
}

/// Reads the `config` object of a canonical Spec.
inline Config from_json(const nlohmann::json& c) {
  Config out;
  read_field(c, "H", out.H);
  read_field(c, "W", out.W);
  read_field(c, "dist_to_success", out.dist_to_success);
  read_field(c, "episode_length", out.episode_length);
  read_field(c, "forward_reward_scale", out.forward_reward_scale);
  read_field(c, "idle_penalty", out.idle_penalty);
  read_field(c, "jump_penalty", out.jump_penalty);
  read_field(c, "timestep_penalty", out.timestep_penalty);
  read_field(c.at("background"), "color_names", out.background.color_names);
  read_field(c.at("background"), "image_dir", out.background.image_dir);
  read_field(c.at("background"), "image_path", out.background.image_path);
  read_field(c.at("background"), "image_paths", out.background.image_paths);
  read_field(c.at("background"), "mode", out.background.mode);
  read_field(c.at("background"), "parallax_factor", out.background.parallax_factor);
  read_field(c.at("background"), "switch_frequency", out.background.switch_frequency);
  read_field(c.at("background"), "tile_horizontal", out.background.tile_horizontal);
  read_field(c.at("camera"), "left_margin", out.camera.left_margin);
  read_field(c.at("camera"), "right_margin", out.camera.right_margin);
  read_field(c.at("character"), "animation_fps", out.character.animation_fps);
  read_field(c.at("character"), "enable_animation", out.character.enable_animation);
  read_field(c.at("character"), "fallback_color", out.character.fallback_color);
  read_field(c.at("character"), "height", out.character.height);
  read_field(c.at("character"), "idle_sprite_idx", out.character.idle_sprite_idx);
  read_field(c.at("character"), "shape_colors", out.character.shape_colors);
  read_field(c.at("character"), "shape_rotate", out.character.shape_rotate);
  read_field(c.at("character"), "shape_rotation_speed", out.character.shape_rotation_speed);
  read_field(c.at("character"), "shape_types", out.character.shape_types);
  read_field(c.at("character"), "sprite_dir", out.character.sprite_dir);
  read_field(c.at("character"), "sprite_path", out.character.sprite_path);
  read_field(c.at("character"), "sprite_paths", out.character.sprite_paths);
  read_field(c.at("character"), "use_shape", out.character.use_shape);
  read_field(c.at("character"), "use_sprites", out.character.use_sprites);
  read_field(c.at("character"), "width", out.character.width);
  read_field(c.at("distractors"), "can_move", out.distractors.can_move);
  read_field(c.at("distractors"), "can_rotate", out.distractors.can_rotate);
  read_field(c.at("distractors"), "count", out.distractors.count);
  read_field(c.at("distractors"), "enabled", out.distractors.enabled);
  read_field(c.at("distractors"), "max_rotation_speed", out.distractors.max_rotation_speed);
  read_field(c.at("distractors"), "max_size", out.distractors.max_size);
  read_field(c.at("distractors"), "max_speed", out.distractors.max_speed);
  read_field(c.at("distractors"), "min_rotation_speed", out.distractors.min_rotation_speed);
  read_field(c.at("distractors"), "min_size", out.distractors.min_size);
  read_field(c.at("distractors"), "min_speed", out.distractors.min_speed);
  read_field(c.at("distractors"), "shape_colors", out.distractors.shape_colors);
  read_field(c.at("distractors"), "shape_types", out.distractors.shape_types);
  read_field(c.at("effects"), "point_light_color_names", out.effects.point_light_color_names);
  read_field(c.at("effects"), "point_light_count", out.effects.point_light_count);
  read_field(c.at("effects"), "point_light_enabled", out.effects.point_light_enabled);
  read_field(c.at("effects"), "point_light_falloff", out.effects.point_light_falloff);
  read_field(c.at("effects"), "point_light_intensity", out.effects.point_light_intensity);
  read_field(c.at("effects"), "point_light_radius", out.effects.point_light_radius);
  read_field(c.at("filters"), "blur_sigma", out.filters.blur_sigma);
  read_field(c.at("filters"), "brightness", out.filters.brightness);
  read_field(c.at("filters"), "color_jitter_std", out.filters.color_jitter_std);
  read_field(c.at("filters"), "color_temp", out.filters.color_temp);
  read_field(c.at("filters"), "contrast", out.filters.contrast);
  read_field(c.at("filters"), "gamma", out.filters.gamma);
  read_field(c.at("filters"), "gaussian_noise_std", out.filters.gaussian_noise_std);
  read_field(c.at("filters"), "hue_shift", out.filters.hue_shift);
  read_field(c.at("filters"), "jpeg_quality", out.filters.jpeg_quality);
  read_field(c.at("filters"), "pixelate_factor", out.filters.pixelate_factor);
  read_field(c.at("filters"), "poisson_noise_scale", out.filters.poisson_noise_scale);
  read_field(c.at("filters"), "pop_filter", out.filters.pop_filter);
  read_field(c.at("filters"), "pop_filter_list", out.filters.pop_filter_list);
  read_field(c.at("filters"), "radial_light_color", out.filters.radial_light_color);
  read_field(c.at("filters"), "radial_light_strength", out.filters.radial_light_strength);
  read_field(c.at("filters"), "saturation", out.filters.saturation);
  read_field(c.at("filters"), "seed", out.filters.seed);
  read_field(c.at("filters"), "sharpen_amount", out.filters.sharpen_amount);
  read_field(c.at("filters"), "vignette_strength", out.filters.vignette_strength);
  read_field(c.at("layout"), "base_ground_y", out.layout.base_ground_y);
  read_field(c.at("layout"), "ground_thickness", out.layout.ground_thickness);
  read_field(c.at("layout"), "height_px", out.layout.height_px);
  read_field(c.at("layout"), "layout_colors", out.layout.layout_colors);
  read_field(c.at("layout"), "length", out.layout.length);
  read_field(c.at("layout"), "max_height", out.layout.max_height);
  read_field(c.at("layout"), "max_step_height", out.layout.max_step_height);
  read_field(c.at("layout"), "min_height", out.layout.min_height);
  read_field(c.at("layout"), "min_step_height", out.layout.min_step_height);
  read_field(c.at("layout"), "p_change", out.layout.p_change);
  read_field(c.at("layout"), "p_up_given_change", out.layout.p_up_given_change);
  read_field(c.at("layout"), "pix_per_unit", out.layout.pix_per_unit);
  read_field(c.at("layout"), "run_width", out.layout.run_width);
  read_field(c.at("npc"), "animation_fps", out.npc.animation_fps);
  read_field(c.at("npc"), "enabled", out.npc.enabled);
  read_field(c.at("npc"), "max_npc_count", out.npc.max_npc_count);
  read_field(c.at("npc"), "max_sticky_count", out.npc.max_sticky_count);
  read_field(c.at("npc"), "min_npc_count", out.npc.min_npc_count);
  read_field(c.at("npc"), "min_sticky_count", out.npc.min_sticky_count);
  read_field(c.at("npc"), "spawn_y_offset", out.npc.spawn_y_offset);
  read_field(c.at("npc"), "sprite_dir", out.npc.sprite_dir);
  read_field(c.at("npc"), "sprite_path", out.npc.sprite_path);
  read_field(c.at("npc"), "sprite_paths", out.npc.sprite_paths);
  read_field(c.at("npc"), "sticky_can_jump", out.npc.sticky_can_jump);
  read_field(c.at("npc"), "sticky_enabled", out.npc.sticky_enabled);
  read_field(c.at("npc"), "sticky_jump_probability", out.npc.sticky_jump_probability);
  read_field(c.at("npc"), "sticky_sprite_dir", out.npc.sticky_sprite_dir);
  read_field(c.at("npc"), "sticky_sprite_dirs", out.npc.sticky_sprite_dirs);
  read_field(c.at("npc"), "sticky_sprite_path", out.npc.sticky_sprite_path);
  read_field(c.at("npc"), "sticky_x_max", out.npc.sticky_x_max);
  read_field(c.at("npc"), "sticky_x_min", out.npc.sticky_x_min);
  read_field(c.at("npc"), "sticky_x_offsets", out.npc.sticky_x_offsets);
  read_field(c.at("npc"), "sticky_y_max_offset", out.npc.sticky_y_max_offset);
  read_field(c.at("npc"), "sticky_y_min_offset", out.npc.sticky_y_min_offset);
  read_field(c.at("npc"), "sticky_y_randomize", out.npc.sticky_y_randomize);
  read_field(c.at("physics"), "air_accel", out.physics.air_accel);
  read_field(c.at("physics"), "air_resistance", out.physics.air_resistance);
  read_field(c.at("physics"), "coyote_time", out.physics.coyote_time);
  read_field(c.at("physics"), "gravity", out.physics.gravity);
  read_field(c.at("physics"), "ground_accel", out.physics.ground_accel);
  read_field(c.at("physics"), "ground_friction", out.physics.ground_friction);
  read_field(c.at("physics"), "ground_snap_dist", out.physics.ground_snap_dist);
  read_field(c.at("physics"), "jump_velocity", out.physics.jump_velocity);
  read_field(c.at("physics"), "max_speed_x", out.physics.max_speed_x);
  read_field(c.at("physics"), "terminal_velocity", out.physics.terminal_velocity);
  return out;
}

}  // namespace kage::spec_fields

// The shape types (ShapeType), in the schema's order (/definitions/shapeType/enum).
#define KAGE_SCHEMA_SHAPE_TYPES(X) \
  X(Circle, "circle") \
  X(Square, "square") \
  X(Line, "line") \
  X(Ellipse, "ellipse") \
  X(Triangle, "triangle") \
  X(Star, "star") \
  X(Polygon, "polygon") \
  X(Cross, "cross") \
  X(Diamond, "diamond")

// The filter presets (Preset), in the schema's order (/definitions/presetName/enum).
#define KAGE_SCHEMA_PRESETS(X) \
  X(Vintage, "vintage") \
  X(Retro, "retro") \
  X(Cyberpunk, "cyberpunk") \
  X(Horror, "horror") \
  X(Noir, "noir") \
  X(None, "none")

// The background modes (BackgroundMode), in the schema's order (/properties/background/properties/mode/enum).
#define KAGE_SCHEMA_BACKGROUND_MODES(X) \
  X(Black, "black") \
  X(Image, "image") \
  X(Noise, "noise") \
  X(Color, "color")

// The certification axes (Axis), in the schema's order (/definitions/axisName/enum).
#define KAGE_SCHEMA_AXES(X) \
  X(Background, "background") \
  X(Agent, "agent") \
  X(Distractors, "distractors") \
  X(Filters, "filters") \
  X(Effects, "effects") \
  X(Layout, "layout") \
  X(Latent, "latent")
