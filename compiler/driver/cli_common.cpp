// CLI11 glue shared by the commands.
#include "compiler/driver/cli_common.h"

#include <ostream>

namespace kage {

void DiagOptions::add_to(CLI::App& app, bool with_format) {
  if (with_format)
    app.add_option("--format", format, "diagnostic format")->check(CLI::IsMember({"text", "json"}));
  app.add_flag("--Werror", werror, "treat warnings as errors");
  app.add_option("--disable", disabled, "silence a rule (repeatable), e.g. --disable inert-setting");
  app.add_option("--asset-root", asset_root,
                 "resolve asset paths against this directory (default: the directory of the file that names them)");
}

bool DiagOptions::apply(DiagEngine& diags, CommandIo& io) const {
  diags.set_werror(werror);
  for (const std::string& id : disabled) {
    if (!find_rule(id)) {
      io.err << "kagec: unknown rule '" << id << "' for --disable; 'kagec rules' lists them\n";
      return false;
    }
    diags.disable(id);
  }
  return true;
}

ResolveOptions DiagOptions::resolve_options() const {
  ResolveOptions r;
  if (!asset_root.empty()) r.asset_root = asset_root;
  return r;
}

std::optional<int> parse_args(CLI::App& app, const std::vector<std::string>& args, CommandIo& io) {
  std::vector<std::string> reversed(args.rbegin(), args.rend());
  try {
    app.parse(reversed);
  } catch (const CLI::CallForHelp&) {
    io.out << app.help();
    return kExitOk;
  } catch (const CLI::ParseError& e) {
    io.err << "kagec " << app.get_name() << ": " << e.what() << "\n" << "Run with --help for usage.\n";
    return kExitUsage;
  }
  return std::nullopt;
}

std::optional<Spec> resolve_file(const char* command, const std::string& file, const DiagOptions& opts,
                                 CommandIo& io, int* exit_code) {
  SourceManager sources;
  DiagEngine diags(sources);
  if (!opts.apply(diags, io)) {
    *exit_code = kExitUsage;
    return std::nullopt;
  }
  DiskFileReader reader;
  auto spec = analyze_file(file, opts.resolve_options(), sources, reader, diags);
  print_text(diags, io.err, io.err_is_terminal);
  if (!spec || diags.has_errors()) {
    io.err << "kagec " << command << ": no Spec: fix the errors above\n";
    *exit_code = kExitErrors;
    return std::nullopt;
  }
  return spec;
}

void emit_diagnostics(const DiagEngine& diags, const DiagOptions& opts, CommandIo& io) {
  if (opts.format == "json")
    print_json(diags, io.out);
  else
    print_text(diags, io.err, io.err_is_terminal);
}

}  // namespace kage
