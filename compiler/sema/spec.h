// Spec: the compiler's intermediate representation of one configuration.
//
// Every parameter explicit (with the original loader's absent-key rules
// applied), inert settings marked, assets located and content-hashed.
// Printed as canonical JSON (sorted keys, shortest round-trip numbers), whose
// SHA-256 (paths left out, asset content in) identifies the configuration.
#pragma once

#include <set>
#include <string>
#include <vector>

#include "compiler/sema/schema.h"

namespace kage {

struct AssetFile {
  std::string file;  // relative to the working directory, normalised
  std::string sha256;
  int width = 0;
  int height = 0;
};

struct AssetSet {
  std::string dir;
  std::vector<AssetFile> frames;
};

struct ResolvedAssets {
  std::vector<AssetFile> backgrounds;
  std::vector<AssetSet> agent_skins, npc_types, sticky_types;
  /// The sets of a sprite group by its name in key_refs.h.
  std::vector<AssetSet>* sets(const std::string& group);
  const std::vector<AssetSet>* sets(const std::string& group) const;
};

struct Spec {
  Json values;                // {"H": 128, "physics": {"gravity": 0.75, ...}, ...}: every non-legacy key
  std::set<std::string> inert;  // dotted paths of settings with no effect in this configuration
  ResolvedAssets assets;

  /// The value of a dotted key path (null if absent).
  const Json& value(const std::string& path) const;
  /// {"kagec_spec": 1, "config": ..., "inert": [...], "assets": {...}}, without the hash.
  Json to_json() const;
  /// The canonical text: to_json() with the hash added, pretty-printed, sorted.
  std::string canonical_text() const;
  /// SHA-256 of the compact canonical form of to_json() without its asset paths (the assets count
  /// by content), so that it does not depend on the working directory or the file's location.
  std::string sha256() const;
  /// Only the latent keys (physics, layout geometry, reward, screen).
  Json latent_values(const Schema& schema) const;
};

/// Reads a canonical Spec back (used to check the fixpoint).
std::optional<Spec> spec_from_json(const Json& j);

}  // namespace kage
