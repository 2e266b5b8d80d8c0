// `extends` chains: loading, cycle detection and deep merging.
#include "compiler/parse/compose.h"

#include <algorithm>
#include <filesystem>
#include <unordered_map>

namespace kage {

namespace fs = std::filesystem;

std::string parent_dir(const std::string& path) { return fs::path(path).parent_path().string(); }

std::string join_path(const std::string& dir, const std::string& rel) {
  fs::path p(rel);
  if (p.is_absolute() || dir.empty()) return p.lexically_normal().string();
  return (fs::path(dir) / p).lexically_normal().string();
}

DocNode merge_documents(const DocNode& base, const DocNode& over) {
  if (!base.is_map() || !over.is_map()) return over;
  DocNode out = base;
  out.range = over.range;
  // Each key's first entry, as DocNode::find gives it, indexed: a file of many keys merges in linear time.
  std::unordered_map<std::string, size_t> first;
  for (size_t i = 0; i < out.entries.size(); ++i) first.emplace(out.entries[i].key, i);
  for (const DocEntry& e : over.entries) {
    const auto at = first.find(e.key);
    DocEntry* existing = at == first.end() ? nullptr : &out.entries[at->second];
    if (!existing) {
      first.emplace(e.key, out.entries.size());
      out.entries.push_back(e);
    } else if (existing->value.is_map() && e.value.is_map()) {
      existing->value = merge_documents(existing->value, e.value);
      existing->key_range = e.key_range;
    } else {
      *existing = e;
    }
  }
  return out;
}

namespace {

std::string identity_of(const std::string& path) {
  std::error_code ec;
  fs::path canon = fs::weakly_canonical(path, ec);
  return ec ? fs::path(path).lexically_normal().string() : canon.string();
}

class Composer {
 public:
  Composer(SourceManager& sources, FileReader& reader, DiagEngine& diags)
      : sources_(sources), reader_(reader), diags_(diags) {}

  std::optional<ComposedConfig> load(const std::string& path, const DiagNote* referrer) {
    auto file = read_mapping(path, referrer);
    if (!file) return std::nullopt;
    return compose(std::move(file->doc), file->id, parent_dir(path), identity_of(path));
  }

  // Follows the chain in a loop (a chain thousands of files long must not exhaust the stack), then
  // merges from the deepest base up.
  std::optional<ComposedConfig> compose(DocNode doc, FileId file, std::string dir, const std::string& id) {
    if (!as_mapping(doc, file)) return std::nullopt;
    ComposedConfig out;
    out.file = file;
    std::vector<DocNode> layers;        // nearest first, without `extends`
    std::vector<std::string> stack{id};  // identities of the chain so far
    while (true) {
      out.chain.push_back(file);
      const DocEntry* ext = doc.find(kExtendsKey);
      if (!ext) {
        layers.push_back(std::move(doc));
        break;
      }
      const Scalar target = scalar_value(ext->value);
      if (!std::holds_alternative<std::string>(target)) {
        diags_.report(Rule::SchemaType, ext->value.range,
                      std::string("'extends' must be a path to a base config, not ") +
                          (std::string(kind_name(ext->value)).find_first_of("aeiou") == 0 ? "an " : "a ") +
                          kind_name(ext->value),
                      "/extends");
        layers.push_back(strip_extends(std::move(doc)));
        break;
      }
      const std::string base_path = join_path(dir, std::get<std::string>(target));
      const std::string base_id = identity_of(base_path);
      if (std::find(stack.begin(), stack.end(), base_id) != stack.end()) {
        Diagnostic& d = diags_.report(Rule::ExtendsCycle, ext->value.range,
                                      "'extends' cycle: '" + base_path + "' is already being loaded; remove one link",
                                      "/extends");
        for (const std::string& s : stack) d.notes.push_back({Loc{}, "in the chain: " + s});
        layers.push_back(strip_extends(std::move(doc)));
        break;
      }
      if (stack.size() >= kMaxExtendsDepth) {
        diags_.report(Rule::ExtendsTooDeep, ext->value.range,
                      "'extends' chain is longer than " + std::to_string(kMaxExtendsDepth) + " files at '" +
                          base_path + "'; merge some of its bases",
                      "/extends");
        layers.push_back(strip_extends(std::move(doc)));
        break;
      }
      const DiagNote referrer{ext->value.range.begin, ""};
      auto base = read_mapping(base_path, &referrer);
      layers.push_back(strip_extends(std::move(doc)));
      if (!base) break;
      doc = std::move(base->doc);
      file = base->id;
      dir = parent_dir(base_path);
      stack.push_back(base_id);
    }
    out.root = std::move(layers.back());
    for (size_t i = layers.size() - 1; i-- > 0;) out.root = merge_documents(out.root, layers[i]);
    return out;
  }

 private:
  struct ParsedFile {
    DocNode doc;
    FileId id;
  };

  // Reads and parses one file of the chain; a failure is reported at the `extends` that named it.
  std::optional<ParsedFile> read_mapping(const std::string& path, const DiagNote* referrer) {
    std::string err;
    const auto text = reader_.read(path, &err);
    if (!text) {
      if (referrer) {
        diags_.report(Rule::ExtendsMissing, Range{referrer->loc, referrer->loc.offset + 1},
                      "cannot read base config '" + path + "': " + err + "; fix the path (it is relative to this file)",
                      "/extends");
      } else {
        diags_.report(Rule::FileUnreadable, Range{}, "cannot read '" + path + "': " + err);
      }
      return std::nullopt;
    }
    const FileId file = sources_.add(path, *text);
    auto doc = parse_yaml(sources_, file, diags_);
    if (!doc) return std::nullopt;
    if (referrer && !as_mapping(*doc, file)) return std::nullopt;
    return ParsedFile{std::move(*doc), file};
  }

  // An empty file is an empty mapping (spec 2.1); anything else that is not a mapping is reported.
  bool as_mapping(DocNode& doc, FileId file) {
    if (doc.is_null()) {
      doc.kind = DocNode::Kind::Mapping;
      doc.range = Range{Loc{file, 0}, 0};
    }
    if (doc.is_map()) return true;
    diags_.report(Rule::YamlNotMapping, doc.range,
                  std::string("a config must be a mapping of keys to values, not ") +
                      (std::string(kind_name(doc)).find_first_of("aeiou") == 0 ? "an " : "a ") + kind_name(doc));
    return false;
  }

  static DocNode strip_extends(DocNode doc) {
    std::erase_if(doc.entries, [](const DocEntry& e) { return e.key == kExtendsKey; });
    return doc;
  }

  SourceManager& sources_;
  FileReader& reader_;
  DiagEngine& diags_;
};

}  // namespace

std::optional<ComposedConfig> load_config(const std::string& path, SourceManager& sources, FileReader& reader,
                                          DiagEngine& diags) {
  return Composer(sources, reader, diags).load(path, nullptr);
}

std::optional<ComposedConfig> compose_document(DocNode doc, FileId file, const std::string& base_dir,
                                               SourceManager& sources, FileReader& reader, DiagEngine& diags) {
  return Composer(sources, reader, diags).compose(std::move(doc), file, base_dir, sources.name(file));
}

}  // namespace kage
