// kage._kage.step_rows: a list of batches stepped by the rows of one actions array in one call into the
// runtime (kage.step_batches), each batch stepped by its own step.
#pragma once

#include <pybind11/pybind11.h>

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "kage/kage.h"

namespace kage::python {

/// One batch of a step_rows call, as the binding's batch presents it.
struct RowBatch {
  int32_t num_envs;
  bool on_gpu;
  void* stream;  ///< the CUstream its work queues on (null: the legacy default stream)
  /// The batch's own step on row `row`'s actions; raises as the batch's step does (row_failure's text).
  std::function<void(size_t row, const Actions&)> step;
};

/// Steps batches[i] with row i of `actions` ([len(batches), num_envs], int32 or int64), each as its own step
/// call would: one call into the runtime for a list of batches (a pack's runs, an evaluation's configs). Host
/// actions: a 2-D numpy array, native and aligned (kage.actions copies other layouts first). Device actions: a
/// DLPack capsule its producer ordered for batches[0]'s stream; the batches' other streams are ordered after
/// that one before any batch steps, so that they still step side by side. A failure leaves the earlier rows
/// stepped (row_failure says so).
void step_rows(const std::vector<RowBatch>& batches, const pybind11::object& actions);

/// The error of row `row`'s step (of `rows`), naming the batch and which batches stepped.
std::string row_failure(size_t row, size_t rows, const std::string& error);

}  // namespace kage::python
