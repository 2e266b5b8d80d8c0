// Compile directories: safe names, staging and publishing, manifest verification (see compiled_dir.h).
#include "compiler/compiled_dir.h"

#include <unistd.h>

#include <cstdlib>
#include <fstream>
#include <random>
#include <sstream>

#include "runtime/io/sha256.h"

namespace kage {

namespace fs = std::filesystem;

namespace {

// The fixed outputs of a compile; the generated source may not take one of these names.
constexpr const char* kOutputNames[] = {kManifestFile, "params.bin", "spec.json", "assets.bin", "kernels.fatbin",
                                        "kernels_host.so"};

bool plain_file_name(const std::string& name) {
  if (name.empty() || name == "." || name == ".." || name.size() > 200) return false;
  for (char c : name) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
                    c == '-' || c == '.';
    if (!ok) return false;
  }
  return name[0] != '.';
}

std::optional<std::string> read_bytes(const fs::path& p) {
  std::ifstream f(p, std::ios::binary);
  if (!f) return std::nullopt;
  std::ostringstream s;
  s << f.rdbuf();
  if (f.bad()) return std::nullopt;
  return s.str();
}

}  // namespace

std::optional<std::string> source_name_problem(const std::string& name) {
  if (!plain_file_name(name) || name.size() < 4 || name.compare(name.size() - 3, 3, ".cu") != 0)
    return "--source-name '" + name + "' must be a plain file name ending in .cu (letters, digits, '_', '-', '.')";
  for (const char* reserved : kOutputNames)
    if (name == reserved) return "--source-name '" + name + "' is the name of another output of the compile";
  return std::nullopt;
}

std::optional<std::string> output_dir_problem(const fs::path& dir) {
  std::error_code ec;
  const fs::path abs = fs::weakly_canonical(fs::absolute(dir, ec), ec);
  if (abs.empty() || abs == abs.root_path()) return "'" + dir.string() + "' is the root directory; name a new directory";
  if (const char* home = std::getenv("HOME"); home && *home && abs == fs::weakly_canonical(home, ec))
    return "'" + dir.string() + "' is the home directory; name a new directory";
  if (!fs::exists(dir, ec)) return std::nullopt;
  if (!fs::is_directory(dir, ec)) return "'" + dir.string() + "' exists and is not a directory";
  if (fs::is_empty(dir, ec) || fs::exists(dir / kManifestFile, ec)) return std::nullopt;
  return "'" + dir.string() + "' is a directory that holds other files (no " + kManifestFile +
         "); name a new or empty directory, or an earlier compile's";
}

std::optional<fs::path> make_staging_dir(const fs::path& dir, std::string* error) {
  const fs::path abs = fs::absolute(dir).lexically_normal();
  const fs::path parent = (abs.has_filename() ? abs : abs.parent_path()).parent_path();
  std::error_code ec;
  fs::create_directories(parent, ec);
  if (ec) {
    *error = "cannot create '" + parent.string() + "': " + ec.message();
    return std::nullopt;
  }
  std::random_device rd;
  const std::string base = (abs.has_filename() ? abs : abs.parent_path()).filename().string();
  const fs::path staging = parent / ("." + base + ".kagec-tmp." + std::to_string(::getpid()) + "." + std::to_string(rd()));
  if (!fs::create_directory(staging, ec) || ec) {
    *error = "cannot create '" + staging.string() + "': " + (ec ? ec.message() : "it exists");
    return std::nullopt;
  }
  return staging;
}

bool publish_staging_dir(const fs::path& staging, const fs::path& dir, std::string* error) {
  std::error_code ec;
  const fs::path target = fs::absolute(dir).lexically_normal();
  const fs::path clean = target.has_filename() ? target : target.parent_path();
  fs::path old;
  if (fs::exists(clean, ec)) {
    old = staging.string() + ".old";
    fs::rename(clean, old, ec);
    if (ec) {
      *error = "cannot move the earlier compile '" + dir.string() + "' aside: " + ec.message();
      return false;
    }
  }
  fs::rename(staging, clean, ec);
  if (ec) {
    *error = "cannot move the new compile to '" + dir.string() + "': " + ec.message();
    std::error_code back;
    if (!old.empty()) fs::rename(old, clean, back);
    return false;
  }
  if (!old.empty()) fs::remove_all(old, ec);  // a leftover costs only disk; the new compile is in place
  return true;
}

std::optional<std::set<std::string>> verify_compiled_files(const fs::path& dir, const Json& manifest,
                                                           std::string* error) {
  const Json files = manifest.value("files", Json());
  if (!files.is_array() || files.empty()) {
    *error = "'" + (dir / kManifestFile).string() + "' lists no files; compile the config again";
    return std::nullopt;
  }
  std::set<std::string> names;
  for (const Json& f : files) {
    const std::string name = f.is_object() ? f.value("name", "") : "";
    const std::string want = f.is_object() ? f.value("sha256", "") : "";
    if (!plain_file_name(name) || want.empty()) {
      *error = "'" + (dir / kManifestFile).string() + "' has a malformed file entry; compile the config again";
      return std::nullopt;
    }
    const auto bytes = read_bytes(dir / name);
    if (!bytes) {
      *error = "'" + (dir / name).string() + "', listed in the manifest, cannot be read; compile the config again";
      return std::nullopt;
    }
    if (sha256_hex(*bytes) != want || f.value("bytes", uint64_t(0)) != bytes->size()) {
      *error = "'" + (dir / name).string() +
               "' does not match the SHA-256 its manifest states (changed after the compile); compile the config again";
      return std::nullopt;
    }
    names.insert(name);
  }
  return names;
}

}  // namespace kage
