// Reads the JSON Schema into the key table.
#include "compiler/sema/schema.h"

#include <cctype>

#include "compiler/basic/internal_error.h"

namespace kage {

namespace {

struct AxisName {
  Axis axis;
  const char* name;
};
constexpr AxisName kAxisNames[] = {
#define KAGE_AXIS(Id, name) {Axis::Id, name},
    KAGE_SCHEMA_AXES(KAGE_AXIS)
#undef KAGE_AXIS
};

}  // namespace

const char* axis_name(Axis axis) {
  for (const AxisName& a : kAxisNames)
    if (a.axis == axis) return a.name;
  return "latent";
}

std::optional<Axis> parse_axis(const std::string& name) {
  for (const AxisName& a : kAxisNames)
    if (name == a.name) return a.axis;
  return std::nullopt;
}

const std::vector<Axis>& visual_axes() {
  static const std::vector<Axis> axes = [] {
    std::vector<Axis> out;
    for (const AxisName& a : kAxisNames)
      if (a.axis != Axis::Latent) out.push_back(a.axis);
    return out;
  }();
  return axes;
}

namespace {

// "shapeColorName" -> "shape colour name" -> "shape colour".
std::string table_title(const std::string& id) {
  std::string out;
  for (char c : id) {
    if (std::isupper(static_cast<unsigned char>(c))) {
      out += ' ';
      out += static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    } else {
      out += c;
    }
  }
  if (out.size() > 5 && out.compare(out.size() - 5, 5, " name") == 0) out.resize(out.size() - 5);
  if (out == "shape type") return out;
  for (auto pos = out.find("color"); pos != std::string::npos; pos = out.find("color", pos + 6))
    out.replace(pos, 5, "colour");
  return out;
}

}  // namespace

class SchemaLoader {
 public:
  explicit SchemaLoader(const Json& doc) : doc_(doc) {}

  Schema load() {
    for (auto& [id, def] : doc_.at("definitions").items()) {
      if (!def.contains("enum")) continue;
      NameTable t;
      t.id = id;
      t.title = table_title(id);
      for (const Json& n : def.at("enum")) t.names.push_back(n.get<std::string>());
      if (def.contains("x-kage-rgb"))
        for (auto& [name, rgb] : def.at("x-kage-rgb").items())
          t.rgb[name] = {rgb.at(0).get<int>(), rgb.at(1).get<int>(), rgb.at(2).get<int>()};
      out_.tables_[id] = std::move(t);
    }
    SectionSchema root;
    root.name = "";
    out_.sections_.push_back(root);
    for (auto& [name, prop] : doc_.at("properties").items()) {
      if (prop.value("x-kage-meta", false)) {
        out_.meta_keys_.insert(name);
        continue;
      }
      if (prop.contains("properties")) {
        add_section(name, prop);
      } else {
        add_key("", name, prop, out_.sections_[0]);
      }
    }
    for (size_t i = 0; i < out_.keys_.size(); ++i) out_.by_path_[out_.keys_[i].path] = i;
    return std::move(out_);
  }

 private:
  const Json& deref(const Json& node) const {
    if (!node.contains("$ref")) return node;
    const std::string ref = node.at("$ref").get<std::string>();
    const std::string prefix = "#/definitions/";
    KAGE_INTERNAL_ASSERT(ref.rfind(prefix, 0) == 0, "unsupported $ref " + ref);
    return doc_.at("definitions").at(ref.substr(prefix.size()));
  }

  const NameTable* table_of(const Json& node) const {
    if (!node.contains("$ref")) return nullptr;
    const std::string ref = node.at("$ref").get<std::string>();
    auto it = out_.tables_.find(ref.substr(ref.rfind('/') + 1));
    return it == out_.tables_.end() ? nullptr : &it->second;
  }

  ValueRule value_rule(const Json& raw, const std::string& path) {
    ValueRule r;
    r.names = table_of(raw);
    const Json& node = deref(raw);
    if (!r.names && node.contains("enum")) r.names = inline_table(path, node.at("enum"));
    if (node.contains("type")) {
      if (node.at("type").is_array())
        for (const Json& t : node.at("type")) r.types.insert(t.get<std::string>());
      else
        r.types.insert(node.at("type").get<std::string>());
    }
    if (node.contains("enum") && r.types.empty()) r.types.insert("string");
    if (node.contains("minimum")) r.minimum = node.at("minimum").get<double>();
    if (node.contains("maximum")) r.maximum = node.at("maximum").get<double>();
    if (node.contains("exclusiveMinimum")) r.exclusive_minimum = node.at("exclusiveMinimum").get<double>();
    return r;
  }

  // A key's own enum (the names the original maps silently): a table named after the key.
  const NameTable* inline_table(const std::string& path, const Json& names) {
    NameTable t;
    t.id = path;
    t.title = "value";
    for (const Json& n : names)
      if (n.is_string()) t.names.push_back(n.get<std::string>());
    return &(out_.tables_[path] = std::move(t));
  }

  void add_key(const std::string& section, const std::string& name, const Json& prop, SectionSchema& sec) {
    KeySchema k;
    k.section = section;
    k.name = name;
    k.path = section.empty() ? name : section + "." + name;
    k.pointer = section.empty() ? "/" + name : "/" + section + "/" + name;
    k.ctype = prop.value("x-kage-ctype", "");
    k.description = prop.value("description", "");
    const auto axis = parse_axis(prop.value("x-kage-axis", ""));
    KAGE_INTERNAL_ASSERT(axis.has_value(), "schema key " + k.path + " has no valid x-kage-axis");
    k.axis = *axis;
    if (prop.contains("anyOf")) {
      // The one anyOf form: a name, or a list of names.
      const Json& alts = prop.at("anyOf");
      for (const Json& alt : alts) {
        if (alt.value("type", "") == "array") {
          k.items = value_rule(alt.at("items"), k.path);
          if (alt.contains("minItems")) k.min_items = alt.at("minItems").get<size_t>();
        } else {
          k.value = value_rule(alt, k.path);
        }
      }
      k.value.types.insert("array");
      k.string_as_list = true;
    } else {
      const Json& node = deref(prop);
      k.value = value_rule(prop, k.path);
      if (node.contains("items")) k.items = value_rule(node.at("items"), k.path);
      if (node.contains("minItems")) k.min_items = node.at("minItems").get<size_t>();
      if (node.contains("maxItems")) k.max_items = node.at("maxItems").get<size_t>();
      if (prop.contains("minItems")) k.min_items = prop.at("minItems").get<size_t>();
      k.string_is_characters = prop.contains("x-kage-string-as-list") && !prop.at("x-kage-string-as-list").get<bool>();
      k.string_as_list = prop.value("x-kage-string-as-list", false);
    }
    if (prop.contains("x-kage-recommended")) {
      const Json& rec = prop.at("x-kage-recommended");
      if (rec.contains("minimum")) k.recommended_min = rec.at("minimum").get<double>();
      if (rec.contains("maximum")) k.recommended_max = rec.at("maximum").get<double>();
    }
    k.default_value = prop.contains("default") ? prop.at("default") : Json();
    k.in_default_yaml = prop.contains("x-kage-yaml-default");
    if (k.in_default_yaml) k.yaml_default = prop.at("x-kage-yaml-default");
    k.alias_of = prop.value("x-kage-alias-of", "");
    if (prop.contains("x-kage-absent-section-default")) {
      k.absent_section_of = prop.at("x-kage-absent-section-default").at("of").get<std::string>();
      k.absent_section_scale = prop.at("x-kage-absent-section-default").value("scale", 1.0);
    }
    k.asset_kind = prop.value("x-kage-asset", "");
    k.observation = prop.value("x-kage-observation", "");
    KAGE_INTERNAL_ASSERT(k.observation.empty() || k.observation == "height" || k.observation == "width",
                         "schema key " + k.path + ": x-kage-observation is height or width");
    if (prop.contains("x-kage-inert-when")) k.inert_when = prop.at("x-kage-inert-when");
    if (prop.contains("x-kage-quirk")) {
      k.quirk_rule = prop.at("x-kage-quirk").at("rule").get<std::string>();
      k.quirk_message = prop.at("x-kage-quirk").at("message").get<std::string>();
    }
    if (prop.contains("x-kage-capacity")) {
      const Json& cap = prop.at("x-kage-capacity");
      k.capacity_limit = cap.at("limit").get<std::string>();
      k.capacity_what = cap.at("what").get<std::string>();
      k.capacity_minus = cap.value("minus", "");
    }
    sec.keys.push_back(out_.keys_.size());
    out_.keys_.push_back(std::move(k));
  }

  void add_section(const std::string& name, const Json& prop) {
    SectionSchema sec;
    sec.name = name;
    for (auto& [key, leaf] : prop.at("properties").items()) add_key(name, key, leaf, sec);
    if (prop.contains("x-kage-exclusive"))
      for (const Json& group : prop.at("x-kage-exclusive")) sec.exclusive.push_back(group.get<std::vector<std::string>>());
    sec.exclusive_counts_empty = prop.value("x-kage-exclusive-counts-empty", false);
    if (prop.contains("x-kage-one-true"))
      for (const Json& pair : prop.at("x-kage-one-true"))
        sec.one_true.emplace_back(pair.at(0).get<std::string>(), pair.at(1).get<std::string>());
    if (prop.contains("x-kage-ordered"))
      for (const Json& pair : prop.at("x-kage-ordered"))
        sec.ordered.emplace_back(pair.at(0).get<std::string>(), pair.at(1).get<std::string>());
    out_.sections_.push_back(std::move(sec));
  }

  const Json& doc_;
  Schema out_;
};

Schema Schema::from_json(const Json& doc) { return SchemaLoader(doc).load(); }

const KeySchema* Schema::find(const std::string& path) const {
  auto it = by_path_.find(path);
  return it == by_path_.end() ? nullptr : &keys_[it->second];
}

const SectionSchema* Schema::section(const std::string& name) const {
  for (const SectionSchema& s : sections_)
    if (s.name == name) return &s;
  return nullptr;
}

const NameTable* Schema::table(const std::string& id) const {
  auto it = tables_.find(id);
  return it == tables_.end() ? nullptr : &it->second;
}

std::vector<std::string> Schema::sections_with_key(const std::string& name) const {
  std::vector<std::string> out;
  for (const KeySchema& k : keys_)
    if (k.name == name && !k.section.empty()) out.push_back(k.section);
  return out;
}

const Schema& config_schema() {
  static const Schema schema = Schema::from_json(Json::parse(config_schema_text()));
  return schema;
}

}  // namespace kage
