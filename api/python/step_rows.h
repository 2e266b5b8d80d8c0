// kage._kage.step_rows: a list of batches stepped by the rows of one actions array in one call into the
// runtime (kage.step_batches): host rows by each batch's own step, device rows by kage::step_together.
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
  /// The batch's own step on row `row`'s actions; raises as the batch's step does (row_failure's text).
  std::function<void(size_t row, const Actions&)> step;
};

/// Every batch stepped by its row of device actions at once (kage::step_together over the batches): the first
/// row and the distance between rows in elements; raises as a batch's step does, naming the batch
/// (together_failure's text), with nothing stepped.
using StepTogether = std::function<void(const Actions& first_row, int64_t row_stride)>;

/// Steps batches[i] with row i of `actions` ([len(batches), num_envs], int32 or int64), each as its own step
/// call would: one call into the runtime for a list of batches (a pack's runs, an evaluation's configs). Host
/// actions: a 2-D numpy array, native and aligned (kage.actions copies other layouts first), every value checked
/// to be in 0..7 before any batch steps, then each row by its batch's own step (a failure of a step itself leaves
/// the earlier rows stepped: row_failure says so). Device actions: a DLPack
/// capsule its producer ordered for batches[0]'s stream, every row by `together` (one launch pair per config
/// over all the batches).
void step_rows(const std::vector<RowBatch>& batches, const pybind11::object& actions, const StepTogether& together);

/// The error of row `row`'s step (of `rows`), naming the batch and which batches stepped.
std::string row_failure(size_t row, size_t rows, const std::string& error);

/// The error of a step_together refusal about batch `row` (of `rows`): nothing stepped.
std::string together_failure(size_t row, size_t rows, const std::string& error);

}  // namespace kage::python
