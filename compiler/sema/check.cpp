// Schema check of a composed config.
#include "compiler/sema/check.h"

#include <cmath>
#include <sstream>

#include "compiler/basic/spell.h"
#include "compiler/basic/utf8.h"

namespace kage {

namespace {

std::string format_number(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

// "an integer", "a list".
std::string with_article(const std::string& noun) {
  return (noun.find_first_of("aeiou") == 0 ? "an " : "a ") + noun;
}

std::string quoted_list(const std::vector<std::string>& names) {
  std::string out;
  for (size_t i = 0; i < names.size(); ++i) out += (i ? ", " : "") + names[i];
  return out;
}

std::string describe_types(const std::set<std::string>& types) {
  std::vector<std::string> words;
  for (const std::string& t : types) {
    if (t == "null") continue;
    words.push_back(t == "array" ? "a list" : t == "integer" ? "an integer" : "a " + t);
  }
  std::string out;
  for (size_t i = 0; i < words.size(); ++i) out += (i ? (i + 1 == words.size() ? " or " : ", ") : "") + words[i];
  if (types.count("null")) out += words.empty() ? "null" : " (or null)";
  return out;
}

// Reports a name not in its table, with a did-you-mean fix-it; false if reported.
bool check_name(const KeySchema& key, const NameTable& table, const DocNode& node, const std::string& name,
                DiagEngine& diags) {
  for (const std::string& n : table.names)
    if (n == name) return true;
  const auto guess = suggest(name, table.names);
  std::string msg = "unknown " + table.title + " '" + name + "' for '" + key.path + "'";
  msg += guess ? "; did you mean '" + *guess + "'?" : "; valid names: " + quoted_list(table.names);
  Diagnostic& d = diags.report(Rule::SchemaUnknownName, node.range, msg, key.pointer);
  if (guess) d.fixits.push_back({node.range, *guess});
  return false;
}

// One scalar against a value rule; returns false if it was reported.
bool check_scalar(const KeySchema& key, const ValueRule& rule, const DocNode& node, DiagEngine& diags,
                  const char* what_prefix) {
  const std::string what = *what_prefix ? std::string(what_prefix) + " " : std::string();
  const Scalar v = scalar_value(node);
  const bool is_null = node.is_null() || std::holds_alternative<std::monostate>(v);
  auto type_error = [&](const std::string& extra) {
    std::string got = kind_name(node);
    if (node.is_scalar() && !is_null) got += " '" + node.text + "'";
    diags.report(Rule::SchemaType, node.range,
                 what + "'" + key.path + "' must be " + describe_types(rule.types) + ", not " + got +
                     extra,
                 key.pointer);
    return false;
  };
  if (is_null) return rule.types.count("null") ? true : type_error("; give a value or remove the key");
  if (!node.is_scalar()) return type_error("");
  if (std::holds_alternative<bool>(v)) return rule.types.count("boolean") ? true : type_error("");
  if (std::holds_alternative<std::string>(v)) {
    if (!rule.types.count("string")) {
      const std::string hint = node.quoted ? "; remove the quotes" : "";
      return type_error(hint);
    }
    if (rule.names) check_name(key, *rule.names, node, std::get<std::string>(v), diags);
    return true;
  }
  const bool is_int = std::holds_alternative<int64_t>(v);
  const double x = is_int ? static_cast<double>(std::get<int64_t>(v)) : std::get<double>(v);
  if (!rule.types.count("number") && !(is_int && rule.types.count("integer"))) {
    if (!is_int && rule.types.count("integer") && std::isfinite(x) && x == std::floor(x))
      return type_error("; write it without a decimal point: " + format_number(x));
    return type_error("");
  }
  if (!std::isfinite(x)) {
    diags.report(Rule::SchemaNonFinite, node.range,
                 what + "'" + key.path + "' must be a finite number, not " + node.text, key.pointer);
    return false;
  }
  auto range_error = [&](const std::string& bound) {
    diags.report(Rule::SchemaRange, node.range,
                 what + "'" + key.path + "' must be " + bound + " (got " + node.text + ")", key.pointer);
    return false;
  };
  if (rule.minimum && x < *rule.minimum) return range_error(">= " + format_number(*rule.minimum));
  if (rule.maximum && x > *rule.maximum) return range_error("<= " + format_number(*rule.maximum));
  if (rule.exclusive_minimum && x <= *rule.exclusive_minimum)
    return range_error("> " + format_number(*rule.exclusive_minimum));
  if ((key.recommended_min && x < *key.recommended_min) || (key.recommended_max && x > *key.recommended_max)) {
    std::string range = "[" + (key.recommended_min ? format_number(*key.recommended_min) : "-inf") + ", " +
                        (key.recommended_max ? format_number(*key.recommended_max) : "inf") + "]";
    diags.report(Rule::RangeRecommended, node.range,
                 "'" + key.path + "' = " + node.text + " is outside the documented range " + range +
                     "; it is accepted, but the original was designed for that range",
                 key.pointer);
  }
  return true;
}

}  // namespace

void check_value(const KeySchema& key, const DocNode& value, DiagEngine& diags) {
  if (value.is_map()) {
    diags.report(Rule::SchemaType, value.range,
                 "'" + key.path + "' must be " + describe_types(key.value.types) + ", not a mapping", key.pointer);
    return;
  }
  if (value.is_seq()) {
    if (!key.value.types.count("array") || !key.items) {
      diags.report(Rule::SchemaType, value.range,
                   "'" + key.path + "' must be " + describe_types(key.value.types) + ", not a list", key.pointer);
      return;
    }
    if (key.min_items && value.items.size() < *key.min_items) {
      diags.report(Rule::SchemaEmptyList, value.range,
                   "'" + key.path + "' needs at least " + std::to_string(*key.min_items) +
                       " entr" + (*key.min_items == 1 ? "y" : "ies") + "; the environment indexes into this list",
                   key.pointer);
    }
    if (key.max_items && value.items.size() > *key.max_items) {
      diags.report(Rule::SchemaType, value.range,
                   "'" + key.path + "' takes at most " + std::to_string(*key.max_items) + " entries (got " +
                       std::to_string(value.items.size()) + ")",
                   key.pointer);
    }
    for (const DocNode& item : value.items) check_scalar(key, *key.items, item, diags, "each entry of");
    return;
  }
  const Scalar v = scalar_value(value);
  if (std::holds_alternative<std::string>(v) && key.string_is_characters) {
    diags.report(Rule::QuirkStringAsCharacters, value.range,
                 "'" + key.path + "' is a string, which the original reads as a list of its characters; write a list: [" +
                     value.text + "]",
                 key.pointer);
    // Each character is then an entry; the first one that is not a name is what the original trips over.
    if (key.items && key.items->names)
      for (const std::string& ch : utf8_characters(std::get<std::string>(v)))
        if (!check_name(key, *key.items->names, value, ch, diags)) break;
    return;
  }
  if (std::holds_alternative<std::string>(v) && key.string_as_list && key.items) {
    check_scalar(key, *key.items, value, diags, "each entry of");
    return;
  }
  check_scalar(key, key.value, value, diags, "");
}

namespace {

std::vector<std::string> root_candidates(const Schema& schema) {
  std::vector<std::string> out;
  for (const SectionSchema& s : schema.sections())
    if (!s.name.empty()) out.push_back(s.name);
  for (size_t i : schema.sections()[0].keys) out.push_back(schema.keys()[i].name);
  for (const std::string& m : schema.meta_keys()) out.push_back(m);
  return out;
}

void report_unknown(const DocEntry& e, const std::string& section, const std::vector<std::string>& candidates,
                    const Schema& schema, DiagEngine& diags) {
  const std::string where = section.empty() ? "at the top level" : "in '" + section + "'";
  std::string msg = "unknown key '" + e.key + "' " + where;
  const auto guess = suggest(e.key, candidates);
  std::vector<std::string> homes = schema.sections_with_key(e.key);
  std::erase(homes, section);
  if (section.empty() && schema.find(e.key) == nullptr && homes.empty() && schema.section(e.key) == nullptr) {
    // keep homes empty
  } else if (!section.empty() && schema.find(e.key) && schema.find(e.key)->section.empty()) {
    homes.push_back("the top level");
  }
  if (guess) {
    msg += "; did you mean '" + *guess + "'?";
  } else if (!homes.empty()) {
    msg += "; it belongs under '" + homes.front() + "'";
  } else {
    msg += "; the original would silently ignore it";
  }
  Diagnostic& d = diags.report(Rule::SchemaUnknownKey, e.key_range, msg, (section.empty() ? "" : "/" + section) + "/" + e.key);
  if (guess) d.fixits.push_back({e.key_range, *guess});
}

bool provided(const DocNode& v, bool empty_counts) {
  return !v.is_null() && (empty_counts || !(v.is_seq() && v.items.empty()));
}

void check_section_rules(const SectionSchema& sec, const DocNode& body, const Schema& schema, DiagEngine& diags) {
  const std::string prefix = sec.name.empty() ? "" : sec.name + ".";
  for (const auto& group : sec.exclusive) {
    std::vector<const DocEntry*> given;
    for (const std::string& k : group)
      if (const DocEntry* e = body.find(k); e && provided(e->value, sec.exclusive_counts_empty)) given.push_back(e);
    if (given.size() < 2) continue;
    Diagnostic& d = diags.report(Rule::SchemaConflict, given[1]->key_range,
                                 "'" + prefix + given[1]->key + "' conflicts with '" + prefix + given[0]->key +
                                     "': give only one of " + quoted_list(group),
                                 "/" + sec.name + "/" + given[1]->key);
    d.notes.push_back({given[0]->key_range.begin, "'" + given[0]->key + "' is given here"});
  }
  for (const auto& [lo_key, hi_key] : sec.ordered) {
    const DocEntry* lo = body.find(lo_key);
    const DocEntry* hi = body.find(hi_key);
    if (!lo && !hi) continue;
    auto number = [&](const DocEntry* e, const std::string& k) -> std::optional<double> {
      if (e) {
        const Scalar v = scalar_value(e->value);
        if (std::holds_alternative<int64_t>(v)) return static_cast<double>(std::get<int64_t>(v));
        if (std::holds_alternative<double>(v)) return std::get<double>(v);
        return std::nullopt;
      }
      const KeySchema* ks = schema.find(prefix + k);
      if (ks && ks->default_value.is_number()) return ks->default_value.get<double>();
      return std::nullopt;
    };
    const auto a = number(lo, lo_key), b = number(hi, hi_key);
    if (!a || !b || *a <= *b) continue;
    const DocEntry* at = hi ? hi : lo;
    std::string msg = "'" + prefix + lo_key + "' (" + format_number(*a) + ") is larger than '" + prefix + hi_key +
                      "' (" + format_number(*b) + ")";
    if (!lo || !hi) msg += std::string("; the absent one takes its default, so set ") + (hi ? lo_key : hi_key) + " too";
    Diagnostic& d = diags.report(Rule::SchemaMinMax, at->value.range, msg, "/" + sec.name + "/" + at->key);
    if (lo && hi) d.notes.push_back({lo->value.range.begin, "the minimum is given here"});
  }
  for (const auto& [a_key, b_key] : sec.one_true) {
    const DocEntry* a = body.find(a_key);
    const DocEntry* b = body.find(b_key);
    if (!a || !b) continue;
    const Scalar av = scalar_value(a->value), bv = scalar_value(b->value);
    if (!std::holds_alternative<bool>(av) || !std::holds_alternative<bool>(bv)) continue;
    if (std::get<bool>(av) != std::get<bool>(bv)) continue;
    Diagnostic& d = diags.report(Rule::SchemaShapeOrSprites, b->value.range,
                                 "'" + prefix + a_key + "' and '" + prefix + b_key +
                                     "' are both given, so exactly one of them must be true; set one to false",
                                 "/" + sec.name + "/" + b_key);
    d.notes.push_back({a->value.range.begin, "'" + a_key + "' is given here"});
  }
  for (size_t i : sec.keys) {
    const KeySchema& k = schema.keys()[i];
    if (k.alias_of.empty()) continue;
    const DocEntry* legacy = body.find(k.name);
    const DocEntry* modern = body.find(k.alias_of);
    if (legacy && modern) {
      Diagnostic& d = diags.report(Rule::SchemaAliasShadowed, legacy->key_range,
                                   "legacy key '" + k.path + "' is ignored because '" + prefix + k.alias_of +
                                       "' is also given; remove one",
                                   k.pointer);
      d.notes.push_back({modern->key_range.begin, "'" + k.alias_of + "' is given here"});
    }
  }
}

}  // namespace

bool check_config(const ComposedConfig& config, const Schema& schema, DiagEngine& diags) {
  const size_t errors_before = diags.error_count();
  const std::vector<std::string> top = root_candidates(schema);
  const DocNode& root = config.root;
  for (const DocEntry& e : root.entries) {
    if (const SectionSchema* sec = schema.section(e.key); sec && !e.key.empty()) {
      if (e.value.is_null()) continue;  // a null section behaves as absent (spec 2.2)
      if (!e.value.is_map()) {
        diags.report(Rule::YamlNotMapping, e.value.range,
                     "section '" + e.key + "' must be a mapping of keys to values, not " + with_article(kind_name(e.value)),
                     "/" + e.key);
        continue;
      }
      std::vector<std::string> names;
      for (size_t i : sec->keys) names.push_back(schema.keys()[i].name);
      for (const DocEntry& inner : e.value.entries) {
        if (const KeySchema* k = schema.find(e.key + "." + inner.key)) {
          check_value(*k, inner.value, diags);
        } else {
          report_unknown(inner, e.key, names, schema, diags);
        }
      }
      check_section_rules(*sec, e.value, schema, diags);
      continue;
    }
    if (const KeySchema* k = schema.find(e.key); k && k->section.empty()) {
      check_value(*k, e.value, diags);
      continue;
    }
    report_unknown(e, "", top, schema, diags);
  }
  check_section_rules(schema.sections()[0], root, schema, diags);
  return diags.error_count() == errors_before;
}

}  // namespace kage
