// The configs and suites shipped beside kagec (<runtime_include_dir()>/configs, /suites), for a hint when
// a command is given a name that is no file here: the Python tools take shipped names, kagec takes paths.
#pragma once

#include <string>
#include <vector>

#include "driver/commands.h"

namespace kage {

/// The shipped files of `kind` ("configs" or "suites") that `value` may have meant when it names no file:
/// <kind>/<value>.yaml (".yaml" and a leading "<kind>/" optional), else every shipped file whose name
/// relative to <kind> ends with "/<value>.yaml", at most five. Empty when `value` exists.
std::vector<std::string> shipped_matches(const std::string& kind, const std::string& value);

/// After a command could not read `file`: one line naming the shipped file(s) it may have meant, if any.
void hint_shipped(const char* command, const std::string& kind, const std::string& file, CommandIo& io);

}  // namespace kage
