// nvcc compile check of the semantics library for sm_90 with --fmad=false (style.md section 5): the
// kernels of semantics_kernels.cuh become device code, so the build fails when a header stops
// compiling for the GPU. The program itself touches no GPU; it reports what was compiled.
#include <cstdio>

#include "tests/cuda/semantics_kernels.cuh"

#define KAGE_STR2(x) #x
#define KAGE_STR(x) KAGE_STR2(x)

int main() {
  const void* kernels[] = {reinterpret_cast<const void*>(&kage_check_latent),
                           reinterpret_cast<const void*>(&kage_check_visual),
                           reinterpret_cast<const void*>(&kage_check_render),
                           reinterpret_cast<const void*>(&kage_check_filter_passes)};
  int n = 0;
  for (const void* k : kernels) n += k != nullptr;
#if defined(__CUDA_ARCH_LIST__)
  std::printf("semantics compiled by nvcc %d.%d for architectures %s: %d kernels\n", __CUDACC_VER_MAJOR__,
              __CUDACC_VER_MINOR__, KAGE_STR(__CUDA_ARCH_LIST__), n);
#else
  std::printf("semantics compiled by nvcc %d.%d: %d kernels\n", __CUDACC_VER_MAJOR__, __CUDACC_VER_MINOR__, n);
#endif
  return n == 4 ? 0 : 1;
}
