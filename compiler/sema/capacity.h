// Capacity: the settings of a Spec that the runtime's fixed storage cannot hold (integers beyond 32
// bits, entity counts and list lengths beyond its arrays, sizes beyond its indexing), found before
// lowering so that `kagec lint` reports them at their keys.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "compiler/basic/diag.h"
#include "compiler/parse/compose.h"
#include "compiler/sema/spec.h"

namespace kage {

/// The runtime's storage bounds. compiler/lower/lower.cpp static_asserts each one against the
/// runtime's own constant, so the two cannot drift apart.
struct RuntimeCapacity {
  static constexpr int32_t kNpcSlots = 32;
  static constexpr int32_t kStickySlots = 8;
  static constexpr int32_t kDistractorSlots = 16;
  static constexpr int32_t kStickyOffsets = 8;
  static constexpr int32_t kListEntries = 32;
  /// Frames are indexed with 32-bit offsets (H * W * 3 per environment).
  static constexpr int32_t kImageSide = 4096;
  /// The layout's mask holds one byte per world column.
  static constexpr int32_t kWorldWidth = 1 << 20;
};

/// A setting the runtime cannot hold: the dotted key and a message naming the limit and the fix.
struct CapacityError {
  std::string path;
  std::string message;
};

/// The capacity errors of a Spec. Settings marked inert are not checked.
std::vector<CapacityError> capacity_errors(const Spec& spec);

/// Reports capacity_errors as `capacity-exceeded` diagnostics at the key's place in `config`
/// (at the file itself when the key is inherited from a default).
void report_capacity(const ComposedConfig& config, const Spec& spec, DiagEngine& diags);

/// Whether the storage bound an `x-kage-capacity` entry of the schema names is known.
bool capacity_limit_known(const std::string& id);

}  // namespace kage
