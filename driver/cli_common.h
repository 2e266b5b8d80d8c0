// Options shared by the commands that read configs (CLI11 glue).
#pragma once

#include <CLI/CLI.hpp>
#include <string>
#include <vector>

#include "compiler/basic/diag.h"
#include "compiler/basic/file_out.h"
#include "driver/commands.h"
#include "driver/shipped_names.h"
#include "compiler/lower/load_lowered.h"
#include "compiler/sema/resolve.h"

namespace kage {

struct DiagOptions {
  std::string format = "text";
  bool werror = false;
  std::vector<std::string> disabled;
  std::string asset_root;

  void add_to(CLI::App& app, bool with_format = true);
  /// Applies --Werror/--disable; reports unknown rule ids to io.err. False on a usage error.
  bool apply(DiagEngine& diags, CommandIo& io) const;
  ResolveOptions resolve_options() const;
};

/// Parses `args` into `app`; on --help or a usage error prints and returns the exit code.
std::optional<int> parse_args(CLI::App& app, const std::vector<std::string>& args, CommandIo& io);

/// Runs the front end on one config and prints its diagnostics. Returns the Spec, or nullopt with
/// *exit_code set (usage error or errors in the file) after telling the user why.
std::optional<Spec> resolve_file(const char* command, const std::string& file, const DiagOptions& opts,
                                 CommandIo& io, int* exit_code);

/// resolve_file, then lowering: the config the runtime runs (with its Spec), or nullopt with *exit_code
/// set after telling the user why (errors in the file, or settings the runtime cannot hold).
std::optional<LoweredFile> lower_file(const char* command, const std::string& file, const DiagOptions& opts,
                                      CommandIo& io, int* exit_code);

/// Prints diagnostics in the chosen format.
void emit_diagnostics(const DiagEngine& diags, const DiagOptions& opts, CommandIo& io);

}  // namespace kage
