// Layout generation (spec 4.3), the solid-mask derivation and the spawn rule (spec 4.4), checked against
// the spec's stated ranges and distributions and against a direct transcription of the mask definition.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <vector>

#include "runtime/latent/layout.h"
#include "runtime/latent/spawn.h"
#include "runtime/rng.h"
#include "tests/runtime/latent_test_params.h"

namespace {

using kage::LatentParams;
using kage::LayoutView;

std::vector<uint8_t> generate(const LatentParams& p, uint64_t seed) {
  std::vector<uint8_t> seg(kage::layout_segment_count(p));
  const kage::Key episode = kage::fold(kage::seed_key(seed), 0u);
  kage::generate_layout(p, kage::stream_key(episode, kage::Stream::Layout), seg.data());
  return seg;
}

std::vector<int32_t> ground_tops(const LatentParams& p, const std::vector<uint8_t>& seg) {
  std::vector<int32_t> gt(p.length);
  for (int32_t c = 0; c < p.length; ++c) gt[c] = kage::ground_top(p, LayoutView{seg.data()}, c);
  return gt;
}

/// The mask exactly as spec 4.3 step 6 words it: the band, then the connector in column c.
std::vector<uint8_t> reference_mask(const LatentParams& p, const std::vector<int32_t>& gt) {
  std::vector<uint8_t> m(static_cast<size_t>(p.height_px) * p.length, 0);
  for (int32_t c = 0; c < p.length; ++c) {
    for (int32_t r = 0; r < p.height_px; ++r) {
      if (gt[c] <= r && r < gt[c] + p.ground_thickness) m[r * p.length + c] = 1;
    }
    if (c >= 1 && gt[c - 1] != gt[c]) {
      const int32_t lo = std::min(gt[c - 1], gt[c]);
      const int32_t hi = std::max(gt[c - 1], gt[c]);
      for (int32_t r = std::max(lo, 0); r < std::min(hi, p.height_px); ++r) m[r * p.length + c] = 1;
    }
  }
  return m;
}

}  // namespace

TEST_CASE("layout thresholds are computed in double, compared in float32", "[layout]") {
  float t_flat = 0, t_up = 0;
  kage::layout_thresholds(0.7, 0.5, t_flat, t_up);
  CHECK(t_flat == 0.3f);
  CHECK(t_up == 0.65f);
}

TEST_CASE("YAML layout: ground_top in [56, 96], even, first segment at 76", "[layout]") {
  const LatentParams p = kage::test::golden_default_params();
  REQUIRE(kage::layout_segment_count(p) == 82);
  int64_t boundaries = 0, changes = 0;
  int32_t lowest = 1000, highest = -1000;
  for (uint64_t seed = 0; seed < 500; ++seed) {
    const std::vector<int32_t> gt = ground_tops(p, generate(p, seed));
    for (int32_t c = 0; c < p.length; ++c) {
      REQUIRE(gt[c] >= 56);
      REQUIRE(gt[c] <= 96);
      REQUIRE(gt[c] % 2 == 0);
      lowest = std::min(lowest, gt[c]);
      highest = std::max(highest, gt[c]);
      if (c < 25) REQUIRE(gt[c] == 76);
      if (c % 25 == 0 && c > 0) {
        ++boundaries;
        changes += gt[c] != gt[c - 1];
        // A change is a step of 5..17 units, possibly cut short by the height clamp.
        const int32_t d = std::abs(gt[c] - gt[c - 1]);
        REQUIRE(d <= 34);
        if (gt[c] != 56 && gt[c] != 96) REQUIRE((d == 0 || d >= 10));
      }
    }
  }
  CHECK(lowest == 56);
  CHECK(highest == 96);
  // Clamping at 0 and 20 turns some drawn changes into no change, so the rate is below p_change.
  const double rate = static_cast<double>(changes) / boundaries;
  CHECK(rate > 0.45);
  CHECK(rate < 0.70);
}

TEST_CASE("segment events and magnitudes follow p_change, p_up_given_change and the step range", "[layout]") {
  LatentParams p = kage::test::golden_default_params();
  // Small steps over a wide height range: the clamp never binds, so every drawn event is visible.
  p.length = 1000;
  p.pix_per_unit = 1;
  p.base_ground_y = 300;
  p.height_px = 400;
  p.min_height = 0;
  p.max_height = 254;
  p.min_step_height = 1;
  p.max_step_height = 3;
  kage::layout_thresholds(0.6, 0.25, p.layout_t_flat, p.layout_t_up);
  const int32_t count = kage::layout_segment_count(p);
  REQUIRE(count == 40);
  int64_t n = 0, changed = 0, up = 0, mag[4] = {0, 0, 0, 0};
  for (uint64_t seed = 0; seed < 2000; ++seed) {
    const std::vector<uint8_t> seg = generate(p, seed);
    REQUIRE(seg[0] == 127);  // (0 + 254) // 2
    for (int32_t s = 1; s < count; ++s) {
      const int32_t d = static_cast<int32_t>(seg[s]) - static_cast<int32_t>(seg[s - 1]);
      ++n;
      if (d != 0) {
        ++changed;
        up += d > 0;
        REQUIRE(std::abs(d) <= 3);
        ++mag[std::abs(d)];
      }
    }
  }
  CHECK(static_cast<double>(changed) / n == Approx(0.6).margin(0.01));
  CHECK(static_cast<double>(up) / changed == Approx(0.25).margin(0.01));
  for (int m = 1; m <= 3; ++m) CHECK(static_cast<double>(mag[m]) / changed == Approx(1.0 / 3).margin(0.01));
}

TEST_CASE("layouts depend on the episode key only", "[layout]") {
  const LatentParams p = kage::test::golden_default_params();
  CHECK(generate(p, 7) == generate(p, 7));
  CHECK(generate(p, 7) != generate(p, 8));
}

TEST_CASE("degenerate layouts: p_change 0 and pix_per_unit 0 are flat", "[layout]") {
  LatentParams p = kage::test::golden_default_params();
  kage::layout_thresholds(0.0, 0.5, p.layout_t_flat, p.layout_t_up);
  for (int32_t v : ground_tops(p, generate(p, 3))) REQUIRE(v == 76);
  p = kage::test::golden_default_params();
  p.pix_per_unit = 0;
  for (int32_t v : ground_tops(p, generate(p, 3))) REQUIRE(v == 96);
}

TEST_CASE("solid() equals the mask as spec 4.3 defines it", "[layout]") {
  for (const LatentParams& p : {kage::test::golden_default_params(), kage::test::golden_variant_params()}) {
    for (uint64_t seed = 0; seed < 20; ++seed) {
      const std::vector<uint8_t> seg = generate(p, seed);
      const std::vector<uint8_t> mask = reference_mask(p, ground_tops(p, seg));
      int64_t solid_cells = 0;
      for (int32_t r = 0; r < p.height_px; ++r) {
        for (int32_t c = 0; c < p.length; ++c) {
          const bool want = mask[r * p.length + c] != 0;
          solid_cells += want;
          if (kage::solid(p, LayoutView{seg.data()}, r, c) != want) FAIL("seed " << seed << " r " << r << " c " << c);
        }
      }
      CHECK(solid_cells >= static_cast<int64_t>(p.length) * p.ground_thickness);
    }
  }
}

TEST_CASE("explicit ground_top round-trips and rejects what segments cannot hold", "[layout]") {
  const LatentParams p = kage::test::golden_default_params();
  std::vector<int32_t> gt = ground_tops(p, generate(p, 11));
  std::vector<uint8_t> seg(kage::layout_segment_count(p));
  REQUIRE(kage::layout_from_ground_top(p, gt.data(), seg.data()));
  CHECK(seg == generate(p, 11));
  gt[30] -= 2;  // not constant over its segment
  CHECK_FALSE(kage::layout_from_ground_top(p, gt.data(), seg.data()));
  gt[30] += 1;
  CHECK_FALSE(kage::layout_from_ground_top(p, gt.data(), seg.data()));
}

TEST_CASE("spawn: first free candidate, else (64, 64)", "[layout][spawn]") {
  LatentParams p = kage::test::golden_variant_params();  // run width 12: segment 6 starts at column 72
  std::vector<int32_t> gt(p.length, 76);
  for (int32_t c = 72; c < p.length; ++c) gt[c] = 40;  // a step up inside candidate 0's box (columns 56..72)
  std::vector<uint8_t> seg(kage::layout_segment_count(p));
  REQUIRE(kage::layout_from_ground_top(p, gt.data(), seg.data()));
  kage::SpawnPoint sp = kage::find_spawn(p, LayoutView{seg.data()});
  CHECK(sp.x == 84);  // 64 + (16 + 4)
  CHECK(sp.y == 40 - 12 - 2);

  std::fill(gt.begin(), gt.end(), 76);
  seg.assign(seg.size(), 0);
  REQUIRE(kage::layout_from_ground_top(p, gt.data(), seg.data()));
  sp = kage::find_spawn(p, LayoutView{seg.data()});
  CHECK(sp.x == 64);
  CHECK(sp.y == 62);

  // Run width 1 alternating between the lowest and the highest ground: every column has a connector
  // over rows 40..99, so every candidate (all at even columns, over the low ground) collides.
  p.run_width = 1;
  seg.assign(kage::layout_segment_count(p), 0);
  for (int32_t c = 0; c < p.length; ++c) seg[c] = c % 2 == 0 ? 0 : 20;
  sp = kage::find_spawn(p, LayoutView{seg.data()});
  CHECK(sp.x == 64);
  CHECK(sp.y == 64);
}
