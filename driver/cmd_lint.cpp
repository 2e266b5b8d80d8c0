// kagec lint FILE...: every diagnostic of the front end, as text or JSON, with a count.
#include <ostream>

#include "driver/cli_common.h"

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
  for (const std::string& f : files) hint_shipped("lint", "configs", f, io);
  return diags.has_errors() ? kExitErrors : kExitOk;
}

}  // namespace kage
