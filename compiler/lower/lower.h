// Lowering: a resolved Spec -> the runtime's plain parameter structs (names to ids and RGB through the
// schema's tables, floats to float32) and the asset files to load; rejects what the runtime cannot hold.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "compiler/sema/capacity.h"
#include "compiler/sema/spec.h"
#include "runtime/io/asset_pack.h"
#include "runtime/latent/latent_params.h"
#include "runtime/visual/visual_params.h"

namespace kage {

/// Everything a backend needs to build environments of one configuration.
struct LoweredConfig {
  LatentParams latent;
  VisualParams visual;
  AssetSources assets;
};

/// Result of lower_spec: `config` when `errors` is empty.
struct [[nodiscard]] LowerResult {
  std::optional<LoweredConfig> config;
  std::vector<CapacityError> errors;
  bool ok() const { return config.has_value(); }
  /// The errors, one "key: message" line each.
  std::string error_text() const;
};

/// Lowers a Spec (normally one the front end produced without errors).
LowerResult lower_spec(const Spec& spec);

/// The config's spelling of a lowered enum value (a background.mode, a shape type, a filter preset);
/// "?" for a value outside the enum.
const char* config_name(BackgroundMode mode);
const char* config_name(ShapeType shape);
const char* config_name(Preset preset);

}  // namespace kage
