// kage_schemagen: schemas/kage-config.schema.json -> compiler/generated/spec_fields.h,
// the typed view of a resolved Spec that lowering code reads (so no C++ file
// spells a key name as a string) and the schema's name tables (shapes, presets,
// background modes, axes) as X-macros. Usage: kage_schemagen SCHEMA OUTPUT
#include <algorithm>
#include <fstream>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <vector>

namespace {

using Json = nlohmann::json;

struct Field {
  std::string name;
  std::string ctype;
};

std::string cpp_type(const std::string& ctype) {
  static const std::map<std::string, std::string> types = {
      {"int", "int64_t"},
      {"float", "double"},
      {"bool", "bool"},
      {"string", "std::string"},
      {"string?", "std::optional<std::string>"},
      {"int?", "std::optional<int64_t>"},
      {"float?", "std::optional<double>"},
      {"string_list", "std::vector<std::string>"},
      {"int_list", "std::vector<int64_t>"},
      {"rgb", "std::array<int64_t, 3>"},
  };
  auto it = types.find(ctype);
  if (it == types.end()) {
    std::cerr << "kage_schemagen: unknown x-kage-ctype '" << ctype << "'\n";
    std::exit(1);
  }
  return it->second;
}

std::string struct_name(const std::string& section) {
  std::string out;
  bool up = true;
  for (char c : section) {
    if (c == '_') {
      up = true;
      continue;
    }
    out += up ? static_cast<char>(std::toupper(static_cast<unsigned char>(c))) : c;
    up = false;
  }
  return out;
}

std::vector<Field> leaves(const Json& properties) {
  std::vector<Field> out;
  for (auto& [name, prop] : properties.items()) {
    if (prop.contains("properties") || prop.value("x-kage-meta", false) || prop.contains("x-kage-alias-of")) continue;
    out.push_back({name, prop.at("x-kage-ctype").get<std::string>()});
  }
  return out;
}

/// The schema's name tables: macro name, JSON Pointer of the enum, what it names.
struct NameTable {
  const char* macro;
  const char* pointer;
  const char* what;
};
const NameTable kNameTables[] = {
    {"KAGE_SCHEMA_SHAPE_TYPES", "/definitions/shapeType/enum", "shape types (ShapeType)"},
    {"KAGE_SCHEMA_PRESETS", "/definitions/presetName/enum", "filter presets (Preset)"},
    {"KAGE_SCHEMA_BACKGROUND_MODES", "/properties/background/properties/mode/enum", "background modes (BackgroundMode)"},
    {"KAGE_SCHEMA_AXES", "/definitions/axisName/enum", "certification axes (Axis)"},
};

/// `X(Enumerator, "name")` lines of one name table, the enumerator being the name in CamelCase.
std::string name_table(const Json& schema, const NameTable& t) {
  const Json::json_pointer pointer(t.pointer);
  if (!schema.contains(pointer) || !schema.at(pointer).is_array()) {
    std::cerr << "kage_schemagen: the schema has no enum at " << t.pointer << "\n";
    std::exit(1);
  }
  std::ostringstream o;
  o << "\n// The " << t.what << ", in the schema's order (" << t.pointer << ").\n#define " << t.macro << "(X)";
  for (const Json& name : schema.at(pointer)) {
    if (!name.is_string()) continue;  // null: the key may be absent
    const std::string n = name.get<std::string>();
    o << " \\\n  X(" << struct_name(n) << ", \"" << n << "\")";
  }
  o << "\n";
  return o.str();
}

/// Exits with a message unless every key's x-kage-axis is one of the schema's axes.
void check_axes(const Json& schema, const Json& properties) {
  const Json& axes = schema.at(Json::json_pointer("/definitions/axisName/enum"));
  for (auto& [name, prop] : properties.items()) {
    if (prop.contains("properties")) check_axes(schema, prop.at("properties"));
    if (!prop.contains("x-kage-axis")) continue;
    if (std::find(axes.begin(), axes.end(), prop.at("x-kage-axis")) == axes.end()) {
      std::cerr << "kage_schemagen: key '" << name << "' has x-kage-axis " << prop.at("x-kage-axis")
                << ", which definitions/axisName does not list\n";
      std::exit(1);
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::cerr << "usage: kage_schemagen SCHEMA.json OUTPUT.h\n";
    return 2;
  }
  std::ifstream in(argv[1]);
  if (!in) {
    std::cerr << "kage_schemagen: cannot read " << argv[1] << "\n";
    return 1;
  }
  const Json schema = Json::parse(in);
  const Json& props = schema.at("properties");
  std::vector<std::pair<std::string, std::vector<Field>>> sections;
  for (auto& [name, prop] : props.items())
    if (prop.contains("properties")) sections.emplace_back(name, leaves(prop.at("properties")));
  const std::vector<Field> root = leaves(props);
  check_axes(schema, props);

  std::ostringstream o;
  o << "// Generated from schemas/kage-config.schema.json by kage_schemagen; do not edit.\n"
       "// The typed view of a resolved Spec's values: one member per key (legacy aliases\n"
       "// are resolved into their modern key and do not appear), then the schema's name tables.\n"
       "#pragma once\n\n#include <array>\n#include <cstdint>\n#include <nlohmann/json.hpp>\n#include <optional>\n"
       "#include <string>\n#include <vector>\n\nnamespace kage::spec_fields {\n\n";
  size_t count = root.size();
  for (const auto& [section, fields] : sections) {
    o << "struct " << struct_name(section) << " {\n";
    for (const Field& f : fields) o << "  " << cpp_type(f.ctype) << " " << f.name << "{};\n";
    o << "};\n\n";
    count += fields.size();
  }
  o << "struct Config {\n";
  for (const Field& f : root) o << "  " << cpp_type(f.ctype) << " " << f.name << "{};\n";
  for (const auto& [section, fields] : sections) o << "  " << struct_name(section) << " " << section << ";\n";
  o << "};\n\n/// Number of keys in a Spec.\ninline constexpr size_t kFieldCount = " << count << ";\n\n";
  o << "template <class T>\nvoid read_field(const nlohmann::json& j, const char* key, T& out) {\n"
       "  const nlohmann::json& v = j.at(key);\n  if (!v.is_null()) out = v.get<T>();\n}\n\n"
       "template <class T>\nvoid read_field(const nlohmann::json& j, const char* key, std::optional<T>& out) {\n"
       "  const nlohmann::json& v = j.at(key);\n  if (!v.is_null()) out = v.get<T>();\n}\n\n";
  o << "/// Reads the `config` object of a canonical Spec.\ninline Config from_json(const nlohmann::json& c) {\n"
       "  Config out;\n";
  for (const Field& f : root) o << "  read_field(c, \"" << f.name << "\", out." << f.name << ");\n";
  for (const auto& [section, fields] : sections)
    for (const Field& f : fields)
      o << "  read_field(c.at(\"" << section << "\"), \"" << f.name << "\", out." << section << "." << f.name << ");\n";
  o << "  return out;\n}\n\n}  // namespace kage::spec_fields\n";
  for (const NameTable& t : kNameTables) o << name_table(schema, t);

  std::ofstream out(argv[2], std::ios::binary);
  out << o.str();
  if (!out) {
    std::cerr << "kage_schemagen: cannot write " << argv[2] << "\n";
    return 1;
  }
  return 0;
}
