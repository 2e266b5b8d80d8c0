// The dependency rules of docs/architecture.md, checked on the #include lines of the source tree:
// no arrow points up (runtime/ <- compiler/ <- api/, verify/ <- driver/), the front end's early stages
// include nothing from runtime/, fileio/ includes only itself, only the driver reaches the verification code,
// and no source includes lab/ (the lab notebook).
#include <catch2/catch.hpp>
#include <initializer_list>
#include <regex>
#include <string>
#include <vector>

#include "test_support.h"

namespace kage::test {
namespace {

/// Every `#include "..."` of the C++ files under `dir`, as "file:line: path".
std::vector<std::pair<std::string, std::string>> project_includes(const std::string& dir) {
  static const std::regex include(R"re(^\s*#\s*include\s+"([^"]+)")re");
  std::vector<std::pair<std::string, std::string>> out;
  for (const auto& e : fs::recursive_directory_iterator(source_dir() / dir)) {
    const std::string ext = e.path().extension().string();
    if (!e.is_regular_file() || (ext != ".cpp" && ext != ".h" && ext != ".cu" && ext != ".cuh")) continue;
    std::istringstream in(read_text(e.path()));
    std::string line;
    for (int n = 1; std::getline(in, line); ++n) {
      std::smatch m;
      if (std::regex_search(line, m, include))
        out.emplace_back(fs::relative(e.path(), source_dir()).generic_string() + ":" + std::to_string(n), m[1]);
    }
  }
  return out;
}

bool starts_with(const std::string& s, const char* prefix) { return s.rfind(prefix, 0) == 0; }

/// The includes under `dirs` of a path starting with one of `above`, one "file:line: path" a line;
/// `seen` counts every include scanned.
std::string includes_of(std::initializer_list<const char*> dirs, std::initializer_list<const char*> above,
                        size_t& seen) {
  std::string report;
  for (const char* dir : dirs) {
    for (const auto& [where, path] : project_includes(dir)) {
      ++seen;
      for (const char* prefix : above)
        if (starts_with(path, prefix)) report += where + ": " + path + "\n";
    }
  }
  return report;
}

}  // namespace

TEST_CASE("basic, parse, sema and analysis include no runtime code", "[layout][one-source-of-truth]") {
  // sema lists, decodes and hashes asset files through fileio/, which the runtime's asset packing shares.
  size_t seen = 0;
  std::vector<std::string> offenders;
  for (const char* dir : {"compiler/basic", "compiler/parse", "compiler/sema", "compiler/analysis"}) {
    for (const auto& [where, path] : project_includes(dir)) {
      ++seen;
      if (starts_with(path, "runtime/")) offenders.push_back(where + ": " + path);
    }
  }
  std::string report;
  for (const std::string& o : offenders) report += o + "\n";
  INFO("includes of the runtime from the front end's early stages:\n" << report);
  CHECK(seen > 50);  // the scan found the stages' own includes
  CHECK(offenders.empty());
}

TEST_CASE("the runtime includes nothing from the compiler, the API, verify/ or the driver", "[layout]") {
  size_t seen = 0;
  const std::string report =
      includes_of({"runtime"}, {"compiler/", "api/", "include/", "kage/", "verify/", "driver/"}, seen);
  INFO("includes of the layers above the runtime:\n" << report);
  CHECK(seen > 150);  // the scan found the runtime's own includes
  CHECK(report.empty());
}

TEST_CASE("the compiler includes nothing from the API, verify/ or the driver", "[layout]") {
  size_t seen = 0;
  // The public header (include/kage/kage.h) is the API's face, so it is above the compiler too.
  const std::string report = includes_of({"compiler"}, {"api/", "include/", "kage/", "verify/", "driver/"}, seen);
  INFO("includes of the layers above the compiler:\n" << report);
  CHECK(seen > 80);
  CHECK(report.empty());
}

TEST_CASE("fileio/ includes only itself, and the API and verify/ nothing from the driver", "[layout]") {
  size_t seen = 0;
  // fileio/ sits beside the runtime, under everything that reads config files.
  std::string report = includes_of(
      {"fileio"}, {"runtime/", "compiler/", "api/", "include/", "kage/", "verify/", "driver/"}, seen);
  const size_t fileio_seen = seen;
  report += includes_of({"api", "verify"}, {"driver/"}, seen);
  INFO("includes against the layout's rules:\n" << report);
  CHECK(fileio_seen >= 2);  // the scan found fileio's own includes
  CHECK(seen > fileio_seen + 50);
  CHECK(report.empty());
}

TEST_CASE("only the driver includes verify/, and nothing includes lab/", "[layout]") {
  size_t seen = 0;
  std::vector<std::string> offenders;
  for (const char* dir : {"compiler", "api", "runtime", "fileio", "verify", "driver"}) {
    for (const auto& [where, path] : project_includes(dir)) {
      ++seen;
      const bool in_verify = starts_with(where, "verify/");
      const bool in_driver = starts_with(where, "driver/");
      if (starts_with(path, "verify/") && !in_verify && !in_driver) offenders.push_back(where + ": " + path);
      if (starts_with(path, "lab/")) offenders.push_back(where + ": " + path);
    }
  }
  std::string report;
  for (const std::string& o : offenders) report += o + "\n";
  INFO("includes against the layout's rules:\n" << report);
  CHECK(seen > 200);
  CHECK(offenders.empty());
}

}  // namespace kage::test
