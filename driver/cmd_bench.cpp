// kagec bench: environment steps per second. --cpu: the CPU runtime, observations rendered, here;
// --gpu: bench_gpu (cmd_bench_gpu.cpp), in builds with the CUDA toolkit.
#include <chrono>
#include <ostream>
#include <thread>

#include "api/environment.h"
#include "driver/cli_common.h"
#include "driver/cmd_bench_gpu.h"
#include "runtime/rng.h"

namespace kage {

int cmd_bench(const std::vector<std::string>& args, CommandIo& io) {
  CLI::App app("Measure environment steps per second (observations rendered).", "bench");
  std::string config, asset_root;
  bool cpu = false, gpu = false;
  GpuBenchOptions gpu_options;
  int envs = 64, steps = 200, warmup = 10;
  int threads = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  app.add_option("config", config, "config file (with --gpu also a suite manifest: each distinct config of its pairs)")
      ->required();
  CLI::Option* cpu_flag = app.add_flag("--cpu", cpu, "run the CPU runtime");
  app.add_flag("--gpu", gpu, "compile in-process (NVRTC) and run on the GPU, against a copy roofline")->excludes(cpu_flag);
  app.add_option("--min-log2", gpu_options.min_log2, "--gpu: smallest batch, 2^K envs")->check(CLI::Range(0, 24));
  app.add_option("--max-log2", gpu_options.max_log2, "--gpu: largest batch, 2^K envs")->check(CLI::Range(0, 24));
  app.add_flag("--no-render", gpu_options.no_render, "--gpu: time only the step without rendering");
  app.add_option("--envs", envs, "environments in the batch")->check(CLI::PositiveNumber);
  app.add_option("--steps", steps, "timed steps of the whole batch")->check(CLI::PositiveNumber);
  app.add_option("--warmup", warmup, "untimed steps before the timed ones")->check(CLI::NonNegativeNumber);
  app.add_option("--threads", threads, "worker threads (default: all cores)")->check(CLI::PositiveNumber);
  app.add_option("--asset-root", asset_root, "resolve asset paths against this directory");
  if (auto code = parse_args(app, args, io)) return *code;
  if (!cpu && !gpu) {
    io.err << "kagec bench: choose a backend: --cpu or --gpu\n";
    return kExitUsage;
  }
  if (gpu) {
#if defined(KAGE_HAVE_GPU_BENCH)
    gpu_options.file = config;
    return bench_gpu(gpu_options, io);
#else
    io.err << "kagec bench --gpu: this kagec was built without the CUDA toolkit\n";
    return kExitErrors;
#endif
  }
  EnvironmentOptions options;
  options.num_envs = envs;
  options.num_threads = threads;
  if (!asset_root.empty()) options.asset_root = asset_root;
  EnvironmentResult opened = Environment::open(config, options);
  if (!opened.ok()) {
    io.err << opened.warnings << opened.error;
    hint_shipped("bench", "configs", config, io);
    return kExitErrors;
  }
  CpuEnv& env = opened.env->env();
  std::vector<uint64_t> seeds(envs);
  for (int i = 0; i < envs; ++i) seeds[i] = static_cast<uint64_t>(i);
  env.reset(seeds.data());
  // Uniform random actions, drawn before timing so that only the environment is measured; a ring of
  // kActionSteps steps bounds their memory whatever --steps is.
  constexpr int64_t kActionSteps = 64;
  std::vector<int32_t> actions(static_cast<size_t>(kActionSteps) * envs);
  for (size_t i = 0; i < actions.size(); ++i) actions[i] = randint(Key{0, 1}, static_cast<uint32_t>(i), 0, 8);
  auto step = [&](int64_t t) { env.step(actions.data() + static_cast<size_t>(t % kActionSteps) * envs); };
  for (int64_t t = 0; t < warmup; ++t) step(t);
  const auto start = std::chrono::steady_clock::now();
  for (int64_t t = warmup; t < int64_t(warmup) + steps; ++t) step(t);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const double rate = static_cast<double>(steps) * envs / seconds;
  io.out << config << ": cpu, " << envs << " envs x " << steps << " steps on " << threads
         << (threads == 1 ? " thread, " : " threads, ") << env.height() << "x" << env.width() << " observations: " << static_cast<long long>(rate)
         << " env-steps/s (" << seconds << " s)\n";
  return kExitOk;
}

}  // namespace kage
