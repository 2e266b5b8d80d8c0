// Suite manifests: loading, running, reporting.
#include "compiler/analysis/suite.h"

#include <algorithm>
#include <cctype>
#include <fstream>
#include <iomanip>
#include <map>
#include <ostream>
#include <set>
#include <sstream>

#include "compiler/basic/file_out.h"
#include "compiler/parse/compose.h"

namespace kage {

std::string ConfigRef::label() const { return inline_doc ? "(inline)" : path; }

namespace {

class SuiteLoader {
 public:
  SuiteLoader(SourceManager& sources, DiagEngine& diags) : sources_(sources), diags_(diags) {}

  std::optional<Suite> load(const std::string& path, FileReader& reader) {
    std::string err;
    const auto text = reader.read(path, &err);
    if (!text) {
      diags_.report(Rule::FileUnreadable, Range{}, "cannot read suite '" + path + "': " + err);
      return std::nullopt;
    }
    Suite suite;
    suite.manifest = path;
    suite.dir = parent_dir(path);
    suite.file = sources_.add(path, *text);
    auto doc = parse_yaml(sources_, suite.file, diags_);
    if (!doc) return std::nullopt;
    if (!doc->is_map()) {
      diags_.report(Rule::YamlNotMapping, doc->range, "a suite manifest must be a mapping with 'suite' and 'pairs'");
      return std::nullopt;
    }
    suite.name = text_of(*doc, "suite", true);
    suite.description = text_of(*doc, "description", false);
    for (const DocEntry& e : doc->entries) {
      if (e.key == "suite" || e.key == "description") continue;
      if (e.key == "pairs") {
        for_each_item(e, [&](const DocNode& item) { add_pair(suite, item); });
      } else if (e.key == "sweeps") {
        for_each_item(e, [&](const DocNode& item) { add_sweep(suite, item); });
      } else {
        diags_.report(Rule::SuiteInvalid, e.key_range,
                      "unknown key '" + e.key + "' in a suite manifest; expected suite, description, pairs, sweeps");
      }
    }
    if (suite.pairs.empty() && !diags_.has_errors())
      diags_.report(Rule::SuiteInvalid, doc->range, "the suite has no pairs; add 'pairs' or 'sweeps'");
    check_names(suite, *doc);
    return suite;
  }

 private:
  // The suite's name names its output directory and each pair's name its certificate file: a name
  // that leaves the directory, or two pairs sharing a file, would overwrite other files.
  void check_names(const Suite& suite, const DocNode& doc) {
    const DocEntry* name = doc.find("suite");
    if (name && !suite.name.empty() && !plain_name(suite.name))
      diags_.report(Rule::SuiteInvalid, name->value.range,
                    "suite name '" + suite.name +
                        "' names the output directory out/<suite>: use letters, digits, '_', '-' and '.' only, "
                        "not starting with '.'");
    std::map<std::string, const SuitePair*> files;
    for (const SuitePair& p : suite.pairs) {
      const auto [it, fresh] = files.emplace(certificate_file_name(p.name), &p);
      if (fresh) continue;
      const LineCol at = sources_.line_col(it->second->range.begin);
      diags_.report(Rule::SuiteInvalid, p.range,
                    "pair '" + p.name + "' has the certificate file of pair '" + it->second->name + "' (line " +
                        std::to_string(at.line) + "): " + it->first + "; give every pair its own name");
    }
  }

  static bool plain_name(const std::string& name) {
    if (name.empty() || name[0] == '.') return false;
    for (char c : name)
      if (!std::isalnum(static_cast<unsigned char>(c)) && c != '_' && c != '-' && c != '.') return false;
    return true;
  }

  template <class F>
  void for_each_item(const DocEntry& e, F f) {
    if (!e.value.is_seq()) {
      diags_.report(Rule::SuiteInvalid, e.value.range, "'" + e.key + "' must be a list");
      return;
    }
    for (const DocNode& item : e.value.items) {
      if (!item.is_map()) {
        diags_.report(Rule::SuiteInvalid, item.range, "each entry of '" + e.key + "' must be a mapping");
        continue;
      }
      f(item);
    }
  }

  std::string text_of(const DocNode& map, const std::string& key, bool required) {
    const DocEntry* e = map.find(key);
    if (!e) {
      if (required) diags_.report(Rule::SuiteInvalid, map.range, "missing required key '" + key + "'");
      return {};
    }
    const Scalar v = scalar_value(e->value);
    if (std::holds_alternative<std::string>(v)) return std::get<std::string>(v);
    if (e->value.is_scalar()) return e->value.text;
    diags_.report(Rule::SuiteInvalid, e->value.range, "'" + key + "' must be text");
    return {};
  }

  std::optional<Axis> axis_of(const DocNode& map) {
    const DocEntry* e = map.find("axis");
    if (!e) {
      diags_.report(Rule::SuiteInvalid, map.range, "missing required key 'axis'");
      return std::nullopt;
    }
    const std::string name = e->value.text;
    const auto axis = parse_axis(name);
    if (!axis || *axis == Axis::Latent) {
      diags_.report(Rule::SuiteUnknownAxis, e->value.range,
                    "unknown axis '" + name + "'; use background, agent, distractors, filters, effects or layout");
      return std::nullopt;
    }
    return axis;
  }

  std::optional<ConfigRef> config_of(const DocNode& map, const std::string& key, const Suite& suite) {
    const DocEntry* e = map.find(key);
    if (!e) {
      diags_.report(Rule::SuiteInvalid, map.range, "missing required key '" + key + "'");
      return std::nullopt;
    }
    ConfigRef ref;
    if (e->value.is_map()) {
      ref.inline_doc = e->value;
      return ref;
    }
    const Scalar v = scalar_value(e->value);
    if (!std::holds_alternative<std::string>(v)) {
      diags_.report(Rule::SuiteInvalid, e->value.range, "'" + key + "' must be a config path or an inline config");
      return std::nullopt;
    }
    ref.path = join_path(suite.dir, std::get<std::string>(v));
    return ref;
  }

  std::vector<Allowance> allow_of(const DocNode& map) {
    std::vector<Allowance> out;
    const DocEntry* e = map.find("allow");
    if (!e) return out;
    for_each_item(*e, [&](const DocNode& item) {
      const auto axis = axis_of(item);
      const std::string reason = text_of(item, "reason", true);
      if (axis && reason.find_first_not_of(" \t") == std::string::npos) {
        diags_.report(Rule::SuiteInvalid, item.range, "an allowance needs a reason saying why the extra axis changes");
        return;
      }
      if (axis) out.push_back(Allowance{*axis, reason});
    });
    return out;
  }

  void add_pair(Suite& suite, const DocNode& item) {
    SuitePair p;
    p.name = text_of(item, "name", true);
    p.range = item.range;
    const auto axis = axis_of(item);
    auto train = config_of(item, "train", suite);
    auto eval = config_of(item, "eval", suite);
    p.allow = allow_of(item);
    if (!axis || !train || !eval) return;
    p.axis = *axis;
    p.train = std::move(*train);
    p.eval = std::move(*eval);
    suite.pairs.push_back(std::move(p));
  }

  void add_sweep(Suite& suite, const DocNode& item) {
    const std::string name = text_of(item, "name", true);
    const auto axis = axis_of(item);
    auto train = config_of(item, "train", suite);
    const std::vector<Allowance> allow = allow_of(item);
    const DocEntry* evals = item.find("evals");
    if (!evals) {
      diags_.report(Rule::SuiteInvalid, item.range, "a sweep needs 'evals'");
      return;
    }
    for_each_item(*evals, [&](const DocNode& ev) {
      SuitePair p;
      p.sweep = name;
      p.sweep_eval = text_of(ev, "name", true);
      p.name = name + "/" + p.sweep_eval;
      p.range = ev.range;
      auto config = config_of(ev, "config", suite);
      if (!axis || !train || !config) return;
      p.axis = *axis;
      p.train = *train;
      p.eval = std::move(*config);
      p.allow = allow;
      for (Allowance& a : allow_of(ev)) p.allow.push_back(a);
      suite.pairs.push_back(std::move(p));
    });
  }

  SourceManager& sources_;
  DiagEngine& diags_;
};

}  // namespace

std::string certificate_file_name(const std::string& pair_name) {
  std::string name = pair_name;
  for (char& c : name)
    if (c == '/' || c == ' ' || c == '\\' || static_cast<unsigned char>(c) < 0x20) c = '_';
  if (name.empty() || name[0] == '.') name.insert(0, "_");
  return name + ".json";
}

std::optional<Suite> load_suite(const std::string& path, SourceManager& sources, FileReader& reader,
                                DiagEngine& diags) {
  return SuiteLoader(sources, diags).load(path, reader);
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

Json suite_report_json(const Suite& suite, const SuiteReport& report) {
  Json pairs = Json::array();
  for (const PairResult& r : report.results) {
    const PairIdentity train{r.pair->train.label(), r.train ? r.train->sha256() : ""};
    const PairIdentity eval{r.pair->eval.label(), r.eval ? r.eval->sha256() : ""};
    Json j = certificate_json(train, eval, r.diff, r.cert);
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
