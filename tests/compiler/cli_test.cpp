// The kagec command line through run_kagec with string streams: exit codes
// 0/1/2, did-you-mean for commands, the frozen JSON diagnostic format.
#include <algorithm>
#include <catch2/catch.hpp>
#include <nlohmann/json.hpp>

#include "driver/commands.h"
#include "test_support.h"

namespace kage::test {
namespace {

struct CliRun {
  int code = -1;
  std::string out, err;
};

CliRun kagec(const std::vector<std::string>& args) {
  fs::current_path(source_dir());  // paths in output are relative to the working directory
  std::ostringstream out, err;
  CommandIo io{out, err, false};
  CliRun r;
  r.code = run_kagec(args, io);
  r.out = out.str();
  r.err = err.str();
  return r;
}

}  // namespace

TEST_CASE("kagec without arguments is a usage error", "[cli]") {
  const CliRun r = kagec({});
  CHECK(r.code == 2);
  CHECK(r.err.find("usage: kagec <command>") != std::string::npos);
  CHECK(r.out.empty());
}

TEST_CASE("an unknown command suggests the closest one", "[cli]") {
  const CliRun r = kagec({"lnt", "x.yaml"});
  CHECK(r.code == 2);
  CHECK(r.err.find("kagec: unknown command 'lnt'; did you mean 'lint'?") != std::string::npos);
  const CliRun far = kagec({"frobnicate"});
  CHECK(far.code == 2);
  CHECK(far.err.find("unknown command 'frobnicate'") != std::string::npos);
  CHECK(far.err.find("did you mean") == std::string::npos);
}

TEST_CASE("an unknown rule for --disable is a usage error", "[cli]") {
  const CliRun r = kagec({"lint", "--disable", "inert-settings", "tests/lint/no-diagnostics.yaml"});
  CHECK(r.code == 2);
  CHECK(r.err.find("unknown rule 'inert-settings' for --disable") != std::string::npos);
}

TEST_CASE("lint exit codes: clean 0, warnings 0, errors 1, --Werror turns warnings into errors", "[cli]") {
  CHECK(kagec({"lint", "tests/lint/no-diagnostics.yaml"}).code == 0);
  const CliRun warn = kagec({"lint", "tests/lint/range-recommended.yaml"});
  CHECK(warn.code == 0);
  CHECK(warn.err.find("0 errors, 2 warnings") != std::string::npos);
  const CliRun werror = kagec({"lint", "--Werror", "tests/lint/range-recommended.yaml"});
  CHECK(werror.code == 1);
  CHECK(werror.err.find("2 errors, 0 warnings") != std::string::npos);
  const CliRun disabled = kagec({"lint", "--Werror", "--disable", "range-recommended", "tests/lint/range-recommended.yaml"});
  CHECK(disabled.code == 0);
  const CliRun err = kagec({"lint", "tests/lint/schema-type.yaml"});
  CHECK(err.code == 1);
  CHECK(err.err.find("tests/lint/schema-type.yaml:4:12: error: 'physics.gravity' must be a number") != std::string::npos);
  CHECK(kagec({"lint"}).code == 2);                       // the file argument is required
  CHECK(kagec({"lint", "--format", "xml", "a.yaml"}).code == 2);  // not a format
}

TEST_CASE("kagec lint of a missing file reports file-unreadable", "[cli]") {
  const CliRun r = kagec({"lint", "tests/lint/there_is_no_such_file.yaml"});
  CHECK(r.code == 1);
  CHECK(r.err.find("cannot read 'tests/lint/there_is_no_such_file.yaml'") != std::string::npos);
  CHECK(r.err.find("[file-unreadable]") != std::string::npos);
}

TEST_CASE("a shipped name where kagec wants a path is answered with the shipped file's path", "[cli]") {
  const CliRun lint = kagec({"lint", "filters/4-eval.yaml"});
  CHECK(lint.code == 1);
  CHECK(lint.err.find("kagec lint: 'filters/4-eval.yaml' is no file here; kagec takes paths, and the shipped config "
                      "of that name is ") != std::string::npos);
  CHECK(lint.err.find("configs/kage_bench/filters/4-eval.yaml\n") != std::string::npos);
  const CliRun resolve = kagec({"resolve", "throughput/simplest"});
  CHECK(resolve.code == 1);
  CHECK(resolve.err.find("configs/throughput/simplest.yaml\n") != std::string::npos);
  const CliRun suite = kagec({"suite", "kage_bench"});
  CHECK(suite.code == 1);
  CHECK(suite.err.find("the shipped suite of that name is ") != std::string::npos);
  CHECK(suite.err.find("suites/kage_bench.yaml\n") != std::string::npos);
  // A short name that several shipped configs end with: each is named.
  const CliRun several = kagec({"lint", "3-eval"});
  CHECK(several.err.find("the shipped configs of that name are ") != std::string::npos);
  CHECK(several.err.find("configs/kage_bench/filters/3-eval.yaml") != std::string::npos);
  CHECK(several.err.find("configs/kage_bench/background/3-eval.yaml") != std::string::npos);
  // A path that matches nothing shipped gets no hint.
  CHECK(kagec({"lint", "tests/lint/there_is_no_such_file.yaml"}).err.find("is no file here") == std::string::npos);
}

TEST_CASE("text diagnostics show the source line, a caret, fix-its and notes", "[cli]") {
  const CliRun r = kagec({"lint", "tests/lint/schema-unknown-key-json.yaml"});
  CHECK(r.code == 1);
  const std::string expected =
      std::string("tests/lint/schema-unknown-key-json.yaml:3:3: error: unknown key 'gravty' in 'physics'; did you "
                  "mean 'gravity'? [schema-unknown-key]\n") +
      "  gravty: 0.5\n" +
      "  ^" + std::string(5, '~') + "\n" +  // caret and tildes under the 6 bytes of "gravty"
      "fix-it: replace with 'gravity'\n" +
      "tests/lint/schema-unknown-key-json.yaml:8:16: error: 'character.use_shape' and 'character.use_sprites' are "
      "both given, so exactly one of them must be true; set one to false [schema-shape-or-sprites]\n" +
      "  use_sprites: true\n" +
      std::string(15, ' ') + "^" + std::string(3, '~') + "\n" +  // under "true"
      "tests/lint/schema-unknown-key-json.yaml:6:14: note: 'use_shape' is given here\n" +
      "2 errors, 0 warnings\n";
  CHECK(r.err == expected);
}

TEST_CASE("json format prints the frozen diagnostic fields", "[cli][json]") {
  const CliRun r = kagec({"lint", "--format", "json", "tests/lint/schema-unknown-key-json.yaml"});
  CHECK(r.code == 1);
  CHECK(r.err.empty());
  const std::string file = "tests/lint/schema-unknown-key-json.yaml";
  const nlohmann::json expected = nlohmann::json::parse(R"({
    "version": 1,
    "diagnostics": [
      {"file": "tests/lint/schema-unknown-key-json.yaml", "line": 3, "col": 3, "end_line": 3, "end_col": 9,
       "offset": 115, "severity": "error", "rule": "schema-unknown-key",
       "message": "unknown key 'gravty' in 'physics'; did you mean 'gravity'?", "path": "/physics/gravty",
       "notes": [],
       "fixits": [{"line": 3, "col": 3, "offset": 115, "length": 6, "replacement": "gravity"}]},
      {"file": "tests/lint/schema-unknown-key-json.yaml", "line": 8, "col": 16, "end_line": 8, "end_col": 20,
       "offset": 309, "severity": "error", "rule": "schema-shape-or-sprites",
       "message": "'character.use_shape' and 'character.use_sprites' are both given, so exactly one of them must be true; set one to false",
       "path": "/character/use_sprites",
       "notes": [{"message": "'use_shape' is given here", "file": "tests/lint/schema-unknown-key-json.yaml", "line": 6, "col": 14}],
       "fixits": []}
    ],
    "summary": {"errors": 2, "warnings": 0}
  })");
  const nlohmann::json actual = nlohmann::json::parse(r.out);
  CHECK(actual == expected);
  // Field order is part of the frozen format.
  const nlohmann::ordered_json ordered = nlohmann::ordered_json::parse(r.out);
  std::vector<std::string> top, fields;
  for (auto& [k, v] : ordered.items()) top.push_back(k);
  for (auto& [k, v] : ordered.at("diagnostics").at(0).items()) fields.push_back(k);
  CHECK(top == std::vector<std::string>{"version", "diagnostics", "summary"});
  CHECK(fields == std::vector<std::string>{"file", "line", "col", "end_line", "end_col", "offset", "severity", "rule",
                                           "message", "path", "notes", "fixits"});
  (void)file;
}

TEST_CASE("diff --certify: usage errors, certified and failing pairs", "[cli][diff]") {
  const std::string train = "configs/kage_bench/bases/shape_black.yaml";
  const std::string eval = "configs/kage_bench/background/1-eval.yaml";
  CHECK(kagec({"diff", "--certify=colour", train, eval}).code == 2);
  CHECK(kagec({"diff", "--axis", "latent", train, eval}).code == 2);
  const CliRun ok = kagec({"diff", train, eval, "--axis", "background"});
  CHECK(ok.code == 0);
  CHECK(ok.out.find("certified: exactly one visual axis changes (background), nothing latent") != std::string::npos);
  const CliRun wrong = kagec({"diff", train, eval, "--certify=filters"});
  CHECK(wrong.code == 1);
  CHECK(wrong.out.find("not certified: declared axis 'filters' does not change") != std::string::npos);
  const CliRun same = kagec({"diff", train, train, "--certify"});
  CHECK(same.code == 1);
  CHECK(same.out.find("no effective differences") != std::string::npos);
  CHECK(same.out.find("degenerate pair") != std::string::npos);
  CHECK(kagec({"diff", train, eval}).code == 0);  // without --certify a diff is information only
  // The old spelling with the axis as a separate word is a usage error that says how to write it.
  const CliRun old = kagec({"diff", "--certify", "background", train, eval});
  CHECK(old.code == 2);
  CHECK(old.err.find("--axis background or --certify=background") != std::string::npos);
}

TEST_CASE("diff --mixture: certified configs, a latent difference, usage errors", "[cli][diff][mixture]") {
  const std::string base = "configs/kage_bench/bases/shape_black.yaml";
  const std::string noise = "configs/kage_bench/background/1-eval.yaml";
  const std::string few = "configs/kage_bench/distractors/5-eval.yaml";
  TempDir tmp("diff_mixture");
  const std::string cert = (tmp.path() / "mixture.json").string();
  const CliRun ok = kagec({"diff", "--mixture", base, noise, few, "-o", cert});
  INFO(ok.err);
  CHECK(ok.code == 0);
  CHECK(ok.out == "certified mixture: 3 configs, one hidden game and one observation shape; they differ on "
                  "background, distractors\n");
  const nlohmann::json j = nlohmann::json::parse(read_text(cert));
  CHECK(j.at("kagec_mixture") == 1);
  CHECK(j.at("configs").size() == 3);
  CHECK(j.at("configs").at(2).at("name") == few);

  const std::string longer = "tests/python/configs/long_episode.yaml";
  const CliRun latent = kagec({"diff", "--mixture", "configs/throughput/simplest.yaml", longer});
  CHECK(latent.code == 1);
  CHECK(latent.out.empty());
  CHECK(latent.err.find(longer + ":4:1: error: mixture of 'configs/throughput/simplest.yaml' and '" + longer +
                        "': latent key 'episode_length' is 500 in 'configs/throughput/simplest.yaml' but 1000 in '" +
                        longer + "'; a mixture's configs must run one hidden game and differ only on visual axes "
                        "[certify-mixture-latent]") != std::string::npos);
  CHECK(latent.err.find("kagec diff: not a mixture: fix the errors above first") != std::string::npos);

  CHECK(kagec({"diff", "--mixture", base, noise, "--certify"}).code == 2);
  const CliRun three = kagec({"diff", base, noise, few});
  CHECK(three.code == 2);
  CHECK(three.err.find("configs batched together are certified with --mixture") != std::string::npos);
}

TEST_CASE("diff: every order of the files, --certify, the axis and -o gives the same certificate", "[cli][diff]") {
  const std::string train = "configs/kage_bench/bases/shape_black.yaml";
  const std::string eval = "configs/kage_bench/background/1-eval.yaml";
  TempDir tmp("diff_orders");
  const std::string cert = (tmp.path() / "cert.json").string();
  // Each option group stays together; the files keep their order (TRAIN before EVAL).
  for (const std::vector<std::string>& axis :
       {std::vector<std::string>{"--certify"}, {"--certify=background"}, {"--axis", "background"},
        {"--certify", "--axis", "background"}}) {
    std::vector<std::vector<std::string>> groups = {{train}, {eval}, axis, {"-o", cert}};
    std::vector<int> order = {0, 1, 2, 3};
    int runs = 0;
    do {
      if (std::find(order.begin(), order.end(), 0) > std::find(order.begin(), order.end(), 1)) continue;
      std::vector<std::string> args = {"diff"};
      for (int g : order) args.insert(args.end(), groups[g].begin(), groups[g].end());
      fs::remove(cert);
      const CliRun r = kagec(args);
      std::string line;
      for (const std::string& a : args) line += a + " ";
      INFO(line << "\n" << r.err);
      CHECK(r.code == 0);
      CHECK(r.out.find("certified: exactly one visual axis changes (background)") != std::string::npos);
      const nlohmann::json j = nlohmann::json::parse(read_text(cert), nullptr, false);
      REQUIRE_FALSE(j.is_discarded());
      CHECK(j.dump().find("shape_black.yaml") != std::string::npos);
      ++runs;
    } while (std::next_permutation(order.begin(), order.end()));
    CHECK(runs == 12);
  }
}

TEST_CASE("resolve -o reports a write that fails", "[cli][resolve]") {
  const CliRun full = kagec({"resolve", "tests/lint/no-diagnostics.yaml", "-o", "/dev/full"});
  CHECK(full.code == 1);
  CHECK(full.err.find("kagec resolve: cannot write '/dev/full': write failed") != std::string::npos);
}

TEST_CASE("diff -o reports a write that fails", "[cli][diff]") {
  const CliRun full = kagec({"diff", "configs/kage_bench/bases/shape_black.yaml",
                             "configs/kage_bench/background/1-eval.yaml", "--certify", "-o", "/dev/full"});
  CHECK(full.code == 1);
  CHECK(full.err.find("kagec diff: cannot write '/dev/full': write failed") != std::string::npos);
  const CliRun dir = kagec({"diff", "configs/kage_bench/bases/shape_black.yaml",
                            "configs/kage_bench/background/1-eval.yaml", "-o", "/nonexistent-dir/cert.json"});
  CHECK(dir.code == 1);
  CHECK(dir.err.find("cannot write '/nonexistent-dir/cert.json'") != std::string::npos);
}

TEST_CASE("resolve prints the canonical Spec, or nothing when there are errors", "[cli][resolve]") {
  const CliRun ok = kagec({"resolve", "tests/lint/no-diagnostics.yaml"});
  CHECK(ok.code == 0);
  const nlohmann::json spec = nlohmann::json::parse(ok.out);
  CHECK(spec.at("kagec_spec") == 1);
  CHECK(spec.at("config").at("W") == 8);
  CHECK(spec.at("sha256").get<std::string>().size() == 64);
  const CliRun bad = kagec({"resolve", "tests/lint/schema-type.yaml"});
  CHECK(bad.code == 1);
  CHECK(bad.out.empty());
  CHECK(bad.err.find("no Spec") != std::string::npos);
}

TEST_CASE("rules lists every rule once", "[cli]") {
  const CliRun r = kagec({"rules"});
  CHECK(r.code == 0);
  for (const RuleInfo& rule : all_rules()) CHECK(r.out.find(std::string(rule.id) + " ") != std::string::npos);
}

}  // namespace kage::test

namespace kage::test {

TEST_CASE("lint, resolve and diff --certify refuse a config of two documents at the second", "[cli][yaml]") {
  TempDir tmp("cli_documents");
  const std::string two = (tmp.path() / "two.yaml").string();
  write_text(two, "extends: " + repo_path("configs/kage_bench/background/1-eval.yaml") +
                      "\n---\nbackground: {mode: black}\n");
  const std::string where = two + ":2:1: error: a second YAML document starts here";
  const CliRun lint = kagec({"lint", two});
  CHECK(lint.code == 1);
  CHECK(lint.err.find(where) != std::string::npos);
  CHECK(lint.err.find("[yaml-multiple-documents]") != std::string::npos);
  const CliRun resolve = kagec({"resolve", two});
  CHECK(resolve.code == 1);
  CHECK(resolve.out.empty());
  CHECK(resolve.err.find(where) != std::string::npos);
  const CliRun certify = kagec({"diff", "--certify", "configs/kage_bench/bases/shape_black.yaml", two});
  CHECK(certify.code == 1);
  CHECK(certify.err.find(where) != std::string::npos);
  CHECK(certify.out.find("certified: exactly one") == std::string::npos);
}

}  // namespace kage::test
