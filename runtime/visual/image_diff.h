// Observation comparison: the deviation measures the golden tolerances are stated in
// (golden/README.md): worst code difference, share of equal channel values, mean absolute difference.
#pragma once

#include "runtime/kage_hd.h"

namespace kage {

/// Deviation between two uint8 buffers of `count` channel values.
struct ImageDiff {
  int32_t max_abs;       ///< largest |a - b| over all channel values
  int64_t equal;         ///< number of equal channel values
  int64_t count;
  double sum_abs;        ///< sum of |a - b|
  /// Share of equal channel values in [0, 1].
  double equal_fraction() const { return count > 0 ? static_cast<double>(equal) / static_cast<double>(count) : 1.0; }
  /// Mean absolute difference per channel value.
  double mean_abs() const { return count > 0 ? sum_abs / static_cast<double>(count) : 0.0; }
};

inline ImageDiff image_diff(const uint8_t* a, const uint8_t* b, int64_t count) {
  ImageDiff d{0, 0, count, 0.0};
  for (int64_t i = 0; i < count; ++i) {
    const int32_t v = a[i] > b[i] ? a[i] - b[i] : b[i] - a[i];
    d.max_abs = v > d.max_abs ? v : d.max_abs;
    d.equal += v == 0;
    d.sum_abs += v;
  }
  return d;
}

}  // namespace kage
