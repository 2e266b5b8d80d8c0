// Hostile input at scale: files of hundreds of thousands of unknown keys, in blocks, on one line, and
// across an `extends` chain. The front end's work grows linearly with them and the text output is
// bounded: kMaxShownPerFile diagnostics a file, then one note that counts the rest.
//
// The million-key case is hidden from the default run; CTest runs it as
// compiler.lint_a_million_unknown_keys under a 60 s timeout, which quadratic work would exceed.
#include <catch2/catch.hpp>

#include "driver/commands.h"
#include "test_support.h"

namespace kage::test {
namespace {

struct Lint {
  int code = -1;
  std::string out, err;
};

Lint lint(const fs::path& file) {
  std::ostringstream out, err;
  CommandIo io{out, err, false};
  Lint r;
  r.code = run_kagec({"lint", file.string()}, io);
  r.out = out.str();
  r.err = err.str();
  return r;
}

/// `n` unknown keys named prefix0, prefix1, ..., one a line.
std::string block_keys(size_t n, const std::string& prefix) {
  std::string text;
  for (size_t i = 0; i < n; ++i) text += prefix + std::to_string(i) + ": " + std::to_string(i) + "\n";
  return text;
}

size_t count(const std::string& text, const std::string& what) {
  size_t n = 0;
  for (size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

}  // namespace

TEST_CASE("lint of 200k unknown keys shows the first ones and counts the rest", "[hostile][scale]") {
  TempDir tmp("scale_block");
  const fs::path file = tmp.path() / "keys.yaml";
  write_text(file, block_keys(200000, "unknown_key_"));
  const Lint r = lint(file);
  CHECK(r.code == 1);
  CHECK(count(r.err, "[schema-unknown-key]") == kMaxShownPerFile);
  CHECK(r.err.find(file.string() + ": note: 199900 more errors not shown; fix the ones above first, or list them "
                                   "all with --format json\n") != std::string::npos);
  CHECK(r.err.find("200000 errors, 0 warnings") != std::string::npos);
  CHECK(r.err.size() < 100 * 1024);
}

TEST_CASE("lint of keys on one long line prints a bounded window of it", "[hostile][scale]") {
  TempDir tmp("scale_flow");
  const fs::path file = tmp.path() / "flow.yaml";
  std::string text = "{";
  for (int i = 0; i < 5000; ++i) text += (i ? ", k" : "k") + std::to_string(i) + ": 1";
  write_text(file, text + "}\n");
  const Lint r = lint(file);
  INFO(r.err.substr(0, 2000));
  CHECK(r.code == 1);
  CHECK(r.err.find("flow.yaml:1:2: error: unknown key 'k0' at the top level") != std::string::npos);
  CHECK(r.err.find(": note: 4900 more errors not shown") != std::string::npos);
  CHECK(r.err.find("5000 errors, 0 warnings") != std::string::npos);
  // Each source line is cut to a window around its caret ("..." where cut).
  CHECK(r.err.find("\n...") != std::string::npos);
  CHECK(r.err.size() < 100 * (2 * kMaxSnippetBytes + 200));
}

TEST_CASE("lint of a million unknown keys finishes", "[.][hostile-scale]") {
  // 16 MiB is the largest config read; a million short keys take 12 MB, split across an extends chain.
  TempDir tmp("scale_million");
  write_text(tmp.path() / "base.yaml", block_keys(500000, "b"));
  write_text(tmp.path() / "child.yaml", "extends: base.yaml\n" + block_keys(500000, "c"));
  const Lint r = lint(tmp.path() / "child.yaml");
  CHECK(r.code == 1);
  CHECK(r.err.find("1000000 errors, 0 warnings") != std::string::npos);
  CHECK(count(r.err, "[schema-unknown-key]") == 2 * kMaxShownPerFile);  // 100 in each of the two files
  CHECK(r.err.find("base.yaml: note: 499900 more errors not shown") != std::string::npos);
  CHECK(r.err.find("child.yaml: note: 499900 more errors not shown") != std::string::npos);
}

}  // namespace kage::test
