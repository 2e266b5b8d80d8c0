// Generic CPU path (CpuEnv, parameters at run time) vs generated host code (parameters constexpr),
// bit for bit: every LatentState byte, reward and flags, and every observation byte, over every config
// generated into this binary, several seeds, hundreds of steps (design.md "Semantics are written once").
#include <catch2/catch.hpp>

#include <algorithm>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

#include "api/environment.h"
#include "compiler/codegen/codegen.h"
#include "runtime/cpu/host_batch.h"
#include "tests/codegen/host_registry.h"

namespace {

const std::string kRoot = std::string(KAGE_SOURCE_DIR) + "/";

/// Writes both sides of a mismatch next to the test's working directory and returns the file name.
std::string dump_case(const std::string& config, int step, int env, const std::string& what,
                      const kage::LatentState& a, const kage::LatentState& b, const uint8_t* fa, const uint8_t* fb,
                      int H, int W) {
  std::string name = "codegen_mismatch_" + config + ".txt";
  const std::string dir = std::string(KAGE_DUMP_DIR) + "/";
  for (char& c : name)
    if (c == '/') c = '_';
  std::ofstream f(dir + name);
  f << "config " << config << " step " << step << " env " << env << " field " << what << '\n';
  auto state = [&](const char* side, const kage::LatentState& s) {
    f << side << ": x " << s.x << " y " << s.y << " vx " << s.vx << " vy " << s.vy << " cam " << s.camera_x << " t "
      << s.t << " episode " << s.episode << " return " << s.episode_return << '\n';
  };
  state("generic", a);
  state("generated", b);
  for (auto [side, px] : {std::pair{"generic", fa}, std::pair{"generated", fb}}) {
    std::ofstream img(dir + name + "." + side + ".ppm", std::ios::binary);
    img << "P6\n" << W << ' ' << H << "\n255\n";
    img.write(reinterpret_cast<const char*>(px), static_cast<std::streamsize>(H) * W * 3);
  }
  return dir + name;
}

struct Coverage {
  double reward_abs = 0;
  float max_dx = 0;
  bool pixels_vary = false;   ///< some frame has more than one byte value
  bool frames_change = false; ///< some step's frame differs from the previous one
  int resets = 0;
  bool equal = true;           ///< false after the first mismatch (already reported)
};

/// Runs one config for `steps` steps over `seeds`, comparing after reset and every step.
Coverage compare_config(const std::string& config, const kage::HostEntryPoints& ep, const std::vector<uint64_t>& seeds,
                        int steps) {
  kage::EnvironmentOptions options;
  options.num_envs = static_cast<int32_t>(seeds.size());
  kage::EnvironmentResult opened = kage::Environment::open(kRoot + config, options);
  INFO(config << ": " << opened.error);
  REQUIRE(opened.ok());
  kage::CpuEnv& generic = opened.env->env();
  const kage::LoweredConfig& lowered = opened.env->config();

  // The generated constants are the lowered parameters, word for word.
  kage::LatentParams gl{};
  kage::VisualParams gv{};
  ep.params(&gl, &gv);
  REQUIRE(kage::param_words(gl) == kage::param_words(lowered.latent));
  REQUIRE(kage::param_words(gv) == kage::param_words(lowered.visual));
  REQUIRE(ep.abi_version() == kage::kHostAbiVersion);

  const int H = gv.H, W = gv.W;
  const size_t n = seeds.size();
  kage::HostBatch spec(kage::generated_host_kernels(ep), opened.env->assets().view(), static_cast<int32_t>(n), 2);
  generic.reset(seeds.data());
  spec.reset(seeds.data(), nullptr);

  Coverage cov;
  std::vector<float> x0(n);
  const size_t all = n * spec.frame_bytes();
  std::vector<uint8_t> prev(spec.observations(), spec.observations() + all);
  auto check_env = [&](int step, int32_t e, const uint8_t* gobs, const uint8_t* sobs, const char* what) {
    const kage::LatentState& a = generic.latent_state(e);
    const kage::LatentState& b = spec.latent_state(e);
    const bool state_ok = std::memcmp(&a, &b, sizeof a) == 0;
    const bool obs_ok = std::memcmp(gobs, sobs, spec.frame_bytes()) == 0;
    if (!state_ok || !obs_ok) {
      const std::string file = dump_case(config, step, e, state_ok ? what : "latent state", a, b, gobs, sobs, H, W);
      FAIL_CHECK(config << ": generated host code differs from the generic path at step " << step << ", env " << e
                        << " (" << (state_ok ? what : "latent state") << "); dumped to " << file);
      cov.equal = false;
      return false;
    }
    return true;
  };
  for (int32_t e = 0; e < static_cast<int32_t>(n); ++e) {
    if (!check_env(0, e, generic.observation(e), spec.observation(e), "reset frame")) return cov;
    x0[e] = spec.latent_state(e).x;
  }

  // Mostly right and jump, some left and idle: the agent travels, lands and collides.
  uint32_t lcg = 12345u;
  std::vector<int32_t> actions(n);
  for (int t = 1; t <= steps; ++t) {
    for (size_t e = 0; e < n; ++e) {
      lcg = lcg * 1664525u + 1013904223u;
      const uint32_t r = lcg >> 24;
      actions[e] = r < 150 ? 2 : r < 200 ? 6 : r < 230 ? 1 : static_cast<int32_t>(r & 7u);
    }
    generic.step(actions.data());
    spec.step(actions.data());
    const kage::BatchInfo& gi = generic.info();
    const kage::BatchInfo& si = spec.info();
    for (int32_t e = 0; e < static_cast<int32_t>(n); ++e) {
      // CpuEnv reports a finished episode's last step in info(); HostBatch in final_info().
      const float* progress = spec.done(e) ? spec.final_info().progress.data() : si.progress.data();
      const bool outcome_ok = std::memcmp(&si.reward[e], &gi.reward[e], 4) == 0 &&
                              si.truncated[e] == gi.truncated[e] && si.terminated[e] == gi.terminated[e] &&
                              std::memcmp(&progress[e], &gi.progress[e], 4) == 0 && spec.done(e) == generic.done(e);
      if (!outcome_ok) {
        FAIL_CHECK(config << ": reward, progress or flags differ at step " << t << ", env " << e);
        cov.equal = false;
        return cov;
      }
      if (spec.done(e)) {
        ++cov.resets;
        if (!check_env(t, e, generic.final_observation(e), spec.final_observation(e), "final frame")) return cov;
      }
      if (!check_env(t, e, generic.observation(e), spec.observation(e), "frame")) return cov;
      cov.reward_abs += si.reward[e] < 0 ? -si.reward[e] : si.reward[e];
      const float dx = spec.latent_state(e).x - x0[e];
      cov.max_dx = std::max(cov.max_dx, dx < 0 ? -dx : dx);
    }
    const uint8_t* obs = spec.observations();
    if (!cov.frames_change) cov.frames_change = !std::equal(prev.begin(), prev.end(), obs);
    if (!cov.pixels_vary) {
      for (size_t i = 1; i < spec.frame_bytes() && !cov.pixels_vary; ++i) cov.pixels_vary = obs[i] != obs[0];
    }
    prev.assign(obs, obs + all);
  }
  return cov;
}

}  // namespace

TEST_CASE("every benchmark, sweep and throughput config is generated into the test", "[codegen][equivalence]") {
  CHECK(kage::test::host_configs().size() == KAGE_CODEGEN_CONFIGS);
  CHECK(kage::test::host_configs().count("configs/throughput/simplest.yaml") == 1);
}

TEST_CASE("generated host code equals the generic CPU path bit for bit", "[codegen][equivalence]") {
  const std::vector<uint64_t> seeds = {0, 1, 42, 2024};
  for (const auto& [config, ep] : kage::test::host_configs()) {
    const Coverage cov = compare_config(config, ep, seeds, 200);
    INFO(config);
    if (!cov.equal) continue;
    CHECK(cov.reward_abs > 0.0);
    CHECK(cov.max_dx >= 10.0f);
    CHECK(cov.pixels_vary);
    CHECK(cov.frames_change);
  }
}

TEST_CASE("generated host code equals the generic path across automatic resets", "[codegen][equivalence]") {
  const auto& configs = kage::test::host_configs();
  const auto it = configs.find("configs/throughput/hardest.yaml");
  REQUIRE(it != configs.end());
  const kage::LatentParams lp = [&] {
    kage::LatentParams l{};
    kage::VisualParams v{};
    it->second.params(&l, &v);
    return l;
  }();
  const Coverage cov = compare_config(it->first, it->second, {7}, lp.episode_length + 40);
  CHECK(cov.resets == 1);
}
