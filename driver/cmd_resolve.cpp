// kagec resolve FILE [-o OUT]: the canonical Spec of a config (every value explicit), as JSON.
#include <ostream>

#include "compiler/basic/file_out.h"
#include "driver/cli_common.h"

namespace kage {

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

}  // namespace kage
