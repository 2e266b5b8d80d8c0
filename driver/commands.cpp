// Dispatch over the command table.
#include "driver/commands.h"

#include <ostream>

#include "compiler/basic/spell.h"

namespace kage {

const std::vector<Command>& commands() {
  static const std::vector<Command> table = {
      {"lint", "check config files and report diagnostics", cmd_lint},
      {"resolve", "print the canonical Spec of a config and its SHA-256", cmd_resolve},
      {"diff", "list the effective differences of a train/eval pair by axis; --certify checks one axis", cmd_diff},
      {"compile", "generate a config's specialized source and build its kernels (fatbin, host library)", cmd_compile},
      {"suite", "lint and certify every pair of a suite manifest", cmd_suite},
      {"rules", "list every diagnostic rule with its severity", cmd_rules},
      {"schema", "print the configuration JSON Schema (for editors)", cmd_schema},
      {"render", "run one environment and write its frames as PNG, GIF or a contact sheet", cmd_render},
      {"bench", "measure environment steps per second (--cpu, or --gpu against a copy roofline)", cmd_bench},
      {"golden", "check the runtime against the reference data of the original (golden check)", cmd_golden},
      {"docs", "print a reference page: config-keys or diagnostics", cmd_docs},
  };
  return table;
}

namespace {

void print_usage(std::ostream& out) {
  out << "usage: kagec <command> [options]\n\ncommands:\n";
  for (const Command& c : commands()) {
    std::string name = c.name;
    name.resize(10, ' ');
    out << "  " << name << c.summary << '\n';
  }
  out << "\nRun 'kagec <command> --help' for the options of a command.\n";
}

}  // namespace

int run_kagec(const std::vector<std::string>& args, CommandIo& io) {
  if (args.empty()) {
    print_usage(io.err);
    return kExitUsage;
  }
  const std::string& name = args[0];
  if (name == "--help" || name == "-h" || name == "help") {
    print_usage(io.out);
    return kExitOk;
  }
  if (name == "--version") {
    io.out << "kagec 0.1.0\n";
    return kExitOk;
  }
  std::vector<std::string> names;
  for (const Command& c : commands()) {
    if (name == c.name) return c.run(std::vector<std::string>(args.begin() + 1, args.end()), io);
    names.push_back(c.name);
  }
  io.err << "kagec: unknown command '" << name << "'";
  if (const auto guess = suggest(name, names)) io.err << "; did you mean '" << *guess << "'?";
  io.err << "\n";
  print_usage(io.err);
  return kExitUsage;
}

}  // namespace kage
