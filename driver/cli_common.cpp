// CLI11 glue shared by the commands.
#include "driver/cli_common.h"

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

namespace {

/// Applies the options, runs `analyze` against a fresh diagnostics engine and prints what it reported;
/// false with *exit_code set on a usage error, or when `analyze` produced nothing or errors were reported.
template <class Analyze>
bool run_front_end(const char* command, const DiagOptions& opts, CommandIo& io, int* exit_code, Analyze analyze) {
  SourceManager sources;
  DiagEngine diags(sources);
  if (!opts.apply(diags, io)) {
    *exit_code = kExitUsage;
    return false;
  }
  DiskFileReader reader;
  const bool produced = analyze(sources, reader, diags);
  print_text(diags, io.err, io.err_is_terminal);
  if (produced && !diags.has_errors()) return true;
  io.err << "kagec " << command << ": no Spec: fix the errors above\n";
  *exit_code = kExitErrors;
  return false;
}

}  // namespace

std::optional<Spec> resolve_file(const char* command, const std::string& file, const DiagOptions& opts,
                                 CommandIo& io, int* exit_code) {
  std::optional<Spec> spec;
  const bool ok = run_front_end(command, opts, io, exit_code, [&](SourceManager& s, FileReader& r, DiagEngine& d) {
    spec = analyze_file(file, opts.resolve_options(), s, r, d);
    return spec.has_value();
  });
  if (!ok) hint_shipped(command, "configs", file, io);
  return ok ? spec : std::nullopt;
}

std::optional<LoweredFile> lower_file(const char* command, const std::string& file, const DiagOptions& opts,
                                      CommandIo& io, int* exit_code) {
  LoweredFile loaded;
  const bool ok = run_front_end(command, opts, io, exit_code, [&](SourceManager& s, FileReader& r, DiagEngine& d) {
    loaded = load_lowered(file, opts.resolve_options(), s, r, d);
    return loaded.spec.has_value();
  });
  if (!ok) {
    hint_shipped(command, "configs", file, io);
    return std::nullopt;
  }
  if (!loaded.ok()) {
    io.err << loaded.lower_errors << "kagec " << command << ": the runtime cannot hold this config\n";
    *exit_code = kExitErrors;
    return std::nullopt;
  }
  return loaded;
}

void emit_diagnostics(const DiagEngine& diags, const DiagOptions& opts, CommandIo& io) {
  if (opts.format == "json")
    print_json(diags, io.out);
  else
    print_text(diags, io.err, io.err_is_terminal);
}

}  // namespace kage
