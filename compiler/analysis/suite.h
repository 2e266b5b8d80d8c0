// Suites: manifests of train/eval pairs (and sweeps: one train, several evals),
// each linted, resolved, diffed and certified against its declared axis. A pair may train on a
// mixture of configs or on a schedule of mixtures (a curriculum) instead of one config.
#pragma once

#include <filesystem>
#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

#include "compiler/analysis/diff.h"
#include "compiler/basic/diag.h"
#include "compiler/parse/yaml_doc.h"
#include "compiler/sema/resolve.h"

namespace kage {

/// One side of a pair: a config file, or a config written inline in the manifest.
struct ConfigRef {
  std::string path;              // set for a file
  std::optional<DocNode> inline_doc;  // set for an inline config
  std::string label() const;
};

/// One config a pair trains on, with its share of the batch.
struct WeightedConfig {
  std::string path;   // resolved against the manifest, or against the schedule file that names it
  double weight = 1;  // finite, >= 0
  Range range;        // where it is written
};

/// From training iteration `start` (counted from 1) on, the mixture of `configs`.
struct TrainStage {
  int64_t start = 1;
  std::vector<WeightedConfig> configs;
};

/// What a pair trains on when it is not one config: a mixture written in the manifest (one stage from
/// iteration 1), or the stages of a schedule file.
struct TrainMixture {
  std::string schedule;  // the schedule file, empty for a mixture written in the manifest
  std::vector<TrainStage> stages;
  /// The distinct configs of every stage, in order of first appearance.
  std::vector<std::string> configs() const;
  /// "mixture of N" (N distinct configs), or the schedule file.
  std::string label() const;
};

struct SuitePair {
  std::string name;
  std::string sweep;       // the sweep this pair belongs to (empty for a plain pair)
  std::string sweep_eval;  // its eval's name within the sweep
  Axis axis = Axis::Background;
  ConfigRef train, eval;
  std::optional<TrainMixture> mixture;  // set when the pair trains on a mixture or a schedule (`train` is then unset)
  std::vector<Allowance> allow;
  Range range;  // where the pair is written
};

struct Suite {
  std::string name;
  std::string description;
  std::string manifest;  // path
  std::string dir;       // for relative paths
  FileId file = kNoFile;
  std::vector<SuitePair> pairs;  // sweeps expanded into pairs
};

/// The file name of a pair's certificate under DIR/certificates/ ('/' and spaces become '_').
std::string certificate_file_name(const std::string& pair_name);

/// Reads a manifest (and the schedule files its pairs name); structural errors go to diags. A schedule's
/// config that is not a file relative to the schedule is looked up as `shipped_configs`/NAME.yaml (the
/// shipped configs' folder, where given).
std::optional<Suite> load_suite(const std::string& path, SourceManager& sources, FileReader& reader,
                                DiagEngine& diags, const std::string& shipped_configs = {});

struct PairResult {
  const SuitePair* pair = nullptr;
  bool lint_ok = false;        // both sides resolved without errors
  size_t warnings = 0;
  std::optional<Spec> train, eval;  // train: unset for a mixture pair
  std::vector<Spec> members;         // a mixture pair's training configs (TrainMixture::configs() order)
  std::vector<SpecDiff> member_diffs;  // each member against the eval (a mixture pair's; `diff` stays empty)
  SpecDiff diff;
  Certification cert;
  bool passed() const { return lint_ok && cert.certified; }
};

struct SuiteReport {
  std::vector<PairResult> results;
  size_t passed() const;
};

/// Lints and certifies every pair; `progress` (may be null) receives one line per pair.
SuiteReport run_suite(const Suite& suite, const ResolveOptions& options, SourceManager& sources, FileReader& reader,
                      DiagEngine& diags, std::ostream* progress);

/// One row per pair: pair, declared axis, measured axes, verdict.
void print_suite_table(const Suite& suite, const SuiteReport& report, std::ostream& out);
/// The JSON report, with a certificate per pair.
Json suite_report_json(const Suite& suite, const SuiteReport& report);

/// The file name of a suite's report inside its output directory, and the folder of its certificates.
inline constexpr const char* kSuiteReportFile = "report.json";
inline constexpr const char* kSuiteCertificateDir = "certificates";

/// Why `dir` cannot receive a suite's report, or nullopt when it can: it is absent, empty, or an
/// earlier `kagec suite` output, that is report.json (a kagec suite report) and certificates/ holding
/// only the certificates of that report's pairs. Anything else is left alone, since the report
/// replaces its directory whole.
std::optional<std::string> suite_output_dir_problem(const std::filesystem::path& dir);

}  // namespace kage
