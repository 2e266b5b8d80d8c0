// The config compiler's front end for the Python package: resolve a config, certify a pair, check a
// suite. Errors come back as kagec's diagnostics text.
#pragma once

#include <string>

namespace kage::python {

/// What a front-end call gives back: `json` on success, else kagec's diagnostics in `error`.
struct FrontEndResult {
  std::string json;
  std::string error;
  bool ok() const { return error.empty(); }
};

/// The canonical Spec of a config (kagec resolve), with its "sha256" field.
FrontEndResult resolve_config_json(const std::string& path, const std::string& asset_root);
/// The certificate of a train/eval pair (kagec diff --certify -o), verdict included.
FrontEndResult certify_pair_json(const std::string& train, const std::string& eval, const std::string& asset_root);
/// The report of a suite manifest (kagec suite's report.json): every pair's paths, axis, sweep and
/// certificate.
FrontEndResult suite_report(const std::string& manifest);

}  // namespace kage::python
