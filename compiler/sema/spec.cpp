// Spec: canonical JSON and hashing.
#include "compiler/sema/spec.h"

#include "fileio/sha256.h"

namespace kage {

std::vector<AssetSet>* ResolvedAssets::sets(const std::string& group) {
  if (group == "agent_skins") return &agent_skins;
  if (group == "npc_types") return &npc_types;
  if (group == "sticky_types") return &sticky_types;
  return nullptr;
}

const std::vector<AssetSet>* ResolvedAssets::sets(const std::string& group) const {
  return const_cast<ResolvedAssets*>(this)->sets(group);
}

const Json& Spec::value(const std::string& path) const {
  static const Json kNull;
  const auto dot = path.find('.');
  if (dot == std::string::npos) return values.contains(path) ? values.at(path) : kNull;
  const std::string section = path.substr(0, dot), key = path.substr(dot + 1);
  if (!values.contains(section) || !values.at(section).contains(key)) return kNull;
  return values.at(section).at(key);
}

namespace {

Json file_json(const AssetFile& f) {
  return Json{{"file", f.file}, {"sha256", f.sha256}, {"width", f.width}, {"height", f.height}};
}

Json sets_json(const std::vector<AssetSet>& sets) {
  Json out = Json::array();
  for (const AssetSet& s : sets) {
    Json frames = Json::array();
    for (const AssetFile& f : s.frames) frames.push_back(file_json(f));
    out.push_back(Json{{"dir", s.dir}, {"frames", frames}});
  }
  return out;
}

AssetFile file_from(const Json& j) {
  return AssetFile{j.at("file").get<std::string>(), j.at("sha256").get<std::string>(), j.at("width").get<int>(),
                   j.at("height").get<int>()};
}

std::vector<AssetSet> sets_from(const Json& j) {
  std::vector<AssetSet> out;
  for (const Json& s : j) {
    AssetSet set;
    set.dir = s.at("dir").get<std::string>();
    for (const Json& f : s.at("frames")) set.frames.push_back(file_from(f));
    out.push_back(std::move(set));
  }
  return out;
}

}  // namespace

Json Spec::to_json() const {
  Json backgrounds = Json::array();
  for (const AssetFile& f : assets.backgrounds) backgrounds.push_back(file_json(f));
  Json j;
  j["kagec_spec"] = 1;
  j["config"] = values;
  j["inert"] = Json(std::vector<std::string>(inert.begin(), inert.end()));
  j["assets"] = Json{{"backgrounds", backgrounds},
                     {"agent_skins", sets_json(assets.agent_skins)},
                     {"npc_types", sets_json(assets.npc_types)},
                     {"sticky_types", sets_json(assets.sticky_types)}};
  return j;
}

std::string Spec::sha256() const {
  // Paths tell where the command ran, not what the configuration is: the hash leaves every asset
  // path out and keeps the assets' content hashes and sizes.
  Json j = to_json();
  Json& config = j["config"];
  auto blank = [](Json& v) {
    if (v.is_string()) v = "";
    if (v.is_array())
      for (Json& item : v)
        if (item.is_string()) item = "";
  };
  for (const KeySchema& k : config_schema().keys()) {
    if (k.asset_kind.empty()) continue;
    if (k.section.empty()) {
      if (config.contains(k.name)) blank(config[k.name]);
    } else if (config.contains(k.section) && config[k.section].is_object() && config[k.section].contains(k.name)) {
      blank(config[k.section][k.name]);
    }
  }
  Json& assets = j["assets"];
  for (Json& f : assets["backgrounds"]) f.erase("file");
  for (const char* group : {"agent_skins", "npc_types", "sticky_types"})
    for (Json& set : assets[group]) {
      set.erase("dir");
      for (Json& f : set["frames"]) f.erase("file");
    }
  return sha256_hex(j.dump());
}

std::string Spec::canonical_text() const {
  Json j = to_json();
  j["sha256"] = sha256();
  return j.dump(2) + "\n";
}

Json Spec::latent_values(const Schema& schema) const {
  Json out = Json::object();
  for (const KeySchema& k : schema.keys()) {
    if (k.axis != Axis::Latent || !k.alias_of.empty()) continue;
    out[k.path] = value(k.path);
  }
  return out;
}

std::optional<Spec> spec_from_json(const Json& j) {
  if (!j.is_object() || j.value("kagec_spec", 0) != 1 || !j.contains("config")) return std::nullopt;
  try {
    Spec s;
    s.values = j.at("config");
    for (const Json& p : j.at("inert")) s.inert.insert(p.get<std::string>());
    const Json& a = j.at("assets");
    for (const Json& f : a.at("backgrounds")) s.assets.backgrounds.push_back(file_from(f));
    s.assets.agent_skins = sets_from(a.at("agent_skins"));
    s.assets.npc_types = sets_from(a.at("npc_types"));
    s.assets.sticky_types = sets_from(a.at("sticky_types"));
    return s;
  } catch (const Json::exception&) {
    return std::nullopt;
  }
}

}  // namespace kage
