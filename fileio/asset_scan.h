// Asset discovery with the original loader's directory rules (spec 2.4):
// which files a background folder or a skin folder contributes, in what order.
#pragma once

#include <optional>
#include <string>
#include <vector>

namespace kage {

/// Bounds of every scan, so that a path such as `/` costs a moment and an error, not a walk of the
/// whole file system: directory entries visited, and levels below the scanned folder.
inline constexpr int kMaxScanEntries = 10000;
inline constexpr int kMaxScanDepth = 8;

/// Each scan below stops at these bounds; it then returns nullopt (or an empty list) and, when
/// `error` is given, says which bound `dir` exceeds.

/// Background images of `dir` (spec 2.4 background step 2): files directly in
/// `dir` matching `*.jpg`, `*.jpeg`, `*.png`, `*.bmp` (case-sensitive), the
/// union sorted by path string ("bg-1", "bg-10", "bg-100", ...). Returns
/// nullopt when `dir` is not an existing directory; an empty list when it has
/// no matching file. Paths are `dir + "/" + name`.
std::optional<std::vector<std::string>> scan_background_dir(const std::string& dir, std::string* error = nullptr);

/// Skin (or NPC type) directories under `dir` (spec 2.4 skins step 1): the
/// immediate subdirectories, sorted by path string. nullopt when `dir` is not
/// an existing directory (the original then warns and loads no sprites).
std::optional<std::vector<std::string>> scan_skin_parent(const std::string& dir, std::string* error = nullptr);

/// Frame files of one skin (spec 2.4 skins step 4): every `*.png` under `dir`,
/// recursively, sorted by path string. Empty when `dir` is missing.
std::vector<std::string> scan_skin_frames(const std::string& dir, std::string* error = nullptr);

}  // namespace kage
