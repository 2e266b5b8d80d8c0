// CPU batch runtime: agreement with the single-environment semantics, autoreset, thread-count
// independence and the render hook.
#include <catch2/catch.hpp>

#include <cstring>
#include <vector>

#include "runtime/cpu/cpu_batch.h"
#include "runtime/latent/latent_step.h"
#include "tests/runtime/latent_test_params.h"

namespace {

using kage::CpuBatch;
using kage::CpuBatchOptions;
using kage::LatentParams;
using kage::LatentState;

std::vector<uint64_t> make_seeds(int32_t n) {
  std::vector<uint64_t> seeds(n);
  for (int32_t i = 0; i < n; ++i) seeds[i] = 1000003ull * i + (static_cast<uint64_t>(i) << 40);
  return seeds;
}

/// A deterministic action mix that moves right, jumps and idles (all 8 values and some outside 0..7).
int32_t action_of(int32_t env, int32_t t) {
  const uint32_t h = kage::bits32(kage::Key{static_cast<uint32_t>(env), 77u}, static_cast<uint32_t>(t));
  return (h % 4 == 0) ? static_cast<int32_t>(h >> 8) - (1 << 22) : ((h >> 3) % 3 == 0 ? 6 : 2);
}

CpuBatch make_batch(const LatentParams& p, int32_t n, int32_t threads, bool autoreset) {
  std::optional<CpuBatch> b = CpuBatch::create(p, n, CpuBatchOptions{threads, autoreset});
  REQUIRE(b.has_value());
  return std::move(*b);
}

}  // namespace

TEST_CASE("batch environments follow the single-environment semantics", "[cpu_batch]") {
  const LatentParams p = kage::test::golden_default_params();
  const int32_t n = 5;
  CpuBatch batch = make_batch(p, n, 2, false);
  const std::vector<uint64_t> seeds = make_seeds(n);
  batch.reset(seeds.data());

  std::vector<std::vector<uint8_t>> seg(n, std::vector<uint8_t>(kage::layout_segment_count(p)));
  std::vector<LatentState> ref(n);
  for (int32_t e = 0; e < n; ++e) {
    kage::latent_reset(p, kage::fold(kage::seed_key(seeds[e]), 0u), 0, seg[e].data(), ref[e]);
    REQUIRE(std::memcmp(&ref[e], &batch.state(e), sizeof(LatentState)) == 0);
  }
  std::vector<int32_t> actions(n);
  float total_reward = 0;
  for (int32_t t = 0; t < 600; ++t) {
    for (int32_t e = 0; e < n; ++e) actions[e] = action_of(e, t);
    batch.step(actions.data());
    for (int32_t e = 0; e < n; ++e) {
      const kage::StepOutcome o = kage::latent_step(p, kage::LayoutView{seg[e].data()}, ref[e], actions[e]);
      REQUIRE(std::memcmp(&ref[e], &batch.state(e), sizeof(LatentState)) == 0);
      REQUIRE(batch.info().reward[e] == o.reward);
      REQUIRE(batch.info().truncated[e] == o.truncated);
      REQUIRE(batch.info().passed_distance[e] == o.passed_distance);
      REQUIRE(batch.info().timestep[e] == t + 1);
      total_reward += o.reward;
    }
  }
  // Without autoreset the core keeps counting past the episode length (spec 5.10).
  CHECK(batch.state(0).t == 600);
  CHECK(batch.info().truncated[0] == 1);
  CHECK(batch.info().terminated[0] == 0);
  CHECK(total_reward != 0.0f);
  CHECK(batch.state(0).x != batch.state(0).initial_x);
}

TEST_CASE("autoreset starts the next episode and reports the finished one", "[cpu_batch]") {
  LatentParams p = kage::test::golden_default_params();
  p.episode_length = 12;
  const int32_t n = 3;
  CpuBatch batch = make_batch(p, n, 1, true);
  const std::vector<uint64_t> seeds = make_seeds(n);
  batch.reset(seeds.data());
  const std::vector<int32_t> right(n, 2);
  for (int32_t t = 1; t <= 11; ++t) batch.step(right.data());
  CHECK(batch.info().truncated[1] == 0);
  LatentState last = batch.state(1);
  const std::vector<uint8_t> old_layout(batch.layout(1).segments,
                                        batch.layout(1).segments + kage::layout_segment_count(p));
  const kage::StepOutcome o = kage::latent_step(p, kage::LayoutView{old_layout.data()}, last, 2);
  batch.step(right.data());

  const kage::BatchInfo& info = batch.info();
  CHECK(info.truncated[1] == 1);
  CHECK(info.timestep[1] == 12);
  CHECK(info.x[1] == last.x);
  CHECK(info.episode_return[1] == last.episode_return);
  CHECK(info.passed_distance[1] == o.passed_distance);
  CHECK(info.passed_distance[1] > 0.0f);
  // The state is the next episode's reset state, on the layout of key fold(seed_key(seed), 1).
  const LatentState& s = batch.state(1);
  CHECK(s.t == 0);
  CHECK(s.episode == 1);
  CHECK(s.episode_return == 0.0f);
  std::vector<uint8_t> seg(kage::layout_segment_count(p));
  LatentState ref;
  kage::latent_reset(p, kage::fold(kage::seed_key(seeds[1]), 1u), 1, seg.data(), ref);
  CHECK(std::memcmp(&ref, &s, sizeof(LatentState)) == 0);
  CHECK(std::memcmp(seg.data(), batch.layout(1).segments, seg.size()) == 0);
}

TEST_CASE("results do not depend on the thread count", "[cpu_batch]") {
  LatentParams p = kage::test::golden_variant_params();
  p.episode_length = 50;  // several autoresets
  const int32_t n = 13;
  const std::vector<uint64_t> seeds = make_seeds(n);
  std::vector<std::vector<uint8_t>> runs;
  for (int32_t threads : {1, 2, 3, 16}) {
    CpuBatch batch = make_batch(p, n, threads, true);
    batch.reset(seeds.data());
    std::vector<uint8_t> bytes;
    std::vector<int32_t> actions(n);
    for (int32_t t = 0; t < 180; ++t) {
      for (int32_t e = 0; e < n; ++e) actions[e] = action_of(e, t);
      batch.step(actions.data());
      const kage::BatchInfo& i = batch.info();
      for (const std::vector<float>* v : {&i.reward, &i.x, &i.y, &i.vx, &i.vy, &i.episode_return, &i.progress}) {
        const auto* b = reinterpret_cast<const uint8_t*>(v->data());
        bytes.insert(bytes.end(), b, b + v->size() * sizeof(float));
      }
      bytes.insert(bytes.end(), i.truncated.begin(), i.truncated.end());
    }
    for (int32_t e = 0; e < n; ++e) {
      const auto* b = reinterpret_cast<const uint8_t*>(&batch.state(e));
      bytes.insert(bytes.end(), b, b + sizeof(LatentState));
    }
    CHECK(batch.state(0).episode == 3);
    runs.push_back(bytes);
  }
  for (size_t r = 1; r < runs.size(); ++r) CHECK(runs[r] == runs[0]);
}

namespace {

struct HookLog {
  std::vector<int32_t> resets;
  std::vector<int32_t> steps;
};

void log_reset(void* user, int32_t env, kage::Key, const LatentParams&, kage::LayoutView, const LatentState& s,
               uint8_t* obs) {
  static_cast<HookLog*>(user)->resets[env] += 1;
  obs[0] = static_cast<uint8_t>(s.t);
  obs[1] = 100;
}

void log_step(void* user, int32_t env, kage::Key, const LatentParams&, kage::LayoutView, const LatentState& s,
              uint8_t* obs) {
  static_cast<HookLog*>(user)->steps[env] += 1;
  obs[0] = static_cast<uint8_t>(s.t);
  obs[1] = 200;
}

}  // namespace

TEST_CASE("the render hook writes each environment's observation", "[cpu_batch]") {
  LatentParams p = kage::test::golden_default_params();
  p.episode_length = 4;
  const int32_t n = 6;
  CpuBatch batch = make_batch(p, n, 3, true);
  HookLog log{std::vector<int32_t>(n, 0), std::vector<int32_t>(n, 0)};
  batch.set_render_hook(kage::RenderHook{&log, &log_reset, &log_step});
  const std::vector<uint64_t> seeds = make_seeds(n);
  batch.reset(seeds.data());
  const std::vector<int32_t> noop(n, 0);
  const size_t frame = static_cast<size_t>(p.screen_h) * p.screen_w * 3;
  for (int32_t t = 1; t <= 4; ++t) {
    batch.step(noop.data());
    for (int32_t e = 0; e < n; ++e) {
      CHECK(batch.observations()[e * frame] == (t < 4 ? t : 0));
      CHECK(batch.observations()[e * frame + 1] == (t < 4 ? 200 : 100));
    }
  }
  for (int32_t e = 0; e < n; ++e) {
    CHECK(log.resets[e] == 2);
    CHECK(log.steps[e] == 3);
  }
}

TEST_CASE("unsupported parameters are refused", "[cpu_batch]") {
  LatentParams p = kage::test::golden_default_params();
  CHECK_FALSE(CpuBatch::create(p, 0, CpuBatchOptions{}).has_value());
  p.run_width = 0;
  CHECK_FALSE(CpuBatch::create(p, 4, CpuBatchOptions{}).has_value());
}
