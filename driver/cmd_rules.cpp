// kagec rules: every diagnostic rule of compiler/basic/diag_rules.def with its severity.
#include <ostream>

#include "driver/cli_common.h"

namespace kage {

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

}  // namespace kage
