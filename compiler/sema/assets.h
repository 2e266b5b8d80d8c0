// Assets of a configuration: located next to the config that names them (or under --asset-root;
// a path found only under the working directory, where the original looks, is used from there with a
// note), expanded with the original's directory rules (spec 2.4), checked to exist and to decode as the
// runtime decodes them, content-hashed.
#pragma once

#include "compiler/basic/diag.h"
#include "compiler/parse/compose.h"
#include "compiler/sema/resolve.h"
#include "compiler/sema/schema.h"
#include "compiler/sema/spec.h"

namespace kage {

/// Rewrites the asset keys of spec.values to working-directory-relative paths and
/// fills spec.assets; reports missing, empty and unreadable assets.
void resolve_assets(const ComposedConfig& config, const Schema& schema, const ResolveOptions& options,
                    const SourceManager& sources, Spec& spec, DiagEngine& diags);

/// A path lexically normalised, relative to the working directory when it lies inside it (deterministic
/// output), else as it is (never "../../x").
std::string display_path(const std::string& path);

/// What `path` is when it exists and is not a folder ("is a file, not a folder; name a folder"),
/// else nullopt.
std::optional<std::string> folder_problem(const std::string& path);

}  // namespace kage
