// The config compiler's front end for the Python package: resolve a config, certify a pair or a mixture,
// check a suite. Errors come back as kagec's diagnostics text.
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

namespace kage::python {

/// What a front-end call gives back: `json` on success, else kagec's diagnostics in `error`.
struct FrontEndResult {
  std::string json;
  std::string error;
  bool ok() const { return error.empty(); }
};

/// The canonical Spec of a config (kagec resolve), with its "sha256" field.
FrontEndResult resolve_config_json(const std::string& path, const std::string& asset_root);
/// kagec lint's diagnostics of a config as text, warnings and errors alike; empty when it is clean.
std::string lint_text(const std::string& path, const std::string& asset_root);
/// The certificate of a train/eval pair (kagec diff --certify -o), verdict included.
FrontEndResult certify_pair_json(const std::string& train, const std::string& eval, const std::string& asset_root);
/// The certificate of a mixture (kagec diff --mixture -o): its configs, their Spec hashes and the visual axes
/// they differ on; kagec's diagnostics when a config has errors or the configs differ on a latent key.
FrontEndResult certify_mixture_json(const std::vector<std::string>& paths, const std::string& asset_root);
/// The spec hash of a mixture batch (kage::open_mixture's): of its parts' Spec hashes and environment counts.
std::string mixture_hash(const std::vector<std::pair<std::string, int32_t>>& parts);
/// The report of a suite manifest (kagec suite's report.json): every pair's paths, axis, sweep and
/// certificate.
FrontEndResult suite_report(const std::string& manifest);

}  // namespace kage::python
