// Latent/visual separation (design.md, style.md 5): the dynamics headers compile alone and include
// nothing outside the latent area and the shared portability, math and RNG headers.
#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <string>
#include <vector>

// Only latent headers: this TU is the compile check; the include scan below checks the graph itself.
#include "runtime/latent/camera.h"
#include "runtime/latent/collision.h"
#include "runtime/latent/latent_params.h"
#include "runtime/latent/latent_state.h"
#include "runtime/latent/latent_step.h"
#include "runtime/latent/layout.h"
#include "runtime/latent/physics.h"
#include "runtime/latent/reward.h"
#include "runtime/latent/spawn.h"
#include "tests/runtime/latent_test_params.h"

namespace {

const std::set<std::string> kAllowedOutsideLatent = {"runtime/kage_hd.h", "runtime/kage_math.h", "runtime/rng.h",
                                                     "runtime/streams.def"};

}  // namespace

TEST_CASE("latent headers alone run an episode", "[latent][isolation]") {
  // Built from the latent headers only: holding RIGHT for 50 steps moves the agent right, earns forward
  // reward and ends on the ground, so the dynamics are usable without anything visual.
  const kage::LatentParams p = kage::test::golden_default_params();
  std::vector<uint8_t> segments(kage::layout_segment_count(p));
  kage::LatentState s{};
  kage::latent_reset(p, kage::Key{7u, 0u}, 0u, segments.data(), s);
  const float x0 = s.x;
  float reward = 0.0f;
  for (int i = 0; i < 50; ++i) reward += kage::latent_step(p, kage::LayoutView{segments.data()}, s, 2).reward;
  CHECK(s.t == 50);
  CHECK(s.x > x0 + 20.0f);
  CHECK(s.x_max >= s.x);
  CHECK(reward != 0.0f);
  CHECK(s.jump_count == 0);
}

TEST_CASE("runtime/latent includes nothing visual or host-side", "[latent][isolation]") {
  const std::filesystem::path root = KAGE_SOURCE_DIR;
  const std::regex include_re(R"re(^\s*#\s*include\s*[<"]([^">]+)[">])re");
  int32_t files = 0, includes = 0;
  for (const auto& entry : std::filesystem::directory_iterator(root / "runtime" / "latent")) {
    std::ifstream in(entry.path());
    REQUIRE(in.good());
    ++files;
    std::string line;
    while (std::getline(in, line)) {
      std::smatch m;
      if (!std::regex_search(line, m, include_re)) continue;
      ++includes;
      const std::string target = m[1];
      INFO(entry.path().filename().string() << ": #include " << target);
      CHECK(target.find("visual") == std::string::npos);
      CHECK((target.rfind("runtime/latent/", 0) == 0 || kAllowedOutsideLatent.count(target) == 1));
    }
  }
  CHECK(files >= 9);
  CHECK(includes > files);
}
