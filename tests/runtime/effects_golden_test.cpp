// Golden replay of the point-light pass (spec 8.2): each golden/effects case's lit frame from its unlit
// frame, with the recorded light positions and effect settings (<= 2 codes, >= 99 % equal).
#include <catch2/catch.hpp>

#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "fileio/image_io.h"
#include "tests/runtime/golden_image_support.h"
#include "runtime/visual/image_diff.h"
#include "runtime/visual/lights.h"

namespace {

const std::string kEffects = std::string(KAGE_SOURCE_DIR) + "/../shared/golden/effects/";

/// LIGHT_COLORS entries the recorded configs use (spec 3.1).
const std::map<std::string, kage::Rgb> kLightColors = {
    {"blue", {100, 150, 255}}, {"pink", {255, 150, 200}}, {"gold", {255, 215, 0}}};

}  // namespace

TEST_CASE("point lights reproduce the golden lit frames", "[visual][golden]") {
  std::ifstream in(kEffects + "index.json");
  REQUIRE(in.good());
  const nlohmann::json index = nlohmann::json::parse(in);
  REQUIRE(index.size() == 4);
  int worst_max = 0;
  double worst_equal = 1.0;
  for (const auto& [name, c] : index.items()) {
    const kage::Image unlit = kage::test::load_rgb(kEffects + name + "_unlit.png");
    const kage::Image lit = kage::test::load_rgb(kEffects + name + "_lit.png");
    const nlohmann::json& fx = c["effects"];
    kage::VisualParams p = kage::identity_visual_params(unlit.height, unlit.width);
    p.point_light_enabled = fx["point_light_enabled"].get<bool>();
    p.point_light_intensity = fx["point_light_intensity"].get<float>();
    p.point_light_radius = fx["point_light_radius"].get<float>();
    const nlohmann::json& falloff = fx["point_light_falloff"];
    p.point_light_falloff = falloff.get<float>();
    p.point_light_falloff_int = falloff.is_number_integer() ? falloff.get<int>() : 0;
    p.point_light_count = fx["point_light_count"].get<int>();
    const auto& names = fx["point_light_color_names"];
    for (int i = 0; i < kage::kMaxLights; ++i) {
      p.light_colors[i] = kLightColors.at(names[i % names.size()].get<std::string>());
    }
    kage::VisualState s{};
    for (int i = 0; i < kage::kMaxLights; ++i) {
      s.light_x[i] = c["light_positions"][i][0].get<float>();
      s.light_y[i] = c["light_positions"][i][1].get<float>();
    }
    std::vector<uint8_t> img = unlit.pixels;
    for (int r = 0; r < p.H; ++r)
      for (int col = 0; col < p.W; ++col) kage::light_pixel(p, s, r, col, img.data() + (r * p.W + col) * 3);
    const int64_t n = static_cast<int64_t>(img.size());
    REQUIRE(kage::image_diff(lit.pixels.data(), unlit.pixels.data(), n).max_abs > 0);
    const kage::ImageDiff d = kage::image_diff(img.data(), lit.pixels.data(), n);
    INFO(name << ": max " << d.max_abs << ", equal " << d.equal_fraction());
    CHECK(d.max_abs <= 2);
    CHECK(d.equal_fraction() >= 0.99);
    worst_max = std::max(worst_max, d.max_abs);
    worst_equal = std::min(worst_equal, d.equal_fraction());
  }
  WARN("effects: worst max deviation " << worst_max << ", worst equal share " << worst_equal);
}

TEST_CASE("integer and fractional falloff agree up to rounding", "[visual]") {
  kage::VisualParams p = kage::identity_visual_params(64, 64);
  p.point_light_enabled = true;
  p.point_light_falloff = 3.0f;
  kage::VisualState s{};
  s.light_x[0] = 0.5f;
  s.light_y[0] = 0.25f;
  std::vector<uint8_t> by_pow(64 * 64 * 3, 10), by_mul(64 * 64 * 3, 10);
  kage::VisualParams q = p;
  q.point_light_falloff_int = 3;
  for (int r = 0; r < 64; ++r)
    for (int c = 0; c < 64; ++c) {
      kage::light_pixel(p, s, r, c, by_pow.data() + (r * 64 + c) * 3);
      kage::light_pixel(q, s, r, c, by_mul.data() + (r * 64 + c) * 3);
    }
  CHECK(kage::image_diff(by_pow.data(), by_mul.data(), 64 * 64 * 3).max_abs <= 1);
  // The light centre (row 16, column 32) gets the full warm_white * 3 = saturated.
  CHECK(by_mul[(16 * 64 + 32) * 3] == 255);
}
