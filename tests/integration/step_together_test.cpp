// kage::step_together's refusals on a machine without a GPU: each names what is wrong, and the batch it is
// about through `failed`, and steps nothing. (Stepping together on the GPU: tests/gpu/test_step_batches_gpu.py.)
#include <catch2/catch.hpp>

#include <cstdint>
#include <string>
#include <vector>

#include "kage/kage.h"
#include "tests/integration/integration_support.h"

namespace {

const std::string kNearGoal = kage::test::kRoot + "/tests/python/configs/near_goal.yaml";

std::unique_ptr<kage::Env> started_cpu_batch() {
  kage::Options o;
  o.num_envs = 2;
  std::string error;
  auto env = kage::open(kNearGoal, o, &error);
  INFO(error);
  REQUIRE(env);
  const std::vector<uint64_t> seeds = {1, 2};
  REQUIRE(env->reset(seeds.data()));
  return env;
}

}  // namespace

TEST_CASE("step_together refuses what it cannot step, naming the batch", "[integration][api]") {
  auto a = started_cpu_batch(), b = started_cpu_batch();
  const std::vector<int32_t> actions = {1, 2, 3, 4};
  std::string error;
  int64_t failed = 7;

  SECTION("no batches") {
    CHECK_FALSE(kage::step_together({}, kage::Actions{actions.data(), kage::Memory::kDevice}, 2, &error, &failed));
    CHECK(error == "kage::step_together: no batches");
    CHECK(failed == -1);
  }
  SECTION("host actions") {
    CHECK_FALSE(kage::step_together({a.get(), b.get()}, kage::Actions{actions.data()}, 2, &error, &failed));
    CHECK(error == "kage::step_together: actions must be in device memory");
    CHECK(failed == -1);
  }
  SECTION("an action type other than int32 or int64") {
    kage::Actions bytes{actions.data(), kage::Memory::kDevice, kage::DType::kUInt8};
    CHECK_FALSE(kage::step_together({a.get(), b.get()}, bytes, 2, &error, &failed));
    CHECK(error == "kage: actions must be int32 or int64");
    CHECK(failed == -1);
  }
  SECTION("a batch on the CPU, and nothing stepped") {
    const std::vector<uint8_t> before(a->obs(), a->obs() + 2 * a->height() * a->width() * 3);
    CHECK_FALSE(kage::step_together({a.get(), b.get()}, kage::Actions{actions.data(), kage::Memory::kDevice}, 2,
                                    &error, &failed));
    CHECK(error == "kage::step_together: the batch runs on the CPU");
    CHECK(failed == 0);
    CHECK(std::vector<uint8_t>(a->obs(), a->obs() + before.size()) == before);
  }
}

TEST_CASE("host_actions_problem says what step would refuse, and nothing for good actions", "[integration][api]") {
  const std::vector<int64_t> good = {0, 7, 3}, bad = {0, 8, 3, 9};
  CHECK(kage::host_actions_problem(kage::Actions{good.data(), kage::Memory::kHost, kage::DType::kInt64}, 3).empty());
  CHECK(kage::host_actions_problem(kage::Actions{bad.data(), kage::Memory::kHost, kage::DType::kInt64}, 4) ==
        std::string("action 8 for environment 1: ") + kage::action_range_text());
  // Every other element (stride 2) of bad is 0 and 3: good.
  CHECK(kage::host_actions_problem(kage::Actions{bad.data(), kage::Memory::kHost, kage::DType::kInt64, 2}, 2).empty());
  CHECK(kage::host_actions_problem(kage::Actions{good.data(), kage::Memory::kHost, kage::DType::kFloat32}, 3) ==
        "actions must be int32 or int64");
}
