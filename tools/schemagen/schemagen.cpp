// kage_schemagen: schemas/kage-config.schema.json -> compiler/generated/spec_fields.h,
// the typed view of a resolved Spec that lowering code reads (so no C++ file
// spells a key name as a string). Usage: kage_schemagen SCHEMA OUTPUT
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

  std::ostringstream o;
  o << "// Generated from schemas/kage-config.schema.json by kage_schemagen; do not edit.\n"
       "// The typed view of a resolved Spec's values: one member per key (legacy aliases\n"
       "// are resolved into their modern key and do not appear).\n"
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

  std::ofstream out(argv[2], std::ios::binary);
  out << o.str();
  if (!out) {
    std::cerr << "kage_schemagen: cannot write " << argv[2] << "\n";
    return 1;
  }
  return 0;
}
