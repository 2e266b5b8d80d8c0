// Golden replay of the filter chain (spec 7): every case of golden/filters/index.json applied to base.png
// with only its settings changed, compared at the README tolerance (<= 2 codes, >= 99 % equal).
#include <catch2/catch.hpp>

#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "fileio/image_io.h"
#include "tests/runtime/golden_image_support.h"
#include "runtime/visual/filters.h"
#include "runtime/visual/image_diff.h"

namespace {

const std::string kFilters = std::string(KAGE_SOURCE_DIR) + "/../shared/golden/filters/";

kage::Preset preset_named(const std::string& name) {
  if (name == "vintage") return kage::Preset::kVintage;
  if (name == "retro") return kage::Preset::kRetro;
  if (name == "cyberpunk") return kage::Preset::kCyberpunk;
  if (name == "horror") return kage::Preset::kHorror;
  if (name == "noir") return kage::Preset::kNoir;
  return kage::Preset::kNone;
}

/// The identity config with the settings of one index.json case applied.
kage::VisualParams case_params(const nlohmann::json& settings, int H, int W) {
  kage::VisualParams p = kage::identity_visual_params(H, W);
  for (const auto& [key, value] : settings.items()) {
    if (key == "brightness") p.brightness = value.get<float>();
    else if (key == "contrast") p.contrast = value.get<float>();
    else if (key == "gamma") p.gamma = value.get<float>();
    else if (key == "saturation") p.saturation = value.get<float>();
    else if (key == "hue_shift") p.hue_shift = value.get<float>();
    else if (key == "color_temp") p.color_temp = value.get<float>();
    else if (key == "blur_sigma") p.blur_sigma = value.get<float>();
    else if (key == "sharpen_amount") p.sharpen_amount = value.get<float>();
    else if (key == "pixelate_factor") p.pixelate_factor = value.get<int>();
    else if (key == "vignette_strength") p.vignette_strength = value.get<float>();
    else if (key == "radial_light_strength") p.radial_light_strength = value.get<float>();
    else if (key == "pop_filter") p.pop_filter = preset_named(value.get<std::string>());
    else FAIL("unhandled filter setting " << key);
  }
  return p;
}

}  // namespace

TEST_CASE("filter chain reproduces every golden filter case", "[visual][golden]") {
  std::ifstream in(kFilters + "index.json");
  REQUIRE(in.good());
  const nlohmann::json index = nlohmann::json::parse(in);
  REQUIRE(index.size() >= 28);
  const kage::Image base = kage::test::load_rgb(kFilters + "base.png");
  const int n = base.width * base.height * 3;
  std::vector<float> f(n), tmp(n);
  int worst_max = 0;
  double worst_equal = 1.0;
  for (const auto& [name, settings] : index.items()) {
    const kage::VisualParams p = case_params(settings, base.height, base.width);
    REQUIRE_FALSE(kage::filters_identity(p));
    std::vector<uint8_t> img = base.pixels;
    kage::apply_filters(p, kage::Preset::kNone, kage::filter_keys(kage::Key{0, 0}, 0), img.data(), f.data(),
                        tmp.data());
    const kage::Image expected = kage::test::load_rgb(kFilters + name + ".png");
    REQUIRE(expected.pixels.size() == img.size());
    const kage::ImageDiff d = kage::image_diff(img.data(), expected.pixels.data(), n);
    // The case must change the frame (no pass on an untouched input).
    CHECK(kage::image_diff(img.data(), base.pixels.data(), n).max_abs > 0);
    INFO(name << ": max " << d.max_abs << ", equal " << d.equal_fraction() << ", mean " << d.mean_abs());
    CHECK(d.max_abs <= 2);
    CHECK(d.equal_fraction() >= 0.99);
    worst_max = std::max(worst_max, d.max_abs);
    worst_equal = std::min(worst_equal, d.equal_fraction());
  }
  WARN("filters: worst max deviation " << worst_max << ", worst equal share " << worst_equal);
}

TEST_CASE("per-episode preset goes through uint8 before the main chain", "[visual]") {
  // A preset from pop_filter_list alone equals the same preset as pop_filter on an identity chain
  // (both end in a truncation to uint8); stacking both applies it twice (spec 11.41).
  const kage::Image base = kage::test::load_rgb(kFilters + "base.png");
  const int n = base.width * base.height * 3;
  std::vector<float> f(n), tmp(n);
  kage::VisualParams single = kage::identity_visual_params(base.height, base.width);
  single.pop_filter = kage::Preset::kNoir;
  std::vector<uint8_t> a = base.pixels, b = base.pixels, twice = base.pixels;
  const kage::FilterKeys keys = kage::filter_keys(kage::Key{1, 2}, 3);
  kage::apply_filters(single, kage::Preset::kNone, keys, a.data(), f.data(), tmp.data());
  const kage::VisualParams identity = kage::identity_visual_params(base.height, base.width);
  kage::apply_filters(identity, kage::Preset::kNoir, keys, b.data(), f.data(), tmp.data());
  CHECK(kage::image_diff(a.data(), b.data(), n).max_abs == 0);
  kage::apply_filters(single, kage::Preset::kNoir, keys, twice.data(), f.data(), tmp.data());
  CHECK(kage::image_diff(a.data(), twice.data(), n).max_abs > 0);
}
