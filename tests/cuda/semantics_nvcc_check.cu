// nvcc compile check of the semantics library for sm_90 with --fmad=false (style.md section 5):
// compiled to a cubin as part of the build (tests/cuda/CMakeLists.txt), whose kernels
// check_cubin_kernels.cmake then requires. Nothing here runs; the GPU is never touched.
#include "tests/cuda/semantics_kernels.cuh"
