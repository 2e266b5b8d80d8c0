// Suite manifests: reading a manifest (its pairs, sweeps, allowances and training mixtures) and the schedule
// files its pairs name into a Suite; structural errors go to the diagnostics, located.
#include "compiler/analysis/suite.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <map>

#include "compiler/basic/spell.h"
#include "compiler/parse/compose.h"

namespace fs = std::filesystem;

namespace kage {

std::string ConfigRef::label() const { return inline_doc ? "(inline)" : path; }

std::vector<std::string> TrainMixture::configs() const {
  std::vector<std::string> out;
  for (const TrainStage& stage : stages)
    for (const WeightedConfig& c : stage.configs)
      if (std::find(out.begin(), out.end(), c.path) == out.end()) out.push_back(c.path);
  return out;
}

std::string TrainMixture::label() const {
  return schedule.empty() ? "mixture of " + std::to_string(configs().size()) : schedule;
}

namespace {

class SuiteLoader {
 public:
  SuiteLoader(SourceManager& sources, FileReader& reader, DiagEngine& diags, std::string shipped_configs)
      : sources_(sources), reader_(reader), diags_(diags), shipped_configs_(std::move(shipped_configs)) {}

  std::optional<Suite> load(const std::string& path) {
    FileReader& reader = reader_;
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
    const std::optional<std::string> path = find_config(std::get<std::string>(v), suite.dir, false, e->value.range);
    if (!path) return std::nullopt;
    ref.path = *path;
    return ref;
  }

  /// `train:` of a pair or sweep: one config (`ref`), or a mixture or schedule (`mixture`). False on errors.
  bool training_of(const DocNode& map, const Suite& suite, ConfigRef& ref, std::optional<TrainMixture>& mixture) {
    const DocEntry* e = map.find("train");
    if (e && e->value.is_seq()) {
      TrainStage stage;
      if (!stage_configs(e->value, nullptr, suite.dir, false, stage)) return false;
      mixture = TrainMixture{{}, {std::move(stage)}};
      return true;
    }
    if (e && e->value.is_map() && e->value.find("schedule")) {
      for (const DocEntry& k : e->value.entries)
        if (k.key != "schedule") {
          diags_.report(Rule::SuiteInvalid, k.key_range,
                        "unknown key '" + k.key + "' beside 'schedule'; write {schedule: PATH} alone");
          return false;
        }
      const Scalar v = scalar_value(e->value.find("schedule")->value);
      if (!std::holds_alternative<std::string>(v)) {
        diags_.report(Rule::SuiteInvalid, e->value.find("schedule")->value.range,
                      "'schedule' must be the path of a schedule file (a YAML list of stages)");
        return false;
      }
      return load_schedule(join_path(suite.dir, std::get<std::string>(v)), e->value.find("schedule")->value.range,
                           mixture);
    }
    if (e && e->value.is_map() && e->value.entries.size() == 1 &&
        suggest(e->value.entries[0].key, {"schedule"})) {  // {schedul: PATH}: not an inline config
      diags_.report(Rule::SuiteInvalid, e->value.entries[0].key_range,
                    "unknown key '" + e->value.entries[0].key + "' in 'train'; did you mean 'schedule'? (write "
                    "{schedule: PATH}; any other mapping here is an inline config)");
      return false;
    }
    auto one = config_of(map, "train", suite);
    if (!one) return false;
    ref = std::move(*one);
    return true;
  }

  /// The configs of a mixture (a list of PATH or {config: PATH, weight: W}), or of a schedule's stage (`configs`
  /// with `weights` beside it, in a schedule file, where names of shipped configs are taken too).
  bool stage_configs(const DocNode& list, const DocEntry* weights, const std::string& dir, bool in_schedule,
                     TrainStage& stage) {
    if (list.items.empty()) {
      diags_.report(in_schedule ? Rule::SuiteScheduleInvalid : Rule::SuiteInvalid, list.range,
                    "a mixture needs at least one config");
      return false;
    }
    bool ok = true;
    for (const DocNode& item : list.items) {
      WeightedConfig c;
      c.range = item.range;
      const DocNode* path = &item;
      if (item.is_map() && !in_schedule) {
        for (const DocEntry& k : item.entries)
          if (k.key != "config" && k.key != "weight") {
            diags_.report(Rule::SuiteInvalid, k.key_range,
                          "unknown key '" + k.key + "' in a mixture's config; expected config and weight");
            ok = false;
          }
        const DocEntry* config = item.find("config");
        if (!config) {
          diags_.report(Rule::SuiteInvalid, item.range, "a mixture's config needs 'config: PATH'");
          ok = false;
          continue;
        }
        path = &config->value;
        if (const DocEntry* w = item.find("weight")) ok = weight_of(w->value, c.weight) && ok;
      }
      const Scalar v = scalar_value(*path);
      if (!std::holds_alternative<std::string>(v)) {
        diags_.report(in_schedule ? Rule::SuiteScheduleInvalid : Rule::SuiteInvalid, path->range,
                      in_schedule ? "each config of a stage must be a path or a shipped config's name"
                                  : "each config of a mixture must be a path or {config: PATH, weight: W}");
        ok = false;
        continue;
      }
      const std::optional<std::string> found = find_config(std::get<std::string>(v), dir, in_schedule, path->range);
      if (!found) {
        ok = false;
        continue;
      }
      c.path = *found;
      stage.configs.push_back(std::move(c));
    }
    if (weights && ok) {
      if (!weights->value.is_seq() || weights->value.items.size() != stage.configs.size()) {
        diags_.report(Rule::SuiteScheduleInvalid, weights->value.range,
                      "'weights' must be a list of " + std::to_string(stage.configs.size()) +
                          " numbers, one per config of the stage");
        return false;
      }
      for (size_t i = 0; i < stage.configs.size(); ++i)
        ok = weight_of(weights->value.items[i], stage.configs[i].weight) && ok;
    }
    if (ok && std::all_of(stage.configs.begin(), stage.configs.end(),
                          [](const WeightedConfig& c) { return c.weight == 0; })) {
      diags_.report(Rule::SuiteMixtureWeight, weights ? weights->value.range : list.range,
                    "every weight of this mixture is 0, so no environment would run any of its configs; give "
                    "one config a weight above 0");
      ok = false;
    }
    return ok;
  }

  bool weight_of(const DocNode& node, double& weight) {
    const Scalar v = scalar_value(node);
    double w = std::nan("");
    if (std::holds_alternative<int64_t>(v)) w = static_cast<double>(std::get<int64_t>(v));
    if (std::holds_alternative<double>(v)) w = std::get<double>(v);
    if (!std::isfinite(w) || w < 0) {
      diags_.report(Rule::SuiteMixtureWeight, node.range,
                    "weight '" + node.text + "' is not a finite number >= 0; a weight is a config's share of "
                    "the batch (default 1): write a number such as 1 or 0.5");
      return false;
    }
    weight = w;
    return true;
  }

  /// `name` as a file relative to `dir`, else (in a schedule) a shipped config's name; reported where absent.
  std::optional<std::string> find_config(const std::string& name, const std::string& dir, bool in_schedule,
                                         Range at) {
    std::string err;
    const std::string path = join_path(dir, name);
    if (reader_.read(path, &err)) return path;
    if (in_schedule && !shipped_configs_.empty()) {
      const bool has_ext = name.size() > 5 && name.compare(name.size() - 5, 5, ".yaml") == 0;
      const std::string shipped = join_path(shipped_configs_, has_ext ? name : name + ".yaml");
      std::string ignored;
      if (reader_.read(shipped, &ignored)) return shipped;
    }
    diags_.report(Rule::SuiteUnknownConfig, at,
                  "unknown config '" + name + "': cannot read '" + path + "' (" + err + ")" +
                      (in_schedule ? ", and it is not a shipped config's name (such as kage_bench/bases/shape_black)"
                                   : "") +
                      "; a path is relative to the " + (in_schedule ? "schedule file" : "manifest"));
    return std::nullopt;
  }

  /// A schedule file: a list of stages {start, configs, weights?}, the first at 1, each later one after the one before.
  bool load_schedule(const std::string& path, Range named_at, std::optional<TrainMixture>& mixture) {
    std::string err;
    const auto text = reader_.read(path, &err);
    if (!text) {
      diags_.report(Rule::SuiteUnknownConfig, named_at,
                    "cannot read schedule '" + path + "' (" + err + "); the path is relative to the manifest");
      return false;
    }
    const FileId file = sources_.add(path, *text);
    const auto doc = parse_yaml(sources_, file, diags_);
    if (!doc) return false;
    const std::string shape = "; a schedule is a list of stages such as '- {start: 1, configs: [a.yaml, b.yaml], "
                              "weights: [3, 1]}'";
    if (!doc->is_seq() || doc->items.empty()) {
      diags_.report(Rule::SuiteScheduleInvalid, doc->is_null() ? Range{Loc{file, 0}, 0} : doc->range,
                    std::string("the schedule is a YAML ") + kind_name(*doc) + ", not a list of stages" + shape);
      return false;
    }
    TrainMixture out;
    out.schedule = path;
    const std::string dir = parent_dir(path);
    bool ok = true;
    const DocNode* previous = nullptr;
    for (const DocNode& item : doc->items) {
      if (!item.is_map()) {
        diags_.report(Rule::SuiteScheduleInvalid, item.range,
                      std::string("a stage is a mapping, not a ") + kind_name(item) + shape);
        ok = false;
        continue;
      }
      for (const DocEntry& k : item.entries)
        if (k.key != "start" && k.key != "configs" && k.key != "weights") {
          diags_.report(Rule::SuiteScheduleInvalid, k.key_range,
                        "unknown key '" + k.key + "' in a stage; expected start, configs and weights");
          ok = false;
        }
      const DocEntry* start = item.find("start");
      const DocEntry* configs = item.find("configs");
      if (!start || !configs || !configs->value.is_seq()) {
        diags_.report(Rule::SuiteScheduleInvalid, item.range,
                      "a stage needs 'start' (its first training iteration) and 'configs' (a list)" + shape);
        ok = false;
        continue;
      }
      const Scalar s = scalar_value(start->value);
      if (!std::holds_alternative<int64_t>(s) || std::get<int64_t>(s) < 1) {
        diags_.report(Rule::SuiteScheduleInvalid, start->value.range,
                      "'start' must be a training iteration, an integer counted from 1");
        ok = false;
        continue;
      }
      TrainStage stage;
      stage.start = std::get<int64_t>(s);
      const int64_t before = out.stages.empty() ? 0 : out.stages.back().start;
      if (out.stages.empty() && stage.start != 1) {
        diags_.report(Rule::SuiteScheduleOrder, start->value.range,
                      "the first stage starts at iteration " + std::to_string(stage.start) +
                          "; it must start at 1, so that training has a mixture from its first iteration");
        ok = false;
      } else if (!out.stages.empty() && stage.start <= before) {
        const LineCol at = sources_.line_col(previous->range.begin);
        diags_.report(Rule::SuiteScheduleOrder, start->value.range,
                      "this stage starts at iteration " + std::to_string(stage.start) +
                          ", not after the stage before it (line " + std::to_string(at.line) + ", start " +
                          std::to_string(before) + "); list stages in the order they start");
        ok = false;
      }
      if (!stage_configs(configs->value, item.find("weights"), dir, true, stage)) {
        ok = false;
        continue;
      }
      previous = &item;
      out.stages.push_back(std::move(stage));
    }
    if (!ok) return false;
    mixture = std::move(out);
    return true;
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

  /// Reports each key of `map` that is not in `allowed` (the suite schema's properties of `what`), with the
  /// closest allowed key when one is near.
  void check_keys(const DocNode& map, const std::vector<std::string>& allowed, const std::string& what) {
    std::string expected;
    for (const std::string& k : allowed) expected += (expected.empty() ? "" : ", ") + k;
    for (const DocEntry& e : map.entries) {
      if (std::find(allowed.begin(), allowed.end(), e.key) != allowed.end()) continue;
      const std::optional<std::string> near = suggest(e.key, allowed);
      diags_.report(Rule::SuiteInvalid, e.key_range,
                    "unknown key '" + e.key + "' in " + what + (near ? "; did you mean '" + *near + "'?" : "") +
                        " (expected " + expected + ")");
    }
  }

  /// A training config of positive weight that is the eval config's file: the pair holds nothing out (a
  /// leave-one-out mixture that leaves nothing out, say).
  void warn_eval_in_training(const TrainMixture& mixture, const ConfigRef& eval) {
    if (eval.inline_doc) return;
    std::error_code ec;
    const fs::path eval_path = fs::weakly_canonical(eval.path, ec);
    if (ec) return;
    for (const TrainStage& stage : mixture.stages)
      for (const WeightedConfig& c : stage.configs) {
        std::error_code same_ec;
        if (c.weight > 0 && fs::weakly_canonical(c.path, same_ec) == eval_path && !same_ec) {
          diags_.report(Rule::SuiteEvalInTraining, c.range,
                        "the eval config '" + eval.path + "' is also a training config here: the pair does not hold "
                        "its eval look out; drop it from the training (or give it weight 0) for a held-out pair");
          return;
        }
      }
  }

  void add_pair(Suite& suite, const DocNode& item) {
    check_keys(item, {"name", "description", "axis", "train", "eval", "allow"}, "a pair");
    SuitePair p;
    p.name = text_of(item, "name", true);
    p.range = item.range;
    const auto axis = axis_of(item);
    const bool train = training_of(item, suite, p.train, p.mixture);
    auto eval = config_of(item, "eval", suite);
    p.allow = allow_of(item);
    if (!axis || !train || !eval) return;
    if (p.mixture) warn_eval_in_training(*p.mixture, *eval);
    p.axis = *axis;
    p.eval = std::move(*eval);
    suite.pairs.push_back(std::move(p));
  }

  void add_sweep(Suite& suite, const DocNode& item) {
    check_keys(item, {"name", "description", "axis", "train", "evals", "allow"}, "a sweep");
    const std::string name = text_of(item, "name", true);
    const auto axis = axis_of(item);
    ConfigRef train_ref;
    std::optional<TrainMixture> mixture;
    const bool train = training_of(item, suite, train_ref, mixture);
    const std::vector<Allowance> allow = allow_of(item);
    const DocEntry* evals = item.find("evals");
    if (!evals) {
      diags_.report(Rule::SuiteInvalid, item.range, "a sweep needs 'evals'");
      return;
    }
    for_each_item(*evals, [&](const DocNode& ev) {
      check_keys(ev, {"name", "config", "allow"}, "a sweep's eval");
      SuitePair p;
      p.sweep = name;
      p.sweep_eval = text_of(ev, "name", true);
      p.name = name + "/" + p.sweep_eval;
      p.range = ev.range;
      auto config = config_of(ev, "config", suite);
      if (!axis || !train || !config) return;
      if (mixture) warn_eval_in_training(*mixture, *config);
      p.axis = *axis;
      p.train = train_ref;
      p.mixture = mixture;
      p.eval = std::move(*config);
      p.allow = allow;
      for (Allowance& a : allow_of(ev)) p.allow.push_back(a);
      suite.pairs.push_back(std::move(p));
    });
  }

  SourceManager& sources_;
  FileReader& reader_;
  DiagEngine& diags_;
  std::string shipped_configs_;
};

}  // namespace

std::optional<Suite> load_suite(const std::string& path, SourceManager& sources, FileReader& reader,
                                DiagEngine& diags, const std::string& shipped_configs) {
  return SuiteLoader(sources, reader, diags, shipped_configs).load(path);
}

}  // namespace kage
