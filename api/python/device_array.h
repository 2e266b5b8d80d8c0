// The Python binding's array of a GPU batch's output: device memory owned by the batch, exported without a
// copy through DLPack and __cuda_array_interface__, or copied to the host; and each kage::DType as numpy,
// DLPack and __array_interface__ name it; a DLPack tensor's shape as an error names it.
#pragma once

#include <dlpack/dlpack.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "kage/kage.h"

namespace kage::python {

/// A kage::DType as DLPack, __array_interface__ and byte size see it.
struct DTypeFacts {
  DLDataType dl;
  const char* typestr;
  size_t bytes;
};
const DTypeFacts& facts(kage::DType t);
pybind11::dtype numpy_dtype(kage::DType t);
/// A DLPack tensor's shape as text for an error: "(6,)", "(2,6)".
std::string shape_text(const DLTensor& t);

/// One output array of a batch on the GPU: device memory owned by the batch.
class DeviceArray {
 public:
  DeviceArray(std::shared_ptr<kage::Env> owner, const void* data, std::vector<int64_t> shape, kage::DType dtype)
      : owner_(std::move(owner)), data_(data), shape_(std::move(shape)), dtype_(dtype) {}

  /// A DLPack capsule of this array, ready for use on `consumer_stream` (the DLPack protocol's value:
  /// None or 1 the legacy default stream, 2 the per-thread default stream, -1 no ordering, else a
  /// CUstream handle).
  pybind11::capsule dlpack(const pybind11::object& consumer_stream) const;
  pybind11::dict cuda_array_interface() const;
  /// A host copy as a numpy array (waits for the batch's queued work).
  pybind11::array numpy() const;
  pybind11::tuple shape() const;
  pybind11::dtype dtype() const { return numpy_dtype(dtype_); }
  uintptr_t data_ptr() const { return reinterpret_cast<uintptr_t>(data_); }

 private:
  std::shared_ptr<kage::Env> owner_;
  const void* data_;
  std::vector<int64_t> shape_;
  kage::DType dtype_;
};

}  // namespace kage::python
