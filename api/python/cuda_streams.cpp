// CUDA stream ordering and copies for the Python binding (see cuda_streams.h).
#include "api/python/cuda_streams.h"

#if defined(KAGE_PY_HAVE_CUDA)
#include <cuda.h>

#include "runtime/cuda/module_loader.h"
#endif

namespace kage::python {

#if defined(KAGE_PY_HAVE_CUDA)
namespace {

bool check(CUresult r, const char* what, std::string* error) {
  if (r == CUDA_SUCCESS) return true;
  *error = cu_error_text(r, what);
  return false;
}

/// Makes the primary context current on this thread if none is (the caller may not be the thread that
/// opened the environment).
bool bind_context(std::string* error) {
  CUcontext current = nullptr;
  if (cuCtxGetCurrent(&current) == CUDA_SUCCESS && current) return true;
  return cuda_primary_context(error) != nullptr;
}

}  // namespace

void* protocol_stream(int64_t s) {
  if (s == 1) return nullptr;
  if (s == 2) return reinterpret_cast<void*>(CU_STREAM_PER_THREAD);
  return reinterpret_cast<void*>(s);
}

bool order_after(void* producer, void* consumer, std::string* error) {
  if (producer == consumer) return true;
  if (!bind_context(error)) return false;
  // One event per thread: a wait captures the event's state when it is queued, so reuse is safe.
  thread_local CUevent event = nullptr;
  if (!event && !check(cuEventCreate(&event, CU_EVENT_DISABLE_TIMING), "cuEventCreate", error)) return false;
  return check(cuEventRecord(event, static_cast<CUstream>(producer)), "cuEventRecord", error) &&
         check(cuStreamWaitEvent(static_cast<CUstream>(consumer), event, 0), "cuStreamWaitEvent", error);
}

bool copy_to_host(void* dst, const void* src, size_t bytes, void* stream, std::string* error) {
  const CUstream s = static_cast<CUstream>(stream);
  return bind_context(error) &&
         check(cuMemcpyDtoHAsync(dst, reinterpret_cast<CUdeviceptr>(src), bytes, s), "cuMemcpyDtoHAsync", error) &&
         check(cuStreamSynchronize(s), "cuStreamSynchronize", error);
}
#else
void* protocol_stream(int64_t s) { return reinterpret_cast<void*>(s == 1 ? 0 : s); }
bool order_after(void*, void*, std::string* error) {
  *error = "this build of kage has no GPU backend";
  return false;
}
bool copy_to_host(void*, const void*, size_t, void*, std::string* error) {
  *error = "this build of kage has no GPU backend";
  return false;
}
#endif

}  // namespace kage::python
