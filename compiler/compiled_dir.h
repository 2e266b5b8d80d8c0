// `kagec compile` output directories: what may be written into one, how a new one replaces an old one
// (built aside, then renamed into place, so no directory ever mixes two compiles), and the check that
// every file a manifest lists is there with its SHA-256 before anything is loaded from it.
#pragma once

#include <filesystem>
#include <optional>
#include <set>
#include <string>

#include "compiler/spec.h"

namespace kage {

/// The manifest's file name inside a compile directory.
inline constexpr const char* kManifestFile = "manifest.json";

/// Why `name` cannot name the generated source (a plain `*.cu` file name that is none of the other
/// outputs), or nullopt when it can.
std::optional<std::string> source_name_problem(const std::string& name);

/// Why `dir` cannot receive a compile (the root or a home directory, an existing file, a non-empty
/// directory without a kagec manifest), or nullopt when it can.
std::optional<std::string> output_dir_problem(const std::filesystem::path& dir);

/// A fresh, empty directory beside `dir` to build into; nullopt with a message in `error`.
std::optional<std::filesystem::path> make_staging_dir(const std::filesystem::path& dir, std::string* error);

/// Moves the finished `staging` directory to `dir`, replacing an earlier compile there; false with a
/// message in `error` (then `dir` still holds what it held before).
[[nodiscard]] bool publish_staging_dir(const std::filesystem::path& staging, const std::filesystem::path& dir,
                                       std::string* error);

/// Checks every entry of the manifest's "files" (a plain name, the size and the SHA-256 it states)
/// and returns the names, or nullopt with a message naming the first file that differs.
std::optional<std::set<std::string>> verify_compiled_files(const std::filesystem::path& dir, const Json& manifest,
                                                           std::string* error);

}  // namespace kage
