// Hints for shipped names given where kagec wants a path (driver/shipped_names.h).
#include "driver/shipped_names.h"

#include <algorithm>
#include <filesystem>
#include <ostream>

#include "compiler/codegen/build.h"

namespace fs = std::filesystem;

namespace kage {

namespace {

constexpr size_t kMostMatches = 5;

bool ends_with(const std::string& text, const std::string& tail) {
  return text.size() >= tail.size() && text.compare(text.size() - tail.size(), tail.size(), tail) == 0;
}

}  // namespace

std::vector<std::string> shipped_matches(const std::string& kind, const std::string& value) {
  std::error_code ec;
  if (value.empty() || fs::exists(value, ec)) return {};
  const fs::path folder = fs::path(runtime_include_dir()) / kind;
  std::string name = value;
  if (ends_with(name, ".yaml")) name.resize(name.size() - 5);
  if (name.rfind(kind + "/", 0) == 0) name = name.substr(kind.size() + 1);
  if (fs::is_regular_file(folder / (name + ".yaml"), ec)) return {(folder / (name + ".yaml")).string()};
  std::vector<std::string> found;
  const std::string tail = "/" + name + ".yaml";
  for (fs::recursive_directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec)) {
    std::error_code entry_ec;
    const std::string relative = "/" + fs::relative(it->path(), folder, entry_ec).generic_string();
    if (!entry_ec && it->is_regular_file(entry_ec) && ends_with(relative, tail)) found.push_back(it->path().string());
  }
  std::sort(found.begin(), found.end());
  if (found.size() > kMostMatches) found.resize(kMostMatches);
  return found;
}

void hint_shipped(const char* command, const std::string& kind, const std::string& file, CommandIo& io) {
  const std::vector<std::string> found = shipped_matches(kind, file);
  if (found.empty()) return;
  io.err << "kagec " << command << ": '" << file << "' is no file here; kagec takes paths, and the shipped "
         << kind.substr(0, kind.size() - 1) << (found.size() == 1 ? " of that name is " : "s of that name are ");
  for (size_t i = 0; i < found.size(); ++i) io.err << (i ? ", " : "") << found[i];
  io.err << '\n';
}

}  // namespace kage
