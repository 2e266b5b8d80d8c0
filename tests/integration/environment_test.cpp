// Environment::open end to end: observations, rewards and motion, determinism, autoreset's final
// observation and info.
#include <catch2/catch.hpp>

#include <cstring>
#include <set>
#include <vector>

#include "api/environment.h"
#include "tests/integration/integration_support.h"

namespace {

using kage::test::kRoot;

constexpr int32_t kRight = 2;
constexpr int32_t kRightJump = 6;

std::unique_ptr<kage::Environment> open_env(const std::string& path, int32_t envs, int32_t threads) {
  kage::EnvironmentOptions options;
  options.num_envs = envs;
  options.num_threads = threads;
  kage::EnvironmentResult r = kage::Environment::open(path, options);
  INFO(r.error);
  REQUIRE(r.ok());
  return std::move(r.env);
}

size_t distinct_colors(const uint8_t* frame, size_t bytes) {
  std::set<uint32_t> colors;
  for (size_t i = 0; i + 2 < bytes; i += 3) colors.insert(frame[i] << 16 | frame[i + 1] << 8 | frame[i + 2]);
  return colors.size();
}

size_t count_color(const uint8_t* frame, size_t bytes, uint8_t r, uint8_t g, uint8_t b) {
  size_t n = 0;
  for (size_t i = 0; i + 2 < bytes; i += 3) n += frame[i] == r && frame[i + 1] == g && frame[i + 2] == b;
  return n;
}

/// Runs `steps` steps of a fixed action pattern and returns every observation byte.
std::vector<uint8_t> trajectory_bytes(kage::CpuEnv& env, int steps) {
  std::vector<uint64_t> seeds(env.size());
  for (int32_t i = 0; i < env.size(); ++i) seeds[i] = 100 + i;
  env.reset(seeds.data());
  std::vector<uint8_t> out(env.observations(), env.observations() + env.size() * env.frame_bytes());
  std::vector<int32_t> actions(env.size());
  for (int t = 0; t < steps; ++t) {
    for (int32_t i = 0; i < env.size(); ++i) actions[i] = (t * 7 + i * 3) % 8;
    env.step(actions.data());
    out.insert(out.end(), env.observations(), env.observations() + env.size() * env.frame_bytes());
  }
  return out;
}

}  // namespace

TEST_CASE("configs/default.yaml gives detailed frames, rewards and motion", "[integration]") {
  auto opened = open_env(kRoot + "/configs/default.yaml", 2, 2);
  kage::CpuEnv& env = opened->env();
  REQUIRE(env.height() == 128);
  REQUIRE(env.width() == 128);
  const uint64_t seeds[] = {0, 1};
  env.reset(seeds);
  // An image background, platforms, sprites and distractors: far more than a handful of colours.
  CHECK(distinct_colors(env.observation(0), env.frame_bytes()) > 100);
  CHECK(std::memcmp(env.observation(0), env.observation(1), env.frame_bytes()) != 0);
  const float x0 = env.info().x[0];
  float total = 0;
  for (int t = 0; t < 30; ++t) {
    const int32_t actions[] = {kRight, kRight};
    env.step(actions);
    total += env.info().reward[0];
  }
  CHECK(env.info().x[0] > x0);
  CHECK(env.info().passed_distance[0] == env.info().x[0] - x0);
  CHECK(env.info().timestep[0] == 30);
  CHECK(total != 0.0f);
  CHECK(env.info().episode_return[0] == Approx(total).margin(1e-3));
}

TEST_CASE("the teal circle agent of the golden default is drawn where it stands", "[integration]") {
  auto opened = open_env(kRoot + "/configs/golden/default.yaml", 1, 1);
  kage::CpuEnv& env = opened->env();
  const uint64_t seed = 7;
  env.reset(&seed);
  const size_t bytes = env.frame_bytes();
  // SHAPE_BLACK: black background, cyan (SHAPE_COLORS) platforms, teal circle of radius 8.
  const size_t teal = count_color(env.observation(0), bytes, 0, 128, 128);
  CHECK(teal > 100);
  CHECK(teal < 300);
  CHECK(count_color(env.observation(0), bytes, 0, 255, 255) > 100);
  CHECK(count_color(env.observation(0), bytes, 0, 0, 0) > bytes / 3 / 2);
  // The circle is centred on the agent's screen position.
  const kage::LatentState s = env.latent_state(0);
  const int cx = static_cast<int>(s.x - s.camera_x), cy = static_cast<int>(s.y) + 1;
  const uint8_t* centre = env.observation(0) + (static_cast<size_t>(cy) * env.width() + cx) * 3;
  CHECK(centre[0] == 0);
  CHECK(centre[1] == 128);
  CHECK(centre[2] == 128);
  // Walking and jumping right moves the circle.
  for (int t = 0; t < 40; ++t) {
    const int32_t a = t % 10 == 0 ? kRightJump : kRight;
    env.step(&a);
  }
  CHECK(env.latent_state(0).x > s.x);
}

TEST_CASE("two runs with the same seeds give the same bytes, whatever the thread count", "[integration]") {
  const std::string path = kRoot + "/configs/default.yaml";
  auto a = open_env(path, 4, 1);
  auto b = open_env(path, 4, 2);
  const std::vector<uint8_t> ra = trajectory_bytes(a->env(), 25);
  const std::vector<uint8_t> rb = trajectory_bytes(b->env(), 25);
  REQUIRE(ra.size() == rb.size());
  CHECK(ra == rb);
  // Not a constant stream: the frames change over the episode.
  CHECK(std::memcmp(ra.data(), ra.data() + ra.size() - a->env().frame_bytes(), a->env().frame_bytes()) != 0);
}

TEST_CASE("autoreset keeps the finished episode's final observation and info", "[integration]") {
  const kage::test::TempConfig short_cfg("short", kage::test::extends_golden_default() + "episode_length: 5\n");
  const kage::test::TempConfig long_cfg("long", kage::test::extends_golden_default() + "episode_length: 50\n");
  auto s = open_env(short_cfg.path(), 1, 1);
  auto l = open_env(long_cfg.path(), 1, 1);
  const uint64_t seed = 3;
  s->env().reset(&seed);
  l->env().reset(&seed);
  for (int t = 1; t <= 5; ++t) {
    const int32_t a = kRight;
    s->env().step(&a);
    l->env().step(&a);
    CHECK(s->env().done(0) == (t == 5));
  }
  const kage::CpuEnv& e = s->env();
  const size_t n = e.frame_bytes();
  // The final frame is the one the longer episode shows after the same five steps.
  CHECK(std::memcmp(e.final_observation(0), l->env().observation(0), n) == 0);
  // The info is the finished episode's last step; the state and observation are the new episode's.
  CHECK(e.info().truncated[0] == 1);
  CHECK(e.info().timestep[0] == 5);
  CHECK(e.info().x[0] == l->env().info().x[0]);
  CHECK(e.info().episode_return[0] == l->env().info().episode_return[0]);
  CHECK(e.latent_state(0).t == 0);
  CHECK(e.latent_state(0).episode == 1);
  CHECK(std::memcmp(e.observation(0), e.final_observation(0), n) != 0);
  const int32_t a = kRight;
  s->env().step(&a);
  CHECK_FALSE(s->env().done(0));
  CHECK(s->env().info().timestep[0] == 1);
}
