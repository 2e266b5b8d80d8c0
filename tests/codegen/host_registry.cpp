// Registry of the generated host configs (filled before main by the generated TUs).
#include "tests/codegen/host_registry.h"

namespace kage::test {

namespace {
std::map<std::string, HostEntryPoints>& registry() {
  static std::map<std::string, HostEntryPoints> r;
  return r;
}
}  // namespace

bool register_host_config(const char* config_path, const HostEntryPoints& entry_points) {
  registry()[config_path] = entry_points;
  return true;
}

const std::map<std::string, HostEntryPoints>& host_configs() { return registry(); }

}  // namespace kage::test
