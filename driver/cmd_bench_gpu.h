// kagec bench --gpu: compiles configs in-process (NVRTC, through the kernel cache) and measures them
// with the measurements of kage_gpu_throughput (verify/throughput/gpu_measure.h). Built only with the CUDA toolkit.
#pragma once

#include <string>

#include "driver/cli_common.h"
#include "driver/commands.h"

namespace kage {

struct GpuBenchOptions {
  std::string file;  ///< a config, or a suite manifest (every distinct config of its pairs)
  int min_log2 = 12;
  int max_log2 = 20;
  bool no_render = false;  ///< time only the state-only step
  DiagOptions diag;
};

/// Prints one table of steps/s per config and batch size. Exit 1 when there is no usable GPU.
int bench_gpu(const GpuBenchOptions& options, CommandIo& io);

}  // namespace kage
