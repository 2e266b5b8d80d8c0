// Resolve: values with the original loader's absent-key rules (spec 2.2, 1.8, 1.9).
#include "compiler/sema/resolve.h"

#include <cmath>

#include "compiler/basic/utf8.h"
#include "compiler/sema/assets.h"
#include "compiler/sema/capacity.h"
#include "compiler/sema/check.h"
#include "compiler/sema/conditions.h"
#include "compiler/sema/lints.h"

namespace kage {

const DocEntry* find_key_entry(const DocNode& root, const KeySchema& key) {
  if (key.section.empty()) return root.find(key.name);
  const DocEntry* sec = root.find(key.section);
  if (!sec || !sec->value.is_map()) return nullptr;
  return sec->value.find(key.name);
}

const DocNode* find_key(const DocNode& root, const KeySchema& key) {
  const DocEntry* e = find_key_entry(root, key);
  return e ? &e->value : nullptr;
}

namespace {

Json scalar_json(const DocNode& node, const std::string& ctype) {
  const Scalar v = scalar_value(node);
  if (std::holds_alternative<std::monostate>(v)) return Json();
  if (std::holds_alternative<bool>(v)) return std::get<bool>(v);
  if (std::holds_alternative<std::string>(v)) return std::get<std::string>(v);
  const bool is_int = std::holds_alternative<int64_t>(v);
  const bool wants_float = ctype.rfind("float", 0) == 0;
  if (is_int && !wants_float) return std::get<int64_t>(v);
  return is_int ? static_cast<double>(std::get<int64_t>(v)) : std::get<double>(v);
}

// Converts a written value to the key's canonical form (strings as lists, ints as floats...).
Json value_json(const KeySchema& key, const DocNode& node) {
  const std::string item_ctype = key.ctype == "int_list" || key.ctype == "rgb" ? "int" : "string";
  if (node.is_seq()) {
    Json list = Json::array();
    for (const DocNode& item : node.items) list.push_back(scalar_json(item, item_ctype));
    return list;
  }
  Json v = scalar_json(node, key.ctype);
  if (v.is_string() && key.ctype == "string_list") {
    if (key.string_is_characters) {  // spec 2.2: a string there is a list of its characters
      Json chars = Json::array();
      for (std::string& c : utf8_characters(v.get<std::string>())) chars.push_back(std::move(c));
      return chars;
    }
    return Json::array({v});
  }
  return v;
}

bool section_present(const DocNode& root, const std::string& section) {
  const DocEntry* e = root.find(section);
  return e && e->value.is_map();
}

}  // namespace

Spec resolve_config(const ComposedConfig& config, const Schema& schema, const ResolveOptions& options,
                    const SourceManager& sources, DiagEngine& diags) {
  Spec spec;
  spec.values = Json::object();
  const DocNode& root = config.root;
  // Root keys first: whole-section defaults scale them (layout.length = 16 * W).
  std::vector<const KeySchema*> order;
  for (const KeySchema& k : schema.keys())
    if (k.section.empty()) order.push_back(&k);
  for (const KeySchema& k : schema.keys())
    if (!k.section.empty()) order.push_back(&k);
  for (const KeySchema* kp : order) {
    const KeySchema& k = *kp;
    if (!k.alias_of.empty()) continue;  // legacy names resolve into their modern key
    Json value = k.default_value;
    if (const DocNode* written = find_key(root, k)) {
      value = value_json(k, *written);
    } else if (const KeySchema* legacy = [&]() -> const KeySchema* {
                 for (const KeySchema& other : schema.keys())
                   if (other.alias_of == k.name && other.section == k.section && find_key(root, other)) return &other;
                 return nullptr;
               }()) {
      value = value_json(k, *find_key(root, *legacy));
    } else if (!k.absent_section_of.empty() && !section_present(root, k.section)) {
      const Json& of = spec.values[k.absent_section_of];
      if (of.is_number()) value = static_cast<int64_t>(std::llround(of.get<double>() * k.absent_section_scale));
    }
    if (k.ctype.rfind("float", 0) == 0 && value.is_number_integer()) value = value.get<double>();
    if (k.string_as_list && value.is_string()) value = Json::array({value});
    if (k.section.empty()) {
      spec.values[k.name] = value;
    } else {
      spec.values[k.section][k.name] = value;
    }
  }
  for (const KeySchema& k : schema.keys())
    if (k.alias_of.empty() && inert_reason(k, spec)) spec.inert.insert(k.path);
  resolve_assets(config, schema, options, sources, spec, diags);
  run_context_lints(config, schema, spec, diags);
  report_capacity(config, spec, diags);
  return spec;
}

std::optional<Spec> analyze_composed(const ComposedConfig& config, const ResolveOptions& options,
                                     SourceManager& sources, DiagEngine& diags) {
  const Schema& schema = config_schema();
  if (!check_config(config, schema, diags)) return std::nullopt;
  return resolve_config(config, schema, options, sources, diags);
}

std::optional<Spec> analyze_file(const std::string& path, const ResolveOptions& options, SourceManager& sources,
                                 FileReader& reader, DiagEngine& diags) {
  auto config = load_config(path, sources, reader, diags);
  if (!config) return std::nullopt;
  return analyze_composed(*config, options, sources, diags);
}

}  // namespace kage
