// Compile directories: safe names, staging and publishing, the manifest, reading back (see compiled_dir.h).
#include "compiler/codegen/compiled_dir.h"

#include <algorithm>
#include <cstring>
#include <fstream>
#include <sstream>

#include "compiler/basic/file_out.h"
#include "fileio/sha256.h"
#include "runtime/io/specialized_assets.h"

namespace kage {

namespace fs = std::filesystem;
using Json = nlohmann::json;

namespace {

// A manifest is a few KB; a larger file named manifest.json is not one (and is not read whole).
constexpr uintmax_t kMaxManifestBytes = uintmax_t(16) << 20;

// The fixed outputs of a compile; the generated source may not take one of these names.
constexpr const char* kOutputNames[] = {kManifestFile, kParamsFile, kSpecFile, kAssetsFile, kFatbinFile,
                                        kHostLibraryFile};

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
  if (std::optional<std::string> problem = output_dir_kind_problem(dir)) return problem;
  std::error_code ec;
  if (!fs::exists(dir, ec) || fs::is_empty(dir, ec)) return std::nullopt;
  const std::string name = dir.string();
  const std::string fix = "; kagec compile replaces its output directory whole, so name a new or empty directory";
  // Only a directory this command wrote is replaced: a kagec manifest that lists every file in it.
  const fs::path manifest_path = dir / kManifestFile;
  const fs::file_status manifest_status = fs::symlink_status(manifest_path, ec);
  if (!fs::exists(manifest_status))
    return "'" + name + "' holds files that kagec did not write (it has no " + kManifestFile + ")" + fix;
  const std::optional<std::string> text =
      fs::is_regular_file(manifest_status) && fs::file_size(manifest_path, ec) <= kMaxManifestBytes
          ? read_bytes(manifest_path)
          : std::nullopt;
  const Json manifest = text ? Json::parse(*text, nullptr, false) : Json();
  const Json files = manifest.is_object() && manifest.value("kagec_manifest", 0) == 1 ? manifest.value("files", Json())
                                                                                      : Json();
  if (!files.is_array())
    return "'" + (dir / kManifestFile).string() + "' is not a kagec compile manifest, so kagec did not write '" + name +
           "'" + fix;
  std::set<std::string> listed{kManifestFile};
  for (const Json& f : files)
    if (f.is_object() && f.value("name", Json()).is_string()) listed.insert(f.value("name", ""));
  std::vector<std::string> foreign;
  for (const fs::directory_entry& e : fs::directory_iterator(dir, ec)) {
    const std::string entry = e.path().filename().string();
    std::error_code st_ec;
    if (!listed.count(entry) || !e.is_regular_file(st_ec) || e.is_symlink(st_ec)) foreign.push_back(entry);
  }
  if (ec) return "cannot list '" + name + "': " + ec.message();
  if (foreign.empty()) return std::nullopt;
  std::sort(foreign.begin(), foreign.end());
  std::string more = foreign.size() > 1 ? " and " + std::to_string(foreign.size() - 1) + " more" : "";
  return "'" + name + "' holds '" + foreign.front() + "'" + more + ", which its " + kManifestFile +
         " does not list (kagec did not write it); move such files out of the directory, or name a new or empty "
         "directory (kagec compile replaces its output directory whole)";
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

std::string params_blob(const std::vector<uint32_t>& latent_words, const std::vector<uint32_t>& visual_words) {
  std::string out;
  for (const std::vector<uint32_t>* words : {&latent_words, &visual_words}) {
    for (uint32_t w : *words) {
      for (int b = 0; b < 4; ++b) out.push_back(static_cast<char>((w >> (8 * b)) & 0xffu));
    }
  }
  return out;
}

std::optional<std::string> manifest_text(const fs::path& dir, const ManifestRecord& r, std::string* error) {
  Json file_list = Json::array();
  for (const std::string& f : r.files) {
    const std::optional<std::string> bytes = read_bytes(dir / f);
    if (!bytes) {
      *error = "cannot read back '" + (dir / f).string() + "' to hash it";
      return std::nullopt;
    }
    file_list.push_back({{"name", f}, {"bytes", bytes->size()}, {"sha256", sha256_hex(*bytes)}});
  }
  const Json manifest = {
      {"kagec_manifest", 1},
      {"spec_sha256", r.spec_sha256},
      {"codegen_version", r.codegen_version},
      {"template_sha256", r.template_sha256},
      {"latent_section_sha256", r.latent_section_sha256},
      {"config_type", r.config_type},
      {"source", r.source},
      {"arch", r.arch},
      {"params", {{"file", kParamsFile}, {"latent_bytes", sizeof(LatentParams)}, {"visual_offset", sizeof(LatentParams)},
                  {"visual_bytes", sizeof(VisualParams)}}},
      {"toolchain", r.toolchain},
      {"flags", r.flags},
      {"builds", r.builds},
      {"files", file_list},
  };
  return json_file_text(manifest);
}

std::optional<CompiledDir> open_compiled_dir(const fs::path& dir, std::string* error) {
  const std::optional<std::string> text = read_bytes(dir / kManifestFile);
  if (!text) {
    *error = std::string("no ") + kManifestFile + " in '" + dir.string() + "' (write one with kagec compile)";
    return std::nullopt;
  }
  CompiledDir c{dir, Json::parse(*text, nullptr, false), {}};
  if (c.manifest.is_discarded() || !c.manifest.is_object() || c.manifest.value("kagec_manifest", 0) != 1) {
    *error = "'" + (dir / kManifestFile).string() + "' is not a kagec manifest";
    return std::nullopt;
  }
  // Nothing is loaded from a directory whose files are not exactly the ones its compile wrote.
  std::optional<std::set<std::string>> files = verify_compiled_files(dir, c.manifest, error);
  if (!files) return std::nullopt;
  c.files = std::move(*files);
  return c;
}

bool read_compiled_params(const CompiledDir& c, LatentParams* latent, VisualParams* visual, std::string* error) {
  const std::optional<std::string> bytes = c.has(kParamsFile) ? read_bytes(c.path(kParamsFile)) : std::nullopt;
  if (!bytes || bytes->size() != sizeof(LatentParams) + sizeof(VisualParams)) {
    *error = "'" + c.path(kParamsFile).string() + "' is missing or has the wrong size; compile the config again";
    return false;
  }
  std::memcpy(latent, bytes->data(), sizeof(LatentParams));
  std::memcpy(visual, bytes->data() + sizeof(LatentParams), sizeof(VisualParams));
  return true;
}

std::optional<AssetPack> read_compiled_assets(const CompiledDir& c, std::string* error) {
  const std::optional<std::string> bytes = c.has(kAssetsFile) ? read_bytes(c.path(kAssetsFile)) : std::nullopt;
  std::optional<AssetPack> pack = bytes ? deserialize_asset_pack(*bytes) : std::nullopt;
  if (!pack) *error = "'" + c.path(kAssetsFile).string() + "' is missing or not an asset blob (compile without --no-build)";
  return pack;
}

std::optional<std::string> read_compiled_source(const CompiledDir& c, std::string* error) {
  const std::string name = c.source_name();
  std::optional<std::string> text = c.has(name) ? read_bytes(c.path(name)) : std::nullopt;
  if (!text) *error = "'" + c.dir.string() + "' has no generated source (its manifest names '" + name + "')";
  return text;
}

}  // namespace kage
