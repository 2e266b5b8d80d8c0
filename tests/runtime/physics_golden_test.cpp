// Golden replay of the latent dynamics: the original's recorded trajectories (../shared/golden/physics_*.json)
// replayed on their recorded layouts, plus the worked examples of spec Appendix B.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "runtime/latent/latent_step.h"
#include "tests/runtime/latent_test_params.h"

namespace {

using kage::LatentParams;
using kage::LatentState;
using kage::LayoutView;
using kage::StepOutcome;
using nlohmann::json;

constexpr double kFloatTolerance = 1e-4;  // golden/README.md

json load_golden(const std::string& name) {
  const std::string path = std::string(KAGE_SOURCE_DIR) + "/../shared/golden/" + name;
  std::ifstream in(path);
  REQUIRE(in.good());
  return json::parse(in);
}

/// Value of a recorded field after a step, as a double (bools and ints exactly representable).
double field_value(const std::string& f, const LatentState& s, const StepOutcome& o) {
  if (f == "x") return s.x;
  if (f == "y") return s.y;
  if (f == "vx") return s.vx;
  if (f == "vy") return s.vy;
  if (f == "grounded") return s.grounded;
  if (f == "coyote_timer") return s.coyote_timer;
  if (f == "camera_x") return s.camera_x;
  if (f == "x_max") return s.x_max;
  if (f == "jump_count") return s.jump_count;
  if (f == "episode_return") return s.episode_return;
  if (f == "t") return s.t;
  if (f == "success_once") return s.success_once;
  if (f == "reward") return o.reward;
  if (f == "passed_distance") return o.passed_distance;
  if (f == "progress") return o.progress;
  if (f == "success") return o.success;
  if (f == "truncated") return o.truncated;
  FAIL("unknown golden field " << f);
  return 0.0;
}

double as_number(const json& v) { return v.is_boolean() ? (v.get<bool>() ? 1.0 : 0.0) : v.get<double>(); }

bool is_exact_field(const json& v) { return v.is_boolean() || v.is_number_integer(); }

/// Installs the recorded ground_top as segment heights and checks it round-trips column by column.
std::vector<uint8_t> install_layout(const LatentParams& p, const json& ep) {
  const std::vector<int32_t> gt = ep["ground_top"].get<std::vector<int32_t>>();
  REQUIRE(static_cast<int32_t>(gt.size()) == p.length);
  std::vector<uint8_t> segments(kage::layout_segment_count(p));
  REQUIRE(kage::layout_from_ground_top(p, gt.data(), segments.data()));
  const LayoutView v{segments.data()};
  for (int32_t c = 0; c < p.length; ++c) REQUIRE(kage::ground_top(p, v, c) == gt[c]);
  return segments;
}

void check_solid_mask(const LatentParams& p, LayoutView v, const json& rows) {
  REQUIRE(static_cast<int32_t>(rows.size()) == p.height_px);
  int64_t solid_cells = 0;
  for (int32_t r = 0; r < p.height_px; ++r) {
    const std::string row = rows[r].get<std::string>();
    REQUIRE(static_cast<int32_t>(row.size()) == p.length);
    for (int32_t c = 0; c < p.length; ++c) {
      const bool expected = row[c] == '1';
      solid_cells += expected;
      if (kage::solid(p, v, r, c) != expected) FAIL("solid mismatch at row " << r << " column " << c);
    }
  }
  CHECK(solid_cells > p.length * p.ground_thickness - 1);  // never an empty mask
}

void check_initial(const LatentState& s, const json& init) {
  CHECK(s.x == init["x"].get<float>());
  CHECK(s.y == init["y"].get<float>());
  CHECK(s.vx == init["vx"].get<float>());
  CHECK(s.vy == init["vy"].get<float>());
  CHECK(static_cast<bool>(s.grounded) == init["grounded"].get<bool>());
  CHECK(s.coyote_timer == init["coyote_timer"].get<int32_t>());
  CHECK(s.camera_x == init["camera_x"].get<float>());
  CHECK(s.x_max == init["x_max"].get<float>());
  CHECK(s.jump_count == init["jump_count"].get<int32_t>());
  CHECK(s.episode_return == init["episode_return"].get<float>());
  CHECK(s.t == init["t"].get<int32_t>());
  CHECK(static_cast<bool>(s.success_once) == init["success_once"].get<bool>());
}

void replay_file(const std::string& name) {
  const json g = load_golden(name);
  const LatentParams p = kage::test::golden_params(g["config"].get<std::string>());
  REQUIRE(g["episode_length"].get<int32_t>() == p.episode_length);
  const std::vector<std::string> fields = g["fields"].get<std::vector<std::string>>();
  REQUIRE(g["episodes"].size() > 0);
  int32_t masks_checked = 0;
  for (const json& ep : g["episodes"]) {
    INFO(name << " seed " << ep["seed"]);
    const std::vector<uint8_t> segments = install_layout(p, ep);
    const LayoutView v{segments.data()};
    if (!ep["solid_mask_rows"].is_null()) {
      check_solid_mask(p, v, ep["solid_mask_rows"]);
      ++masks_checked;
    }
    // The recorded reset state must be what our spawn and camera rules give on that layout.
    LatentState s;
    kage::latent_reset_on_layout(p, v, 0, s);
    check_initial(s, ep["initial"]);

    const std::vector<int32_t> actions = ep["actions"].get<std::vector<int32_t>>();
    const json& traj = ep["trajectory"];
    REQUIRE(static_cast<int32_t>(actions.size()) == p.episode_length);
    int32_t mismatches = 0;
    size_t compared = 0;
    float x_min = s.x, x_max = s.x;
    for (size_t i = 0; i < actions.size(); ++i) {
      const StepOutcome o = kage::latent_step(p, v, s, actions[i]);
      x_min = std::min(x_min, s.x);
      x_max = std::max(x_max, s.x);
      for (const std::string& f : fields) {
        const json& expected = traj[f][i];
        const double want = as_number(expected);
        const double got = field_value(f, s, o);
        const bool ok = is_exact_field(expected) ? got == want : std::fabs(got - want) <= kFloatTolerance;
        ++compared;
        if (!ok && ++mismatches <= 5) {
          FAIL_CHECK("step " << i + 1 << " action " << actions[i] << " field " << f << ": expected " << want
                             << ", got " << got);
        }
      }
      if (mismatches > 0) break;  // later steps diverge from the first difference on
    }
    CHECK(mismatches == 0);
    CHECK(compared == actions.size() * fields.size());
    CHECK(x_max - x_min > 10.0f);  // the recording is not a trajectory standing still
  }
  CHECK(masks_checked >= 1);
}

LatentParams yaml_params() { return kage::test::golden_default_params(); }

/// A flat layout at ground_top = 76 (height 10 with the YAML layout) everywhere.
std::vector<uint8_t> flat_layout(const LatentParams& p, int32_t gt) {
  return std::vector<uint8_t>(kage::layout_segment_count(p),
                              static_cast<uint8_t>((p.base_ground_y - gt) / p.pix_per_unit - p.min_height));
}

}  // namespace

TEST_CASE("golden physics replay: default config", "[latent][golden]") { replay_file("physics_default.json"); }

TEST_CASE("golden physics replay: variant config", "[latent][golden]") { replay_file("physics_variant.json"); }

TEST_CASE("Appendix B: spawn, settle and rest over a band at 76", "[latent]") {
  const LatentParams p = yaml_params();
  const std::vector<uint8_t> seg = flat_layout(p, 76);
  const LayoutView v{seg.data()};
  LatentState s;
  kage::latent_reset_on_layout(p, v, 0, s);
  CHECK(s.x == 64.0f);
  CHECK(s.y == 62.0f);
  CHECK(s.camera_x == 0.0f);
  kage::latent_step(p, v, s, 0);
  CHECK(s.grounded == 1);
  CHECK(s.y == 63.0f);
  CHECK(s.vy == 0.75f);
  kage::latent_step(p, v, s, 0);  // 64.5 rounds to 64 (half to even), collides, back to 63
  CHECK(s.y == 63.0f);
  CHECK(s.vy == 0.0f);
}

TEST_CASE("Appendix B: jump from rest", "[latent]") {
  const LatentParams p = yaml_params();
  const std::vector<uint8_t> seg = flat_layout(p, 76);
  const LayoutView v{seg.data()};
  LatentState s;
  kage::latent_reset_on_layout(p, v, 0, s);
  kage::latent_step(p, v, s, 0);
  kage::latent_step(p, v, s, 0);
  REQUIRE(s.y == 63.0f);
  const float ys[] = {56, 50, 45, 40, 36, 33, 31, 30, 29, 29, 30, 32, 34, 37, 41, 46, 51, 57, 63};
  const float vys[] = {-6.75f, -6.0f, -5.25f, -4.5f, -3.75f, -3.0f, -2.25f, -1.5f, -0.75f, 0.0f,
                       0.75f,  1.5f,  2.25f,  3.0f,  3.75f,  4.5f,  5.25f, 6.0f,  0.0f};
  for (int i = 0; i < 19; ++i) {
    INFO("jump step " << i + 1);
    const StepOutcome o = kage::latent_step(p, v, s, i == 0 ? 4 : 0);
    CHECK(s.y == ys[i]);
    CHECK(s.vy == vys[i]);
    CHECK(s.grounded == 0);
    if (i == 0) CHECK(o.reward == Approx(-15.1f));
  }
  kage::latent_step(p, v, s, 0);
  CHECK(s.grounded == 1);
}

TEST_CASE("Appendix B: walking right and the camera", "[latent]") {
  const LatentParams p = yaml_params();
  const std::vector<uint8_t> seg = flat_layout(p, 76);
  const LayoutView v{seg.data()};
  LatentState s;
  kage::latent_reset_on_layout(p, v, 0, s);
  for (int i = 0; i < 40; ++i) {
    const float x_before = s.x;
    const StepOutcome o = kage::latent_step(p, v, s, 2);
    CHECK(s.x == x_before + 1.0f);
    CHECK(o.reward == Approx(0.1f));
    CHECK(s.camera_x == std::max(0.0f, s.x - 88.0f));
  }
  CHECK(s.camera_x == 104.0f - 88.0f);
}

TEST_CASE("actions are read as a bit mask", "[latent]") {
  CHECK(kage::decode_action(3).action_x == 0);
  CHECK(kage::decode_action(5).action_x == -1);
  CHECK(kage::decode_action(6).jump_pressed);
  CHECK(kage::decode_action(10).action_x == 1);  // higher bits ignored
  CHECK_FALSE(kage::decode_action(8).jump_pressed);
  CHECK(kage::decode_action(-1).action_x == 0);  // all three bits set
  CHECK(kage::decode_action(-1).jump_pressed);
}
