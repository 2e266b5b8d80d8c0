// Inline-expectation fixtures (style.md 6): every tests/lint/*.yaml is linted
// through the library and its `# expect-...` comments must match the
// diagnostics exactly; tests/lint/suite/*.yaml are suite manifests.
//
//   # expect-error@+1 {{substring}} [rule]      the next line (also @-N, or no @ for this line)
//   # expect-warning@+1:3 {{substring}} [rule]  line and 1-based byte column
//   # expect-note@+1 {{substring}}              a note with a location ([rule] of its diagnostic optional)
//   # expect-no-diagnostics                     nothing at all
#include <algorithm>
#include <catch2/catch.hpp>
#include <regex>
#include <set>

#include "compiler/analysis/suite.h"
#include "compiler/parse/compose.h"
#include "test_support.h"

namespace kage::test {
namespace {

struct Expectation {
  std::string file;
  uint32_t line = 0;
  std::optional<uint32_t> col;
  std::string severity;
  std::string substring;
  std::string rule;  // may be empty for notes
  uint32_t written_at = 0;
};

struct Actual {
  std::string file;
  uint32_t line = 0, col = 0;
  std::string severity, rule, message;
};

struct FixtureExpectations {
  std::vector<Expectation> expected;
  bool no_diagnostics = false;
};

FixtureExpectations parse_expectations(const std::string& file, const std::string& text) {
  static const std::regex re(
      R"(expect-(error|warning|note)(?:@([+-][0-9]+))?(?::([0-9]+))?\s*\{\{(.*?)\}\}\s*(?:\[([a-z0-9-]+)\])?)");
  FixtureExpectations out;
  std::istringstream in(text);
  std::string line;
  uint32_t n = 0;
  while (std::getline(in, line)) {
    ++n;
    const auto hash = line.find('#');
    if (hash == std::string::npos) continue;
    const std::string comment = line.substr(hash);
    if (comment.find("expect-no-diagnostics") != std::string::npos) out.no_diagnostics = true;
    for (auto it = std::sregex_iterator(comment.begin(), comment.end(), re); it != std::sregex_iterator(); ++it) {
      const std::smatch& m = *it;
      Expectation e;
      e.file = file;
      e.written_at = n;
      e.severity = m[1];
      e.line = n + (m[2].matched ? std::stoi(m[2]) : 0);
      if (m[3].matched) e.col = static_cast<uint32_t>(std::stoul(m[3]));
      e.substring = m[4];
      e.rule = m[5];
      out.expected.push_back(e);
    }
  }
  return out;
}

std::vector<Actual> actual_diagnostics(const DiagEngine& diags, const SourceManager& sources) {
  std::vector<Actual> out;
  for (const Diagnostic& d : diags.sorted()) {
    Actual a;
    if (d.range.begin.valid()) {
      a.file = sources.name(d.range.begin.file);
      const LineCol lc = sources.line_col(d.range.begin);
      a.line = lc.line;
      a.col = lc.col;
    }
    a.severity = severity_name(d.severity);
    a.rule = rule_info(d.rule).id;
    a.message = d.message;
    out.push_back(a);
    for (const DiagNote& note : d.notes) {
      if (!note.loc.valid()) continue;  // notes without a place are not checked
      Actual n;
      n.file = sources.name(note.loc.file);
      const LineCol lc = sources.line_col(note.loc);
      n.line = lc.line;
      n.col = lc.col;
      n.severity = "note";
      n.rule = a.rule;
      n.message = note.message;
      out.push_back(n);
    }
  }
  return out;
}

bool matches(const Expectation& e, const Actual& a) {
  if (fs::path(e.file).lexically_normal() != fs::path(a.file).lexically_normal()) return false;
  if (e.line != a.line || e.severity != a.severity) return false;
  if (e.col && *e.col != a.col) return false;
  if (!e.rule.empty() && e.rule != a.rule) return false;
  return a.message.find(e.substring) != std::string::npos;
}

struct FixtureResult {
  std::vector<std::string> problems;
  std::set<std::string> expected_rules;
  bool declared = false;  // the fixture itself has expectations or expect-no-diagnostics
};

std::string describe(const Actual& a) {
  return a.file + ":" + std::to_string(a.line) + ":" + std::to_string(a.col) + ": " + a.severity + ": " + a.message +
         " [" + a.rule + "]";
}

// Compares the diagnostics of one fixture with the expectations of every file involved.
FixtureResult compare(const std::string& fixture, const std::set<std::string>& files, const DiagEngine& diags,
                      const SourceManager& sources) {
  FixtureResult r;
  std::vector<Actual> actual = actual_diagnostics(diags, sources);
  std::set<std::string> all_files = files;
  for (const Actual& a : actual)
    if (!a.file.empty()) all_files.insert(a.file);
  std::vector<Expectation> expected;
  bool no_diags = false;
  for (const std::string& f : all_files) {
    const auto id = sources.find(f);
    const std::string text = id ? sources.text(*id) : read_text(f);
    FixtureExpectations fe = parse_expectations(f, text);
    if (f == fixture) {
      r.declared = fe.no_diagnostics || !fe.expected.empty();
      no_diags = fe.no_diagnostics;
    }
    expected.insert(expected.end(), fe.expected.begin(), fe.expected.end());
  }
  r.declared = r.declared || !expected.empty();  // e.g. a cycle is expected in the helper that closes it
  if (no_diags && !expected.empty())
    r.problems.push_back(fixture + ": expect-no-diagnostics together with expectations");
  std::vector<bool> used(actual.size(), false);
  for (const Expectation& e : expected) {
    if (!e.rule.empty()) r.expected_rules.insert(e.rule);
    bool found = false;
    for (size_t i = 0; i < actual.size() && !found; ++i) {
      if (!used[i] && matches(e, actual[i])) used[i] = found = true;
    }
    if (!found)
      r.problems.push_back("missing: " + e.file + ":" + std::to_string(e.line) +
                           (e.col ? ":" + std::to_string(*e.col) : "") + ": " + e.severity + " {{" + e.substring +
                           "}} [" + e.rule + "] (written on line " + std::to_string(e.written_at) + ")");
  }
  for (size_t i = 0; i < actual.size(); ++i)
    if (!used[i]) r.problems.push_back("unexpected: " + describe(actual[i]));
  return r;
}

FixtureResult run_config_fixture(const std::string& path) {
  fs::current_path(source_dir());  // asset paths in messages are relative to the working directory
  SourceManager sources;
  DiagEngine diags(sources);
  DiskFileReader reader;
  std::set<std::string> files{path};
  if (auto config = load_config(path, sources, reader, diags)) {
    for (FileId id : config->chain) files.insert(sources.name(id));
    analyze_composed(*config, ResolveOptions{}, sources, diags);
  }
  return compare(path, files, diags, sources);
}

FixtureResult run_suite_fixture(const std::string& path) {
  fs::current_path(source_dir());
  SourceManager sources;
  DiagEngine diags(sources);
  DiskFileReader reader;
  const auto suite = load_suite(path, sources, reader, diags);
  if (suite && !diags.has_errors()) run_suite(*suite, ResolveOptions{}, sources, reader, diags, nullptr);
  return compare(path, {path}, diags, sources);
}

std::vector<std::string> yaml_files(const fs::path& dir) {
  std::vector<std::string> out;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.is_regular_file() && e.path().extension() == ".yaml") out.push_back(e.path().lexically_normal().string());
  std::sort(out.begin(), out.end());
  return out;
}

fs::path lint_dir() { return source_dir() / "tests" / "lint"; }

// Rules that no config or manifest file can trigger, with the reason.
const std::map<std::string, std::string>& rules_without_fixture() {
  static const std::map<std::string, std::string> m = {
      {"file-unreadable",
       "only a file named on the command line can be unreadable (a missing base is extends-missing); "
       "covered by the 'kagec lint of a missing file' test in cli_test.cpp"},
      {"extends-too-deep",
       "needs a chain of more than 64 files; covered by the 'a deep extends chain' test in hostile_input_test.cpp"},
      {"certify-mixture-shape",
       "compares several configs given together (kagec diff --mixture, kage.make_vec's mixtures), never one file; "
       "covered by the mixture tests of diff_suite_test.cpp and cli_test.cpp"},
      {"certify-mixture-latent",
       "compares several configs given together (kagec diff --mixture, kage.make_vec's mixtures), never one file; "
       "covered by the mixture tests of diff_suite_test.cpp and cli_test.cpp"},
  };
  return m;
}

}  // namespace

TEST_CASE("every config lint fixture matches its inline expectations", "[lint][fixtures]") {
  const auto files = yaml_files(lint_dir());
  REQUIRE(files.size() >= 30);
  for (const std::string& f : files) {
    DYNAMIC_SECTION(fs::path(f).filename().string()) {
      const FixtureResult r = run_config_fixture(f);
      INFO(f);
      CHECK(r.declared);
      for (const std::string& p : r.problems) FAIL_CHECK(p);
    }
  }
}

TEST_CASE("every suite lint fixture matches its inline expectations", "[lint][fixtures][suite]") {
  const auto files = yaml_files(lint_dir() / "suite");
  REQUIRE(!files.empty());
  for (const std::string& f : files) {
    DYNAMIC_SECTION(fs::path(f).filename().string()) {
      const FixtureResult r = run_suite_fixture(f);
      INFO(f);
      CHECK(r.declared);
      for (const std::string& p : r.problems) FAIL_CHECK(p);
    }
  }
}

TEST_CASE("every rule of diag_rules.def has a fixture named after it that expects it", "[lint][fixtures][meta]") {
  std::map<std::string, std::set<std::string>> expected_by_file;  // fixture stem -> rules it expects
  for (const std::string& f : yaml_files(lint_dir()))
    expected_by_file[fs::path(f).stem().string()] = run_config_fixture(f).expected_rules;
  for (const std::string& f : yaml_files(lint_dir() / "suite"))
    expected_by_file[fs::path(f).stem().string()] = run_suite_fixture(f).expected_rules;
  for (const RuleInfo& rule : all_rules()) {
    const std::string id = rule.id;
    INFO("rule " << id);
    if (rules_without_fixture().count(id)) {
      // An exempt rule must really have no fixture (else drop the exemption).
      bool any = false;
      for (const auto& [stem, rules] : expected_by_file) any = any || rules.count(id);
      CHECK_FALSE(any);
      continue;
    }
    bool found = false;
    for (const auto& [stem, rules] : expected_by_file)
      if ((stem == id || stem.rfind(id + "-", 0) == 0) && rules.count(id)) found = true;
    CHECK(found);
  }
  for (const auto& [id, reason] : rules_without_fixture()) {
    INFO(id);
    CHECK(find_rule(id) != nullptr);
    CHECK(!reason.empty());
  }
}

TEST_CASE("the expectation parser reads offsets, columns and rules", "[lint][fixtures]") {
  const std::string text =
      "a: 1\n"
      "# expect-error@+1 {{unknown key 'gravty'}} [schema-unknown-key]\n"
      "gravty: 1\n"
      "b: 2 # expect-warning@-1:3 {{x}} [inert-setting]\n"
      "# expect-note@+2 {{first given here}}\n";
  const FixtureExpectations fe = parse_expectations("f.yaml", text);
  REQUIRE(fe.expected.size() == 3);
  CHECK(fe.expected[0].line == 3);
  CHECK(fe.expected[0].severity == "error");
  CHECK(fe.expected[0].substring == "unknown key 'gravty'");
  CHECK(fe.expected[0].rule == "schema-unknown-key");
  CHECK_FALSE(fe.expected[0].col);
  CHECK(fe.expected[1].line == 3);
  CHECK(fe.expected[1].col == 3u);
  CHECK(fe.expected[2].line == 7);
  CHECK(fe.expected[2].rule.empty());
  CHECK_FALSE(fe.no_diagnostics);
  CHECK(parse_expectations("g.yaml", "# expect-no-diagnostics\nH: 64\n").no_diagnostics);
}

}  // namespace kage::test
