// The "simplest" throughput config's kernels (bench_configs.h), built into a fatbin for the benchmark.
#include "bench/bench_configs.h"
#include "runtime/cuda/kernels.cuh"
KAGE_INSTANTIATE_KERNELS(kage::bench::SimplestCfg)
