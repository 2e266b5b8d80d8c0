// CUDA stream ordering and copies for the Python binding's device arrays (driver API, no sync unless a
// copy to the host asks for one).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace kage::python {

/// The CUstream a DLPack / __cuda_array_interface__ stream number stands for: 1 the legacy default
/// stream (null), 2 the per-thread default stream, anything else a CUstream handle.
void* protocol_stream(int64_t s);

/// Makes work queued later on `consumer` wait for the work queued so far on `producer` (an event, no
/// host wait); nothing when they are the same stream.
bool order_after(void* producer, void* consumer, std::string* error);

/// Copies `bytes` from device memory to host memory once `stream`'s queued work is done; waits.
bool copy_to_host(void* dst, const void* src, size_t bytes, void* stream, std::string* error);

}  // namespace kage::python
