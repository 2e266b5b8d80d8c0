// DeviceArray (device_array.h): the export of a GPU batch's output through DLPack and
// __cuda_array_interface__, ordered on the consumer's stream, and its copy to the host.
#include "api/python/device_array.h"

#include <iterator>
#include <stdexcept>

#include "api/python/cuda_streams.h"

namespace py = pybind11;

namespace kage::python {

namespace {

// DLPack's bool type code (kDLBool, DLPack 0.8); Debian's dlpack.h is 0.6, which lacks the name.
constexpr auto kDLPackBool = static_cast<DLDataTypeCode>(6);
constexpr DTypeFacts kDTypes[] = {
    {{kDLUInt, 8, 1}, "|u1", 1},  {{kDLInt, 32, 1}, "<i4", 4}, {{kDLInt, 64, 1}, "<i8", 8},
    {{kDLFloat, 32, 1}, "<f4", 4}, {{kDLPackBool, 8, 1}, "|b1", 1}};
static_assert(std::size(kDTypes) == static_cast<size_t>(kage::DType::kBool) + 1, "a DType without facts");

}  // namespace

const DTypeFacts& facts(kage::DType t) { return kDTypes[static_cast<size_t>(t)]; }
py::dtype numpy_dtype(kage::DType t) { return py::dtype(facts(t).typestr); }

std::string shape_text(const DLTensor& t) {
  std::string s = "(";
  for (int32_t i = 0; i < t.ndim; ++i) s += std::to_string(t.shape[i]) + (t.ndim == 1 || i + 1 < t.ndim ? "," : "");
  return s + ")";
}

py::capsule DeviceArray::dlpack(const py::object& consumer_stream) const {
  const int64_t s = consumer_stream.is_none() ? 1 : consumer_stream.cast<int64_t>();
  if (s == 0) throw py::value_error("__dlpack__: stream 0 is ambiguous for CUDA; pass 1 for the legacy default stream");
  std::string error;
  if (s != -1 && !order_after(owner_->stream(), protocol_stream(s), &error))
    throw std::runtime_error(error);
  struct Context {
    std::shared_ptr<kage::Env> owner;
    std::vector<int64_t> shape;
  };
  auto* ctx = new Context{owner_, shape_};
  auto* t = new DLManagedTensor{};
  t->dl_tensor.data = const_cast<void*>(data_);
  t->dl_tensor.device = {kDLCUDA, 0};
  t->dl_tensor.ndim = static_cast<int32_t>(ctx->shape.size());
  t->dl_tensor.dtype = facts(dtype_).dl;
  t->dl_tensor.shape = ctx->shape.data();
  t->dl_tensor.strides = nullptr;
  t->dl_tensor.byte_offset = 0;
  t->manager_ctx = ctx;
  // Runs without the GIL when the consumer frees its tensor: C++ objects only.
  t->deleter = [](DLManagedTensor* self) {
    delete static_cast<Context*>(self->manager_ctx);
    delete self;
  };
  return py::capsule(t, "dltensor", [](PyObject* capsule) {
    // A consumer renames a capsule it took ("used_dltensor") and owns it from then on.
    if (PyCapsule_IsValid(capsule, "dltensor")) {
      auto* t = static_cast<DLManagedTensor*>(PyCapsule_GetPointer(capsule, "dltensor"));
      if (t && t->deleter) t->deleter(t);
    }
  });
}

py::dict DeviceArray::cuda_array_interface() const {
  py::dict d;
  py::tuple shape(shape_.size());
  for (size_t i = 0; i < shape_.size(); ++i) shape[i] = shape_[i];
  d["shape"] = shape;
  d["typestr"] = facts(dtype_).typestr;
  d["data"] = py::make_tuple(reinterpret_cast<uintptr_t>(data_), false);
  d["version"] = 3;
  d["strides"] = py::none();
  // Version 3: the stream the data is ready on (1: the legacy default stream).
  const uintptr_t s = reinterpret_cast<uintptr_t>(owner_->stream());
  d["stream"] = s == 0 ? uintptr_t{1} : s;
  return d;
}

py::array DeviceArray::numpy() const {
  py::array out(numpy_dtype(dtype_), shape_);
  std::string error;
  if (!copy_to_host(out.mutable_data(), data_, static_cast<size_t>(out.nbytes()), owner_->stream(),
                                  &error))
    throw std::runtime_error(error);
  return out;
}

py::tuple DeviceArray::shape() const {
  py::tuple t(shape_.size());
  for (size_t i = 0; i < shape_.size(); ++i) t[i] = shape_[i];
  return t;
}

}  // namespace kage::python
