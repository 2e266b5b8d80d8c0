#include "verify/throughput/gpu_measure.h"

#include <algorithm>
#include <optional>
#include <string>
#include <vector>

#include "runtime/cuda/device_batch.h"

namespace kage::throughput {
namespace {

constexpr int32_t kRepeats = 5;
constexpr int32_t kWarmupSteps = 3;

void cu_or_throw(CUresult r, const char* what) {
  if (r != CUDA_SUCCESS) throw MeasureError(cu_error_text(r, what));
}

void ok_or_throw(bool ok, const std::string& error) {
  if (!ok) throw MeasureError(error);
}

/// How a timed step runs: with observations (DeviceBatch's step), or state only.
enum class StepMode { kWithObs, kStateOnly };

}  // namespace

double median_ms(const std::function<void()>& run_once) {
  CUevent a, b;
  cu_or_throw(cuEventCreate(&a, CU_EVENT_DEFAULT), "cuEventCreate");
  cu_or_throw(cuEventCreate(&b, CU_EVENT_DEFAULT), "cuEventCreate");
  std::vector<double> t;
  for (int32_t i = 0; i < kRepeats; ++i) {
    cu_or_throw(cuEventRecord(a, nullptr), "cuEventRecord");
    run_once();
    cu_or_throw(cuEventRecord(b, nullptr), "cuEventRecord");
    cu_or_throw(cuEventSynchronize(b), "cuEventSynchronize");
    float ms = 0.0f;
    cu_or_throw(cuEventElapsedTime(&ms, a, b), "cuEventElapsedTime");
    t.push_back(ms);
  }
  cu_or_throw(cuEventDestroy(a), "cuEventDestroy");
  cu_or_throw(cuEventDestroy(b), "cuEventDestroy");
  std::sort(t.begin(), t.end());
  return t[t.size() / 2];
}

double measure_roofline() {
  const size_t bytes = size_t{4} << 30;
  CUdeviceptr src, dst;
  cu_or_throw(cuMemAlloc(&src, bytes), "cuMemAlloc(roofline)");
  cu_or_throw(cuMemAlloc(&dst, bytes), "cuMemAlloc(roofline)");
  cu_or_throw(cuMemsetD8(src, 0x5A, bytes), "cuMemsetD8");
  cu_or_throw(cuMemcpyDtoD(dst, src, bytes), "cuMemcpyDtoD");
  const double ms = median_ms([&] { cu_or_throw(cuMemcpyDtoD(dst, src, bytes), "cuMemcpyDtoD"); });
  cu_or_throw(cuMemFree(src), "cuMemFree");
  cu_or_throw(cuMemFree(dst), "cuMemFree");
  return 2.0 * static_cast<double>(bytes) / (ms * 1e-3) / 1e9;
}

double measure_fp32_rate(const CudaModule& module) {
  std::string error;
  CUfunction f = module.function("kage_fp32_peak", &error);
  if (!f) throw MeasureError(error);
  constexpr int32_t kThreads = 256, kBlocks = 8192, kIterations = 4096, kChains = 8;
  CUdeviceptr out;
  cu_or_throw(cuMemAlloc(&out, sizeof(float) * kThreads * kBlocks), "cuMemAlloc(fp32)");
  int32_t iterations = kIterations;
  float seed = 1.0f;
  void* args[] = {&out, &iterations, &seed};
  auto launch = [&] {
    cu_or_throw(cuLaunchKernel(f, kBlocks, 1, 1, kThreads, 1, 1, 0, nullptr, args, nullptr), "cuLaunchKernel(fp32)");
  };
  launch();
  const double ms = median_ms(launch);
  cu_or_throw(cuMemFree(out), "cuMemFree");
  const double flops = 2.0 * kChains * static_cast<double>(kIterations) * kThreads * kBlocks;
  return flops / (ms * 1e-3) / 1e9;
}

Timing time_config(const MeasureTarget& c, int32_t n, bool render, bool state_too) {
  std::string error;
  std::optional<DeviceBatch> b = DeviceBatch::create(*c.module, c.lp, c.vp, c.assets, n, &error);
  if (!b) throw MeasureError(error);
  std::vector<uint64_t> seeds(n);
  for (int32_t i = 0; i < n; ++i) seeds[i] = static_cast<uint64_t>(i);
  ok_or_throw(b->reset(seeds.data(), nullptr, &error), error);
  uint32_t t = 0;
  auto steps = [&](int32_t count, StepMode mode) {
    for (int32_t s = 0; s < count; ++s) {
      ok_or_throw(b->sample_actions(11, ++t, &error), error);
      ok_or_throw(mode == StepMode::kWithObs ? b->step_device_actions(&error) : b->step_no_render(&error), error);
    }
  };
  // Each timed repeat runs enough steps for about 100 ms, judged from one timed warm-up step.
  auto steps_per_repeat = [&](StepMode mode) {
    steps(kWarmupSteps - 1, mode);
    CUevent a, b2;
    cu_or_throw(cuEventCreate(&a, CU_EVENT_DEFAULT), "cuEventCreate");
    cu_or_throw(cuEventCreate(&b2, CU_EVENT_DEFAULT), "cuEventCreate");
    cu_or_throw(cuEventRecord(a, nullptr), "cuEventRecord");
    steps(1, mode);
    cu_or_throw(cuEventRecord(b2, nullptr), "cuEventRecord");
    cu_or_throw(cuEventSynchronize(b2), "cuEventSynchronize");
    float ms = 0.0f;
    cu_or_throw(cuEventElapsedTime(&ms, a, b2), "cuEventElapsedTime");
    cu_or_throw(cuEventDestroy(a), "cuEventDestroy");
    cu_or_throw(cuEventDestroy(b2), "cuEventDestroy");
    return std::clamp(static_cast<int32_t>(100.0f / std::max(ms, 1e-3f)), 1, 1024);
  };
  auto rate = [&](StepMode mode) {
    const int32_t k = steps_per_repeat(mode);
    const double ms = median_ms([&] { steps(k, mode); });
    return static_cast<double>(n) * k / (ms * 1e-3);
  };
  Timing out{render ? rate(StepMode::kWithObs) : 0.0, state_too ? rate(StepMode::kStateOnly) : 0.0};
  cu_or_throw(cuCtxSynchronize(), "cuCtxSynchronize");
  return out;
}

}  // namespace kage::throughput
