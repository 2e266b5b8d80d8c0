// kage_api_trace: runs a batch through the C++ API (include/kage/kage.h) with fixed seeds and actions and
// writes every output to a file, for the Python tests to compare the binding against, byte for byte.
//   usage: kage_api_trace CONFIG NUM_ENVS STEPS THREADS OUT
// Seeds: 1000 + 7919 * env. Actions at step t (1-based): (5 * t + 3 * env) % 8. Per record (the reset,
// then each step): obs, reward, terminated, truncated, every info field (info_fields() order),
// final_mask, final_obs, every final info field; each as the raw bytes of its [N] array.
#include <cstdio>
#include <fstream>
#include <string>
#include <vector>

#include "kage/kage.h"

namespace {

void write(std::ofstream& out, const void* data, size_t bytes) {
  out.write(static_cast<const char*>(data), static_cast<std::streamsize>(bytes));
}

size_t dtype_bytes(kage::DType t) { return t == kage::DType::kUInt8 ? 1 : t == kage::DType::kInt64 ? 8 : 4; }

void record(std::ofstream& out, const kage::Env& env) {
  const size_t n = static_cast<size_t>(env.num_envs());
  const size_t frame = static_cast<size_t>(env.height()) * env.width() * 3;
  int32_t count = 0;
  const kage::InfoFieldDesc* fields = kage::info_fields(&count);
  write(out, env.obs(), n * frame);
  write(out, env.reward(), n * sizeof(float));
  write(out, env.terminated(), n);
  write(out, env.truncated(), n);
  for (int32_t i = 0; i < count; ++i) write(out, env.info(fields[i].field), n * dtype_bytes(fields[i].dtype));
  write(out, env.final_mask(), n);
  write(out, env.final_obs(), n * frame);
  for (int32_t i = 0; i < count; ++i) write(out, env.final_info(fields[i].field), n * dtype_bytes(fields[i].dtype));
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 6) {
    std::fprintf(stderr, "usage: %s CONFIG NUM_ENVS STEPS THREADS OUT\n", argv[0]);
    return 2;
  }
  kage::Options o;
  o.num_envs = std::stoi(argv[2]);
  o.num_threads = std::stoi(argv[4]);
  const int steps = std::stoi(argv[3]);
  std::string error;
  auto env = kage::open(argv[1], o, &error);
  if (!env) return std::fprintf(stderr, "%s\n", error.c_str()), 1;
  std::ofstream out(argv[5], std::ios::binary);
  std::vector<uint64_t> seeds(static_cast<size_t>(o.num_envs));
  for (int32_t i = 0; i < o.num_envs; ++i) seeds[i] = 1000u + 7919u * static_cast<uint64_t>(i);
  if (!env->reset(seeds.data(), &error)) return std::fprintf(stderr, "%s\n", error.c_str()), 1;
  record(out, *env);
  std::vector<int32_t> actions(static_cast<size_t>(o.num_envs));
  for (int t = 1; t <= steps; ++t) {
    for (int32_t i = 0; i < o.num_envs; ++i) actions[i] = (5 * t + 3 * i) % 8;
    if (!env->step(actions.data(), &error)) return std::fprintf(stderr, "%s\n", error.c_str()), 1;
    record(out, *env);
  }
  return out ? 0 : 1;
}
