// kagec lint, resolve, rules, schema.
#include <ostream>

#include "compiler/cli_common.h"
#include "compiler/file_out.h"
#include "compiler/schema.h"

namespace kage {

int cmd_lint(const std::vector<std::string>& args, CommandIo& io) {
  CLI::App app("Check config files against the schema and the original's rules.", "lint");
  std::vector<std::string> files;
  DiagOptions opts;
  app.add_option("files", files, "config files")->required();
  opts.add_to(app);
  if (auto code = parse_args(app, args, io)) return *code;
  SourceManager sources;
  DiagEngine diags(sources);
  if (!opts.apply(diags, io)) return kExitUsage;
  DiskFileReader reader;
  for (const std::string& f : files) analyze_file(f, opts.resolve_options(), sources, reader, diags);
  emit_diagnostics(diags, opts, io);
  if (opts.format == "text") {
    const size_t e = diags.error_count(), w = diags.warning_count();
    if (e || w) io.err << e << " error" << (e == 1 ? "" : "s") << ", " << w << " warning" << (w == 1 ? "" : "s") << "\n";
  }
  return diags.has_errors() ? kExitErrors : kExitOk;
}

int cmd_resolve(const std::vector<std::string>& args, CommandIo& io) {
  CLI::App app("Print the canonical Spec of a config (every value explicit) and its SHA-256.", "resolve");
  std::string file, output;
  DiagOptions opts;
  app.add_option("file", file, "config file")->required();
  app.add_option("-o,--output", output, "write the Spec here instead of standard output");
  opts.add_to(app, false);
  if (auto code = parse_args(app, args, io)) return *code;
  int exit_code = kExitOk;
  const auto spec = resolve_file("resolve", file, opts, io, &exit_code);
  if (!spec) return exit_code;
  if (output.empty()) {
    io.out << spec->canonical_text();
  } else {
    std::string error;
    if (!write_file(output, spec->canonical_text(), &error)) {
      io.err << "kagec resolve: " << error << '\n';
      return kExitErrors;
    }
  }
  return kExitOk;
}

int cmd_rules(const std::vector<std::string>& args, CommandIo& io) {
  CLI::App app("List every diagnostic rule.", "rules");
  if (auto code = parse_args(app, args, io)) return *code;
  for (const RuleInfo& r : all_rules()) {
    std::string id = r.id;
    id.resize(30, ' ');
    std::string sev = severity_name(r.severity);
    sev.resize(9, ' ');
    io.out << id << sev << r.doc << '\n';
  }
  return kExitOk;
}

int cmd_schema(const std::vector<std::string>& args, CommandIo& io) {
  CLI::App app("Print a JSON Schema (config by default).", "schema");
  bool suite = false;
  app.add_flag("--suite", suite, "print the suite manifest schema instead");
  if (auto code = parse_args(app, args, io)) return *code;
  io.out << (suite ? suite_schema_text() : config_schema_text());
  return kExitOk;
}

}  // namespace kage
