// kagec suite MANIFEST [-o DIR].
#include <filesystem>
#include <fstream>
#include <ostream>

#include "compiler/cli_common.h"
#include "compiler/suite.h"

namespace kage {

namespace fs = std::filesystem;

int cmd_suite(const std::vector<std::string>& args, CommandIo& io) {
  CLI::App app("Lint and certify every train/eval pair of a suite manifest.", "suite");
  std::string manifest, out_dir;
  bool verbose = false;
  DiagOptions opts;
  app.add_option("manifest", manifest, "suite manifest (YAML)")->required();
  app.add_option("-o,--output", out_dir, "directory for report.json and one certificate per pair (default: out/<suite>)");
  app.add_flag("-v,--verbose", verbose, "also print the warnings of every config");
  opts.add_to(app, false);
  if (auto code = parse_args(app, args, io)) return *code;
  SourceManager sources;
  DiagEngine diags(sources);
  if (!opts.apply(diags, io)) return kExitUsage;
  DiskFileReader reader;
  const auto suite = load_suite(manifest, sources, reader, diags);
  if (!suite || diags.has_errors()) {
    print_text(diags, io.err, io.err_is_terminal);
    return kExitErrors;
  }
  const SuiteReport report =
      run_suite(*suite, opts.resolve_options(), sources, reader, diags, io.err_is_terminal ? &io.err : nullptr);
  if (!verbose) diags.disable_warnings();
  print_text(diags, io.err, io.err_is_terminal);
  print_suite_table(*suite, report, io.out);

  const fs::path dir = out_dir.empty() ? fs::path("out") / suite->name : fs::path(out_dir);
  std::error_code ec;
  fs::create_directories(dir / "certificates", ec);
  const Json json = suite_report_json(*suite, report);
  std::ofstream f(dir / "report.json", std::ios::binary);
  f << json.dump(2) << '\n';
  for (const Json& pair : json.at("pairs")) {
    std::string name = pair.at("pair").get<std::string>();
    for (char& c : name)
      if (c == '/' || c == ' ') c = '_';
    std::ofstream cf(dir / "certificates" / (name + ".json"), std::ios::binary);
    cf << pair.dump(2) << '\n';
  }
  if (!f || ec) {
    io.err << "kagec suite: cannot write the report under '" << dir.string() << "'\n";
    return kExitErrors;
  }
  io.out << "report: " << (dir / "report.json").string() << '\n';
  return report.passed() == report.results.size() ? kExitOk : kExitErrors;
}

}  // namespace kage
