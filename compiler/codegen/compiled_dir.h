// The one module that knows the layout of a `kagec compile` output directory: what may be written
// into one, how a new one replaces an old one (built aside, then renamed into place, so no directory
// ever mixes two compiles), the manifest.json it ends with, and the reading of such a directory back
// (manifest, SHA-256 of every listed file, params.bin, assets.bin, the generated source).
#pragma once

#include <cstdint>
#include <filesystem>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "runtime/io/asset_pack.h"
#include "runtime/latent/latent_params.h"
#include "runtime/visual/visual_params.h"

namespace kage {

/// The manifest's file name inside a compile directory.
inline constexpr const char* kManifestFile = "manifest.json";
/// The fixed outputs of a compile (the generated source is named by the compile).
inline constexpr const char* kParamsFile = "params.bin";
inline constexpr const char* kSpecFile = "spec.json";
inline constexpr const char* kAssetsFile = "assets.bin";
inline constexpr const char* kFatbinFile = "kernels.fatbin";
inline constexpr const char* kHostLibraryFile = "kernels_host.so";

/// Why `name` cannot name the generated source (a plain `*.cu` file name that is none of the other
/// outputs), or nullopt when it can.
std::optional<std::string> source_name_problem(const std::string& name);

/// Why `dir` cannot receive a compile, or nullopt when it can: it is absent, empty, or an earlier
/// compile, whose kagec manifest lists every entry in it (each a regular file). Anything else (the root
/// or home directory, a symbolic link, a file, a directory holding a file kagec did not write) is left
/// alone, since a compile replaces its directory whole (make_staging_dir, publish_staging_dir in
/// compiler/basic/file_out.h).
std::optional<std::string> output_dir_problem(const std::filesystem::path& dir);

/// params.bin: the LatentParams words, then the VisualParams words (codegen's param_words), little-endian.
std::string params_blob(const std::vector<uint32_t>& latent_words, const std::vector<uint32_t>& visual_words);

/// What a compile records in its manifest besides the parameter layout and the files' hashes.
struct ManifestRecord {
  std::string spec_sha256;
  int codegen_version = 0;
  std::string template_sha256;
  std::string latent_section_sha256;
  std::string config_type;
  std::string source;  ///< the generated source's file name
  std::string arch;
  nlohmann::json toolchain;  ///< {nvcc, nvrtc, host_cxx}: a version, or null when absent
  nlohmann::json flags;      ///< {nvcc, host}
  nlohmann::json builds;     ///< per build: {output, status, note}
  std::vector<std::string> files;  ///< every file written into the directory, in order
};

/// The text of manifest.json for `record`, hashing each of its files in `dir`; nullopt with a message in
/// `error` when one cannot be read back.
std::optional<std::string> manifest_text(const std::filesystem::path& dir, const ManifestRecord& record,
                                         std::string* error);

/// Checks every entry of the manifest's "files" (a plain name, the size and the SHA-256 it states)
/// and returns the names, or nullopt with a message naming the first file that differs.
std::optional<std::set<std::string>> verify_compiled_files(const std::filesystem::path& dir,
                                                           const nlohmann::json& manifest, std::string* error);

/// A compile directory whose manifest was read and whose listed files all match their hashes.
struct CompiledDir {
  std::filesystem::path dir;
  nlohmann::json manifest;
  std::set<std::string> files;  ///< the names the manifest lists
  std::string spec_sha256() const { return manifest.value("spec_sha256", ""); }
  /// The generated source's file name ("" when the manifest names none).
  std::string source_name() const { return manifest.value("source", ""); }
  bool has(const std::string& name) const { return files.count(name) != 0; }
  std::filesystem::path path(const std::string& name) const { return dir / name; }
};

/// Reads and verifies `dir`; nullopt with a message in `error` (no manifest, not a kagec manifest,
/// a listed file missing or changed).
std::optional<CompiledDir> open_compiled_dir(const std::filesystem::path& dir, std::string* error);

/// The parameters of params.bin; false with a message in `error` when it is missing or the wrong size.
[[nodiscard]] bool read_compiled_params(const CompiledDir& c, LatentParams* latent, VisualParams* visual,
                                        std::string* error);
/// The asset pack of assets.bin; nullopt with a message in `error`.
std::optional<AssetPack> read_compiled_assets(const CompiledDir& c, std::string* error);
/// The generated source's text; nullopt with a message in `error`.
std::optional<std::string> read_compiled_source(const CompiledDir& c, std::string* error);

}  // namespace kage
