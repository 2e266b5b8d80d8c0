// The two throughput configurations of the suite (spec kage-bench-suite.md "Throughput configurations")
// written out as lowered parameters, for the GPU benchmark until `kagec compile` output is read instead:
// "simplest" (SHAPE_BLACK: black background, teal circle agent, nothing else) and "hardest" (the YAML
// defaults with every visual stage on). Values are the YAML values of spec kage-env.md section 1.
// Compiles under nvcc, NVRTC and a host compiler: the configs are also kernel template arguments.
#pragma once

#include "runtime/kage_hd.h"
#include "runtime/latent/latent_params.h"
#include "runtime/visual/visual_params.h"

namespace kage::bench {

/// The YAML physics, layout and reward (both configs share the hidden game).
KAGE_HD constexpr LatentParams yaml_latent() {
  LatentParams p{};
  p.screen_h = 128;
  p.screen_w = 128;
  p.char_width = 16;
  p.hw = 8;
  p.hh = 12;
  p.length = 2048;
  p.height_px = 128;
  p.base_ground_y = 96;
  p.pix_per_unit = 2;
  p.ground_thickness = 2;
  p.run_width = 25;
  p.layout_t_flat = 0.3f;  // layout_thresholds(0.7, 0.5)
  p.layout_t_up = 0.65f;
  p.min_step_height = 5;
  p.max_step_height = 17;
  p.min_height = 0;
  p.max_height = 20;
  p.left_margin = 40;
  p.right_margin = 40;
  p.gravity = 0.75f;
  p.jump_velocity = -7.5f;
  p.max_speed_x = 1.0f;
  p.terminal_velocity = 8.0f;
  p.ground_friction = 0.8f;
  p.air_resistance = 0.95f;
  p.ground_accel = 1.0f;
  p.air_accel = 0.4f;
  p.coyote_time = 3;
  p.ground_snap_dist = 2;
  p.episode_length = 500;
  p.forward_reward_scale = 0.2f;
  p.jump_penalty = 10.0f;
  p.timestep_penalty = 0.1f;
  p.idle_penalty = 5.0f;
  p.dist_to_success = 490.0f;
  return p;
}

/// Visual values shared by both configs (YAML values; every filter at its identity, lights off).
KAGE_HD constexpr VisualParams yaml_visual_base() {
  VisualParams p{};
  p.H = 128;
  p.W = 128;
  p.char_width = 16;
  p.char_height = 24;
  p.hw = 8;
  p.hh = 12;
  p.world_length = 2048;
  p.base_ground_y = 96;
  p.gravity = 0.75f;
  p.jump_velocity = -7.5f;
  p.bg_mode = BackgroundMode::kBlack;
  p.parallax_factor = 0.5f;
  p.tile_horizontal = true;
  p.fallback_color = Rgb{255, 0, 0};
  p.enable_animation = true;
  p.animation_fps = 12.0f;
  p.shape_type_count = 1;
  p.shape_types[0] = ShapeType::kCircle;
  p.shape_color_count = 1;
  p.shape_colors[0] = Rgb{0, 128, 128};  // teal
  p.shape_rotation_speed = 5.0f;
  p.layout_color_count = 1;
  p.layout_colors[0] = Rgb{0, 255, 255};  // "cyan", drawn from SHAPE_COLORS
  p.npc_animation_fps = 12.0f;
  p.max_npc_count = 20;
  p.min_npc_count = 5;
  p.max_sticky_count = 5;
  p.min_sticky_count = 1;
  p.sticky_can_jump = true;
  p.sticky_jump_probability = 0.01f;
  p.sticky_y_randomize = true;
  p.sticky_y_min_offset = -40;
  p.sticky_y_max_offset = -10;
  p.sticky_x_bounds_set = true;
  p.sticky_x_min = -60;
  p.sticky_x_max = 60;
  p.distractor_can_move = true;
  p.distractor_max_speed = 1.0f;
  p.distractor_can_rotate = true;
  p.distractor_min_rotation = -0.3f;
  p.distractor_max_rotation = 0.3f;
  p.distractor_min_size = 4;
  p.distractor_max_size = 12;
  p.contrast = 1.0f;
  p.gamma = 1.0f;
  p.saturation = 1.0f;
  p.pixelate_factor = 1;
  p.radial_light_color = Rgb{255, 255, 200};
  p.point_light_intensity = 1.0f;
  p.point_light_radius = 0.1f;
  p.point_light_falloff = 2.0f;
  p.point_light_falloff_int = 2;
  p.point_light_count = 4;
  for (int32_t i = 0; i < kMaxLights; ++i) p.light_colors[i] = Rgb{255, 255, 255};
  return p;
}

/// "simplest" = SHAPE_BLACK: black background, a teal circle agent (no rotation), no NPCs, no
/// distractors, no filters, no lights.
KAGE_HD constexpr VisualParams simplest_visual() {
  VisualParams p = yaml_visual_base();
  p.use_sprites = false;
  p.use_shape = true;
  return p;
}

/// "hardest": image backgrounds switching with probability 0.01, sprite agent, 20 world NPCs, 5 sticky
/// NPCs, 10 distractors of all 9 shapes, every filter of the suite table, 5 point lights, 16 layout
/// colours. The suite lists 21 distractor colours; VisualParams holds kMaxListEntries = 16, so the
/// first 16 of SHAPE_COLORS' order are used (same cost per pixel).
KAGE_HD constexpr VisualParams hardest_visual() {
  VisualParams p = yaml_visual_base();
  p.bg_mode = BackgroundMode::kImage;
  p.switch_frequency = 0.01f;
  p.use_sprites = true;
  p.use_shape = false;
  const Rgb layout[16] = {{80, 80, 80},   {255, 255, 255}, {255, 0, 0},     {255, 165, 0},
                          {255, 255, 0},  {0, 255, 0},     {0, 255, 255},   {0, 0, 255},
                          {128, 0, 128},  {255, 192, 203}, {165, 42, 42},   {80, 80, 80},
                          {0, 255, 0},    {0, 128, 128},   {75, 0, 130},    {255, 0, 255}};
  p.layout_color_count = 16;
  for (int32_t i = 0; i < 16; ++i) p.layout_colors[i] = layout[i];
  p.npc_enabled = true;
  p.min_npc_count = 20;
  p.max_npc_count = 20;
  p.sticky_enabled = true;
  p.min_sticky_count = 5;
  p.max_sticky_count = 5;
  p.distractors_enabled = true;
  p.distractor_count = 10;
  p.distractor_shape_count = 9;
  for (int32_t i = 0; i < 9; ++i) p.distractor_shapes[i] = static_cast<ShapeType>(i);
  const Rgb shape_colors[16] = {{255, 0, 0},   {0, 255, 0},   {0, 0, 255},     {255, 165, 0},
                                {255, 255, 0}, {128, 0, 128}, {255, 0, 255},   {0, 255, 255},
                                {255, 192, 203}, {165, 42, 42}, {128, 0, 128}, {0, 255, 0},
                                {0, 0, 128},   {128, 0, 0},   {128, 128, 0},   {0, 128, 128}};
  p.distractor_color_count = 16;
  for (int32_t i = 0; i < 16; ++i) p.distractor_colors[i] = shape_colors[i];
  p.brightness = 1.0f;
  p.contrast = 2.0f;
  p.gamma = 2.0f;
  p.saturation = 2.0f;
  p.hue_shift = 180.0f;
  p.color_temp = 1.0f;
  p.color_jitter_std = 1.0f;
  p.gaussian_noise_std = 15.0f;
  p.poisson_noise_scale = 1.0f;
  p.blur_sigma = 1.0f;
  p.sharpen_amount = 1.0f;
  p.pixelate_factor = 2;
  p.vignette_strength = 1.0f;
  p.radial_light_strength = 1.0f;
  p.point_light_enabled = true;
  p.point_light_count = 5;
  // names[i mod 12] of the 12 LIGHT_COLORS for slots 0..4.
  const Rgb lights[kMaxLights] = {{255, 245, 230}, {230, 240, 255}, {255, 255, 100}, {255, 160, 50}, {255, 80, 80}};
  for (int32_t i = 0; i < kMaxLights; ++i) p.light_colors[i] = lights[i];
  return p;
}

/// Config types for the kernel templates (the shape of a generated config).
struct SimplestCfg {
  static KAGE_HD constexpr LatentParams latent() { return yaml_latent(); }
  static KAGE_HD constexpr VisualParams visual() { return simplest_visual(); }
};
struct HardestCfg {
  static KAGE_HD constexpr LatentParams latent() { return yaml_latent(); }
  static KAGE_HD constexpr VisualParams visual() { return hardest_visual(); }
};

}  // namespace kage::bench
