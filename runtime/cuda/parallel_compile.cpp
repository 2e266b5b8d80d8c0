// Several configs' kernels compiled at once (see parallel_compile.h).
#include "runtime/cuda/parallel_compile.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <mutex>
#include <thread>

namespace kage {

size_t compile_threads(size_t jobs) {
  const size_t cores = std::max<size_t>(std::thread::hardware_concurrency(), 1);
  return std::clamp<size_t>(std::min<size_t>(cores, jobs), 1, 16);
}

void compile_jobs(std::vector<KernelJob>& jobs, const NvrtcOptions& options, const std::string& arch,
                  size_t threads, const std::function<void(const KernelJob&, size_t done)>& finished) {
  std::atomic<size_t> next{0};
  std::mutex mutex;
  size_t done = 0;
  auto work = [&] {
    for (size_t i = next++; i < jobs.size(); i = next++) {
      KernelJob& j = jobs[i];
      const auto start = std::chrono::steady_clock::now();
      j.cubin = cubin_for_arch(j.source, j.name, options, arch, &j.error, &j.cached);
      j.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      const std::lock_guard<std::mutex> lock(mutex);
      ++done;
      if (finished) finished(j, done);
    }
  };
  std::vector<std::thread> pool;
  for (size_t t = 1; t < std::max<size_t>(threads, 1); ++t) pool.emplace_back(work);
  work();
  for (std::thread& t : pool) t.join();
}

}  // namespace kage
