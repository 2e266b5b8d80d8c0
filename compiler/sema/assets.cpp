// Asset location, existence and hashing for the asset groups of key_refs.h.
#include "compiler/sema/assets.h"

#include <stb/stb_image.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <sstream>

#include "compiler/basic/utf8.h"
#include "compiler/sema/key_refs.h"
#include "fileio/asset_scan.h"
#include "fileio/image_io.h"
#include "fileio/sha256.h"

namespace kage {

namespace fs = std::filesystem;

std::string display_path(const std::string& path) {
  fs::path p = fs::path(path).lexically_normal();
  if (p.is_absolute()) {
    // Relative only inside the working directory: "../../x" would name the path less plainly.
    std::error_code ec;
    const fs::path rel = p.lexically_relative(fs::current_path(ec));
    if (!ec && !rel.empty() && *rel.begin() != "..") p = rel;
  }
  std::string s = p.generic_string();
  if (s.size() > 1 && s.back() == '/') s.pop_back();
  return s;
}

std::optional<std::string> folder_problem(const std::string& path) {
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);
  if (!fs::exists(st) || fs::is_directory(st)) return std::nullopt;
  if (fs::is_regular_file(st)) return "is a file, not a folder; name a folder";
  return "is not a folder (a FIFO, device or socket); name a folder";
}

namespace {

class AssetResolver {
 public:
  AssetResolver(const ComposedConfig& config, const Schema& schema, const ResolveOptions& options,
                const SourceManager& sources, Spec& spec, DiagEngine& diags)
      : config_(config), schema_(schema), options_(options), sources_(sources), spec_(spec), diags_(diags) {}

  void run() {
    rewrite_paths();
    for (const AssetGroupRef& group : kAssetGroups) {
      const Json& enable = spec_.value(group.enable_key);
      const bool on = enable.is_boolean() ? (enable.get<bool>() && std::string(group.enable_value) == "true")
                                          : enable == Json(group.enable_value);
      if (!on) continue;
      if (group.images)
        resolve_backgrounds(group);
      else
        resolve_skins(group);
    }
  }

 private:
  // Each asset key's value becomes a working-directory-relative path.
  void rewrite_paths() {
    for (const KeySchema& k : schema_.keys()) {
      if (k.asset_kind.empty()) continue;
      const DocEntry* entry = find_key_entry(config_.root, k);
      if (!entry) continue;
      Json& v = k.section.empty() ? spec_.values[k.name] : spec_.values[k.section][k.name];
      const std::string base = base_dir(entry->value);
      if (v.is_string()) v = locate(base, v.get<std::string>(), entry->value.range, k);
      if (v.is_array())
        for (size_t i = 0; i < v.size(); ++i)
          if (v[i].is_string()) {
            const Range at = i < entry->value.items.size() ? entry->value.items[i].range : entry->value.range;
            v[i] = locate(base, v[i].get<std::string>(), at, k);
          }
    }
  }

  // A relative path is taken next to the file that writes it. The original takes it from the working
  // directory, so its own configs name paths like src/kage_bench/assets/...: such a path that exists
  // only under the working directory is used from there (with a note), and one that names two
  // different files is a warning. The Spec identifies assets by content, so either way the hash
  // does not depend on where the command ran.
  std::string locate(const std::string& base, const std::string& path, Range at, const KeySchema& k) {
    if (fs::path(path).is_absolute()) {  // shown as written (normalised), wherever the command runs
      std::string as_given = fs::path(path).lexically_normal().generic_string();
      if (as_given.size() > 1 && as_given.back() == '/') as_given.pop_back();
      return as_given;
    }
    const std::string here = display_path(join_path(base, path));
    if (options_.asset_root) return here;
    const std::string cwd = display_path(path);
    if (cwd == here) return here;
    std::error_code ec;
    const bool here_exists = fs::exists(here, ec), cwd_exists = fs::exists(cwd, ec);
    if (here_exists && cwd_exists && !fs::equivalent(here, cwd, ec)) {
      diags_.report(Rule::AssetAmbiguous, at,
                    "asset path '" + path + "' names '" + here + "' next to the config, which is used, and '" + cwd +
                        "' under the working directory, where the original looks; pass --asset-root to choose",
                    k.pointer);
    } else if (!here_exists && cwd_exists) {
      diags_.report(Rule::AssetCwdRelative, at,
                    "asset path '" + path + "' is not next to the config; using '" + cwd +
                        "' under the working directory, as the original does",
                    k.pointer);
      return cwd;
    }
    return here;
  }

  std::string base_dir(const DocNode& node) const {
    if (options_.asset_root) return *options_.asset_root;
    if (!node.range.begin.valid()) return "";
    return parent_dir(sources_.name(node.range.begin.file));
  }

  std::string pointer_of(const std::string& path) const {
    const KeySchema* k = schema_.find(path);
    return k ? k->pointer : std::string();
  }

  const DocNode* node_of(const char* path) const {
    const KeySchema* k = schema_.find(path);
    return k ? find_key(config_.root, *k) : nullptr;
  }

  Range range_of(const char* path) const {
    const DocEntry* e = nullptr;
    if (const KeySchema* k = schema_.find(path)) e = find_key_entry(config_.root, *k);
    return e ? e->value.range : Range{};
  }

  // The range of list item i of a key, or the key's range.
  Range item_range(const char* path, size_t i) const {
    const DocNode* n = node_of(path);
    if (n && n->is_seq() && i < n->items.size()) return n->items[i].range;
    return range_of(path);
  }

  // The canonical Spec is JSON, which holds only UTF-8: a file or folder whose name is not is refused.
  bool utf8_name(const std::string& path, Range at, const std::string& key) {
    if (!invalid_utf8_offset(path)) return true;
    diags_.report(Rule::AssetUnreadable, at,
                  "asset path '" + utf8_from_latin1_strays(path) + "' (from '" + key +
                      "') is not valid UTF-8; rename the file or folder",
                  pointer_of(key));
    return false;
  }

  std::optional<AssetFile> hash_image(const std::string& file, Range at, const std::string& key) {
    if (!utf8_name(file, at, key)) return std::nullopt;
    // Read only a regular file of a sane size: a directory, a FIFO or device, or a 1 GB file is
    // refused before any byte is read, with what it is.
    const ImageFileBytes read = read_image_file(file);
    if (!read.ok()) {
      diags_.report(read.kind == ImageError::kMissing || read.not_a_file ? Rule::AssetMissing : Rule::AssetUnreadable, at,
                    "asset file '" + file + "' (from '" + key + "') " +
                        (read.kind == ImageError::kMissing ? "does not exist; fix the path" : read.reason),
                    pointer_of(key));
      return std::nullopt;
    }
    const std::string& bytes = *read.bytes;
    const auto* data = reinterpret_cast<const uint8_t*>(bytes.data());
    // A header claiming more pixels than the runtime decodes says so (stb_image's own reason for
    // some such sizes is "unknown image type").
    if (const std::optional<std::string> too_large = header_size_problem(data, bytes.size())) {
      diags_.report(Rule::AssetUnreadable, at, "asset file '" + file + "' cannot be decoded: " + *too_large,
                    pointer_of(key));
      return std::nullopt;
    }
    int w = 0, h = 0, c = 0;
    if (!stbi_info_from_memory(data, static_cast<int>(bytes.size()), &w, &h, &c) || w <= 0 || h <= 0) {
      diags_.report(Rule::AssetUnreadable, at,
                    "asset file '" + file + "' is not a readable PNG, JPEG or BMP image (" +
                        (stbi_failure_reason() ? stbi_failure_reason() : "unknown format") + "); replace it",
                    pointer_of(key));
      return std::nullopt;
    }
    const std::string hash = sha256_hex(bytes);
    // Decoded as the runtime will decode it (a header can be fine and the data truncated).
    if (const std::string problem = decode_problem(hash, bytes); !problem.empty()) {
      diags_.report(Rule::AssetUnreadable, at, "asset file '" + file + "' cannot be decoded: " + problem + "; replace it",
                    pointer_of(key));
      return std::nullopt;
    }
    return AssetFile{display_path(file), hash, w, h};
  }

  // What the runtime's decoder says about these bytes ("" when they decode), remembered by content
  // hash: a suite or a fuzz run names the same images many times.
  static std::string decode_problem(const std::string& hash, const std::string& bytes) {
    static std::mutex mutex;
    static std::map<std::string, std::string> known;
    {
      const std::lock_guard<std::mutex> lock(mutex);
      if (const auto it = known.find(hash); it != known.end()) return it->second;
    }
    const ImageResult r = decode_image(reinterpret_cast<const uint8_t*>(bytes.data()), bytes.size(), 3, "");
    std::string problem = r.ok() ? std::string() : r.error.substr(r.error.find_first_not_of(": "));
    const std::lock_guard<std::mutex> lock(mutex);
    return known.emplace(hash, std::move(problem)).first->second;
  }

  void resolve_backgrounds(const AssetGroupRef& g) {
    const char* paths_key = g.sources[0];
    const char* dir_key = g.sources[1];
    const char* file_key = g.sources[2];
    struct Source {
      std::string file;
      Range at;
      const char* key;
    };
    std::vector<Source> files;
    const Json& list = spec_.value(paths_key);
    if (list.is_array() && !list.empty()) {
      for (size_t i = 0; i < list.size(); ++i) files.push_back({list[i].get<std::string>(), item_range(paths_key, i), paths_key});
    } else if (const Json& dir = spec_.value(dir_key); dir.is_string()) {
      std::string bound;
      const auto found = scan_background_dir(dir.get<std::string>(), &bound);
      if (!found) {
        const std::optional<std::string> kind = folder_problem(dir.get<std::string>());
        diags_.report(bound.empty() ? Rule::AssetMissing : Rule::AssetUnreadable, range_of(dir_key),
                      !bound.empty() ? "background folder " + bound
                                     : "background folder '" + dir.get<std::string>() + "' " +
                                           kind.value_or("does not exist; fix the path"),
                      pointer_of(dir_key));
        return;
      }
      for (const std::string& f : *found) files.push_back({f, range_of(dir_key), dir_key});
    }
    if (files.empty()) {
      if (const Json& one = spec_.value(file_key); one.is_string()) files.push_back({one.get<std::string>(), range_of(file_key), file_key});
    }
    if (files.empty()) {
      const Range at = range_of(g.enable_key);
      diags_.report(Rule::AssetEmpty, at,
                    "background mode is 'image' but no background images were found; set one of " +
                        std::string(paths_key) + ", " + dir_key + " or " + file_key,
                    pointer_of(g.enable_key));
      return;
    }
    for (const Source& src : files)
      if (auto f = hash_image(src.file, src.at, src.key)) spec_.assets.backgrounds.push_back(*f);
  }

  void resolve_skins(const AssetGroupRef& g) {
    struct Source {
      std::string dir;
      Range at;
      const char* key;
    };
    std::vector<Source> dirs;
    const Json& parent = spec_.value(g.sources[0]);
    const Json& list = spec_.value(g.sources[1]);
    const Json& single = spec_.value(g.sources[2]);
    if (parent.is_string()) {
      std::string bound;
      const auto found = scan_skin_parent(parent.get<std::string>(), &bound);
      if (!found && !bound.empty()) {
        diags_.report(Rule::AssetUnreadable, range_of(g.sources[0]), "sprite folder " + bound, pointer_of(g.sources[0]));
        return;
      }
      if (!found) {
        const std::optional<std::string> kind = folder_problem(parent.get<std::string>());
        diags_.report(Rule::AssetMissing, range_of(g.sources[0]),
                      "sprite folder '" + parent.get<std::string>() + "' " +
                          kind.value_or("does not exist (the original would load no sprites and draw nothing); fix "
                                        "the path"),
                      pointer_of(g.sources[0]));
        return;
      }
      for (const std::string& d : *found) dirs.push_back({d, range_of(g.sources[0]), g.sources[0]});
    } else if (list.is_array() && !list.empty()) {
      for (size_t i = 0; i < list.size(); ++i) dirs.push_back({list[i].get<std::string>(), item_range(g.sources[1], i), g.sources[1]});
    } else if (single.is_string()) {
      dirs.push_back({single.get<std::string>(), range_of(g.sources[2]), g.sources[2]});
    }
    if (dirs.empty()) {
      diags_.report(Rule::AssetNoSprites, range_of(g.enable_key),
                    "'" + std::string(g.enable_key) + "' is true but no sprites are given, so nothing is drawn; set " +
                        g.sources[0] + ", " + g.sources[1] + " or " + g.sources[2],
                    pointer_of(g.enable_key));
      return;
    }
    std::vector<AssetSet>& sets = *spec_.assets.sets(g.name);
    for (const auto& [dir, at, key] : dirs) {
      if (!utf8_name(dir, at, key)) continue;
      std::error_code ec;
      if (!fs::is_directory(dir, ec)) {
        diags_.report(Rule::AssetMissing, at,
                      "sprite folder '" + dir + "' " + folder_problem(dir).value_or("does not exist; fix the path"),
                      pointer_of(key));
        continue;
      }
      AssetSet set;
      set.dir = display_path(dir);
      std::string bound;
      const std::vector<std::string> frames = scan_skin_frames(dir, &bound);
      if (!bound.empty()) {
        diags_.report(Rule::AssetUnreadable, at, "sprite folder " + bound, pointer_of(key));
        continue;
      }
      for (const std::string& frame : frames)
        if (auto f = hash_image(frame, at, key)) set.frames.push_back(*f);
      if (set.frames.empty()) {
        diags_.report(Rule::AssetEmpty, at, "sprite folder '" + dir + "' holds no PNG frames; add frames or remove it",
                      pointer_of(key));
        continue;
      }
      sets.push_back(std::move(set));
    }
  }

  const ComposedConfig& config_;
  const Schema& schema_;
  const ResolveOptions& options_;
  const SourceManager& sources_;
  Spec& spec_;
  DiagEngine& diags_;
};

}  // namespace

void resolve_assets(const ComposedConfig& config, const Schema& schema, const ResolveOptions& options,
                    const SourceManager& sources, Spec& spec, DiagEngine& diags) {
  AssetResolver(config, schema, options, sources, spec, diags).run();
}

}  // namespace kage
