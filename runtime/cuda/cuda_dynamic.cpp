// The CUDA driver (libcuda.so.1) and NVRTC, opened at run time instead of linked: a program built with
// the CUDA backend then starts on a machine without a driver or toolkit, and its first driver call
// (cuInit) fails with a message that says to use the CPU backend. Each function the runtime calls is
// defined here with cuda.h's signature (and cuda.h's versioned symbol name, e.g. cuMemAlloc_v2) and
// forwards to the symbol of that name in the library.
#include <cuda.h>
#include <dlfcn.h>
#include <nvrtc.h>

#include <mutex>

#include "runtime/cuda/nvrtc_search.h"

namespace {

#define KAGE_STR2(x) #x
#define KAGE_STR(x) KAGE_STR2(x)

void* open_first(const char* const* names) {
  for (const char* const* n = names; *n; ++n) {
    if (void* h = dlopen(*n, RTLD_NOW | RTLD_LOCAL)) return h;
  }
  return nullptr;
}

void* driver() {
  static std::once_flag once;
  static void* handle = nullptr;
  std::call_once(once, [] {
    static const char* const names[] = {"libcuda.so.1", "libcuda.so", nullptr};
    handle = open_first(names);
  });
  return handle;
}

void* nvrtc() {
  static std::once_flag once;
  static void* handle = nullptr;
  std::call_once(once, [] { handle = kage::open_nvrtc(); });
  return handle;
}

template <class F>
F symbol(void* lib, const char* name) {
  return lib ? reinterpret_cast<F>(dlsym(lib, name)) : nullptr;
}

}  // namespace

// CUDA_ERROR_STUB_LIBRARY: what the driver's own stub answers when no real driver is installed.
#define KAGE_CU_FORWARD(name, params, args)                                                 \
  extern "C" CUresult CUDAAPI name params {                                                 \
    using Fn = CUresult(CUDAAPI*) params;                                                   \
    static const Fn fn = symbol<Fn>(driver(), KAGE_STR(name));                              \
    return fn ? fn args : CUDA_ERROR_STUB_LIBRARY;                                          \
  }

KAGE_CU_FORWARD(cuInit, (unsigned int flags), (flags))
KAGE_CU_FORWARD(cuDeviceGet, (CUdevice * d, int ordinal), (d, ordinal))
KAGE_CU_FORWARD(cuDeviceGetName, (char* name, int len, CUdevice d), (name, len, d))
KAGE_CU_FORWARD(cuDeviceGetAttribute, (int* v, CUdevice_attribute a, CUdevice d), (v, a, d))
KAGE_CU_FORWARD(cuDevicePrimaryCtxRetain, (CUcontext * c, CUdevice d), (c, d))
KAGE_CU_FORWARD(cuCtxSetCurrent, (CUcontext c), (c))
KAGE_CU_FORWARD(cuCtxGetDevice, (CUdevice * d), (d))
KAGE_CU_FORWARD(cuCtxGetCurrent, (CUcontext * c), (c))
KAGE_CU_FORWARD(cuCtxSynchronize, (void), ())
KAGE_CU_FORWARD(cuModuleLoadData, (CUmodule * m, const void* image), (m, image))
KAGE_CU_FORWARD(cuModuleUnload, (CUmodule m), (m))
KAGE_CU_FORWARD(cuModuleGetFunction, (CUfunction * f, CUmodule m, const char* name), (f, m, name))
KAGE_CU_FORWARD(cuModuleGetGlobal, (CUdeviceptr * p, size_t* bytes, CUmodule m, const char* name), (p, bytes, m, name))
KAGE_CU_FORWARD(cuFuncSetAttribute, (CUfunction f, CUfunction_attribute a, int v), (f, a, v))
KAGE_CU_FORWARD(cuMemAlloc, (CUdeviceptr * p, size_t bytes), (p, bytes))
KAGE_CU_FORWARD(cuMemFree, (CUdeviceptr p), (p))
KAGE_CU_FORWARD(cuMemcpyHtoD, (CUdeviceptr dst, const void* src, size_t bytes), (dst, src, bytes))
KAGE_CU_FORWARD(cuMemcpyDtoH, (void* dst, CUdeviceptr src, size_t bytes), (dst, src, bytes))
KAGE_CU_FORWARD(cuMemcpyDtoD, (CUdeviceptr dst, CUdeviceptr src, size_t bytes), (dst, src, bytes))
KAGE_CU_FORWARD(cuMemsetD8, (CUdeviceptr p, unsigned char v, size_t n), (p, v, n))
KAGE_CU_FORWARD(cuMemsetD32, (CUdeviceptr p, unsigned int v, size_t n), (p, v, n))
KAGE_CU_FORWARD(cuMemsetD8Async, (CUdeviceptr p, unsigned char v, size_t n, CUstream s), (p, v, n, s))
KAGE_CU_FORWARD(cuMemcpyHtoDAsync, (CUdeviceptr dst, const void* src, size_t bytes, CUstream s), (dst, src, bytes, s))
KAGE_CU_FORWARD(cuMemcpyDtoHAsync, (void* dst, CUdeviceptr src, size_t bytes, CUstream s), (dst, src, bytes, s))
KAGE_CU_FORWARD(cuMemcpyDtoDAsync, (CUdeviceptr dst, CUdeviceptr src, size_t bytes, CUstream s), (dst, src, bytes, s))
KAGE_CU_FORWARD(cuMemcpy2DAsync, (const CUDA_MEMCPY2D* c, CUstream s), (c, s))
KAGE_CU_FORWARD(cuMemHostAlloc, (void** p, size_t bytes, unsigned int flags), (p, bytes, flags))
KAGE_CU_FORWARD(cuMemHostGetDevicePointer, (CUdeviceptr * d, void* p, unsigned int flags), (d, p, flags))
KAGE_CU_FORWARD(cuMemFreeHost, (void* p), (p))
KAGE_CU_FORWARD(cuStreamCreate, (CUstream * s, unsigned int flags), (s, flags))
KAGE_CU_FORWARD(cuStreamDestroy, (CUstream s), (s))
KAGE_CU_FORWARD(cuStreamSynchronize, (CUstream s), (s))
KAGE_CU_FORWARD(cuStreamWaitEvent, (CUstream s, CUevent e, unsigned int flags), (s, e, flags))
KAGE_CU_FORWARD(cuThreadExchangeStreamCaptureMode, (CUstreamCaptureMode * mode), (mode))
KAGE_CU_FORWARD(cuLaunchKernel,
                (CUfunction f, unsigned gx, unsigned gy, unsigned gz, unsigned bx, unsigned by, unsigned bz,
                 unsigned smem, CUstream s, void** params, void** extra),
                (f, gx, gy, gz, bx, by, bz, smem, s, params, extra))
KAGE_CU_FORWARD(cuEventCreate, (CUevent * e, unsigned int flags), (e, flags))
KAGE_CU_FORWARD(cuEventRecord, (CUevent e, CUstream s), (e, s))
KAGE_CU_FORWARD(cuEventSynchronize, (CUevent e), (e))
KAGE_CU_FORWARD(cuEventElapsedTime, (float* ms, CUevent a, CUevent b), (ms, a, b))
KAGE_CU_FORWARD(cuEventDestroy, (CUevent e), (e))

// Error texts must work without a driver, since they report its absence.
extern "C" CUresult CUDAAPI cuGetErrorString(CUresult r, const char** s) {
  using Fn = CUresult(CUDAAPI*)(CUresult, const char**);
  static const Fn fn = symbol<Fn>(driver(), "cuGetErrorString");
  if (fn) return fn(r, s);
  *s = "no CUDA driver (libcuda.so.1 not found)";
  return CUDA_SUCCESS;
}
extern "C" CUresult CUDAAPI cuGetErrorName(CUresult r, const char** s) {
  using Fn = CUresult(CUDAAPI*)(CUresult, const char**);
  static const Fn fn = symbol<Fn>(driver(), "cuGetErrorName");
  if (fn) return fn(r, s);
  *s = r == CUDA_ERROR_STUB_LIBRARY ? "CUDA_ERROR_STUB_LIBRARY (no CUDA driver)" : "CUDA_ERROR (no CUDA driver)";
  return CUDA_SUCCESS;
}

#define KAGE_NVRTC_FORWARD(name, params, args)                                              \
  extern "C" nvrtcResult name params {                                                      \
    using Fn = nvrtcResult (*) params;                                                      \
    static const Fn fn = symbol<Fn>(nvrtc(), #name);                                        \
    return fn ? fn args : NVRTC_ERROR_INTERNAL_ERROR;                                       \
  }

KAGE_NVRTC_FORWARD(nvrtcVersion, (int* major, int* minor), (major, minor))
KAGE_NVRTC_FORWARD(nvrtcCreateProgram,
                   (nvrtcProgram * p, const char* src, const char* name, int n, const char* const* headers,
                    const char* const* include_names),
                   (p, src, name, n, headers, include_names))
KAGE_NVRTC_FORWARD(nvrtcCompileProgram, (nvrtcProgram p, int n, const char* const* opts), (p, n, opts))
KAGE_NVRTC_FORWARD(nvrtcDestroyProgram, (nvrtcProgram * p), (p))
KAGE_NVRTC_FORWARD(nvrtcGetCUBINSize, (nvrtcProgram p, size_t* n), (p, n))
KAGE_NVRTC_FORWARD(nvrtcGetCUBIN, (nvrtcProgram p, char* out), (p, out))
KAGE_NVRTC_FORWARD(nvrtcGetProgramLogSize, (nvrtcProgram p, size_t* n), (p, n))
KAGE_NVRTC_FORWARD(nvrtcGetProgramLog, (nvrtcProgram p, char* out), (p, out))

extern "C" const char* nvrtcGetErrorString(nvrtcResult r) {
  using Fn = const char* (*)(nvrtcResult);
  static const Fn fn = symbol<Fn>(nvrtc(), "nvrtcGetErrorString");
  return fn ? fn(r) : "NVRTC unavailable (libnvrtc.so not found; install the CUDA toolkit or use prebuilt kernels)";
}
