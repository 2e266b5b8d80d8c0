// Distribution checks of the visual reset and step draws against the ranges of spec 8.1, 9.1-9.3, 4.1,
// plus the noise samplers' moments (A.4).
#include <catch2/catch.hpp>

#include <cmath>
#include <set>

#include "runtime/visual/render.h"
#include "runtime/visual/visual_random.h"
#include "runtime/visual/visual_update.h"

namespace {

constexpr int kEpisodes = 400;

/// A flat world: ground_top 76 everywhere.
struct FlatGround {
  int32_t operator()(int32_t) const { return 76; }
};

/// Sprite tables with `types` one-frame sets (no pixels needed for spawn and step).
struct FakeSprites {
  kage::SpriteSet sets[4] = {{0, 1}, {0, 1}, {0, 1}, {0, 1}};
  kage::AssetView view(int types) const {
    kage::AssetView a{};
    a.npc_types = kage::SpriteSetTable{sets, types, 1};
    a.sticky_types = kage::SpriteSetTable{sets, types, 1};
    return a;
  }
};

kage::VisualParams busy_params(int length) {
  kage::VisualParams p = kage::identity_visual_params(128, 128);
  p.world_length = length;
  p.npc_enabled = true;
  p.min_npc_count = 5;
  p.max_npc_count = 20;
  p.sticky_enabled = true;
  p.min_sticky_count = 1;
  p.max_sticky_count = 5;
  p.sticky_y_randomize = true;
  p.sticky_y_min_offset = -40;
  p.sticky_y_max_offset = -10;
  p.sticky_x_bounds_set = true;
  p.sticky_x_min = -60;
  p.sticky_x_max = 60;
  p.distractors_enabled = true;
  p.distractor_count = 5;
  p.distractor_shape_count = 3;
  p.distractor_color_count = 3;
  p.distractor_can_move = true;
  p.distractor_max_speed = 1.0f;
  p.distractor_can_rotate = true;
  p.distractor_min_rotation = -0.3f;
  p.distractor_max_rotation = 0.3f;
  p.distractor_min_size = 4;
  p.distractor_max_size = 12;
  return p;
}

}  // namespace

TEST_CASE("reset draws stay in the original's ranges", "[visual][distribution]") {
  const FakeSprites sprites;
  for (int length : {2048, 256}) {
    const kage::VisualParams p = busy_params(length);
    const kage::AssetView a = sprites.view(3);
    const int x_hi = std::max(300, length - 200);  // exclusive bound of 9.1, then clipped to L - 1
    std::set<int> counts, sizes;
    float lx_min = 1, lx_max = 0;
    for (int e = 0; e < kEpisodes; ++e) {
      kage::VisualState s;
      kage::visual_reset(p, a, kage::Key{7u, static_cast<uint32_t>(e)}, FlatGround{}, s);
      for (int i = 0; i < kage::kMaxLights; ++i) {
        CHECK(s.light_x[i] >= 0.15f);
        CHECK(s.light_x[i] < 0.85f);
        CHECK(s.light_y[i] >= 0.15f);
        CHECK(s.light_y[i] < 0.85f);
        lx_min = std::min(lx_min, s.light_x[i]);
        lx_max = std::max(lx_max, s.light_x[i]);
      }
      REQUIRE(s.npc_count >= 5);
      REQUIRE(s.npc_count <= 20);
      counts.insert(s.npc_count);
      for (int i = 0; i < s.npc_count; ++i) {
        CHECK(s.npc_x[i] >= std::min(200, length - 1));
        CHECK(s.npc_x[i] < std::min(x_hi, length));
        CHECK(s.npc_y[i] == 76 - 12 - 2);
        CHECK(s.npc_type[i] >= 0);
        CHECK(s.npc_type[i] < 3);
      }
      CHECK(s.sticky_count >= 1);
      CHECK(s.sticky_count <= 5);
      for (int i = 0; i < 5; ++i) {
        CHECK(s.sticky_offset[i] >= -60);
        CHECK(s.sticky_offset[i] <= 60);
        CHECK(s.sticky_home_y[i] >= 96 - 40);
        CHECK(s.sticky_home_y[i] <= 96 - 10);
      }
      for (int i = 0; i < 5; ++i) {
        CHECK(s.dist_x[i] >= 15.0f);
        CHECK(s.dist_x[i] < 113.0f);
        CHECK(s.dist_y[i] >= 15.0f);
        CHECK(s.dist_y[i] < 113.0f);
        CHECK(std::fabs(s.dist_vx[i]) <= 1.0f);
        CHECK(s.dist_rot[i] >= -0.3f);
        CHECK(s.dist_rot[i] < 0.3f);
        CHECK(s.dist_size[i] >= 4);
        CHECK(s.dist_size[i] <= 12);
        sizes.insert(s.dist_size[i]);
      }
    }
    // Both ends of the inclusive ranges occur, and the light positions spread over the range.
    CHECK(counts.count(5) == 1);
    CHECK(counts.count(20) == 1);
    CHECK(sizes.count(4) == 1);
    CHECK(sizes.count(12) == 1);
    CHECK(lx_min < 0.2f);
    CHECK(lx_max > 0.8f);
  }
}

TEST_CASE("distractors and sticky NPCs stay in bounds while stepping", "[visual][distribution]") {
  const FakeSprites sprites;
  kage::VisualParams p = busy_params(2048);
  p.sticky_can_jump = true;
  p.sticky_jump_probability = 0.2f;
  p.gravity = 0.75f;
  p.jump_velocity = -7.5f;
  const kage::AssetView a = sprites.view(2);
  kage::VisualState s;
  const kage::Key ep{3u, 4u};
  kage::visual_reset(p, a, ep, FlatGround{}, s);
  int airborne = 0;
  for (uint32_t t = 1; t <= 500; ++t) {
    kage::visual_step(p, a, ep, t, 1.0f, s);
    for (int i = 0; i < 5; ++i) {
      REQUIRE(s.dist_x[i] >= 15.0f);
      REQUIRE(s.dist_x[i] <= 113.0f);
      REQUIRE(s.dist_angle[i] >= 0.0f);
      REQUIRE(s.dist_angle[i] < 360.0f);
      REQUIRE(s.sticky_y[i] <= s.sticky_home_y[i]);
      airborne += !s.sticky_on_ground[i];
    }
  }
  CHECK(airborne > 100);  // with p = 0.2 the sticky NPCs do jump
}

TEST_CASE("normal and Poisson samplers have the right moments", "[visual][distribution]") {
  const kage::Key k{11u, 12u};
  constexpr int n = 20000;
  double sum = 0, sum2 = 0;
  for (int i = 0; i < n; ++i) {
    const double z = kage::normal(k, i);
    sum += z;
    sum2 += z * z;
  }
  CHECK(std::fabs(sum / n) < 0.03);
  CHECK(std::fabs(sum2 / n - 1.0) < 0.05);
  for (float lam : {0.5f, 4.0f, 25.0f, 120.0f}) {
    double ps = 0, ps2 = 0;
    for (int i = 0; i < n; ++i) {
      const double v = kage::poisson(kage::fold(k, static_cast<uint32_t>(i)), lam);
      ps += v;
      ps2 += v * v;
    }
    const double mean = ps / n, var = ps2 / n - mean * mean;
    INFO("lam " << lam << " mean " << mean << " var " << var);
    CHECK(std::fabs(mean - lam) < 0.05 * lam + 0.03);
    CHECK(std::fabs(var - lam) < 0.1 * lam + 0.05);
  }
}

TEST_CASE("colour mode picks every listed colour and noise is static between switches", "[visual][distribution]") {
  kage::VisualParams p = kage::identity_visual_params(16, 16);
  p.bg_mode = kage::BackgroundMode::kColor;
  p.bg_color_count = 3;
  std::set<int> seen;
  for (int e = 0; e < 100; ++e) {
    kage::VisualState s;
    kage::visual_reset(p, kage::AssetView{}, kage::Key{1u, static_cast<uint32_t>(e)}, FlatGround{}, s);
    seen.insert(s.bg_index);
  }
  CHECK(seen == std::set<int>{0, 1, 2});
  p.bg_mode = kage::BackgroundMode::kNoise;
  p.switch_frequency = 0.0f;
  kage::VisualState s;
  kage::visual_reset(p, kage::AssetView{}, kage::Key{5u, 6u}, FlatGround{}, s);
  const kage::Key before = s.bg_noise_key;
  for (uint32_t t = 1; t <= 20; ++t) kage::visual_step(p, kage::AssetView{}, kage::Key{5u, 6u}, t, 0.0f, s);
  CHECK(s.bg_noise_key.k0 == before.k0);
  CHECK(s.bg_noise_key.k1 == before.k1);
  p.switch_frequency = 1.0f;
  kage::visual_step(p, kage::AssetView{}, kage::Key{5u, 6u}, 21, 0.0f, s);
  CHECK((s.bg_noise_key.k0 != before.k0 || s.bg_noise_key.k1 != before.k1));
}
