// Several configs' kernels compiled at once. NVRTC compiles one program per call on the calling thread, and a
// generated config takes tens of seconds, so a process that opens batches of ten configs one after another
// waits minutes; compiled side by side into the kernel cache first, the batches then open from it.
#pragma once

#include <cstddef>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "runtime/cuda/module_loader.h"

namespace kage {

/// One source to compile, and what came of it.
struct KernelJob {
  std::string source;                ///< a generated config source
  std::string name;                  ///< its file name in diagnostics
  std::optional<std::string> cubin;  ///< from the kernel cache or NVRTC; empty on failure
  std::string error;                 ///< why `cubin` is empty
  bool cached = false;               ///< the cubin came from the cache
  double seconds = 0;                ///< how long this job took
};

/// How many threads compile `jobs` sources: one per core, at most one per job and at most 16 (each NVRTC
/// compile holds its own memory).
size_t compile_threads(size_t jobs);

/// Fills every job's cubin for `arch` (cubin_for_arch: the kernel cache, else NVRTC) on `threads` threads.
/// `finished`, if given, is called after each job, one call at a time, with the job and how many are done.
void compile_jobs(std::vector<KernelJob>& jobs, const NvrtcOptions& options, const std::string& arch,
                  size_t threads, const std::function<void(const KernelJob&, size_t done)>& finished = {});

}  // namespace kage
