// agent_shape_reach bounds every pixel inside_agent_shape accepts, for every shape type, character
// sizes from 1 to 40 (square and not) and many angles: the GPU renderers skip the agent outside it.
#include <catch2/catch.hpp>

#include <cstdint>
#include <cstdlib>

#include "runtime/visual/shapes.h"

namespace kage {
namespace {

TEST_CASE("every agent shape pixel lies within agent_shape_reach of the centre", "[shapes]") {
  constexpr int32_t kCx = 100, kCy = 100;
  int64_t inside_total = 0;
  for (int32_t t = 0; t <= static_cast<int32_t>(ShapeType::kDiamond); ++t) {
    const auto type = static_cast<ShapeType>(t);
    for (int32_t w = 1; w <= 40; w += 3) {
      for (int32_t h : {w, w / 2 + 1, 2 * w}) {
        const int32_t reach = agent_shape_reach(type, w, h);
        CHECK(reach <= (w > h ? w : h));
        for (int32_t step = 0; step < 48; ++step) {
          const float a = static_cast<float>(step) * 7.5f * kPi / 180.0f;
          const ShapeFrame sf = shape_frame(type, kCx, kCy, 0.5f * static_cast<float>(mini(w, h)), a);
          const int32_t e = maxi(w, h) + 2;  // agent_pixel's own test box, and a margin
          for (int32_t r = kCy - e; r <= kCy + e; ++r) {
            for (int32_t c = kCx - e; c <= kCx + e; ++c) {
              if (!inside_agent_shape(type, kCx, kCy, w, h, sf, c, r)) continue;
              ++inside_total;
              if (std::abs(c - kCx) > reach || std::abs(r - kCy) > reach)
                FAIL_CHECK("type " << t << " w " << w << " h " << h << " angle step " << step << ": pixel ("
                                   << c - kCx << ", " << r - kCy << ") beyond reach " << reach);
            }
          }
        }
      }
    }
  }
  CHECK(inside_total > 100000);  // the shapes were drawn, so the bound was tested
}

TEST_CASE("agent_shape_reach is tighter than the max(w, h) box for the circle", "[shapes]") {
  CHECK(agent_shape_reach(ShapeType::kCircle, 16, 16) == 9);
  CHECK(agent_shape_reach(ShapeType::kEllipse, 16, 8) == 9);
  CHECK(agent_shape_reach(ShapeType::kSquare, 16, 16) == 13);
}

}  // namespace
}  // namespace kage
