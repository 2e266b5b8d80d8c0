// yaml-cpp nodes -> DocNode trees with byte ranges; PyYAML-compatible scalar typing.
#include "compiler/parse/yaml_doc.h"

#include "compiler/basic/utf8.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <map>
#include <regex>

namespace kage {

const DocEntry* DocNode::find(const std::string& key) const {
  for (const DocEntry& e : entries)
    if (e.key == key) return &e;
  return nullptr;
}

DocEntry* DocNode::find(const std::string& key) {
  for (DocEntry& e : entries)
    if (e.key == key) return &e;
  return nullptr;
}

namespace {

// PyYAML's implicit resolvers (YAML 1.1), restricted to the types configs use.
const std::regex kBoolRe("^(yes|Yes|YES|no|No|NO|true|True|TRUE|false|False|FALSE|on|On|ON|off|Off|OFF)$");
const std::regex kNullRe("^(~|null|Null|NULL|)$");
const std::regex kIntRe("^[-+]?(0|[1-9][0-9_]*)$");
const std::regex kHexRe("^[-+]?0x[0-9a-fA-F_]+$");
const std::regex kOctRe("^[-+]?0[0-7_]+$");
const std::regex kFloatRe("^[-+]?([0-9][0-9_]*)?\\.[0-9_]*([eE][-+][0-9]+)?$");
const std::regex kInfRe("^[-+]?\\.(inf|Inf|INF)$");
const std::regex kNanRe("^\\.(nan|NaN|NAN)$");

std::string strip_underscores(const std::string& s) {
  std::string out;
  for (char c : s)
    if (c != '_') out += c;
  return out;
}

}  // namespace

Scalar scalar_value(const DocNode& node) {
  if (node.kind != DocNode::Kind::Scalar) return std::monostate{};
  const std::string& t = node.text;
  if (node.quoted) return t;
  if (std::regex_match(t, kNullRe)) return std::monostate{};
  if (std::regex_match(t, kBoolRe)) {
    const char c = static_cast<char>(std::tolower(static_cast<unsigned char>(t[0])));
    return c == 'y' || c == 't' || (c == 'o' && (t[1] == 'n' || t[1] == 'N'));
  }
  try {
    if (std::regex_match(t, kIntRe)) return static_cast<int64_t>(std::stoll(strip_underscores(t)));
    if (std::regex_match(t, kHexRe)) return static_cast<int64_t>(std::stoll(strip_underscores(t), nullptr, 16));
    if (std::regex_match(t, kOctRe)) return static_cast<int64_t>(std::stoll(strip_underscores(t), nullptr, 8));
  } catch (const std::exception&) {
    return t;  // out of int64 range: leave as text, the type check reports it
  }
  if (std::regex_match(t, kFloatRe) && t.find_first_of("0123456789") != std::string::npos)
    return std::strtod(strip_underscores(t).c_str(), nullptr);  // 1e400 is inf, as in PyYAML (stod would throw)
  if (std::regex_match(t, kInfRe))
    return t[0] == '-' ? -std::numeric_limits<double>::infinity() : std::numeric_limits<double>::infinity();
  if (std::regex_match(t, kNanRe)) return std::numeric_limits<double>::quiet_NaN();
  return t;
}

const char* kind_name(const DocNode& node) {
  switch (node.kind) {
    case DocNode::Kind::Null: return "null";
    case DocNode::Kind::Sequence: return "list";
    case DocNode::Kind::Mapping: return "mapping";
    case DocNode::Kind::Scalar: break;
  }
  const Scalar v = scalar_value(node);
  if (std::holds_alternative<bool>(v)) return "boolean";
  if (std::holds_alternative<int64_t>(v)) return "integer";
  if (std::holds_alternative<double>(v)) return "number";
  if (std::holds_alternative<std::monostate>(v)) return "null";
  return "string";
}

namespace {

class Converter {
 public:
  Converter(const SourceManager& sm, FileId file, DiagEngine& diags)
      : sm_(sm), file_(file), diags_(diags), text_(sm.text(file)) {}

  // `pointer` is the JSON Pointer of `n` (for diagnostics).
  DocNode convert(const YAML::Node& n, uint32_t fallback_offset, const std::string& pointer) {
    DocNode out;
    const uint32_t begin = offset_of(n, fallback_offset);
    out.range = Range{Loc{file_, begin}, begin};
    // Aliases share nodes; expanded, a few lines can name billions of them. Stop at a budget.
    if (budget_ == 0) return out;
    if (--budget_ == 0) {
      diags_.report(Rule::YamlSyntax, Range{Loc{file_, begin}, begin},
                    "the document expands to more than " + std::to_string(kNodeBudget) +
                        " nodes (through aliases?); a config is far smaller");
      return out;
    }
    switch (n.Type()) {
      case YAML::NodeType::Undefined:
      case YAML::NodeType::Null:
        out.kind = DocNode::Kind::Null;
        break;
      case YAML::NodeType::Scalar:
        out.kind = DocNode::Kind::Scalar;
        out.text = utf8_from_latin1_strays(n.Scalar());
        out.quoted = n.Tag() == "!" || n.Tag() == "tag:yaml.org,2002:str";
        out.range.end = scalar_end(begin, out.text, out.quoted);
        break;
      case YAML::NodeType::Sequence:
        out.kind = DocNode::Kind::Sequence;
        for (const YAML::Node& item : n)
          out.items.push_back(convert(item, begin, pointer + "/" + std::to_string(out.items.size())));
        out.range.end = out.items.empty() ? begin + 1 : out.items.back().range.end;
        break;
      case YAML::NodeType::Map: {
        out.kind = DocNode::Kind::Mapping;
        std::map<std::string, Range> seen;
        for (auto it = n.begin(); it != n.end(); ++it) {
          DocEntry e;
          const uint32_t kb = offset_of(it->first, begin);
          e.key = it->first.IsScalar() ? utf8_from_latin1_strays(it->first.Scalar()) : std::string("?");
          e.key_range = Range{Loc{file_, kb}, kb + static_cast<uint32_t>(e.key.size())};
          e.value = convert(it->second, e.key_range.end, pointer + "/" + e.key);
          if (e.value.is_null()) e.value.range = Range{Loc{file_, e.key_range.begin.offset}, e.key_range.end};
          auto [prev, inserted] = seen.emplace(e.key, e.key_range);
          if (!inserted) {
            Diagnostic& d = diags_.report(Rule::YamlDuplicateKey, e.key_range,
                                          "duplicate key '" + e.key + "'; remove one of the two", pointer + "/" + e.key);
            d.notes.push_back({prev->second.begin, "first given here (the original would silently use the last one)"});
          }
          out.entries.push_back(std::move(e));
        }
        out.range.end = out.entries.empty() ? begin + 1 : out.entries.back().value.range.end;
        break;
      }
    }
    return out;
  }

 private:
  uint32_t offset_of(const YAML::Node& n, uint32_t fallback) const {
    const int pos = n.Mark().pos;
    if (pos < 0 || static_cast<size_t>(pos) > text_.size()) return fallback;
    return static_cast<uint32_t>(pos);
  }
  // The end of a scalar as written; quoted scalars include their quotes.
  uint32_t scalar_end(uint32_t begin, const std::string& value, bool quoted) const {
    uint32_t end = begin;
    if (quoted && end < text_.size() && (text_[end] == '"' || text_[end] == '\'')) {
      const char q = text_[end++];
      while (end < text_.size() && text_[end] != q && text_[end] != '\n') ++end;
      return std::min<uint32_t>(end + 1, static_cast<uint32_t>(text_.size()));
    }
    end = begin + static_cast<uint32_t>(value.size());
    return std::min<uint32_t>(end, static_cast<uint32_t>(text_.size()));
  }

  static constexpr size_t kNodeBudget = 1000000;
  size_t budget_ = kNodeBudget;
  const SourceManager& sm_;
  FileId file_;
  DiagEngine& diags_;
  const std::string& text_;
};

}  // namespace

std::optional<DocNode> parse_yaml(const SourceManager& sources, FileId file, DiagEngine& diags) {
  const std::string& text = sources.text(file);
  // PyYAML rejects bytes that are not UTF-8; so does the original (and JSON output could not hold them).
  if (const auto bad = invalid_utf8_offset(text)) {
    const uint32_t off = static_cast<uint32_t>(*bad);
    diags.report(Rule::YamlSyntax, Range{Loc{file, off}, off + 1}, "invalid YAML: the file is not valid UTF-8");
    return std::nullopt;
  }
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    uint32_t off = e.mark.pos >= 0 ? static_cast<uint32_t>(e.mark.pos) : 0;
    off = std::min<uint32_t>(off, static_cast<uint32_t>(text.size()));
    const uint32_t end = std::min<uint32_t>(off + 1, static_cast<uint32_t>(text.size()));
    diags.report(Rule::YamlSyntax, Range{Loc{file, off}, end}, "invalid YAML: " + e.msg);
    return std::nullopt;
  }
  Converter conv(sources, file, diags);
  DocNode doc = conv.convert(root, 0, "");
  return doc;
}

}  // namespace kage
