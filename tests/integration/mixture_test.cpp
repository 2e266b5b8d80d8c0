// kage::open_mixture: one CPU batch over configs that differ only on visual axes equals each config run alone
// (kage::open) with the same seeds and actions, row for row; config_index(); the refusals and their kinds.
#include <catch2/catch.hpp>

#include <cstring>
#include <string>
#include <vector>

#include "kage/kage.h"
#include "tests/integration/integration_support.h"

namespace {

using kage::test::kRoot;

const std::string kNearGoal = kRoot + "/tests/python/configs/near_goal.yaml";
const std::string kNearGoalRed = kRoot + "/tests/python/configs/near_goal_red.yaml";
const std::string kNearGoalNoisy = kRoot + "/tests/python/configs/near_goal_noisy.yaml";

size_t dtype_bytes(kage::DType t) { return t == kage::DType::kUInt8 ? 1 : t == kage::DType::kInt64 ? 8 : 4; }

/// Rows [first, first + count) of every output of `env`, as bytes.
std::string rows(const kage::Env& env, int32_t first, int32_t count) {
  const size_t frame = static_cast<size_t>(env.height()) * env.width() * 3;
  std::string out;
  auto take = [&](const void* data, size_t row_bytes) {
    out.append(static_cast<const char*>(data) + first * row_bytes, count * row_bytes);
  };
  take(env.obs(), frame);
  take(env.reward(), sizeof(float));
  take(env.terminated(), 1);
  take(env.truncated(), 1);
  take(env.final_mask(), 1);
  take(env.final_obs(), frame);
  int32_t n = 0;
  const kage::InfoFieldDesc* fields = kage::info_fields(&n);
  for (int32_t i = 0; i < n; ++i) {
    take(env.info(fields[i].field), dtype_bytes(fields[i].dtype));
    take(env.final_info(fields[i].field), dtype_bytes(fields[i].dtype));
  }
  return out;
}

}  // namespace

TEST_CASE("a mixture equals its configs run alone, row for row", "[integration][api][mixture]") {
  const std::vector<kage::MixturePart> parts = {{kNearGoal, 2}, {kNearGoalRed, 0}, {kNearGoalNoisy, 3}};
  kage::Options o;
  o.num_threads = 2;
  std::string error;
  kage::ErrorKind kind = kage::ErrorKind::kOther;
  const auto mixed = kage::open_mixture(parts, o, &error, &kind);
  INFO(error);
  REQUIRE(mixed);
  CHECK(kind == kage::ErrorKind::kNone);
  REQUIRE(mixed->num_envs() == 5);
  CHECK(std::vector<int32_t>(mixed->config_index(), mixed->config_index() + 5) == std::vector<int32_t>{0, 0, 2, 2, 2});
  std::vector<std::unique_ptr<kage::Env>> alone;
  for (const kage::MixturePart& p : {parts[0], parts[2]}) {
    kage::Options one;
    one.num_envs = p.num_envs;
    alone.push_back(kage::open(p.path, one, &error));
    REQUIRE(alone.back());
    CHECK(alone.back()->config_index()[0] == 0);
  }
  const std::vector<uint64_t> seeds = {11, 22, 33, 44, 55};
  REQUIRE(mixed->reset(seeds.data()));
  REQUIRE(alone[0]->reset(seeds.data()));
  REQUIRE(alone[1]->reset(seeds.data() + 2));
  int finished = 0;
  for (int t = 1; t <= 90; ++t) {  // 40-step episodes: two automatic resets
    std::vector<int32_t> actions(5);
    for (int32_t i = 0; i < 5; ++i) actions[static_cast<size_t>(i)] = (5 * t + 3 * i) % 8;
    REQUIRE(mixed->step(actions.data()));
    REQUIRE(alone[0]->step(actions.data()));
    REQUIRE(alone[1]->step(actions.data() + 2));
    INFO("step " << t);
    CHECK(rows(*mixed, 0, 2) == rows(*alone[0], 0, 2));
    CHECK(rows(*mixed, 2, 3) == rows(*alone[1], 0, 3));
    for (int32_t i = 0; i < 5; ++i) finished += mixed->final_mask()[i];
  }
  CHECK(finished == 10);
  // The mixture's identity is not either config's, and a state saved from it restores only into it.
  CHECK(mixed->spec_hash() != alone[0]->spec_hash());
  std::vector<uint8_t> state;
  REQUIRE(mixed->save_state(&state));
  CHECK_FALSE(alone[0]->load_state(state.data(), state.size(), &error));
}

TEST_CASE("open_mixture refuses before it loads anything, each refusal of its kind", "[integration][api][mixture]") {
  kage::Options o;
  std::string error;
  kage::ErrorKind kind = kage::ErrorKind::kNone;
  // long_episode.yaml is simplest.yaml but for episode_length, which it sets on line 4.
  CHECK_FALSE(kage::open_mixture({{kRoot + "/configs/throughput/simplest.yaml", 2},
                                  {kRoot + "/tests/python/configs/long_episode.yaml", 2}}, o, &error, &kind));
  CHECK(kind == kage::ErrorKind::kConfig);
  CHECK(error.find("long_episode.yaml:4:1: error: mixture of") != std::string::npos);
  CHECK(error.find("[certify-mixture-latent]") != std::string::npos);
  CHECK_FALSE(kage::open_mixture({{kNearGoal, 2}, {kNearGoalRed, -1}}, o, &error, &kind));
  CHECK(kind == kage::ErrorKind::kUsage);
  CHECK_FALSE(kage::open_mixture({{kNearGoal, 0}}, o, &error, &kind));
  CHECK(kind == kage::ErrorKind::kUsage);
  CHECK_FALSE(kage::open_mixture({}, o, &error, &kind));
  CHECK(kind == kage::ErrorKind::kUsage);
  CHECK_FALSE(kage::open_mixture({{kNearGoal, 1}, {kRoot + "/configs", 1}}, o, &error, &kind));
  CHECK(kind == kage::ErrorKind::kUsage);
  CHECK(error.find("is a kagec compile directory") != std::string::npos);
  // On the GPU backend the certificate comes first too, before any device is looked for.
  kage::Options gpu;
  gpu.backend = kage::Backend::kGpu;
  CHECK_FALSE(kage::open_mixture({{kRoot + "/configs/throughput/simplest.yaml", 2},
                                  {kRoot + "/tests/python/configs/long_episode.yaml", 2}},
                                 gpu, &error, &kind));
  CHECK(kind == kage::ErrorKind::kConfig);
  CHECK(error.find("long_episode.yaml:4:1: error: mixture of") != std::string::npos);
  CHECK(error.find("[certify-mixture-latent]") != std::string::npos);
}

TEST_CASE("open_mixture on the GPU backend refuses with kDevice where there is none", "[integration][api][mixture]") {
  // These tests link kage_api (no GPU backend): past the certificate, the refusal says so. The GPU mixture
  // itself is tests/gpu/test_mixture_gpu.py's (run on a GPU machine).
  kage::Options gpu;
  gpu.backend = kage::Backend::kGpu;
  std::string error;
  kage::ErrorKind kind = kage::ErrorKind::kNone;
  CHECK_FALSE(kage::open_mixture({{kNearGoal, 3}, {kNearGoalRed, 2}}, gpu, &error, &kind));
  CHECK(kind == kage::ErrorKind::kDevice);
  CHECK(error.find("GPU backend not built") != std::string::npos);
}

TEST_CASE("open and open_mixture give a YAML config's warnings, located, on success", "[integration][api][mixture]") {
  const kage::test::TempConfig inert("open-warnings", "extends: " + kNearGoal + "\nbackground:\n  mode: black\n"
                                                      "  parallax_factor: 0.8\n");
  kage::Options o;
  o.num_envs = 2;
  std::string error, warnings = "stale";
  REQUIRE(kage::open(inert.path(), o, &error, nullptr, &warnings));
  CHECK(warnings.find(inert.path() + ":4:3: warning: 'background.parallax_factor' has no effect") != std::string::npos);
  CHECK(warnings.find("[inert-setting]") != std::string::npos);
  REQUIRE(kage::open(kNearGoal, o, &error, nullptr, &warnings));
  CHECK(warnings.empty());
  warnings = "stale";
  REQUIRE(kage::open_mixture({{kNearGoal, 1}, {inert.path(), 1}}, o, &error, nullptr, &warnings));
  CHECK(warnings.find(inert.path() + ":4:3: warning:") != std::string::npos);
  warnings = "stale";  // a failure leaves none
  CHECK_FALSE(kage::open(kRoot + "/no/such.yaml", o, &error, nullptr, &warnings));
  CHECK(warnings.empty());
}
