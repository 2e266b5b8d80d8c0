// kagec schema [--suite]: the embedded JSON Schema of configs or suite manifests, for editors.
#include <ostream>

#include "driver/cli_common.h"
#include "compiler/sema/schema.h"

namespace kage {

int cmd_schema(const std::vector<std::string>& args, CommandIo& io) {
  CLI::App app("Print a JSON Schema (config by default).", "schema");
  bool suite = false;
  app.add_flag("--suite", suite, "print the suite manifest schema instead");
  if (auto code = parse_args(app, args, io)) return *code;
  io.out << (suite ? suite_schema_text() : config_schema_text());
  return kExitOk;
}

}  // namespace kage
