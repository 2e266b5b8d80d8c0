// kagec suite MANIFEST [-o DIR].
#include <filesystem>
#include <fstream>
#include <ostream>

#include "compiler/analysis/suite.h"
#include "compiler/basic/file_out.h"
#include "compiler/codegen/build.h"
#include "driver/cli_common.h"
#include "verify/isolation/isolation.h"

namespace kage {

namespace fs = std::filesystem;

namespace {

/// Adds "dynamic_isolation" to each pair's certificate (verify/isolation/isolation.h); returns the failures.
size_t add_isolation_evidence(const SuiteReport& report, Json& json, std::ostream& out) {
  size_t failures = 0;
  for (size_t i = 0; i < report.results.size(); ++i) {
    const PairResult& r = report.results[i];
    if (!r.train || !r.eval) continue;  // a mixture pair has no one train Spec: its evidence is its certificate
    IsolationOptions options;
    options.latent_pair = r.pair->axis == Axis::Latent;
    const IsolationEvidence ev = dynamic_isolation(*r.train, *r.eval, config_schema(), options);
    json["pairs"][i]["dynamic_isolation"] = ev.to_json(options);
    failures += ev.ok() ? 0 : 1;
    out << "  " << r.pair->name << ": dynamics " << (ev.dynamics_source_identical ? "identical" : "DIFFER")
        << ", trajectories " << (ev.trajectories_identical ? "identical" : "DIVERGE") << ", mean |train - eval| "
        << ev.mean_abs_pixel_diff << (ev.ok() ? "" : "  FAILED") << '\n';
    for (const std::string& p : ev.problems) out << "    " << p << '\n';
  }
  return failures;
}

}  // namespace

int cmd_suite(const std::vector<std::string>& args, CommandIo& io) {
  CLI::App app("Lint and certify every train/eval pair of a suite manifest.", "suite");
  std::string manifest, out_dir;
  bool verbose = false, compile = false;
  DiagOptions opts;
  app.add_option("manifest", manifest, "suite manifest (YAML)")->required();
  app.add_option("-o,--output", out_dir, "directory for report.json and one certificate per pair (default: out/<suite>)");
  app.add_flag("-v,--verbose", verbose, "also print the warnings of every config");
  app.add_flag("--compile", compile,
               "also gather dynamic isolation evidence per pair (generated dynamics, latent trajectories, frames)");
  opts.add_to(app, false);
  if (auto code = parse_args(app, args, io)) return *code;
  SourceManager sources;
  DiagEngine diags(sources);
  if (!opts.apply(diags, io)) return kExitUsage;
  DiskFileReader reader;
  // A schedule may name shipped configs (kage_bench/bases/shape_black), found beside the runtime headers.
  const auto suite = load_suite(manifest, sources, reader, diags, runtime_include_dir() + "/configs");
  if (!suite || diags.has_errors()) {
    print_text(diags, io.err, io.err_is_terminal);
    hint_shipped("suite", "suites", manifest, io);
    return kExitErrors;
  }
  const fs::path dir = out_dir.empty() ? fs::path("out") / suite->name : fs::path(out_dir);
  // The report and its certificates replace the directory whole (no certificate of an earlier run
  // survives beside them), and only a directory that holds nothing but an earlier report is replaced.
  if (const auto problem = suite_output_dir_problem(dir)) {
    io.err << "kagec suite: " << *problem << '\n';
    return kExitUsage;
  }
  const SuiteReport report =
      run_suite(*suite, opts.resolve_options(), sources, reader, diags, io.err_is_terminal ? &io.err : nullptr);
  if (!verbose) diags.disable_warnings();
  print_text(diags, io.err, io.err_is_terminal);
  print_suite_table(*suite, report, io.out);

  Json json = suite_report_json(*suite, report);
  size_t isolation_failures = 0;
  if (compile) isolation_failures = add_isolation_evidence(report, json, io.out);
  std::string error;
  const std::optional<fs::path> staging = make_staging_dir(dir, &error);
  if (!staging) {
    io.err << "kagec suite: " << error << '\n';
    return kExitErrors;
  }
  struct Cleanup {  // removes the staging directory unless it was published
    fs::path path;
    ~Cleanup() {
      std::error_code ec;
      if (!path.empty()) fs::remove_all(path, ec);
    }
  } cleanup{*staging};
  std::error_code ec;
  fs::create_directory(*staging / kSuiteCertificateDir, ec);
  bool written = !ec;
  if (ec) error = "cannot create '" + (*staging / kSuiteCertificateDir).string() + "': " + ec.message();
  if (written) written = write_file((*staging / kSuiteReportFile).string(), json_file_text(json), &error);
  for (const Json& pair : json.at("pairs")) {
    if (!written) break;
    written = write_file((*staging / kSuiteCertificateDir / certificate_file_name(pair.at("pair").get<std::string>())).string(),
                         json_file_text(pair), &error);
  }
  if (!written || !publish_staging_dir(*staging, dir, &error)) {
    io.err << "kagec suite: " << error << '\n';
    return kExitErrors;
  }
  cleanup.path.clear();
  io.out << "report: " << (dir / kSuiteReportFile).string() << '\n';
  return report.passed() == report.results.size() && isolation_failures == 0 ? kExitOk : kExitErrors;
}

}  // namespace kage
