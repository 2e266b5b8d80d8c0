// A config file through the whole front end and lowering: the one way every consumer (kagec compile,
// kagec golden, the public API, Environment::open) turns a file into runtime parameters.
#pragma once

#include <optional>
#include <string>

#include "compiler/basic/diag.h"
#include "compiler/basic/source.h"
#include "compiler/lower/lower.h"
#include "compiler/sema/resolve.h"

namespace kage {

/// What load_lowered produced: `config` when both the front end and lowering succeeded.
struct [[nodiscard]] LoweredFile {
  std::optional<Spec> spec;             ///< set when the front end reported no error
  std::optional<LoweredConfig> config;  ///< set when lowering succeeded too
  std::string lower_errors;             ///< lowering's errors ("key: message" lines) when it failed
  bool ok() const { return config.has_value(); }
};

/// load + check + resolve + lower of `path`. Diagnostics are added to `diags` (the caller prints them
/// as it likes); a Spec is kept only when no error was reported, and lowered only then.
LoweredFile load_lowered(const std::string& path, const ResolveOptions& options, SourceManager& sources,
                         FileReader& reader, DiagEngine& diags);

}  // namespace kage
