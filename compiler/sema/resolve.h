// Resolve: a checked, composed document -> Spec, with the original loader's
// absent-key rules (dataclass defaults, whole-section defaults, legacy aliases),
// inert marks, located assets and the context-dependent lints.
#pragma once

#include <optional>
#include <string>

#include "compiler/basic/diag.h"
#include "compiler/parse/compose.h"
#include "compiler/sema/schema.h"
#include "compiler/sema/spec.h"

namespace kage {

struct ResolveOptions {
  /// Asset paths are relative to this directory; unset: relative to the file that writes them.
  std::optional<std::string> asset_root;
};

/// Computes every value. Reports asset and context lints; returns the Spec even
/// when errors were reported (callers must not emit it then).
Spec resolve_config(const ComposedConfig& config, const Schema& schema, const ResolveOptions& options,
                    const SourceManager& sources, DiagEngine& diags);

/// load + check + resolve of one file: the front end's whole pipeline.
std::optional<Spec> analyze_file(const std::string& path, const ResolveOptions& options, SourceManager& sources,
                                 FileReader& reader, DiagEngine& diags);

/// The same for a composed document (e.g. an inline suite config).
std::optional<Spec> analyze_composed(const ComposedConfig& config, const ResolveOptions& options,
                                     SourceManager& sources, DiagEngine& diags);

/// The document node of a key, if written (sections and keys looked up by name).
const DocNode* find_key(const DocNode& root, const KeySchema& key);
const DocEntry* find_key_entry(const DocNode& root, const KeySchema& key);

}  // namespace kage
