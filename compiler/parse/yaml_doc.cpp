// yaml-cpp nodes -> DocNode trees with byte ranges; PyYAML-compatible scalar typing.
#include "compiler/parse/yaml_doc.h"

#include "compiler/basic/utf8.h"

#include <yaml-cpp/eventhandler.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <map>
#include <regex>
#include <sstream>
#include <unordered_map>

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
const std::regex kBinRe("^[-+]?0b[0-1_]+$");
const std::regex kSexagesimalIntRe("^[-+]?[1-9][0-9_]*(:[0-5]?[0-9])+$");
const std::regex kFloatRe("^[-+]?([0-9][0-9_]*)?\\.[0-9_]*([eE][-+][0-9]+)?$");
const std::regex kSexagesimalFloatRe("^[-+]?[0-9][0-9_]*(:[0-5]?[0-9])+\\.[0-9_]*$");
const std::regex kInfRe("^[-+]?\\.(inf|Inf|INF)$");
const std::regex kNanRe("^\\.(nan|NaN|NAN)$");

std::string strip_underscores(const std::string& s) {
  std::string out;
  for (char c : s)
    if (c != '_') out += c;
  return out;
}

/// Unsigned digits in `base`, all of `s` and at least one; nullopt past uint64.
std::optional<uint64_t> digits_value(std::string_view s, int base) {
  uint64_t v = 0;
  if (s.empty()) return std::nullopt;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), v, base);
  if (ec != std::errc() || end != s.data() + s.size()) return std::nullopt;
  return v;
}

/// PyYAML's construct_yaml_int (YAML 1.1): '_' is ignored, 0b is binary, 0x hex, a leading 0 octal,
/// a:b:c base 60. Nullopt when `text` is no integer or lies outside int64.
std::optional<int64_t> construct_int(const std::string& text) {
  std::string v = strip_underscores(text);
  if (v.empty()) return std::nullopt;
  const bool negative = v[0] == '-';
  if (v[0] == '-' || v[0] == '+') v.erase(0, 1);
  std::optional<uint64_t> magnitude;
  if (v == "0") {
    magnitude = 0;
  } else if (v.rfind("0b", 0) == 0) {
    magnitude = digits_value(std::string_view(v).substr(2), 2);
  } else if (v.rfind("0x", 0) == 0) {
    magnitude = digits_value(std::string_view(v).substr(2), 16);
  } else if (!v.empty() && v[0] == '0') {
    const bool prefixed = v.size() > 1 && (v[1] == 'o' || v[1] == 'O');  // Python's int(v, 8) takes 0o too
    magnitude = digits_value(std::string_view(v).substr(prefixed ? 2 : 0), 8);
  } else if (v.find(':') != std::string::npos) {
    uint64_t total = 0;
    std::istringstream parts(v);
    std::string part;
    magnitude = 0;
    while (magnitude && std::getline(parts, part, ':')) {
      const std::optional<uint64_t> digit = digits_value(part, 10);
      if (!digit || total > (std::numeric_limits<uint64_t>::max() - *digit) / 60) {
        magnitude.reset();
        break;
      }
      total = total * 60 + *digit;
    }
    if (magnitude && v.back() == ':') magnitude.reset();
    if (magnitude) magnitude = total;
  } else {
    magnitude = digits_value(v, 10);
  }
  if (!magnitude) return std::nullopt;
  const uint64_t limit = uint64_t(std::numeric_limits<int64_t>::max()) + (negative ? 1 : 0);
  if (*magnitude > limit) return std::nullopt;
  return negative ? static_cast<int64_t>(0 - *magnitude) : static_cast<int64_t>(*magnitude);
}

/// Python's float() on one part of a YAML float: digits, a point and an exponent, or inf/nan words.
std::optional<double> python_float(const std::string& s) {
  if (s.empty() || s.find_first_of("xX(") != std::string::npos) return std::nullopt;
  char* end = nullptr;
  const double v = std::strtod(s.c_str(), &end);
  if (end != s.c_str() + s.size()) return std::nullopt;
  return v;
}

/// PyYAML's construct_yaml_float: '_' is ignored, .inf and .nan in any case, a:b:c.d base 60, else
/// Python's float(). Nullopt when `text` is no number.
std::optional<double> construct_float(const std::string& text) {
  std::string v = strip_underscores(text);
  for (char& c : v) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (v.empty()) return std::nullopt;
  const double sign = v[0] == '-' ? -1.0 : 1.0;
  if (v[0] == '-' || v[0] == '+') v.erase(0, 1);
  if (v == ".inf") return sign * std::numeric_limits<double>::infinity();
  if (v == ".nan") return std::numeric_limits<double>::quiet_NaN();
  if (v.find(':') == std::string::npos) {
    const std::optional<double> f = python_float(v);
    return f ? std::optional<double>(sign * *f) : std::nullopt;
  }
  double total = 0.0;
  std::istringstream parts(v);
  std::string part;
  while (std::getline(parts, part, ':')) {
    const std::optional<double> f = python_float(part);
    if (!f) return std::nullopt;
    total = total * 60.0 + *f;
  }
  if (v.back() == ':') return std::nullopt;
  return sign * total;
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
  if (std::regex_match(t, kIntRe) || std::regex_match(t, kHexRe) || std::regex_match(t, kOctRe) ||
      std::regex_match(t, kBinRe) || std::regex_match(t, kSexagesimalIntRe)) {
    if (const std::optional<int64_t> v = construct_int(t)) return *v;
    return t;  // out of int64 range: leave as text, the type check reports it
  }
  if (std::regex_match(t, kFloatRe) && t.find_first_of("0123456789") != std::string::npos)
    return std::strtod(strip_underscores(t).c_str(), nullptr);  // 1e400 is inf, as in PyYAML (stod would throw)
  if (std::regex_match(t, kSexagesimalFloatRe)) return construct_float(t).value_or(0.0);
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

// The tags PyYAML's safe loader knows (yaml.org's, "!!name" when written), by what kagec does with them.
enum class TagKind { None, Str, Null, Bool, Int, Float, Map, Seq, Merge, NoConfigValue, Unknown };

constexpr std::string_view kYamlTagPrefix = "tag:yaml.org,2002:";

TagKind classify_tag(const std::string& tag) {
  if (tag.empty() || tag == "?" || tag == "!") return TagKind::None;  // "!": quoted, or written as a bare '!'
  if (tag.rfind(kYamlTagPrefix, 0) != 0) return TagKind::Unknown;
  const std::string name = tag.substr(kYamlTagPrefix.size());
  static const std::map<std::string, TagKind> kKnown = {
      {"str", TagKind::Str},      {"null", TagKind::Null},   {"bool", TagKind::Bool},
      {"int", TagKind::Int},      {"float", TagKind::Float}, {"map", TagKind::Map},
      {"seq", TagKind::Seq},      {"merge", TagKind::Merge}, {"binary", TagKind::NoConfigValue},
      {"timestamp", TagKind::NoConfigValue}, {"set", TagKind::NoConfigValue}, {"omap", TagKind::NoConfigValue},
      {"pairs", TagKind::NoConfigValue}};
  const auto it = kKnown.find(name);
  return it == kKnown.end() ? TagKind::Unknown : it->second;
}

/// A tag as it is usually written: "!!int" for yaml.org's, else as yaml-cpp gives it.
std::string written_tag(const std::string& tag) {
  if (tag.rfind(kYamlTagPrefix, 0) == 0) return "!!" + tag.substr(kYamlTagPrefix.size());
  return tag;
}

/// `v` as plain text that the implicit float rule reads back to the same double.
std::string float_text(double v) {
  if (std::isnan(v)) return ".nan";
  if (std::isinf(v)) return v < 0 ? "-.inf" : ".inf";
  char buf[64];
  const auto [end, ec] = std::to_chars(buf, buf + sizeof buf, v);
  std::string out(buf, ec == std::errc() ? end : buf);
  if (out.find('.') == std::string::npos) {
    const size_t e = out.find('e');
    out.insert(e == std::string::npos ? out.size() : e, ".0");
  }
  return out;
}

std::string trimmed(const std::string& s) {
  const size_t b = s.find_first_not_of(" \t\r\n");
  if (b == std::string::npos) return "";
  return s.substr(b, s.find_last_not_of(" \t\r\n") - b + 1);
}

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
      case YAML::NodeType::Map:
        convert_map(n, begin, pointer, out);
        break;
    }
    apply_tag(n.Tag(), begin, pointer, out);
    return out;
  }

 private:
  // A mapping's entries; merge keys (`<<: *base`) are expanded as PyYAML's flatten_mapping does.
  void convert_map(const YAML::Node& n, uint32_t begin, const std::string& pointer, DocNode& out) {
    out.kind = DocNode::Kind::Mapping;
    std::map<std::string, Range> seen;
    std::vector<DocEntry> merged;  // the entries of the merged mappings, in PyYAML's order
    bool has_merge = false;
    uint32_t previous_end = begin;  // the end of the entry before, where the text up to the next key starts
    for (auto it = n.begin(); it != n.end(); ++it) {
      DocEntry e;
      const uint32_t mark = offset_of(it->first, begin);
      const uint32_t kb = it->first.IsNull() ? explicit_key_indicator(previous_end, mark) : mark;
      e.key = it->first.IsScalar() ? utf8_from_latin1_strays(it->first.Scalar()) : std::string("?");
      // Clamped: an empty explicit key (`?` alone) at the end of the file is a null node marked at its end.
      e.key_range = Range{Loc{file_, kb},
                          std::min(kb + static_cast<uint32_t>(e.key.size()), static_cast<uint32_t>(text_.size()))};
      const std::string key_tag = it->first.Tag();
      const TagKind key_kind = classify_tag(key_tag);
      if (key_kind == TagKind::Merge || (key_tag == "?" && it->first.IsScalar() && e.key == "<<")) {
        has_merge = true;
        add_merged(convert(it->second, e.key_range.end, pointer + "/<<"), e.key_range, merged);
        previous_end = e.key_range.end;
        continue;
      }
      if (key_kind != TagKind::None && key_kind != TagKind::Str)
        diags_.report(Rule::YamlTag, Range{Loc{file_, kb}, tag_end(kb)},
                      "key '" + e.key + "' has the tag '" + written_tag(key_tag) +
                          "'; a config key is a plain name: remove the tag",
                      pointer + "/" + e.key);
      e.value = convert(it->second, e.key_range.end, pointer + "/" + e.key);
      if (e.value.is_null()) e.value.range = Range{Loc{file_, e.key_range.begin.offset}, e.key_range.end};
      auto [prev, inserted] = seen.emplace(e.key, e.key_range);
      if (!inserted) {
        Diagnostic& d = diags_.report(Rule::YamlDuplicateKey, e.key_range,
                                      "duplicate key '" + e.key + "'; remove one of the two", pointer + "/" + e.key);
        d.notes.push_back({prev->second.begin, "first given here (the original would silently use the last one)"});
      }
      previous_end = std::max(e.key_range.end, e.value.range.end);
      out.entries.push_back(std::move(e));
    }
    out.range.end = out.entries.empty() ? begin + 1 : out.entries.back().value.range.end;
    if (!has_merge) return;
    // A merged key takes the value of the first mapping that gives it, and one written in this mapping
    // overrides them all; each key keeps the place of its first appearance (a Python dict's order).
    std::vector<DocEntry> entries;
    std::unordered_map<std::string, size_t> at;
    for (DocEntry& m : merged) {
      if (seen.count(m.key)) continue;
      const auto [it, fresh] = at.emplace(m.key, entries.size());
      if (fresh)
        entries.push_back(std::move(m));
      else
        entries[it->second] = std::move(m);
    }
    for (DocEntry& e : out.entries) entries.push_back(std::move(e));
    out.entries = std::move(entries);
  }

  // The value of one merge key: a mapping, or a list of mappings of which the first wins.
  void add_merged(DocNode value, Range key_range, std::vector<DocEntry>& merged) {
    std::vector<DocNode*> maps;
    if (value.is_map()) maps.push_back(&value);
    if (value.is_seq())
      for (DocNode& item : value.items) maps.push_back(item.is_map() ? &item : nullptr);
    if (maps.empty() || std::find(maps.begin(), maps.end(), nullptr) != maps.end()) {
      diags_.report(Rule::YamlNotMapping, value.range.begin.valid() ? value.range : key_range,
                    std::string("the value of the merge key '<<' must be a mapping or a list of mappings (such as "
                                "*base or [*a, *b]), not ") +
                        (value.is_seq() ? "a list holding other values" : kind_name(value)));
      return;
    }
    // PyYAML appends the mappings of a list last to first, so that the first one's values win.
    for (auto it = maps.rbegin(); it != maps.rend(); ++it)
      for (DocEntry& e : (*it)->entries) merged.push_back(std::move(e));
  }

  // A node's explicit tag, with the meaning PyYAML's safe loader gives it; a tag it refuses, or a
  // value its tag cannot construct, is an error (the node is then read as if untagged).
  void apply_tag(const std::string& tag, uint32_t begin, const std::string& pointer, DocNode& out) {
    const TagKind kind = classify_tag(tag);
    if (kind == TagKind::None) return;
    const std::string shown = written_tag(tag);
    auto refuse = [&](const std::string& why) {
      diags_.report(Rule::YamlTag, Range{Loc{file_, begin}, tag_end(begin)}, why, pointer);
    };
    const std::string kind_of = kind_name(out);
    const std::string node_kind =
        kind_of == "null" ? kind_of : (kind_of.find_first_of("aeiou") == 0 ? "an " : "a ") + kind_of;
    const bool scalar = out.is_scalar() || out.is_null();
    switch (kind) {
      case TagKind::None:
        return;
      case TagKind::Map:
        if (!out.is_map()) refuse("'" + shown + "' needs a mapping, not " + node_kind + "; remove the tag");
        return;
      case TagKind::Seq:
        if (!out.is_seq()) refuse("'" + shown + "' needs a list, not " + node_kind + "; remove the tag");
        return;
      case TagKind::Merge:
      case TagKind::Unknown:
        refuse("unknown tag '" + shown +
               "': the original's loader (PyYAML safe_load) refuses it (no constructor); remove the tag");
        return;
      case TagKind::NoConfigValue:
        refuse("'" + shown + "' makes a value that no config key takes (the original's loader reads it as a date, "
               "bytes, a set or pairs); remove the tag and write a plain value");
        return;
      default:
        break;
    }
    if (!scalar) {
      refuse("'" + shown + "' needs a single value, not " + node_kind + "; remove the tag");
      return;
    }
    const std::string text = trimmed(out.text);
    std::optional<std::string> plain;  // the value as untagged text with the same meaning
    switch (kind) {
      case TagKind::Str:
        out.kind = DocNode::Kind::Scalar;  // quoted already; an empty !!str is the empty string
        out.quoted = true;
        return;
      case TagKind::Null:
        out.kind = DocNode::Kind::Null;  // PyYAML's !!null is None whatever follows it
        out.text.clear();
        out.quoted = false;
        return;
      case TagKind::Bool: {
        std::string lower = text;
        for (char& c : lower) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
        if (lower == "yes" || lower == "true" || lower == "on") plain = "true";
        if (lower == "no" || lower == "false" || lower == "off") plain = "false";
        break;
      }
      case TagKind::Int:
        if (const std::optional<int64_t> v = construct_int(text)) plain = std::to_string(*v);
        break;
      case TagKind::Float:
        if (const std::optional<double> v = construct_float(text)) plain = float_text(*v);
        break;
      default:
        break;
    }
    if (!plain) {
      const char* want = kind == TagKind::Bool  ? "true, false, yes, no, on or off"
                         : kind == TagKind::Int ? "an integer (within 64 bits)"
                                                : "a number";
      refuse("'" + shown + " " + out.text + "' is not " + want +
             " (the original's loader fails on it); fix the value or remove the tag");
      return;
    }
    out.kind = DocNode::Kind::Scalar;
    out.text = *plain;
    out.quoted = false;
  }

  // An empty explicit key (`?` alone) is a null node that yaml-cpp marks at the next token: the `?` written
  // between `from` (the end of the entry before) and that mark, outside comments; else the mark.
  uint32_t explicit_key_indicator(uint32_t from, uint32_t mark) const {
    const auto space = [this](size_t i) { return i >= text_.size() || std::isspace(static_cast<unsigned char>(text_[i])); };
    bool comment = false;
    for (uint32_t i = from; i < mark && i < text_.size(); ++i) {
      if (text_[i] == '\n')
        comment = false;
      else if (!comment && text_[i] == '#' && (i == 0 || space(i - 1)))
        comment = true;
      else if (!comment && text_[i] == '?' && space(i + 1))
        return i;
    }
    return mark;
  }

  uint32_t offset_of(const YAML::Node& n, uint32_t fallback) const {
    const int pos = n.Mark().pos;
    if (pos < 0 || static_cast<size_t>(pos) > text_.size()) return fallback;
    return static_cast<uint32_t>(pos);
  }
  // The end of a tag written at `begin` (a node's mark is its tag's when it has one).
  uint32_t tag_end(uint32_t begin) const {
    uint32_t end = begin;
    while (end < text_.size() && text_[end] != ' ' && text_[end] != '\t' && text_[end] != '\n' && text_[end] != '\r')
      ++end;
    return std::max(end, std::min<uint32_t>(begin + 1, static_cast<uint32_t>(text_.size())));
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

/// The offset and length of the first character YAML forbids in a stream (PyYAML's NON_PRINTABLE: C0
/// controls but tab, LF and CR, DEL, C1 controls but NEL, U+FFFE and U+FFFF); `text` is valid UTF-8.
/// yaml-cpp does not refuse them: a NUL even makes it read the file as UTF-16.
std::optional<std::pair<size_t, size_t>> forbidden_character(const std::string& text) {
  for (size_t i = 0; i < text.size(); ++i) {
    const auto c = static_cast<unsigned char>(text[i]);
    if ((c < 0x20 && c != '\t' && c != '\n' && c != '\r') || c == 0x7f) return std::make_pair(i, size_t(1));
    if (c == 0xc2 && i + 1 < text.size()) {
      const auto d = static_cast<unsigned char>(text[i + 1]);
      if (d >= 0x80 && d <= 0x9f && d != 0x85) return std::make_pair(i, size_t(2));
    }
    if (c == 0xef && i + 2 < text.size() && static_cast<unsigned char>(text[i + 1]) == 0xbf &&
        (static_cast<unsigned char>(text[i + 2]) & 0xfe) == 0xbe)
      return std::make_pair(i, size_t(3));
  }
  return std::nullopt;
}

/// How a forbidden character is named in a message: \0 (NUL), \x01, U+0086.
std::string character_name(const std::string& text, size_t at, size_t size) {
  static const char kHex[] = "0123456789abcdef";
  const auto c = static_cast<unsigned char>(text[at]);
  if (c == 0) return "\\0 (NUL)";
  if (size == 1) return std::string("\\x") + kHex[c >> 4] + kHex[c & 15];
  const auto d = static_cast<unsigned char>(text[at + 1]);
  if (size == 2) return std::string("U+00") + kHex[(0x80 | (d & 0x3f)) >> 4] + kHex[d & 15];
  return (static_cast<unsigned char>(text[at + 2]) & 1) ? "U+FFFF" : "U+FFFE";
}

// Counts documents without building nodes; stops at the start of the second.
class DocumentCounter final : public YAML::EventHandler {
 public:
  struct SecondDocument {
    YAML::Mark mark;
  };
  void OnDocumentStart(const YAML::Mark& mark) override {
    if (++documents_ == 2) throw SecondDocument{mark};
  }
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark&, YAML::anchor_t) override {}
  void OnAlias(const YAML::Mark&, YAML::anchor_t) override {}
  void OnScalar(const YAML::Mark&, const std::string&, YAML::anchor_t, const std::string&) override {}
  void OnSequenceStart(const YAML::Mark&, const std::string&, YAML::anchor_t, YAML::EmitterStyle::value) override {}
  void OnSequenceEnd() override {}
  void OnMapStart(const YAML::Mark&, const std::string&, YAML::anchor_t, YAML::EmitterStyle::value) override {}
  void OnMapEnd() override {}

 private:
  int documents_ = 0;
};

/// Reports a second document, or text after the first that is not YAML. yaml-cpp's Load reads the
/// first document and ignores the rest; the original's loader (PyYAML safe_load) refuses both.
bool single_document(const std::string& text, FileId file, DiagEngine& diags) {
  // A second document starts after a '---' or '...' line; without either the first runs to the end.
  if (text.find("---") == std::string::npos && text.find("...") == std::string::npos) return true;
  auto at = [&](int pos) {
    const uint32_t off = std::min<uint32_t>(pos >= 0 ? static_cast<uint32_t>(pos) : 0, static_cast<uint32_t>(text.size()));
    return Range{Loc{file, off}, std::min<uint32_t>(off + 3, static_cast<uint32_t>(text.size()))};
  };
  std::istringstream in(text);
  DocumentCounter counter;
  try {
    YAML::Parser parser(in);
    while (parser.HandleNextDocument(counter)) {
    }
  } catch (const DocumentCounter::SecondDocument& second) {
    diags.report(Rule::YamlMultipleDocuments, at(second.mark.pos),
                 "a second YAML document starts here; the original's loader (PyYAML safe_load) refuses a file of "
                 "several documents, and only the first would be read: merge them into one mapping or split "
                 "them into separate files");
    return false;
  } catch (const YAML::Exception& e) {
    diags.report(Rule::YamlSyntax, at(e.mark.pos), "invalid YAML after the first document: " + e.msg);
    return false;
  }
  return true;
}

/// Reports each rule id of the file's disable comments that names no rule: such a comment silences nothing.
void check_disable_comments(const std::string& text, FileId file, DiagEngine& diags) {
  for (const DisabledRule& d : find_disabled_rules(text)) {
    const std::string id(d.rule);
    if (find_rule(id)) continue;
    diags.report(Rule::DisableUnknownRule, Range{Loc{file, d.offset}, d.offset + static_cast<uint32_t>(id.size())},
                 (id.empty() ? std::string("an empty rule id") : "'" + id + "' is no rule") +
                     ", so this comment silences nothing: name rules as `kagec rules` lists them, separated by "
                     "commas without spaces");
  }
}

}  // namespace

std::optional<DocNode> parse_yaml(const SourceManager& sources, FileId file, DiagEngine& diags) {
  const std::string& text = sources.text(file);
  // PyYAML rejects bytes that are not UTF-8; so does the original (and JSON output could not hold them).
  if (const auto bad = invalid_utf8_offset(text)) {
    const uint32_t off = static_cast<uint32_t>(*bad);
    diags.report(Rule::YamlSyntax, Range{Loc{file, off}, off + 1}, "invalid YAML: the file is not valid UTF-8");
    return std::nullopt;
  }
  if (const auto bad = forbidden_character(text)) {
    const uint32_t off = static_cast<uint32_t>(bad->first);
    diags.report(Rule::YamlSyntax, Range{Loc{file, off}, off + static_cast<uint32_t>(bad->second)},
                 "the file holds the control character " + character_name(text, bad->first, bad->second) +
                     ", which YAML does not allow (the original's loader refuses the file); remove it, or write it as "
                     "an escape inside double quotes (\"\\0\", \"\\x01\")");
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
  if (!single_document(text, file, diags)) return std::nullopt;
  check_disable_comments(text, file, diags);
  Converter conv(sources, file, diags);
  DocNode doc = conv.convert(root, 0, "");
  return doc;
}

}  // namespace kage
