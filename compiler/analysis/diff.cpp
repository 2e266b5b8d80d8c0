// Per-axis differences and the single-axis certificate.
#include "compiler/analysis/diff.h"

#include <algorithm>
#include <ostream>

#include "compiler/sema/key_refs.h"

namespace kage {

std::set<Axis> SpecDiff::axes() const {
  std::set<Axis> out;
  for (const Change& c : changes) out.insert(c.axis);
  return out;
}

namespace {

bool same_number_or_value(const Json& a, const Json& b) {
  if (a.is_number() && b.is_number()) return a.get<double>() == b.get<double>();
  return a == b;
}

// Content identity of the asset group a key feeds (hash lists), or null.
Json group_content(const Spec& spec, const std::string& path) {
  for (const AssetGroupRef& g : kAssetGroups) {
    if (std::find_if(g.sources.begin(), g.sources.end(), [&](const char* s) { return path == s; }) == g.sources.end())
      continue;
    Json hashes = Json::array();
    if (g.images) {
      for (const AssetFile& f : spec.assets.backgrounds) hashes.push_back(f.sha256);
    } else {
      for (const AssetSet& s : *spec.assets.sets(g.name)) {
        Json frames = Json::array();
        for (const AssetFile& f : s.frames) frames.push_back(f.sha256);
        hashes.push_back(frames);
      }
    }
    return hashes;
  }
  return Json();
}

}  // namespace

SpecDiff diff_specs(const Spec& train, const Spec& eval, const Schema& schema) {
  SpecDiff out;
  for (const KeySchema& k : schema.keys()) {
    if (!k.alias_of.empty()) continue;
    const bool inert_both = train.inert.count(k.path) && eval.inert.count(k.path);
    if (inert_both) continue;
    const Json& a = train.value(k.path);
    const Json& b = eval.value(k.path);
    if (same_number_or_value(a, b)) continue;
    if (!k.asset_kind.empty()) {
      const Json ca = group_content(train, k.path), cb = group_content(eval, k.path);
      if (!ca.is_null() && ca == cb) continue;  // different paths, same images
    }
    out.changes.push_back(Change{k.path, k.axis, a, b});
  }
  std::stable_sort(out.changes.begin(), out.changes.end(),
                   [](const Change& x, const Change& y) { return x.axis < y.axis; });
  return out;
}

std::string axes_text(const std::set<Axis>& axes) {
  std::string out;
  for (Axis a : axes) out += (out.empty() ? "" : ", ") + std::string(axis_name(a));
  return out.empty() ? "none" : out;
}

Certification certify(const SpecDiff& diff, std::optional<Axis> declared, const std::vector<Allowance>& allowed) {
  Certification c;
  c.declared = declared;
  c.measured = diff.axes();
  if (diff.changes.empty()) c.problems.push_back("degenerate pair: train and eval have no effective difference");
  if (c.measured.count(Axis::Latent)) {
    std::string keys;
    for (const Change& ch : diff.changes)
      if (ch.axis == Axis::Latent) keys += (keys.empty() ? "" : ", ") + ch.path;
    c.problems.push_back("latent keys change (the hidden game differs): " + keys);
  }
  std::set<Axis> visual = c.measured;
  visual.erase(Axis::Latent);
  if (declared) {
    if (!visual.empty() && !visual.count(*declared))
      c.problems.push_back(std::string("declared axis '") + axis_name(*declared) + "' does not change");
    for (Axis a : visual) {
      if (a == *declared) continue;
      auto allow = std::find_if(allowed.begin(), allowed.end(), [&](const Allowance& al) { return al.axis == a; });
      if (allow == allowed.end())
        c.problems.push_back(std::string("axis '") + axis_name(a) + "' also changes and is not allowed");
      else
        c.used_allowances.push_back(*allow);
    }
  } else if (visual.size() > 1) {
    c.problems.push_back("more than one visual axis changes: " + axes_text(visual));
  }
  c.certified = c.problems.empty();
  return c;
}

Json certificate_json(const PairIdentity& train, const PairIdentity& eval, const SpecDiff& diff,
                      const Certification& cert) {
  Json changes = Json::array();
  for (const Change& ch : diff.changes)
    changes.push_back(Json{{"path", ch.path}, {"axis", axis_name(ch.axis)}, {"train", ch.train}, {"eval", ch.eval}});
  Json measured = Json::array();
  for (Axis a : cert.measured) measured.push_back(axis_name(a));
  Json allowances = Json::array();
  for (const Allowance& al : cert.used_allowances)
    allowances.push_back(Json{{"axis", axis_name(al.axis)}, {"reason", al.reason}});
  Json j;
  j["kagec_certificate"] = 1;
  j["train"] = Json{{"name", train.name}, {"spec_sha256", train.sha256}};
  j["eval"] = Json{{"name", eval.name}, {"spec_sha256", eval.sha256}};
  j["declared_axis"] = cert.declared ? Json(axis_name(*cert.declared)) : Json();
  j["measured_axes"] = measured;
  j["changes"] = changes;
  j["allowances"] = allowances;
  j["certified"] = cert.certified;
  j["problems"] = cert.problems;
  return j;
}

void print_diff(const SpecDiff& diff, std::ostream& out) {
  if (diff.changes.empty()) {
    out << "no effective differences\n";
    return;
  }
  std::optional<Axis> current;
  for (const Change& ch : diff.changes) {
    if (!current || *current != ch.axis) {
      current = ch.axis;
      size_t n = std::count_if(diff.changes.begin(), diff.changes.end(), [&](const Change& c) { return c.axis == ch.axis; });
      out << axis_name(ch.axis) << " (" << n << " change" << (n == 1 ? "" : "s") << ")\n";
    }
    out << "  " << ch.path << ": " << ch.train.dump() << " -> " << ch.eval.dump() << "\n";
  }
}

}  // namespace kage
