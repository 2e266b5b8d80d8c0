// The schema against spec section 1 (key names written out by hand here),
// its cross-references (quirk rules, asset groups of key_refs.h), and a scan
// of the C++ sources for key names spelt as string literals.
#include <catch2/catch.hpp>
#include <regex>
#include <set>

#include "compiler/sema/key_refs.h"
#include "compiler/sema/schema.h"
#include "test_support.h"

namespace kage::test {
namespace {

// Spec 1.1-1.9: the 93 keys of default_config.yaml.
const std::set<std::string> kYamlKeys = {
    // 1.1 root (8)
    "episode_length", "forward_reward_scale", "jump_penalty", "timestep_penalty", "idle_penalty", "dist_to_success",
    "H", "W",
    // 1.2 background (6)
    "background.mode", "background.image_dir", "background.parallax_factor", "background.tile_horizontal",
    "background.switch_frequency", "background.color_names",
    // 1.3 character (12)
    "character.width", "character.height", "character.use_sprites", "character.sprite_dir",
    "character.enable_animation", "character.animation_fps", "character.idle_sprite_idx", "character.use_shape",
    "character.shape_types", "character.shape_colors", "character.shape_rotate", "character.shape_rotation_speed",
    // 1.4 npc (17)
    "npc.enabled", "npc.min_npc_count", "npc.max_npc_count", "npc.spawn_y_offset", "npc.animation_fps",
    "npc.sprite_dir", "npc.sticky_enabled", "npc.min_sticky_count", "npc.max_sticky_count", "npc.sticky_sprite_dir",
    "npc.sticky_can_jump", "npc.sticky_jump_probability", "npc.sticky_y_min_offset", "npc.sticky_y_max_offset",
    "npc.sticky_x_offsets", "npc.sticky_x_min", "npc.sticky_x_max",
    // 1.5 distractors (12)
    "distractors.enabled", "distractors.count", "distractors.shape_types", "distractors.shape_colors",
    "distractors.can_move", "distractors.min_speed", "distractors.max_speed", "distractors.can_rotate",
    "distractors.min_rotation_speed", "distractors.max_rotation_speed", "distractors.min_size", "distractors.max_size",
    // 1.6 filters (15)
    "filters.brightness", "filters.contrast", "filters.gamma", "filters.saturation", "filters.hue_shift",
    "filters.color_temp", "filters.color_jitter_std", "filters.gaussian_noise_std", "filters.poisson_noise_scale",
    "filters.blur_sigma", "filters.sharpen_amount", "filters.pixelate_factor", "filters.vignette_strength",
    "filters.radial_light_strength", "filters.pop_filter_list",
    // 1.7 effects (6)
    "effects.point_light_enabled", "effects.point_light_intensity", "effects.point_light_radius",
    "effects.point_light_falloff", "effects.point_light_count", "effects.point_light_color_names",
    // 1.8 layout (11)
    "layout.length", "layout.height_px", "layout.base_ground_y", "layout.pix_per_unit", "layout.ground_thickness",
    "layout.run_width", "layout.p_change", "layout.p_up_given_change", "layout.min_step_height",
    "layout.max_step_height", "layout.layout_colors",
    // 1.9 physics (6, three of them legacy aliases)
    "physics.gravity", "physics.move_speed", "physics.jump_force", "physics.ground_friction", "physics.air_resistance",
    "physics.max_fall_speed",
};

// Spec 1.10: the 25 accepted names absent from default_config.yaml.
const std::set<std::string> kExtraKeys = {
    "camera.left_margin", "camera.right_margin", "layout.min_height", "layout.max_height",
    "physics.terminal_velocity", "physics.jump_velocity", "physics.max_speed_x", "physics.coyote_time",
    "physics.ground_accel", "physics.air_accel", "physics.ground_snap_dist", "background.image_path",
    "background.image_paths", "character.sprite_paths", "character.sprite_path", "character.fallback_color",
    "npc.sprite_paths", "npc.sprite_path", "npc.sticky_sprite_dirs", "npc.sticky_sprite_path",
    "npc.sticky_y_randomize", "filters.jpeg_quality", "filters.radial_light_color", "filters.pop_filter",
    "filters.seed",
};

// Single-word key names that are ordinary English; a literal equal to one of these proves nothing.
const std::set<std::string> kCommonWords = {"enabled", "count", "mode", "width", "height", "length", "seed",
                                            "gravity", "brightness", "contrast", "gamma", "saturation", "H", "W"};

}  // namespace

TEST_CASE("the schema has exactly the 118 key names of spec section 1", "[schema]") {
  REQUIRE(kYamlKeys.size() == 93);
  REQUIRE(kExtraKeys.size() == 25);
  std::set<std::string> with_yaml, without_yaml;
  for (const KeySchema& k : config_schema().keys()) (k.in_default_yaml ? with_yaml : without_yaml).insert(k.path);
  CHECK(config_schema().keys().size() == 118);
  CHECK(with_yaml == kYamlKeys);
  CHECK(without_yaml == kExtraKeys);
  // The JSON text agrees with the table: 93 keys carry x-kage-yaml-default.
  const Json doc = Json::parse(config_schema_text());
  size_t yaml_defaults = 0, keys = 0;
  for (auto& [name, prop] : doc.at("properties").items()) {
    if (prop.contains("properties")) {
      for (auto& [k, v] : prop.at("properties").items()) {
        ++keys;
        yaml_defaults += v.contains("x-kage-yaml-default");
      }
    } else if (!prop.value("x-kage-meta", false)) {
      ++keys;
      yaml_defaults += prop.contains("x-kage-yaml-default");
    }
  }
  CHECK(keys == 118);
  CHECK(yaml_defaults == 93);
}

TEST_CASE("every key has an axis; the legacy aliases and their modern names", "[schema]") {
  const Json doc = Json::parse(config_schema_text());
  for (auto& [name, prop] : doc.at("properties").items()) {
    if (!prop.contains("properties")) {
      if (!prop.value("x-kage-meta", false)) CHECK(prop.contains("x-kage-axis"));
      continue;
    }
    for (auto& [k, v] : prop.at("properties").items()) {
      INFO(name << "." << k);
      REQUIRE(v.contains("x-kage-axis"));
      CHECK(parse_axis(v.at("x-kage-axis").get<std::string>()).has_value());
    }
  }
  const Schema& s = config_schema();
  CHECK(s.find("physics.move_speed")->alias_of == "max_speed_x");
  CHECK(s.find("physics.jump_force")->alias_of == "jump_velocity");
  CHECK(s.find("physics.max_fall_speed")->alias_of == "terminal_velocity");
  size_t aliases = 0;
  for (const KeySchema& k : s.keys()) aliases += !k.alias_of.empty();
  CHECK(aliases == 3);
  // Spot checks of spec 1: latent hitbox under character, layout colour its own axis.
  CHECK(s.find("character.width")->axis == Axis::Latent);
  CHECK(s.find("layout.layout_colors")->axis == Axis::Layout);
  CHECK(s.find("layout.run_width")->axis == Axis::Latent);
  CHECK(s.find("npc.enabled")->axis == Axis::Distractors);
  CHECK(s.find("physics.max_speed_x")->default_value == 3.0);
  CHECK(s.find("effects.point_light_falloff")->yaml_default == 2);
}

TEST_CASE("every x-kage-quirk names a rule of diag_rules.def", "[schema]") {
  size_t quirks = 0;
  for (const KeySchema& k : config_schema().keys()) {
    if (k.quirk_rule.empty()) continue;
    ++quirks;
    INFO(k.path << " -> " << k.quirk_rule);
    const RuleInfo* rule = find_rule(k.quirk_rule);
    REQUIRE(rule != nullptr);
    CHECK(std::string(rule->id).rfind("quirk-", 0) == 0);
    CHECK(!k.quirk_message.empty());
  }
  CHECK(quirks == 7);
}

TEST_CASE("asset keys and the groups of key_refs.h refer to each other", "[schema]") {
  std::set<std::string> sources_in_refs;
  for (const AssetGroupRef& g : kAssetGroups) {
    INFO(g.name);
    REQUIRE(config_schema().find(g.enable_key) != nullptr);
    for (const char* src : g.sources) {
      REQUIRE(src != nullptr);
      INFO(src);
      const KeySchema* k = config_schema().find(src);
      REQUIRE(k != nullptr);
      CHECK(!k->asset_kind.empty());
      sources_in_refs.insert(src);
    }
  }
  for (const KeySchema& k : config_schema().keys()) {
    if (k.asset_kind.empty()) continue;
    INFO(k.path << " (" << k.asset_kind << ") has no group in key_refs.h");
    CHECK(sources_in_refs.count(k.path));
  }
  CHECK(sources_in_refs.size() == 12);
}

// A line may mark a literal that is a field of another format (e.g. a recording) with `not-a-config-key`.
TEST_CASE("no key name is spelt as a string literal in the C++ sources", "[schema][one-source-of-truth]") {
  std::set<std::string> names;
  for (const KeySchema& k : config_schema().keys()) {
    names.insert(k.path);
    if (!kCommonWords.count(k.name)) names.insert(k.name);
  }
  const std::regex literal(R"re("((?:[^"\\\n]|\\.)*)")re");
  std::vector<std::string> offenders;
  for (const char* dir : {"compiler", "runtime", "api", "verify"}) {
    for (const auto& e : fs::recursive_directory_iterator(source_dir() / dir)) {
      if (!e.is_regular_file()) continue;
      const std::string ext = e.path().extension().string();
      if (ext != ".cpp" && ext != ".h" && ext != ".cu" && ext != ".cuh" && ext != ".hpp") continue;
      const std::string rel = fs::relative(e.path(), source_dir()).generic_string();
      if (rel.rfind("compiler/generated/", 0) == 0 || rel == "compiler/sema/key_refs.h") continue;
      std::istringstream in(read_text(e.path()));
      std::string line;
      int n = 0;
      while (std::getline(in, line)) {
        ++n;
        if (line.find("not-a-config-key") != std::string::npos) continue;
        const auto comment = line.find("//");
        const std::string code = comment == std::string::npos ? line : line.substr(0, comment);
        for (auto it = std::sregex_iterator(code.begin(), code.end(), literal); it != std::sregex_iterator(); ++it)
          if (names.count((*it)[1])) offenders.push_back(rel + ":" + std::to_string(n) + ": \"" + (*it)[1].str() + "\"");
      }
    }
  }
  std::string report;
  for (const std::string& o : offenders) report += o + "\n";
  INFO("string literals naming schema keys (use the schema table or compiler/generated/spec_fields.h):\n" << report);
  CHECK(offenders.empty());
}

}  // namespace kage::test
