// The kagec command table: one entry per subcommand drives dispatch, help and did-you-mean.
#pragma once

#include <iosfwd>
#include <string>
#include <vector>

namespace kage {

/// Streams a command writes to; tests pass string streams.
struct CommandIo {
  std::ostream& out;
  std::ostream& err;
  bool err_is_terminal = false;
};

using CommandFn = int (*)(const std::vector<std::string>& args, CommandIo& io);

struct Command {
  const char* name;
  const char* summary;
  CommandFn run;
};

/// Exit codes shared by every command.
inline constexpr int kExitOk = 0;
inline constexpr int kExitErrors = 1;
inline constexpr int kExitUsage = 2;

const std::vector<Command>& commands();

/// Runs `kagec <args...>` (args exclude the program name).
int run_kagec(const std::vector<std::string>& args, CommandIo& io);

// The commands (each in its own cmd_*.cpp).
int cmd_lint(const std::vector<std::string>& args, CommandIo& io);
int cmd_resolve(const std::vector<std::string>& args, CommandIo& io);
int cmd_diff(const std::vector<std::string>& args, CommandIo& io);
int cmd_suite(const std::vector<std::string>& args, CommandIo& io);
int cmd_rules(const std::vector<std::string>& args, CommandIo& io);
int cmd_schema(const std::vector<std::string>& args, CommandIo& io);
int cmd_render(const std::vector<std::string>& args, CommandIo& io);
int cmd_bench(const std::vector<std::string>& args, CommandIo& io);
int cmd_golden(const std::vector<std::string>& args, CommandIo& io);
int cmd_compile(const std::vector<std::string>& args, CommandIo& io);
int cmd_docs(const std::vector<std::string>& args, CommandIo& io);

}  // namespace kage
