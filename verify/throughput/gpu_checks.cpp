// GPU vs CPU batch checks (see gpu_checks.h).
#include "verify/throughput/gpu_checks.h"

#include <cstring>
#include <set>
#include <thread>
#include <vector>

#include "runtime/cuda/device_batch.h"
#include "runtime/cpu/host_batch.h"
#include "runtime/visual/image_diff.h"

namespace kage::throughput {
namespace {

constexpr uint64_t kActionSeed = 7;
constexpr uint8_t kPoison = 0xA5;

template <class T>
bool download(std::vector<T>& out, const T* device, size_t n, std::string* error) {
  out.resize(n);
  const CUresult r = cuMemcpyDtoH(out.data(), reinterpret_cast<CUdeviceptr>(device), n * sizeof(T));
  if (r != CUDA_SUCCESS) *error = cu_error_text(r, "cuMemcpyDtoH");
  return r == CUDA_SUCCESS;
}

/// Number of environments whose latent state, layout or used visual-state prefix differ.
int32_t count_state_mismatches(const DeviceBatch& b, const HostBatch& cpu, int32_t extent, std::string* error) {
  const DeviceEnvs& e = b.envs();
  const size_t n = static_cast<size_t>(e.num_envs);
  const size_t layout_bytes = static_cast<size_t>(layout_segment_count(cpu.latent_params()));
  std::vector<LatentState> lat;
  std::vector<VisualState> vis;
  std::vector<uint8_t> seg;
  if (!download(lat, e.latent, n, error) || !download(vis, e.visual, n, error) ||
      !download(seg, e.segments, n * e.segment_stride, error))
    return -1;
  int32_t bad = 0;
  for (size_t i = 0; i < n; ++i) {
    const int32_t env = static_cast<int32_t>(i);
    const bool same = std::memcmp(&lat[i], &cpu.latent_state(env), sizeof(LatentState)) == 0 &&
                      std::memcmp(&vis[i], &cpu.visual_state(env), static_cast<size_t>(extent)) == 0 &&
                      std::memcmp(seg.data() + i * e.segment_stride, cpu.segments(env), layout_bytes) == 0;
    bad += same ? 0 : 1;
  }
  return bad;
}

/// The actions kage_sample_actions draws for step t.
std::vector<int32_t> sampled_actions(int32_t envs, uint32_t t) {
  std::vector<int32_t> a(static_cast<size_t>(envs));
  for (int32_t i = 0; i < envs; ++i) a[i] = benchmark_action(kActionSeed, t, static_cast<uint32_t>(i));
  return a;
}

}  // namespace

std::string CheckResult::summary() const {
  if (!error.empty()) return "error: " + error;
  return std::string(ok ? "PASS" : "FAIL") + " state mismatches " + std::to_string(state_mismatches) +
         ", obs max |diff| " + std::to_string(obs_max_abs) + ", equal " + std::to_string(obs_equal * 100.0) + " %";
}

CheckResult check_against_cpu(const CudaModule& module, const LatentParams& lp, const VisualParams& vp,
                              const AssetView& assets, int32_t envs, int32_t steps, int32_t max_code_diff) {
  CheckResult res;
  std::optional<DeviceBatch> b = DeviceBatch::create(module, lp, vp, assets, envs, &res.error);
  if (!b) return res;
  const int32_t threads = static_cast<int32_t>(std::max(1u, std::thread::hardware_concurrency()));
  HostBatch cpu(generic_host_kernels(lp, vp), assets, envs, threads);
  std::vector<uint64_t> seeds(envs);
  for (int32_t i = 0; i < envs; ++i) seeds[i] = 1000u + static_cast<uint64_t>(i) * 7919u;
  const std::set<int32_t> checkpoints = {0, 1, 2, 3, 100, lp.episode_length - 1, lp.episode_length,
                                         lp.episode_length + 1, steps};
  const int32_t extent = visual_state_extent(vp, assets);
  const size_t obs_bytes = b->obs_bytes_per_env() * envs;
  int64_t equal = 0, count = 0;
  std::vector<uint8_t> gpu_obs;
  auto poison = [&]() {
    const CUresult r = cuMemsetD8(b->obs(), kPoison, obs_bytes);
    if (r != CUDA_SUCCESS) res.error = cu_error_text(r, "cuMemsetD8(poison)");
    return r == CUDA_SUCCESS;
  };
  auto compare = [&]() {
    const int32_t bad = count_state_mismatches(*b, cpu, extent, &res.error);
    if (bad < 0) return false;
    res.state_mismatches += bad;
    if (!download(gpu_obs, b->envs().obs, obs_bytes, &res.error)) return false;
    const ImageDiff d = image_diff(gpu_obs.data(), cpu.observations(), static_cast<int64_t>(obs_bytes));
    res.obs_max_abs = std::max(res.obs_max_abs, d.max_abs);
    equal += d.equal;
    count += d.count;
    return true;
  };

  if (!poison() || !b->reset(seeds.data(), nullptr, &res.error)) return res;
  cpu.reset(seeds.data(), nullptr);
  if (!compare()) return res;
  for (int32_t t = 1; t <= steps; ++t) {
    const bool check_now = checkpoints.count(t) > 0;
    if (check_now && !poison()) return res;
    if (!b->sample_actions(kActionSeed, static_cast<uint32_t>(t), &res.error) || !b->step_device_actions(&res.error))
      return res;
    cpu.step(sampled_actions(envs, static_cast<uint32_t>(t)).data());
    if (check_now && !compare()) return res;
  }
  // The state-only kernel over the same episode from a fresh reset.
  if (!b->reset(seeds.data(), nullptr, &res.error)) return res;
  cpu.reset(seeds.data(), nullptr);
  for (int32_t t = 1; t <= steps; ++t) {
    if (!b->sample_actions(kActionSeed, static_cast<uint32_t>(t), &res.error) || !b->step_no_render(&res.error))
      return res;
    cpu.step(sampled_actions(envs, static_cast<uint32_t>(t)).data());
  }
  const int32_t bad = count_state_mismatches(*b, cpu, extent, &res.error);
  if (bad < 0) return res;
  res.state_mismatches += bad;
  const CUresult r = cuCtxSynchronize();
  if (r != CUDA_SUCCESS) {
    res.error = cu_error_text(r, "cuCtxSynchronize");
    return res;
  }
  res.obs_equal = count > 0 ? static_cast<double>(equal) / static_cast<double>(count) : 1.0;
  res.ok = res.state_mismatches == 0 && res.obs_max_abs <= max_code_diff;
  return res;
}

}  // namespace kage::throughput
