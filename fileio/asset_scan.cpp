// Directory scanning for backgrounds and sprite skins, reproducing pathlib's
// glob/rglob + sorted() as used by the original environment constructor.
#include "fileio/asset_scan.h"

#include <algorithm>
#include <filesystem>
#include <system_error>

namespace kage {
namespace {

namespace fs = std::filesystem;

bool ends_with(const std::string& s, const std::string& suffix) {
  return s.size() >= suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// Python's str(Path(dir) / name): drop a trailing separator from `dir`.
std::string join(const std::string& dir, const std::string& name) {
  std::string base = dir;
  while (base.size() > 1 && base.back() == '/') base.pop_back();
  if (base.empty() || base == ".") return name;
  return base + (base.back() == '/' ? "" : "/") + name;
}

bool is_dir(const std::string& dir) {
  std::error_code ec;
  return fs::is_directory(dir, ec);
}

bool too_many(const std::string& dir, int visited, std::string* error) {
  if (visited <= kMaxScanEntries) return false;
  if (error)
    *error = "'" + dir + "' holds more than " + std::to_string(kMaxScanEntries) +
             " entries; point at a folder of assets";
  return true;
}

}  // namespace

std::optional<std::vector<std::string>> scan_background_dir(const std::string& dir, std::string* error) {
  if (!is_dir(dir)) return std::nullopt;
  static const char* const kPatterns[] = {".jpg", ".jpeg", ".png", ".bmp"};
  std::vector<std::string> out;
  std::error_code ec;
  int visited = 0;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    if (too_many(dir, ++visited, error)) return std::nullopt;
    const std::string name = entry.path().filename().string();
    for (const char* suffix : kPatterns) {
      if (ends_with(name, suffix)) {
        out.push_back(join(dir, name));
        break;
      }
    }
  }
  std::sort(out.begin(), out.end());
  return out;
}

std::optional<std::vector<std::string>> scan_skin_parent(const std::string& dir, std::string* error) {
  if (!is_dir(dir)) return std::nullopt;
  std::vector<std::string> out;
  std::error_code ec;
  int visited = 0;
  for (const auto& entry : fs::directory_iterator(dir, ec)) {
    if (too_many(dir, ++visited, error)) return std::nullopt;
    std::error_code ec2;
    if (entry.is_directory(ec2)) out.push_back(join(dir, entry.path().filename().string()));
  }
  std::sort(out.begin(), out.end());
  return out;
}

std::vector<std::string> scan_skin_frames(const std::string& dir, std::string* error) {
  std::vector<std::string> out;
  if (!is_dir(dir)) return out;
  std::error_code ec;
  int visited = 0;
  for (auto it = fs::recursive_directory_iterator(dir, ec); !ec && it != fs::recursive_directory_iterator();
       it.increment(ec)) {
    if (too_many(dir, ++visited, error)) return {};
    if (it.depth() >= kMaxScanDepth) {
      if (error)
        *error = "'" + dir + "' is nested deeper than " + std::to_string(kMaxScanDepth) +
                 " levels; point at a folder of assets";
      return {};
    }
    const std::string name = it->path().filename().string();
    if (!ends_with(name, ".png")) continue;
    std::error_code ec2;
    if (it->is_directory(ec2)) continue;
    // Path relative to `dir`, re-joined so the prefix matches the other scans.
    const std::string rel = it->path().lexically_relative(dir).generic_string();
    out.push_back(join(dir, rel));
  }
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace kage
