// `extends` chains: loading, cycle detection and deep merging.
#include "compiler/compose.h"

#include <filesystem>

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
  for (const DocEntry& e : over.entries) {
    DocEntry* existing = out.find(e.key);
    if (!existing) {
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
    std::string err;
    const auto text = reader_.read(path, &err);
    if (!text) {
      if (referrer) {
        Diagnostic& d = diags_.report(Rule::ExtendsMissing, Range{referrer->loc, referrer->loc.offset + 1},
                                      "cannot read base config '" + path + "': " + err +
                                          "; fix the path (it is relative to this file)",
                                      "/extends");
        (void)d;
      } else {
        diags_.report(Rule::FileUnreadable, Range{}, "cannot read '" + path + "': " + err);
      }
      return std::nullopt;
    }
    const FileId file = sources_.add(path, *text);
    auto doc = parse_yaml(sources_, file, diags_);
    if (!doc) return std::nullopt;
    return compose(std::move(*doc), file, parent_dir(path), identity_of(path));
  }

  std::optional<ComposedConfig> compose(DocNode doc, FileId file, const std::string& dir, const std::string& id) {
    if (doc.is_null()) {
      doc.kind = DocNode::Kind::Mapping;  // an empty file is an empty mapping (spec 2.1)
      doc.range = Range{Loc{file, 0}, 0};
    }
    if (!doc.is_map()) {
      diags_.report(Rule::YamlNotMapping, doc.range,
                    std::string("a config must be a mapping of keys to values, not ") +
                        (std::string(kind_name(doc)).find_first_of("aeiou") == 0 ? "an " : "a ") + kind_name(doc));
      return std::nullopt;
    }
    ComposedConfig out;
    out.file = file;
    out.chain.push_back(file);
    const DocEntry* ext = doc.find(kExtendsKey);
    if (!ext) {
      out.root = std::move(doc);
      return out;
    }
    const Scalar target = scalar_value(ext->value);
    if (!std::holds_alternative<std::string>(target)) {
      diags_.report(Rule::SchemaType, ext->value.range,
                    std::string("'extends' must be a path to a base config, not ") +
                        (std::string(kind_name(ext->value)).find_first_of("aeiou") == 0 ? "an " : "a ") +
                        kind_name(ext->value),
                    "/extends");
      out.root = strip_extends(std::move(doc));
      return out;
    }
    const std::string base_path = join_path(dir, std::get<std::string>(target));
    const std::string base_id = identity_of(base_path);
    stack_.push_back(id);
    for (const std::string& seen : stack_) {
      if (seen == base_id) {
        Diagnostic& d = diags_.report(Rule::ExtendsCycle, ext->value.range,
                                      "'extends' cycle: '" + base_path + "' is already being loaded; remove one link",
                                      "/extends");
        for (const std::string& s : stack_) d.notes.push_back({Loc{}, "in the chain: " + s});
        stack_.pop_back();
        out.root = strip_extends(std::move(doc));
        return out;
      }
    }
    DiagNote referrer{ext->value.range.begin, ""};
    auto base = load(base_path, &referrer);
    stack_.pop_back();
    DocNode own = strip_extends(std::move(doc));
    if (!base) {
      out.root = std::move(own);
      return out;
    }
    out.root = merge_documents(base->root, own);
    out.chain.insert(out.chain.end(), base->chain.begin(), base->chain.end());
    return out;
  }

 private:
  static DocNode strip_extends(DocNode doc) {
    std::erase_if(doc.entries, [](const DocEntry& e) { return e.key == kExtendsKey; });
    return doc;
  }

  SourceManager& sources_;
  FileReader& reader_;
  DiagEngine& diags_;
  std::vector<std::string> stack_;
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
