// The generated host configs compiled into the codegen test binary, by config path.
#pragma once

#include <map>
#include <string>

#include "runtime/cpu/specialized_env.h"

namespace kage::test {

/// Called from each generated TU's static initializer; returns true.
bool register_host_config(const char* config_path, const HostEntryPoints& entry_points);

/// Config path (relative to the source tree) -> its generated entry points.
const std::map<std::string, HostEntryPoints>& host_configs();

}  // namespace kage::test
