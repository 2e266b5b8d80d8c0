// Minimal use of the kage C++ API: open a config (YAML or a `kagec compile` output dir), reset a
// batch, step it with a fixed policy, print the returns and an observation checksum.
//   usage: kage_example_minimal CONFIG_OR_DIR [cpu|gpu]
#include <cstdint>
#include <cstdio>
#include <string>
#include <vector>

#include "kage/kage.h"

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s CONFIG_OR_DIR [cpu|gpu]\n", argv[0]);
    return 2;
  }
  kage::Options options;
  options.num_envs = 4;
  options.backend = argc > 2 && std::string(argv[2]) == "gpu" ? kage::Backend::kGpu : kage::Backend::kCpu;
  std::string error;
  std::unique_ptr<kage::Env> env = kage::open(argv[1], options, &error);
  if (!env) {
    std::fprintf(stderr, "%s\n", error.c_str());
    return 1;
  }
  std::vector<uint64_t> seeds = {0, 1, 2, 3};
  std::vector<int32_t> actions(env->num_envs(), 2 | 4);  // right + jump
  if (!env->reset(seeds.data(), &error)) return std::fprintf(stderr, "%s\n", error.c_str()), 1;
  double total = 0;
  for (int t = 0; t < 100; ++t) {
    if (!env->step(actions.data(), &error)) return std::fprintf(stderr, "%s\n", error.c_str()), 1;
    // Rewards and info are host arrays on the CPU backend, device arrays on the GPU backend.
    if (env->backend() == kage::Backend::kCpu) {
      for (int32_t i = 0; i < env->num_envs(); ++i) total += env->reward()[i];
    }
  }
  // FNV-1a over every observation byte, copied to the host on either backend.
  std::vector<uint8_t> obs(static_cast<size_t>(env->num_envs()) * env->height() * env->width() * 3);
  if (!env->copy_obs(obs.data(), &error)) return std::fprintf(stderr, "%s\n", error.c_str()), 1;
  uint64_t h = 1469598103934665603ull;
  for (uint8_t byte : obs) h = (h ^ byte) * 1099511628211ull;
  std::printf("spec %.16s  envs %d  %dx%d  obs fnv1a %016llx\n", env->spec_hash().c_str(), env->num_envs(),
              env->height(), env->width(), static_cast<unsigned long long>(h));
  if (env->backend() == kage::Backend::kCpu)
    std::printf("total reward %.4f  x[0] %.1f\n", total, static_cast<const float*>(env->info(kage::InfoField::kX))[0]);
  return 0;
}
