// Shared helpers of the front-end tests: paths into the source tree, files,
// an in-memory FileReader and the whole pipeline run on one file.
#pragma once

#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include <unistd.h>

#include "compiler/basic/diag.h"
#include "compiler/basic/source.h"
#include "compiler/sema/resolve.h"

namespace kage::test {

namespace fs = std::filesystem;

/// The repository root.
inline fs::path source_dir() { return fs::path(KAGE_SOURCE_DIR); }

/// A path inside the repository, as a string.
inline std::string repo_path(const std::string& rel) { return (source_dir() / rel).lexically_normal().string(); }

inline std::string read_text(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

inline void write_text(const fs::path& path, const std::string& text) {
  fs::create_directories(path.parent_path());
  std::ofstream out(path, std::ios::binary);
  out << text;
}

/// Files held in memory (tests never touch the disk through it).
class MemoryFileReader final : public FileReader {
 public:
  std::map<std::string, std::string> files;
  std::optional<std::string> read(const std::string& path, std::string* err) override {
    const auto it = files.find(fs::path(path).lexically_normal().string());
    if (it == files.end()) {
      if (err) *err = "no such file";
      return std::nullopt;
    }
    return it->second;
  }
};

/// A fresh directory under the system temp dir, removed when the object dies.
class TempDir {
 public:
  explicit TempDir(const std::string& tag) {
    static int counter = 0;
    path_ = fs::temp_directory_path() /
            ("kagec_test_" + tag + "_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~TempDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

/// One run of the front end (load, check, resolve) on a file.
struct Analysis {
  SourceManager sources;
  DiagEngine diags{sources};
  std::optional<Spec> spec;

  /// "rule: message" of every surviving diagnostic, for failure messages.
  std::string dump() const {
    std::string out;
    for (const Diagnostic& d : diags.sorted())
      out += std::string(rule_info(d.rule).id) + ": " + d.message + "\n";
    return out;
  }
  size_t count(const std::string& rule_id) const {
    size_t n = 0;
    for (const Diagnostic& d : diags.sorted()) n += rule_id == rule_info(d.rule).id;
    return n;
  }
};

inline void analyze(Analysis& a, const std::string& path, FileReader& reader, ResolveOptions options = {}) {
  a.spec = analyze_file(path, options, a.sources, reader, a.diags);
}

}  // namespace kage::test
