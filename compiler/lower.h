// Lowering: a resolved Spec -> the runtime's plain parameter structs (names to ids and RGB through the
// schema's tables, floats to float32) and the asset files to load; rejects what the runtime cannot hold.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "compiler/compose.h"
#include "compiler/diag.h"
#include "compiler/spec.h"
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

/// A setting the runtime cannot hold: the dotted key and a message naming the limit and the fix.
struct CapacityError {
  std::string path;
  std::string message;
};

/// Result of lower_spec: `config` when `errors` is empty.
struct [[nodiscard]] LowerResult {
  std::optional<LoweredConfig> config;
  std::vector<CapacityError> errors;
  bool ok() const { return config.has_value(); }
  /// The errors, one "key: message" line each.
  std::string error_text() const;
};

/// The capacity errors of a Spec (entity counts and list lengths beyond the runtime's fixed arrays,
/// layouts the compact storage cannot hold). Settings marked inert are not checked.
std::vector<CapacityError> capacity_errors(const Spec& spec);

/// Lowers a Spec (normally one the front end produced without errors).
LowerResult lower_spec(const Spec& spec);

/// Reports capacity_errors as `capacity-exceeded` diagnostics at the key's place in `config`
/// (at the file itself when the key is inherited from a default).
void report_capacity(const ComposedConfig& config, const Spec& spec, DiagEngine& diags);

/// The config's spelling of a lowered enum value (a background.mode, a shape type, a filter preset);
/// "?" for a value outside the enum.
const char* config_name(BackgroundMode mode);
const char* config_name(ShapeType shape);
const char* config_name(Preset preset);

/// Whether lowering knows the storage bound an `x-kage-capacity` entry of the schema names.
bool capacity_limit_known(const std::string& id);

}  // namespace kage
