// Lowering: values and palettes of known configs (golden/README.md, spec 3.1, 11.11), and the capacity
// errors for configs the runtime cannot hold, from Environment::open and from `kagec lint`.
#include <catch2/catch.hpp>

#include <sstream>

#include "api/environment.h"
#include "compiler/lower/lower.h"
#include "compiler/sema/resolve.h"
#include "compiler/sema/schema.h"
#include "driver/commands.h"
#include "tests/integration/integration_support.h"

namespace {

using kage::test::kRoot;

kage::LoweredConfig lower_file(const std::string& path, const std::optional<std::string>& root = std::nullopt) {
  kage::SourceManager sources;
  kage::DiagEngine diags(sources);
  kage::DiskFileReader reader;
  kage::ResolveOptions options;
  options.asset_root = root;
  const std::optional<kage::Spec> spec = kage::analyze_file(path, options, sources, reader, diags);
  REQUIRE(spec);
  REQUIRE_FALSE(diags.has_errors());
  kage::LowerResult r = kage::lower_spec(*spec);
  INFO(r.error_text());
  REQUIRE(r.ok());
  return *r.config;
}

bool same(kage::Rgb a, kage::Rgb b) { return a.r == b.r && a.g == b.g && a.b == b.b; }

}  // namespace

TEST_CASE("the golden configs lower to the README's physics, layout and reward", "[integration][lower]") {
  const kage::LoweredConfig d = lower_file(kRoot + "/configs/golden/default.yaml");
  CHECK(d.latent.gravity == 0.75f);
  CHECK(d.latent.max_speed_x == 1.0f);  // legacy move_speed
  CHECK(d.latent.jump_velocity == -7.5f);
  CHECK(d.latent.terminal_velocity == 8.0f);
  CHECK(d.latent.run_width == 25);
  CHECK(d.latent.layout_t_flat == 0.3f);
  CHECK(d.latent.layout_t_up == 0.65f);
  CHECK(d.latent.hw == 8);
  CHECK(d.latent.hh == 12);
  CHECK(d.latent.dist_to_success == 490.0f);
  CHECK(d.visual.bg_mode == kage::BackgroundMode::kBlack);
  CHECK(d.visual.use_shape);
  CHECK_FALSE(d.visual.use_sprites);
  CHECK(same(d.visual.shape_colors[0], kage::Rgb{0, 128, 128}));   // teal
  CHECK(same(d.visual.layout_colors[0], kage::Rgb{0, 255, 255}));  // cyan drawn from SHAPE_COLORS
  CHECK(d.assets.backgrounds.empty());
  const kage::LoweredConfig v = lower_file(kRoot + "/configs/golden/variant.yaml");
  CHECK(v.latent.episode_length == 300);
  CHECK(v.latent.pix_per_unit == 3);
  CHECK(v.latent.layout_t_flat == static_cast<float>(1.0 - 0.9));
  CHECK(v.latent.layout_t_up == static_cast<float>(1.0 - 0.9 + 0.9 * 0.6));
  CHECK(v.latent.air_resistance == 0.9f);
}

TEST_CASE("palettes: layout gray draws (80,80,80), lights by index, unknown-free fallbacks", "[integration][lower]") {
  const kage::test::TempConfig cfg(
      "palette", kage::test::extends_golden_default() +
                     "layout:\n  layout_colors: [gray, red, black]\n"
                     "background:\n  mode: color\n  color_names: [red, teal]\n"
                     "effects:\n  point_light_enabled: true\n  point_light_falloff: 3\n"
                     "  point_light_color_names: [blue, fire]\n"
                     "filters:\n  pop_filter_list: [noir, none]\n  pop_filter: retro\n"
                     "character:\n  shape_types: [star, diamond]\n");
  const kage::LoweredConfig c = lower_file(cfg.path());
  REQUIRE(c.visual.layout_color_count == 3);
  CHECK(same(c.visual.layout_colors[0], kage::Rgb{80, 80, 80}));
  CHECK(same(c.visual.layout_colors[1], kage::Rgb{255, 0, 0}));
  CHECK(same(c.visual.layout_colors[2], kage::Rgb{80, 80, 80}));
  CHECK(c.visual.bg_mode == kage::BackgroundMode::kColor);
  CHECK(same(c.visual.bg_colors[0], kage::Rgb{220, 20, 60}));  // COLOR_PALETTE red, not SHAPE_COLORS
  CHECK(same(c.visual.bg_colors[1], kage::Rgb{0, 128, 128}));
  CHECK(c.visual.point_light_falloff_int == 3);
  CHECK(same(c.visual.light_colors[0], kage::Rgb{100, 150, 255}));
  CHECK(same(c.visual.light_colors[1], kage::Rgb{255, 140, 0}));
  CHECK(same(c.visual.light_colors[2], kage::Rgb{100, 150, 255}));
  CHECK(c.visual.pop_filter_count == 2);
  CHECK(c.visual.pop_filter_list[0] == kage::Preset::kNoir);
  CHECK(c.visual.pop_filter_list[1] == kage::Preset::kNone);
  CHECK(c.visual.pop_filter == kage::Preset::kRetro);
  CHECK(c.visual.shape_types[0] == kage::ShapeType::kStar);
  CHECK(c.visual.shape_types[1] == kage::ShapeType::kDiamond);
}

TEST_CASE("the original-format image config lowers its assets", "[integration][lower]") {
  // The fixture writes src/kage_bench/assets/...; ../shared/kage-assets stands in for that folder here.
  const kage::test::TempConfig holder("assets-root", "{}\n");
  const std::filesystem::path root = std::filesystem::path(holder.path()).parent_path();
  std::filesystem::create_directories(root / "src/kage_bench");
  std::filesystem::create_directory_symlink(std::filesystem::absolute(kRoot + "/../shared/kage-assets"),
                                            root / "src/kage_bench/assets");
  const kage::LoweredConfig c = lower_file(kRoot + "/tests/compat/original/filters/1-train.yaml", root.string());
  REQUIRE(c.assets.backgrounds.size() == 1);
  CHECK(c.assets.backgrounds[0].find("bg-1.jpeg") != std::string::npos);
  REQUIRE(c.assets.agent_skins.size() == 1);
  CHECK(c.assets.agent_skins[0].find("skeleton") != std::string::npos);
  CHECK(c.visual.bg_mode == kage::BackgroundMode::kImage);
  CHECK(c.visual.use_sprites);
  CHECK(c.visual.animation_fps == 12.0f);
}

TEST_CASE("configs beyond the runtime's capacity are rejected with the key and the limit", "[integration][lower]") {
  const kage::test::TempConfig cfg("capacity", kage::test::extends_golden_default() +
                                                   "distractors:\n  enabled: true\n  count: 40\n"
                                                   "layout:\n  min_height: 0\n  max_height: 300\n");
  kage::EnvironmentResult r = kage::Environment::open(cfg.path(), kage::EnvironmentOptions{});
  CHECK_FALSE(r.ok());
  CHECK(r.error.find("'distractors.count' is 40") != std::string::npos);
  CHECK(r.error.find("at most 16") != std::string::npos);
  CHECK(r.error.find("'layout.max_height'") != std::string::npos);
  CHECK(r.error.find("[capacity-exceeded]") != std::string::npos);

  // kagec lint reports them at the key.
  std::ostringstream out, err;
  kage::CommandIo io{out, err};
  CHECK(kage::run_kagec({"lint", cfg.path()}, io) == kage::kExitErrors);
  CHECK(err.str().find("config.yaml:4:3: error: 'distractors.count' is 40") != std::string::npos);
  CHECK(err.str().find("config.yaml:7:3: error: 'layout.max_height' minus 'layout.min_height' is 300") !=
        std::string::npos);

  // A disabled feature is not held to its capacity.
  const kage::test::TempConfig off("capacity-off", kage::test::extends_golden_default() +
                                                       "distractors:\n  enabled: false\n  count: 40\n");
  CHECK(kage::Environment::open(off.path(), kage::EnvironmentOptions{}).ok());
}

TEST_CASE("every capacity bound in the schema is known to lowering", "[integration][lower]") {
  size_t bounded = 0;
  for (const kage::KeySchema& k : kage::config_schema().keys()) {
    if (k.capacity_limit.empty()) continue;
    ++bounded;
    INFO(k.path << " names limit " << k.capacity_limit);
    CHECK(kage::capacity_limit_known(k.capacity_limit));
    if (!k.capacity_minus.empty()) CHECK(kage::config_schema().find(k.capacity_minus) != nullptr);
  }
  CHECK(bounded >= 10);
}
