// Certification of a mixture: the first latent difference of a later config from the first, located.
#include "compiler/analysis/mixture.h"

#include <algorithm>

#include "fileio/sha256.h"

namespace kage {
namespace {

/// Where `member`'s chain writes `key` (the key itself), or nullopt when it takes its default.
std::optional<Range> written_at(const MixtureMember& member, const KeySchema& key) {
  const DocEntry* e = find_key_entry(member.config->root, key);
  if (!e) return std::nullopt;
  return e->key_range;
}

/// " (its default)" when `member` does not write `key`.
std::string default_note(const MixtureMember& member, const KeySchema& key) {
  return written_at(member, key) ? "" : " (its default)";
}

/// The place of a difference between `first` and `later` on `key`: where `later` writes it, else where
/// `first` does, else the start of `later`'s file.
Range place(const MixtureMember& first, const MixtureMember& later, const KeySchema& key) {
  if (const auto r = written_at(later, key)) return *r;
  if (const auto r = written_at(first, key)) return *r;
  return Range{Loc{later.config->file, 0}, 0};
}

const KeySchema* key_of(const Schema& schema, const std::string& path) {
  const auto& keys = schema.keys();
  const auto it = std::find_if(keys.begin(), keys.end(), [&](const KeySchema& k) { return k.path == path; });
  return it == keys.end() ? nullptr : &*it;
}

/// "128x64" from the observation sides of a Spec (height x width).
std::string shape_text(const Spec& spec, const Schema& schema) {
  std::string height, width;
  for (const KeySchema& k : schema.keys()) {
    if (k.observation == "height") height = spec.value(k.path).dump();
    if (k.observation == "width") width = spec.value(k.path).dump();
  }
  return height + "x" + width;
}

}  // namespace

bool certify_mixture(const std::vector<MixtureMember>& members, const Schema& schema, DiagEngine& diags) {
  if (members.size() < 2) return true;
  const MixtureMember& first = members.front();
  for (size_t i = 1; i < members.size(); ++i) {
    const MixtureMember& later = members[i];
    const SpecDiff diff = diff_specs(*first.spec, *later.spec, schema);
    const Change* shape = nullptr;
    const Change* latent = nullptr;
    for (const Change& c : diff.changes) {
      if (c.axis != Axis::Latent) continue;
      const KeySchema* k = key_of(schema, c.path);
      if (!shape && k && !k->observation.empty()) shape = &c;
      if (!latent) latent = &c;
    }
    if (shape) {
      const KeySchema& k = *key_of(schema, shape->path);
      diags.report(Rule::CertifyMixtureShape, place(first, later, k),
                   "mixture of '" + first.name + "' and '" + later.name + "': observations are " +
                       shape_text(*first.spec, schema) + " (height x width) in '" + first.name + "' but " +
                       shape_text(*later.spec, schema) + " in '" + later.name +
                       "'; one batch has one observation shape",
                   k.pointer);
      return false;
    }
    if (latent) {
      const KeySchema& k = *key_of(schema, latent->path);
      diags.report(Rule::CertifyMixtureLatent, place(first, later, k),
                   "mixture of '" + first.name + "' and '" + later.name + "': latent key '" + k.path + "' is " +
                       latent->train.dump() + default_note(first, k) + " in '" + first.name + "' but " +
                       latent->eval.dump() + default_note(later, k) + " in '" + later.name +
                       "'; a mixture's configs must run one hidden game and differ only on visual axes",
                   k.pointer);
      return false;
    }
  }
  return true;
}

std::optional<std::vector<Spec>> analyze_mixture(const std::vector<std::string>& paths, const ResolveOptions& options,
                                                 SourceManager& sources, FileReader& reader, DiagEngine& diags) {
  std::vector<ComposedConfig> configs;
  std::vector<Spec> specs;
  bool ok = true;
  for (const std::string& path : paths) {
    std::optional<ComposedConfig> config = load_config(path, sources, reader, diags);
    std::optional<Spec> spec = config ? analyze_composed(*config, options, sources, diags) : std::nullopt;
    if (!config || !spec) {
      ok = false;
      continue;
    }
    configs.push_back(std::move(*config));
    specs.push_back(std::move(*spec));
  }
  if (!ok || diags.has_errors()) return std::nullopt;
  std::vector<MixtureMember> members;
  for (size_t i = 0; i < paths.size(); ++i) members.push_back(MixtureMember{paths[i], &configs[i], &specs[i]});
  if (!certify_mixture(members, config_schema(), diags)) return std::nullopt;
  return specs;
}

std::string mixture_sha256(const std::vector<std::pair<std::string, int32_t>>& parts) {
  Json list = Json::array();
  for (const auto& [hash, num_envs] : parts) list.push_back(Json{{"num_envs", num_envs}, {"spec_sha256", hash}});
  return sha256_hex(Json{{"kage_mixture", 1}, {"parts", list}}.dump());
}

Json mixture_json(const std::vector<std::string>& names, const std::vector<Spec>& specs, const Schema& schema) {
  Json configs = Json::array();
  std::set<Axis> axes;
  for (size_t i = 0; i < specs.size(); ++i) {
    configs.push_back(Json{{"name", names[i]}, {"spec_sha256", specs[i].sha256()}});
    if (i > 0)
      for (Axis a : diff_specs(specs[0], specs[i], schema).axes()) axes.insert(a);
  }
  Json axis_names = Json::array();
  for (Axis a : axes) axis_names.push_back(axis_name(a));
  return Json{{"kagec_mixture", 1}, {"certified", true}, {"configs", configs}, {"axes", axis_names}};
}

}  // namespace kage
