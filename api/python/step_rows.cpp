// kage._kage.step_rows: checks the actions array against the batches, then steps each batch by its row (host
// actions) or every batch at once (device actions).
#include "api/python/step_rows.h"

#include <dlpack/dlpack.h>
#include <pybind11/numpy.h>


#include "api/python/device_array.h"

namespace py = pybind11;

namespace kage::python {
namespace {

std::string expected_rows(size_t rows, int32_t n) {
  return "expected (" + std::to_string(rows) + ", " + std::to_string(n) +
         "): a row of one action per environment for each batch";
}

void step_host_rows(const std::vector<RowBatch>& batches, const py::array& a, int32_t n) {
  const auto& dt = a.dtype();
  const py::ssize_t item = dt.itemsize();
  if (dt.kind() != 'i' || (item != 4 && item != 8) || a.ndim() != 2 || !dt.attr("isnative").cast<bool>() ||
      a.strides(0) % item != 0 || a.strides(1) % item != 0 || reinterpret_cast<uintptr_t>(a.data()) % item != 0)
    throw py::value_error("internal: step_rows wants a 2-D native, aligned int32 or int64 array");
  if (a.shape(0) != static_cast<py::ssize_t>(batches.size()) || a.shape(1) != n)
    throw py::value_error("actions of shape (" + std::to_string(a.shape(0)) + ", " + std::to_string(a.shape(1)) +
                          "), " + expected_rows(batches.size(), n));
  const char* data = static_cast<const char*>(a.data());
  auto row = [&](size_t i) {
    return Actions{data + static_cast<py::ssize_t>(i) * a.strides(0), Memory::kHost,
                   item == 8 ? DType::kInt64 : DType::kInt32, a.strides(1) / item};
  };
  // Every row is checked before any batch steps, so that a bad action leaves every batch as it was.
  for (size_t i = 0; i < batches.size(); ++i) {
    const std::string problem = host_actions_problem(row(i), n);
    if (!problem.empty()) throw py::value_error(together_failure(i, batches.size(), "kage: " + problem));
  }
  for (size_t i = 0; i < batches.size(); ++i) batches[i].step(i, row(i));
}

/// What keeps device actions `d` from stepping `batches` (n environments each) by rows; empty if nothing.
std::string device_rows_problem(const std::vector<RowBatch>& batches, const DLTensor& d, int32_t n) {
  for (size_t i = 0; i < batches.size(); ++i)
    if (!batches[i].on_gpu)
      return "actions are in GPU memory but batch " + std::to_string(i) + " runs on the CPU: pass host actions "
             "(e.g. actions.cpu()) or make the batches with device='cuda'";
  if (d.device.device_type != kDLCUDA || d.device.device_id != 0)
    return "actions on DLPack device (" + std::to_string(d.device.device_type) + ", " +
           std::to_string(d.device.device_id) + "), the environments run on cuda:0";
  if (d.ndim != 2 || d.shape[0] != static_cast<int64_t>(batches.size()) || d.shape[1] != n)
    return "actions of shape " + shape_text(d) + ", " + expected_rows(batches.size(), n);
  if (d.dtype.lanes != 1 || d.dtype.code != kDLInt || (d.dtype.bits != 32 && d.dtype.bits != 64))
    return "actions of DLPack type (code " + std::to_string(d.dtype.code) + ", " + std::to_string(d.dtype.bits) +
           " bits), expected int32 or int64";
  if ((reinterpret_cast<uintptr_t>(d.data) + d.byte_offset) % (d.dtype.bits / 8) != 0)
    return "actions: device data not aligned to the item size: pass a contiguous copy (e.g. actions.contiguous())";
  return "";
}

void step_device_rows(const DLTensor& d, const StepTogether& together) {
  const int64_t row_stride = d.strides ? d.strides[0] : d.shape[1];
  const int64_t stride = d.strides ? d.strides[1] : 1;
  together(Actions{static_cast<const char*>(d.data) + d.byte_offset, Memory::kDevice,
                   d.dtype.bits == 64 ? DType::kInt64 : DType::kInt32, stride},
           row_stride);
}

}  // namespace

void step_rows(const std::vector<RowBatch>& batches, const py::object& actions, const StepTogether& together) {
  if (batches.empty()) throw py::value_error("step_rows: no batches");
  const int32_t n = batches[0].num_envs;
  for (size_t i = 0; i < batches.size(); ++i)
    if (batches[i].num_envs != n)
      throw py::value_error("batch " + std::to_string(i) + " has " + std::to_string(batches[i].num_envs) +
                            " environments, batch 0 has " + std::to_string(n) + ": step batches of one size together");
  if (py::isinstance<py::array>(actions)) return step_host_rows(batches, actions.cast<py::array>(), n);
  auto* t = static_cast<DLManagedTensor*>(PyCapsule_GetPointer(actions.ptr(), "dltensor"));
  if (!t) throw py::error_already_set();
  const std::string problem = device_rows_problem(batches, t->dl_tensor, n);
  PyCapsule_SetName(actions.ptr(), "used_dltensor");  // ours now: freed below, after the launches
  try {
    if (problem.empty()) step_device_rows(t->dl_tensor, together);
  } catch (...) {
    if (t->deleter) t->deleter(t);
    throw;
  }
  if (t->deleter) t->deleter(t);
  if (!problem.empty()) throw py::value_error(problem);
}

namespace {

/// `error` led by `which` batch failed (after kage's own "kage: " prefix, when it has one).
std::string batch_failure(const std::string& which, const std::string& error) {
  const std::string lead = "kage: ";
  if (error.compare(0, lead.size(), lead) == 0) return lead + which + ": " + error.substr(lead.size());
  return which + ": " + error;
}

}  // namespace

std::string row_failure(size_t row, size_t rows, const std::string& error) {
  return batch_failure("batch " + std::to_string(row) + " of " + std::to_string(rows) +
                           (row == 0 ? " (none stepped)"
                                     : " (the " + std::to_string(row) + " before it stepped, the rest did not)"),
                       error);
}

std::string together_failure(size_t row, size_t rows, const std::string& error) {
  return batch_failure("batch " + std::to_string(row) + " of " + std::to_string(rows) + " (none stepped)", error);
}

}  // namespace kage::python
