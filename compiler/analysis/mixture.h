// Certification of a mixture: several configs run as one batch (kage.make_vec([a, b, ...]), kagec diff
// --mixture), each environment on one of them. They must run one hidden game and render one observation
// shape, so that they differ only in how the game looks: their Specs are equal on every latent key (diff.h's
// notion of a change: a setting inert on both sides is none).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "compiler/analysis/diff.h"
#include "compiler/basic/diag.h"
#include "compiler/parse/compose.h"
#include "compiler/sema/resolve.h"

namespace kage {

/// One config of a mixture: its name as given, its composed document (where its keys are written) and its Spec.
struct MixtureMember {
  std::string name;
  const ComposedConfig* config = nullptr;
  const Spec* spec = nullptr;
};

/// Compares every member with the first and reports the first difference a mixture cannot have, as one
/// error: a side of the observation (certify-mixture-shape), else the first latent key in schema order
/// (certify-mixture-latent). It is located where the later member's chain writes the key (else where the
/// first member's does, else at the start of the later member's file) and names both files and values.
/// True when nothing was reported.
bool certify_mixture(const std::vector<MixtureMember>& members, const Schema& schema, DiagEngine& diags);

/// Every file through the front end (load, check, resolve), then certify_mixture: the Specs, in order, or
/// nullopt when a file has errors or the mixture does not certify (the reasons in `diags`).
std::optional<std::vector<Spec>> analyze_mixture(const std::vector<std::string>& paths, const ResolveOptions& options,
                                                 SourceManager& sources, FileReader& reader, DiagEngine& diags);

/// The identity of a batch over a mixture: the SHA-256 of the compact JSON
/// {"kage_mixture": 1, "parts": [{"num_envs": n, "spec_sha256": h}, ...]} of its parts in order (a config's
/// Spec hash, and how many environments run it).
std::string mixture_sha256(const std::vector<std::pair<std::string, int32_t>>& parts);

/// The certificate of a mixture that certified: {"kagec_mixture": 1, "certified": true, "configs": [{"name",
/// "spec_sha256"}, ...], "axes": [the visual axes on which some config differs from the first]}.
Json mixture_json(const std::vector<std::string>& names, const std::vector<Spec>& specs, const Schema& schema);

}  // namespace kage
