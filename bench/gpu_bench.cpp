// kage_gpu_bench: correctness (GPU vs CPU reference) and throughput of the CUDA runtime for the
// throughput configs, against a device-to-device copy roofline measured in the same run.
//
// Usage: kage_gpu_bench MODULE_DIR ASSET_BLOB [--min-log2 K] [--max-log2 K] [--check-envs N]
//                       [--nvrtc-root DIR] [--breakdown] [--skip-checks] [--configs simplest,hardest]
// MODULE_DIR holds simplest.fatbin, hardest.fatbin and dynamic.fatbin (the bench build's outputs).
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <functional>
#include <sstream>
#include <string>
#include <vector>

#include "bench/asset_blob.h"
#include "bench/bench_checks.h"
#include "bench/bench_configs.h"
#include "runtime/cuda/device_batch.h"
#include "runtime/cuda/module_loader.h"

namespace kage::bench {
namespace {

constexpr int32_t kRepeats = 5;
constexpr int32_t kWarmupSteps = 3;

[[noreturn]] void die(const std::string& msg) {
  std::fprintf(stderr, "kage_gpu_bench: %s\n", msg.c_str());
  std::exit(1);
}

void ok_or_die(bool ok, const std::string& error) {
  if (!ok) die(error);
}

void cu_or_die(CUresult r, const char* what) {
  if (r != CUDA_SUCCESS) die(cu_error_text(r, what));
}

/// Median of kRepeats timings (ms) of `run_once`, each bracketed by events on the default stream.
double median_ms(const std::function<void()>& run_once) {
  CUevent a, b;
  cu_or_die(cuEventCreate(&a, CU_EVENT_DEFAULT), "cuEventCreate");
  cu_or_die(cuEventCreate(&b, CU_EVENT_DEFAULT), "cuEventCreate");
  std::vector<double> t;
  for (int32_t i = 0; i < kRepeats; ++i) {
    cu_or_die(cuEventRecord(a, nullptr), "cuEventRecord");
    run_once();
    cu_or_die(cuEventRecord(b, nullptr), "cuEventRecord");
    cu_or_die(cuEventSynchronize(b), "cuEventSynchronize");
    float ms = 0.0f;
    cu_or_die(cuEventElapsedTime(&ms, a, b), "cuEventElapsedTime");
    t.push_back(ms);
  }
  cu_or_die(cuEventDestroy(a), "cuEventDestroy");
  cu_or_die(cuEventDestroy(b), "cuEventDestroy");
  std::sort(t.begin(), t.end());
  return t[t.size() / 2];
}

/// Device-to-device copy bandwidth in GB/s (bytes read + written), 4 GiB each way.
double measure_roofline() {
  const size_t bytes = size_t{4} << 30;
  CUdeviceptr src, dst;
  cu_or_die(cuMemAlloc(&src, bytes), "cuMemAlloc(roofline)");
  cu_or_die(cuMemAlloc(&dst, bytes), "cuMemAlloc(roofline)");
  cu_or_die(cuMemsetD8(src, 0x5A, bytes), "cuMemsetD8");
  cu_or_die(cuMemcpyDtoD(dst, src, bytes), "cuMemcpyDtoD");
  const double ms = median_ms([&] { cu_or_die(cuMemcpyDtoD(dst, src, bytes), "cuMemcpyDtoD"); });
  cu_or_die(cuMemFree(src), "cuMemFree");
  cu_or_die(cuMemFree(dst), "cuMemFree");
  return 2.0 * static_cast<double>(bytes) / (ms * 1e-3) / 1e9;
}

struct Config {
  std::string name;
  const CudaModule* module;
  LatentParams lp;
  VisualParams vp;
};

struct Timing {
  double render_steps_per_s;
  double state_steps_per_s;
  double split_steps_per_s;  ///< state-only step kernel, then the render kernel
};

/// How a timed step runs: fused step + render, state only, or the two kernels one after the other.
enum class StepMode { kFused, kStateOnly, kSplit };

/// Steps/s of the fused step + render, of the state-only step and of the split step + render for n
/// environments (the last two only with `state_too`).
Timing time_config(const Config& c, const AssetView& assets, int32_t n, bool state_too) {
  std::string error;
  std::optional<DeviceBatch> b = DeviceBatch::create(*c.module, c.lp, c.vp, assets, n, &error);
  if (!b) die(c.name + ": " + error);
  std::vector<uint64_t> seeds(n);
  for (int32_t i = 0; i < n; ++i) seeds[i] = static_cast<uint64_t>(i);
  ok_or_die(b->reset(seeds.data(), &error), error);
  uint32_t t = 0;
  auto steps = [&](int32_t count, StepMode mode) {
    for (int32_t s = 0; s < count; ++s) {
      ok_or_die(b->sample_actions(11, ++t, &error), error);
      ok_or_die(mode == StepMode::kFused ? b->step_device_actions(&error) : b->step_no_render(&error), error);
      if (mode == StepMode::kSplit) ok_or_die(b->render(&error), error);
    }
  };
  // Each timed repeat runs enough steps for about 100 ms, judged from one timed warm-up step.
  auto steps_per_repeat = [&](StepMode render) {
    steps(kWarmupSteps - 1, render);
    CUevent a, b2;
    cu_or_die(cuEventCreate(&a, CU_EVENT_DEFAULT), "cuEventCreate");
    cu_or_die(cuEventCreate(&b2, CU_EVENT_DEFAULT), "cuEventCreate");
    cu_or_die(cuEventRecord(a, nullptr), "cuEventRecord");
    steps(1, render);
    cu_or_die(cuEventRecord(b2, nullptr), "cuEventRecord");
    cu_or_die(cuEventSynchronize(b2), "cuEventSynchronize");
    float ms = 0.0f;
    cu_or_die(cuEventElapsedTime(&ms, a, b2), "cuEventElapsedTime");
    cu_or_die(cuEventDestroy(a), "cuEventDestroy");
    cu_or_die(cuEventDestroy(b2), "cuEventDestroy");
    return std::clamp(static_cast<int32_t>(100.0f / std::max(ms, 1e-3f)), 1, 1024);
  };
  auto rate = [&](StepMode mode) {
    const int32_t k = steps_per_repeat(mode);
    const double ms = median_ms([&] { steps(k, mode); });
    return static_cast<double>(n) * k / (ms * 1e-3);
  };
  Timing out{rate(StepMode::kFused), 0.0, 0.0};
  if (state_too) {
    out.state_steps_per_s = rate(StepMode::kStateOnly);
    out.split_steps_per_s = rate(StepMode::kSplit);
  }
  cu_or_die(cuCtxSynchronize(), "cuCtxSynchronize");
  return out;
}

std::string read_text(const std::string& path) {
  std::ifstream in(path);
  if (!in) die(path + ": cannot read");
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

CudaModule load(const std::string& path) {
  std::string error;
  std::optional<CudaModule> m = CudaModule::load_file(path, &error);
  if (!m) die(error);
  return std::move(*m);
}

/// Hardest-config variants with one group of stages removed, run through the generic build.
std::vector<std::pair<std::string, VisualParams>> breakdown_variants() {
  const VisualParams h = hardest_visual();
  std::vector<std::pair<std::string, VisualParams>> v;
  v.emplace_back("hardest (all stages)", h);
  VisualParams p = h;
  p.poisson_noise_scale = 0.0f;
  v.emplace_back("without poisson noise", p);
  p.gaussian_noise_std = 0.0f;
  p.color_jitter_std = 0.0f;
  v.emplace_back("without any noise/jitter", p);
  p = h;
  p.point_light_enabled = false;
  v.emplace_back("without point lights", p);
  p = h;
  p.blur_sigma = 0.0f;
  p.sharpen_amount = 0.0f;
  p.pixelate_factor = 1;
  v.emplace_back("without blur/sharpen/pixelate (register path)", p);
  p = h;
  p.npc_enabled = false;
  p.sticky_enabled = false;
  p.distractors_enabled = false;
  v.emplace_back("without NPCs/sticky/distractors", p);
  p = h;
  p.brightness = 0.0f; p.contrast = 1.0f; p.gamma = 1.0f; p.saturation = 1.0f; p.hue_shift = 0.0f;
  p.color_temp = 0.0f; p.color_jitter_std = 0.0f; p.gaussian_noise_std = 0.0f; p.poisson_noise_scale = 0.0f;
  p.blur_sigma = 0.0f; p.sharpen_amount = 0.0f; p.pixelate_factor = 1; p.vignette_strength = 0.0f;
  p.radial_light_strength = 0.0f;
  p.point_light_enabled = false;
  v.emplace_back("compose only (no filters, no lights)", p);
  return v;
}

}  // namespace
}  // namespace kage::bench

int main(int argc, char** argv) {
  using namespace kage;
  using namespace kage::bench;
  if (argc < 3) die("usage: kage_gpu_bench MODULE_DIR ASSET_BLOB [--min-log2 K] [--max-log2 K] [--check-envs N] "
                    "[--nvrtc-root DIR] [--breakdown]");
  const std::string dir = argv[1];
  int32_t min_log2 = 12, max_log2 = 20, check_envs = 64;
  std::string nvrtc_root;
  std::string only = "simplest,hardest";
  bool breakdown = false;
  bool skip_checks = false;
  for (int i = 3; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) die(a + " needs a value");
      return argv[++i];
    };
    if (a == "--min-log2") min_log2 = std::atoi(next().c_str());
    else if (a == "--max-log2") max_log2 = std::atoi(next().c_str());
    else if (a == "--check-envs") check_envs = std::atoi(next().c_str());
    else if (a == "--nvrtc-root") nvrtc_root = next();
    else if (a == "--configs") only = next();
    else if (a == "--breakdown") breakdown = true;
    else if (a == "--skip-checks") skip_checks = true;
    else die("unknown option " + a);
  }
  std::string error;
  std::optional<AssetBlob> blob = read_asset_blob(argv[2], &error);
  if (!blob) die(error);
  const AssetView assets = blob->view();
  const AssetView no_assets{};

  CUcontext ctx = cuda_primary_context(&error);
  if (!ctx) die(error);
  CUdevice dev;
  char name[256];
  cu_or_die(cuCtxGetDevice(&dev), "cuCtxGetDevice");
  cu_or_die(cuDeviceGetName(name, sizeof name, dev), "cuDeviceGetName");
  std::printf("# kage_gpu_bench on %s\n\n", name);

  const CudaModule simplest = load(dir + "/simplest.fatbin");
  const CudaModule hardest = load(dir + "/hardest.fatbin");
  const CudaModule dynamic = load(dir + "/dynamic.fatbin");
  const Config cfgs[] = {{"simplest", &simplest, yaml_latent(), simplest_visual()},
                         {"hardest", &hardest, yaml_latent(), hardest_visual()}};
  auto assets_of = [&](const Config& c) { return c.name == "simplest" ? no_assets : assets; };

  std::printf("## Correctness (GPU vs CPU reference, %d envs, %d steps)\n\n", check_envs, yaml_latent().episode_length + 5);
  bool all_ok = true;
  for (const Config& c : skip_checks ? std::vector<Config>{} : std::vector<Config>(std::begin(cfgs), std::end(cfgs))) {
    // Every config within 1 code per channel: the transcendentals are IEEE-only (kage_math.h), so the
    // noise samplers draw the same samples on both sides (identical frames expected).
    const int32_t tol = 1;
    for (const auto& [label, module] : {std::pair<std::string, const CudaModule*>{"specialized", c.module},
                                        std::pair<std::string, const CudaModule*>{"generic", &dynamic}}) {
      const CheckResult r = check_against_cpu(*module, c.lp, c.vp, assets_of(c), check_envs,
                                              c.lp.episode_length + 5, tol);
      std::printf("- %s (%s): %s\n", c.name.c_str(), label.c_str(), r.summary().c_str());
      all_ok = all_ok && r.ok;
    }
  }
  if (!nvrtc_root.empty() && !skip_checks) {
    NvrtcOptions o{nvrtc_root, "bench-1", {}};
    const std::string src = read_text(nvrtc_root + "/bench/modules/simplest.cu");
    for (int pass = 0; pass < 2; ++pass) {
      bool hit = false;
      std::optional<CudaModule> m = CudaModule::compile(src, "simplest.cu", o, &error, &hit);
      if (!m) die("NVRTC: " + error);
      const CheckResult r = check_against_cpu(*m, yaml_latent(), simplest_visual(), no_assets, 16, 8, 1);
      std::printf("- simplest via NVRTC (cache %s): %s\n", hit ? "hit" : "miss", r.summary().c_str());
      all_ok = all_ok && r.ok;
    }
  }
  std::fflush(stdout);

  const double roof = measure_roofline();
  std::printf("\n## Roofline\n\ndevice-to-device copy: %.1f GB/s (read + write) = %.1f M frames/s of 128x128x3\n",
              roof, roof * 1e9 / 49152.0 / 1e6);
  std::printf("per-env state: %zu bytes (+ %d observation bytes)\n\n", device_state_bytes_per_env(yaml_latent()),
              128 * 128 * 3);
  std::printf("## Throughput\n\n| config | envs | steps/s with obs (fused) | obs GB/s | %% of roofline | "
              "split step+render steps/s | split %% of roofline | steps/s state only |\n"
              "|---|---|---|---|---|---|---|---|\n");
  for (const Config& c : cfgs) {
    if (only.find(c.name) == std::string::npos) continue;
    for (int32_t k = min_log2; k <= max_log2; ++k) {
      const Timing t = time_config(c, assets_of(c), 1 << k, true);
      const double gbs = t.render_steps_per_s * 49152.0 / 1e9;
      const double split_gbs = t.split_steps_per_s * 49152.0 / 1e9;
      std::printf("| %s | 2^%d | %.3g | %.0f | %.1f | %.3g | %.1f | %.3g |\n", c.name.c_str(), k,
                  t.render_steps_per_s, gbs, 100.0 * gbs / roof, t.split_steps_per_s, 100.0 * split_gbs / roof,
                  t.state_steps_per_s);
      std::fflush(stdout);
    }
  }
  if (breakdown) {
    std::printf("\n## Hardest, stages removed (generic build, 2^14 envs)\n\n| variant | steps/s with obs |\n|---|---|\n");
    for (const auto& [label, vp] : breakdown_variants()) {
      const Config c{"hardest", &dynamic, yaml_latent(), vp};
      std::printf("| %s | %.3g |\n", label.c_str(), time_config(c, assets, 1 << 14, false).render_steps_per_s);
      std::fflush(stdout);
    }
    std::printf("| hardest, specialized build | %.3g |\n",
                time_config(cfgs[1], assets, 1 << 14, false).render_steps_per_s);
  }
  std::printf("\n%s\n", all_ok ? "all checks passed" : "SOME CHECKS FAILED");
  return all_ok ? 0 : 1;
}
