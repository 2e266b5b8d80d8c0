// The generic kernels: parameters from __constant__ memory, uploaded by DeviceBatch (any config).
#include "runtime/cuda/kernels.cuh"
KAGE_INSTANTIATE_KERNELS(kage::DynamicCfg)
