// kage_gpu_throughput: correctness (GPU vs CPU batch), load times and throughput of the CUDA runtime
// for configs compiled by `kagec compile`, against a device-to-device copy roofline measured in the
// same run, and the device's FP32 rate (fp32_peak.fatbin beside GENERIC_FATBIN).
//
// Usage: kage_gpu_throughput GENERIC_FATBIN --compiled DIR... [--min-log2 K] [--max-log2 K] [--check-envs N]
//                            [--nvrtc-root DIR] [--breakdown] [--skip-checks] [--check-only]
// GENERIC_FATBIN is this build's dynamic.fatbin. Each DIR is a `kagec compile` output directory
// (its manifest, kernels.fatbin, the generated source, params.bin, assets.bin, read and verified
// through compiler/codegen/compiled_dir.h), named after its last path component;
// --breakdown needs one named "hardest". With --nvrtc-root (the directory holding runtime/), the
// generated source is also compiled with NVRTC, cold (empty cache) and warm (disk cache hit).
// --check-only checks every DIR through the generic build against the CPU batch (observations
// within 1 code) and stops: DIRs need only params.bin and assets.bin (kagec compile --no-gpu), so all
// shipped configs can be checked without building a fatbin for each.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include "compiler/codegen/compiled_dir.h"
#include "runtime/cuda/device_batch.h"
#include "runtime/cuda/module_loader.h"
#include "verify/throughput/gpu_checks.h"
#include "verify/throughput/gpu_measure.h"

namespace kage::throughput {
namespace {

[[noreturn]] void die(const std::string& msg) {
  std::fprintf(stderr, "kage_gpu_throughput: %s\n", msg.c_str());
  std::exit(1);
}

void ok_or_die(bool ok, const std::string& error) {
  if (!ok) die(error);
}

void cu_or_die(CUresult r, const char* what) {
  if (r != CUDA_SUCCESS) die(cu_error_text(r, what));
}

/// One timed config: its name and what its batches run with.
struct Config : MeasureTarget {
  std::string name;
};

CudaModule load(const std::string& path) {
  std::string error;
  std::optional<CudaModule> m = CudaModule::load_file(path, &error);
  if (!m) die(error);
  return std::move(*m);
}

SpriteSetTable table_of(const std::vector<SpriteSet>& sets) {
  SpriteSetTable t{};
  t.sets = sets.empty() ? nullptr : sets.data();
  t.count = static_cast<int32_t>(sets.size());
  for (const SpriteSet& s : sets) t.max_frames = std::max(t.max_frames, s.frame_count);
  return t;
}

/// One `kagec compile` directory: its parameters, assets (host copies) and generated source.
struct BenchDir {
  std::string name;
  std::filesystem::path dir;
  LatentParams lp{};
  VisualParams vp{};
  AssetPack pack;
  std::string source;       ///< kage_<hash>.cu
  std::string source_name;

  /// AssetPack::view() lives in the host runtime (image decoders); this program has only the CUDA
  /// toolkit, so it builds the same pointer view itself.
  AssetView assets() const {
    AssetView v{};
    v.bg = pack.bg.empty() ? nullptr : pack.bg.data();
    v.bg_count = pack.bg_count;
    v.bg_h = pack.bg_h;
    v.bg_w = pack.bg_w;
    v.sprite_pixels = pack.sprite_pixels.empty() ? nullptr : pack.sprite_pixels.data();
    v.frames = pack.frames.empty() ? nullptr : pack.frames.data();
    v.agent_skins = table_of(pack.agent_skins);
    v.npc_types = table_of(pack.npc_types);
    v.sticky_types = table_of(pack.sticky_types);
    return v;
  }
};

BenchDir read_compiled(const std::string& path) {
  namespace fs = std::filesystem;
  std::string error;
  const std::optional<CompiledDir> compiled = open_compiled_dir(path, &error);
  if (!compiled) die(error);
  BenchDir c;
  c.dir = compiled->dir;
  c.name = fs::absolute(c.dir).lexically_normal().filename().string();
  if (c.name.empty()) c.name = fs::absolute(c.dir).lexically_normal().parent_path().filename().string();
  if (!read_compiled_params(*compiled, &c.lp, &c.vp, &error)) die(error);
  std::optional<AssetPack> pack = read_compiled_assets(*compiled, &error);
  if (!pack) die(error);
  c.pack = std::move(*pack);
  // --check-only needs no source; the NVRTC pass checks for one.
  if (std::optional<std::string> source = read_compiled_source(*compiled, &error)) {
    c.source = std::move(*source);
    c.source_name = compiled->source_name();
  }
  return c;
}

using Clock = std::chrono::steady_clock;

/// Seconds from `start` to the end of the first step of 1,024 environments of module `m`.
double first_step_s(const CudaModule& m, const BenchDir& c, Clock::time_point start) {
  std::string error;
  std::optional<DeviceBatch> b = DeviceBatch::create(m, c.lp, c.vp, c.assets(), 1024, &error);
  if (!b) die(c.name + ": " + error);
  std::vector<uint64_t> seeds(1024);
  for (size_t i = 0; i < seeds.size(); ++i) seeds[i] = i;
  ok_or_die(b->reset(seeds.data(), nullptr, &error), error);
  ok_or_die(b->sample_actions(11, 1, &error), error);
  ok_or_die(b->step_device_actions(&error), error);
  cu_or_die(cuCtxSynchronize(), "cuCtxSynchronize");
  return std::chrono::duration<double>(Clock::now() - start).count();
}

/// Hardest-config variants with one group of stages removed, run through the generic build.
std::vector<std::pair<std::string, VisualParams>> breakdown_variants(const VisualParams& h) {
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

/// Every dir through the generic build: state identical, observations within 1 code (the generic
/// build must match the CPU on every shipped config, not only on the two timed ones). Returns the
/// exit status.
int check_only(const CudaModule& dynamic, const std::vector<BenchDir>& dirs, int32_t envs) {
  std::printf("## Generic build vs CPU batch, every config (%d envs, episode length + 5 steps)\n\n"
              "| config | episode length | steps | state mismatches | obs max diff | obs equal %% | result |\n"
              "|---|---|---|---|---|---|---|\n", envs);
  int32_t passed = 0;
  for (const BenchDir& c : dirs) {
    const int32_t steps = c.lp.episode_length + 5;
    const CheckResult r = check_against_cpu(dynamic, c.lp, c.vp, c.assets(), envs, steps, 1);
    if (!r.error.empty()) {
      std::printf("| %s | %d | %d | - | - | - | error: %s |\n", c.name.c_str(), c.lp.episode_length, steps,
                  r.error.c_str());
    } else {
      std::printf("| %s | %d | %d | %d | %d | %.4f | %s |\n", c.name.c_str(), c.lp.episode_length, steps,
                  r.state_mismatches, r.obs_max_abs, 100.0 * r.obs_equal, r.ok ? "PASS" : "FAIL");
    }
    std::fflush(stdout);
    passed += r.ok ? 1 : 0;
  }
  std::printf("\n%d of %zu configs passed\n", passed, dirs.size());
  return passed == static_cast<int32_t>(dirs.size()) ? 0 : 1;
}

}  // namespace
}  // namespace kage::throughput

namespace {

int run(int argc, char** argv) {
  using namespace kage;
  using namespace kage::throughput;
  if (argc < 2) die("usage: kage_gpu_throughput GENERIC_FATBIN --compiled DIR... [--min-log2 K] [--max-log2 K] "
                    "[--check-envs N] [--nvrtc-root DIR] [--breakdown] [--skip-checks] [--check-only]");
  int32_t min_log2 = 12, max_log2 = 20, check_envs = 64;
  std::string nvrtc_root;
  std::vector<std::string> dirs;
  bool breakdown = false;
  bool skip_checks = false;
  bool only_checks = false;
  for (int i = 2; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> std::string {
      if (i + 1 >= argc) die(a + " needs a value");
      return argv[++i];
    };
    if (a == "--min-log2") min_log2 = std::atoi(next().c_str());
    else if (a == "--max-log2") max_log2 = std::atoi(next().c_str());
    else if (a == "--check-envs") check_envs = std::atoi(next().c_str());
    else if (a == "--nvrtc-root") nvrtc_root = next();
    else if (a == "--compiled") {
      while (i + 1 < argc && std::strncmp(argv[i + 1], "--", 2) != 0) dirs.push_back(argv[++i]);
    }
    else if (a == "--breakdown") breakdown = true;
    else if (a == "--skip-checks") skip_checks = true;
    else if (a == "--check-only") only_checks = true;
    else die("unknown option " + a);
  }
  if (dirs.empty()) die("no --compiled DIR");
  std::vector<BenchDir> compiled;
  for (const std::string& d : dirs) compiled.push_back(read_compiled(d));

  std::string error;
  CUcontext ctx = cuda_primary_context(&error);
  if (!ctx) die(error);
  CUdevice dev;
  char name[256];
  cu_or_die(cuCtxGetDevice(&dev), "cuCtxGetDevice");
  cu_or_die(cuDeviceGetName(name, sizeof name, dev), "cuDeviceGetName");
  std::printf("# kage_gpu_throughput on %s\n\n", name);
  if (only_checks) return check_only(load(argv[1]), compiled, check_envs);

  // Load to first step: the fatbin through the driver, then the generated source through NVRTC with
  // an empty cache (run_device.sh empties it) and again from the disk cache.
  std::printf("## Load to first step (1,024 envs: load, batch, reset, one step)\n\n"
              "| config | fatbin s | NVRTC cold s | NVRTC warm s (cache hit) |\n|---|---|---|---|\n");
  std::vector<CudaModule> modules;
  bool all_ok = true;
  for (const BenchDir& c : compiled) {
    Clock::time_point t0 = Clock::now();
    modules.push_back(load((c.dir / "kernels.fatbin").string()));
    const double fatbin_s = first_step_s(modules.back(), c, t0);
    double times[2] = {0.0, 0.0};
    bool hits[2] = {false, false};
    for (int pass = 0; pass < 2 && !nvrtc_root.empty(); ++pass) {
      if (c.source_name.empty()) die(c.dir.string() + ": its manifest names no generated source");
      const NvrtcOptions o{nvrtc_root, "bench-compiled-1", {}};
      t0 = Clock::now();
      std::optional<CudaModule> m = CudaModule::compile(c.source, c.source_name, o, &error, &hits[pass]);
      if (!m) die("NVRTC: " + error);
      times[pass] = first_step_s(*m, c, t0);
      if (pass == 1 && !skip_checks) {
        const CheckResult r = check_against_cpu(*m, c.lp, c.vp, c.assets(), 16, 8, 0);
        std::printf("<!-- %s via NVRTC: %s -->\n", c.name.c_str(), r.summary().c_str());
        all_ok = all_ok && r.ok;
      }
    }
    std::printf("| %s | %.3f | %.3f%s | %.3f%s |\n", c.name.c_str(), fatbin_s, times[0], hits[0] ? " (hit!)" : "",
                times[1], nvrtc_root.empty() || hits[1] ? "" : " (miss!)");
    std::fflush(stdout);
  }
  const CudaModule dynamic = load(argv[1]);
  std::vector<Config> cfgs;
  for (size_t i = 0; i < compiled.size(); ++i)
    cfgs.push_back({{&modules[i], compiled[i].lp, compiled[i].vp, compiled[i].assets()}, compiled[i].name});

  std::printf("\n## Correctness (GPU vs CPU batch, %d envs, episode length + 5 steps)\n\n", check_envs);
  for (const Config& c : skip_checks ? std::vector<Config>{} : cfgs) {
    // Identical frames expected: the transcendentals are IEEE-only (kage_math.h), so the noise
    // samplers draw the same samples on both sides.
    for (const auto& [label, module] : {std::pair<std::string, const CudaModule*>{"specialized", c.module},
                                        std::pair<std::string, const CudaModule*>{"generic", &dynamic}}) {
      const CheckResult r = check_against_cpu(*module, c.lp, c.vp, c.assets, check_envs, c.lp.episode_length + 5, 0);
      std::printf("- %s (%s): %s\n", c.name.c_str(), label.c_str(), r.summary().c_str());
      all_ok = all_ok && r.ok;
    }
  }
  std::fflush(stdout);

  const double roof = measure_roofline();
  // The FP32 kernel sits beside the generic kernels (verify/throughput/CMakeLists.txt).
  const CudaModule fp32 = load((std::filesystem::path(argv[1]).parent_path() / "fp32_peak.fatbin").string());
  const double fp32_gflops = measure_fp32_rate(fp32);
  std::printf("\n## Roofline\n\ndevice-to-device copy: %.1f GB/s (read + write) = %.1f M frames/s of 128x128x3\n"
              "FP32 (chains of fused multiply-adds, 2 FLOPs each): %.1f TFLOP/s\n\n",
              roof, roof * 1e9 / 49152.0 / 1e6, fp32_gflops / 1e3);
  std::printf("## Throughput\n\n| config | envs | steps/s with obs | obs GB/s | %% of roofline | steps/s state only |\n"
              "|---|---|---|---|---|---|\n");
  for (const Config& c : cfgs) {
    const double frame_bytes = 3.0 * c.vp.H * c.vp.W;
    for (int32_t k = min_log2; k <= max_log2; ++k) {
      const Timing t = time_config(c, 1 << k, true, true);
      const double gbs = t.render_steps_per_s * frame_bytes / 1e9;
      std::printf("| %s | 2^%d | %.3g | %.0f | %.1f | %.3g |\n", c.name.c_str(), k, t.render_steps_per_s, gbs,
                  100.0 * gbs / roof, t.state_steps_per_s);
      std::fflush(stdout);
    }
  }
  if (breakdown) {
    const auto hardest = std::find_if(cfgs.begin(), cfgs.end(), [](const Config& c) { return c.name == "hardest"; });
    if (hardest == cfgs.end()) die("--breakdown needs a compiled dir named hardest");
    std::printf("\n## Hardest, stages removed (generic build, 2^14 envs)\n\n| variant | steps/s with obs |\n|---|---|\n");
    for (const auto& [label, vp] : breakdown_variants(hardest->vp)) {
      const MeasureTarget c{&dynamic, hardest->lp, vp, hardest->assets};
      std::printf("| %s | %.3g |\n", label.c_str(), time_config(c, 1 << 14, true, false).render_steps_per_s);
      std::fflush(stdout);
    }
    const double rate = time_config(*hardest, 1 << 14, true, false).render_steps_per_s;
    std::printf("| hardest, specialized build | %.3g |\n\nAt %.3g frames/s the measured FP32 rate leaves %.0f FP32 "
                "operations per pixel; 2 M frames/s would leave %.0f.\n",
                rate, rate, fp32_gflops * 1e9 / rate / (hardest->vp.H * hardest->vp.W),
                fp32_gflops * 1e9 / 2e6 / (hardest->vp.H * hardest->vp.W));
  }
  std::printf("\n%s\n", all_ok ? "all checks passed" : "SOME CHECKS FAILED");
  return all_ok ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    return run(argc, argv);
  } catch (const kage::throughput::MeasureError& e) {
    kage::throughput::die(e.what());
  }
}
