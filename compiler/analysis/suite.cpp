// Suite manifests: certifying each pair (suite_load.cpp reads the manifest), the table and the JSON report.
#include "compiler/analysis/suite.h"

#include <algorithm>
#include <fstream>
#include <iomanip>
#include <map>
#include <ostream>
#include <set>
#include <sstream>

#include "compiler/analysis/mixture.h"
#include "compiler/basic/file_out.h"
#include "compiler/parse/compose.h"
#include "fileio/sha256.h"

namespace kage {

std::string certificate_file_name(const std::string& pair_name) {
  std::string name = pair_name;
  for (char& c : name)
    if (c == '/' || c == ' ' || c == '\\' || static_cast<unsigned char>(c) < 0x20) c = '_';
  if (name.empty() || name[0] == '.') name.insert(0, "_");
  return name + ".json";
}

size_t SuiteReport::passed() const {
  size_t n = 0;
  for (const PairResult& r : results) n += r.passed();
  return n;
}

namespace {

struct Analysed {
  std::optional<Spec> spec;
  bool ok = false;
  size_t warnings = 0;
};

// Each side in its own engine so that a pair's verdict sees only its own errors.
Analysed analyse(const ConfigRef& ref, const Suite& suite, const ResolveOptions& options, SourceManager& sources,
                 FileReader& reader, DiagEngine& all) {
  DiagEngine local(sources);
  Analysed out;
  if (ref.inline_doc) {
    auto composed = compose_document(*ref.inline_doc, suite.file, suite.dir, sources, reader, local);
    if (composed) out.spec = analyze_composed(*composed, options, sources, local);
  } else {
    out.spec = analyze_file(ref.path, options, sources, reader, local);
  }
  out.ok = out.spec.has_value() && !local.has_errors();
  out.warnings = local.warning_count();
  for (const Diagnostic& d : local.sorted()) all.report(d.rule, d.range, d.message, d.path) = d;
  return out;
}

/// A mixture pair's verdict: each training config differs from the eval on the declared axis only (or on
/// an allowed one, or not at all), and at least one differs on the declared axis.
Certification certify_members(PairResult& r, const SuitePair& pair) {
  const std::vector<std::string> names = pair.mixture->configs();
  Certification c;
  c.declared = pair.axis;
  bool declared_changes = false;
  for (size_t i = 0; i < r.members.size(); ++i) {
    r.member_diffs.push_back(diff_specs(r.members[i], *r.eval, config_schema()));
    const SpecDiff& diff = r.member_diffs.back();
    for (Axis a : diff.axes()) c.measured.insert(a);
    declared_changes = declared_changes || diff.axes().count(pair.axis);
    if (diff.changes.empty()) continue;  // a training config equal to the eval changes nothing
    const Certification one = certify(diff, pair.axis, pair.allow);
    for (const std::string& problem : one.problems) c.problems.push_back("training config '" + names[i] + "': " + problem);
    for (const Allowance& a : one.used_allowances)
      if (std::none_of(c.used_allowances.begin(), c.used_allowances.end(),
                       [&](const Allowance& u) { return u.axis == a.axis; }))
        c.used_allowances.push_back(a);
  }
  if (!declared_changes)
    c.problems.push_back(std::string("declared axis '") + axis_name(pair.axis) +
                         "' does not change: no training config differs from the eval on it");
  c.certified = c.problems.empty();
  return c;
}

}  // namespace

SuiteReport run_suite(const Suite& suite, const ResolveOptions& options, SourceManager& sources, FileReader& reader,
                      DiagEngine& diags, std::ostream* progress) {
  SuiteReport report;
  std::map<std::string, Analysed> cache;  // files shared by several pairs are analysed once
  auto side = [&](const ConfigRef& ref) -> Analysed {
    if (ref.inline_doc) return analyse(ref, suite, options, sources, reader, diags);
    auto it = cache.find(ref.path);
    if (it == cache.end()) it = cache.emplace(ref.path, analyse(ref, suite, options, sources, reader, diags)).first;
    return it->second;
  };
  size_t index = 0;
  for (const SuitePair& pair : suite.pairs) {
    ++index;
    if (progress)
      *progress << "\r\033[K[" << index << "/" << suite.pairs.size() << "] " << pair.name << std::flush;
    PairResult r;
    r.pair = &pair;
    if (pair.mixture) {  // the training configs as one mixture, then each against the eval
      const Analysed eval = side(pair.eval);
      DiagEngine local(sources);
      auto members = analyze_mixture(pair.mixture->configs(), options, sources, reader, local);
      for (const Diagnostic& d : local.sorted()) diags.report(d.rule, d.range, d.message, d.path) = d;
      r.lint_ok = members && !local.has_errors() && eval.ok;
      r.warnings = local.warning_count() + eval.warnings;
      r.eval = eval.spec;
      if (members) r.members = std::move(*members);
      if (r.lint_ok) {
        r.cert = certify_members(r, pair);
      } else {
        r.cert.declared = pair.axis;
        r.cert.problems.push_back(
            "a config of this pair has errors, or its training configs are no mixture (see the diagnostics above)");
      }
      report.results.push_back(std::move(r));
      continue;
    }
    const Analysed train = side(pair.train);
    const Analysed eval = side(pair.eval);
    r.lint_ok = train.ok && eval.ok;
    r.warnings = train.warnings + eval.warnings;
    r.train = train.spec;
    r.eval = eval.spec;
    if (r.lint_ok) {
      r.diff = diff_specs(*r.train, *r.eval, config_schema());
      r.cert = certify(r.diff, pair.axis, pair.allow);
    } else {
      r.cert.declared = pair.axis;
      r.cert.problems.push_back("a config of this pair has errors (see the diagnostics above)");
    }
    report.results.push_back(std::move(r));
  }
  if (progress) *progress << "\r\033[K" << std::flush;
  return report;
}

void print_suite_table(const Suite& suite, const SuiteReport& report, std::ostream& out) {
  size_t width = 4;
  for (const PairResult& r : report.results) width = std::max(width, r.pair->name.size());
  out << std::left << std::setw(static_cast<int>(width) + 2) << "pair" << std::setw(13) << "declared"
      << std::setw(26) << "measured" << "verdict\n";
  for (const PairResult& r : report.results) {
    std::string verdict;
    if (r.passed()) {
      verdict = r.cert.used_allowances.empty() ? "certified" : "certified (allowed: ";
      for (size_t i = 0; i < r.cert.used_allowances.size(); ++i)
        verdict += std::string(i ? ", " : "") + axis_name(r.cert.used_allowances[i].axis);
      if (!r.cert.used_allowances.empty()) verdict += ")";
    } else {
      verdict = "FAILED: " + (r.cert.problems.empty() ? std::string("errors") : r.cert.problems.front());
    }
    out << std::setw(static_cast<int>(width) + 2) << r.pair->name << std::setw(13) << axis_name(r.pair->axis)
        << std::setw(26) << (r.lint_ok ? axes_text(r.cert.measured) : "-") << verdict << '\n';
  }
  out << suite.name << ": " << report.passed() << " of " << report.results.size() << " pairs certified\n";
}

namespace {

/// A mixture pair's "train": {"name": "mixture of N" or the schedule file, "spec_sha256": the SHA-256 of the
/// compact JSON {"kage_training": 1, "stages": [{"configs": [{"spec_sha256", "weight"}], "start"}]} (what the
/// training runs, whatever the files are called; "" while a config has errors), "schedule": the schedule
/// file or null, "stages": [{"start", "configs": [{"name", "spec_sha256", "weight"}]}]}.
Json training_json(const PairResult& r) {
  const TrainMixture& m = *r.pair->mixture;
  const std::vector<std::string> names = m.configs();
  auto hash_of = [&](const std::string& path) -> std::string {
    const size_t i = static_cast<size_t>(std::find(names.begin(), names.end(), path) - names.begin());
    return i < r.members.size() ? r.members[i].sha256() : "";
  };
  Json stages = Json::array(), identity = Json::array();
  for (const TrainStage& stage : m.stages) {
    Json configs = Json::array(), hashes = Json::array();
    for (const WeightedConfig& c : stage.configs) {
      configs.push_back(Json{{"name", c.path}, {"spec_sha256", hash_of(c.path)}, {"weight", c.weight}});
      hashes.push_back(Json{{"spec_sha256", hash_of(c.path)}, {"weight", c.weight}});
    }
    stages.push_back(Json{{"start", stage.start}, {"configs", configs}});
    identity.push_back(Json{{"start", stage.start}, {"configs", hashes}});
  }
  const bool complete = r.members.size() == names.size();
  return Json{{"name", m.label()},
              {"spec_sha256", complete ? sha256_hex(Json{{"kage_training", 1}, {"stages", identity}}.dump()) : ""},
              {"schedule", m.schedule.empty() ? Json() : Json(m.schedule)},
              {"stages", stages}};
}

/// A mixture pair's changes: each training config's against the eval, marked with the config's name.
Json member_changes(const PairResult& r) {
  const std::vector<std::string> names = r.pair->mixture->configs();
  Json changes = Json::array();
  for (size_t i = 0; i < r.member_diffs.size(); ++i)
    for (const Change& ch : r.member_diffs[i].changes)
      changes.push_back(Json{{"config", names[i]}, {"path", ch.path}, {"axis", axis_name(ch.axis)},
                             {"train", ch.train}, {"eval", ch.eval}});
  return changes;
}

}  // namespace

Json suite_report_json(const Suite& suite, const SuiteReport& report) {
  Json pairs = Json::array();
  for (const PairResult& r : report.results) {
    const PairIdentity train{r.pair->mixture ? r.pair->mixture->label() : r.pair->train.label(),
                             r.train ? r.train->sha256() : ""};
    const PairIdentity eval{r.pair->eval.label(), r.eval ? r.eval->sha256() : ""};
    Json j = certificate_json(train, eval, r.diff, r.cert);
    if (r.pair->mixture) {
      j["train"] = training_json(r);
      j["changes"] = member_changes(r);
    }
    j["pair"] = r.pair->name;
    j["sweep"] = r.pair->sweep.empty() ? Json() : Json(r.pair->sweep);
    j["sweep_eval"] = r.pair->sweep.empty() ? Json() : Json(r.pair->sweep_eval);
    j["lint_ok"] = r.lint_ok;
    j["warnings"] = r.warnings;
    pairs.push_back(j);
  }
  return Json{{"kagec_suite_report", 1},
              {"suite", suite.name},
              {"manifest", suite.manifest},
              {"pairs", pairs},
              {"passed", report.passed()},
              {"total", report.results.size()}};
}

std::optional<std::string> suite_output_dir_problem(const std::filesystem::path& dir) {
  namespace fs = std::filesystem;
  if (std::optional<std::string> problem = output_dir_kind_problem(dir)) return problem;
  std::error_code ec;
  if (!fs::exists(dir, ec) || fs::is_empty(dir, ec)) return std::nullopt;
  const std::string name = dir.string();
  const std::string fix = "; kagec suite replaces its output directory whole, so name a new or empty directory with -o";
  const fs::path report_path = dir / kSuiteReportFile;
  const fs::file_status report_status = fs::symlink_status(report_path, ec);
  if (!fs::exists(report_status))
    return "'" + name + "' holds files that kagec did not write (it has no " + kSuiteReportFile + ")" + fix;
  Json report;
  if (fs::is_regular_file(report_status) && fs::file_size(report_path, ec) <= (uintmax_t(64) << 20)) {
    std::ifstream in(report_path, std::ios::binary);
    std::ostringstream text;
    text << in.rdbuf();
    report = Json::parse(text.str(), nullptr, false);
  }
  if (!report.is_object() || report.value("kagec_suite_report", 0) != 1 || !report.value("pairs", Json()).is_array())
    return "'" + report_path.string() + "' is not a kagec suite report, so kagec did not write '" + name + "'" + fix;
  std::set<std::string> certificates;
  for (const Json& pair : report.at("pairs"))
    if (pair.is_object() && pair.value("pair", Json()).is_string())
      certificates.insert(certificate_file_name(pair.value("pair", "")));
  // Every entry must be one the report accounts for: report.json, certificates/ and its pairs' files.
  std::vector<std::string> foreign;
  auto judge = [&](const fs::path& folder, const std::string& prefix, auto&& allowed) {
    std::error_code list_ec;
    for (const fs::directory_entry& e : fs::directory_iterator(folder, list_ec)) {
      const std::string entry = e.path().filename().string();
      if (!allowed(entry, e)) foreign.push_back(prefix + entry);
    }
    if (list_ec) foreign.push_back(prefix + " (cannot be listed: " + list_ec.message() + ")");
  };
  judge(dir, "", [&](const std::string& entry, const fs::directory_entry& e) {
    std::error_code st;
    if (e.is_symlink(st)) return false;
    if (entry == kSuiteReportFile) return e.is_regular_file(st);
    return entry == kSuiteCertificateDir && e.is_directory(st);
  });
  if (fs::is_directory(fs::symlink_status(dir / kSuiteCertificateDir, ec)))
    judge(dir / kSuiteCertificateDir, std::string(kSuiteCertificateDir) + "/",
          [&](const std::string& entry, const fs::directory_entry& e) {
            std::error_code st;
            return certificates.count(entry) && e.is_regular_file(st) && !e.is_symlink(st);
          });
  if (foreign.empty()) return std::nullopt;
  std::sort(foreign.begin(), foreign.end());
  const std::string more = foreign.size() > 1 ? " and " + std::to_string(foreign.size() - 1) + " more" : "";
  return "'" + name + "' holds '" + foreign.front() + "'" + more + ", which its " + kSuiteReportFile +
         " does not account for (kagec did not write it); move such files out of the directory, or name a new or "
         "empty directory with -o (kagec suite replaces its output directory whole)";
}

}  // namespace kage
