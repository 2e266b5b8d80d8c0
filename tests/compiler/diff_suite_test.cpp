// Diff and certification of pairs; suites (the shipped KAGE-Bench suite, edited
// copies of it that must fail); compatibility with the original's own files.
#include <catch2/catch.hpp>

#include "compiler/analysis/diff.h"
#include "compiler/analysis/suite.h"
#include "test_support.h"
#include "tests/skip.h"

namespace kage::test {
namespace {

Spec spec_of(const std::string& text) {
  MemoryFileReader reader;
  reader.files["p.yaml"] = text;
  Analysis a;
  analyze(a, "p.yaml", reader);
  INFO(a.dump());
  REQUIRE(a.spec);
  REQUIRE_FALSE(a.diags.has_errors());
  return *a.spec;
}

const std::string kTrain = "background: {mode: color, color_names: [purple]}\ncharacter: {use_shape: true}\n";

Certification certify_texts(const std::string& train, const std::string& eval, std::optional<Axis> declared,
                            const std::vector<Allowance>& allowed = {}) {
  return certify(diff_specs(spec_of(train), spec_of(eval), config_schema()), declared, allowed);
}

bool has_problem(const Certification& c, const std::string& text) {
  for (const std::string& p : c.problems)
    if (p.find(text) != std::string::npos) return true;
  return false;
}

}  // namespace

TEST_CASE("a setting inert on both sides is no change", "[diff]") {
  const Spec a = spec_of("background: {mode: black, parallax_factor: 0.5}\n");
  const Spec b = spec_of("background: {mode: black, parallax_factor: 0.9}\n");
  CHECK(a.sha256() != b.sha256());  // the Specs differ ...
  const SpecDiff d = diff_specs(a, b, config_schema());
  CHECK(d.changes.empty());  // ... but not effectively
  const Certification c = certify(d, Axis::Background, {});
  CHECK_FALSE(c.certified);
  CHECK(has_problem(c, "degenerate pair"));
}

TEST_CASE("one visual axis certifies; its changes are listed by axis", "[diff]") {
  const SpecDiff d = diff_specs(spec_of(kTrain),
                                spec_of("background: {mode: color, color_names: [lime]}\ncharacter: {use_shape: true}\n"),
                                config_schema());
  REQUIRE(d.changes.size() == 1);
  CHECK(d.changes[0].path == "background.color_names");
  CHECK(d.changes[0].axis == Axis::Background);
  CHECK(d.changes[0].train == Json::array({"purple"}));
  CHECK(d.changes[0].eval == Json::array({"lime"}));
  const Certification c = certify(d, Axis::Background, {});
  CHECK(c.certified);
  CHECK(c.problems.empty());
  CHECK(certify(d, std::nullopt, {}).certified);
}

TEST_CASE("a latent change fails certification", "[diff]") {
  const Certification c =
      certify_texts(kTrain, kTrain + "filters: {brightness: 0.5}\nphysics: {gravity: 0.9}\n", Axis::Filters);
  CHECK_FALSE(c.certified);
  CHECK(c.measured.count(Axis::Latent));
  CHECK(has_problem(c, "latent keys change (the hidden game differs): physics.gravity"));
  // The hitbox is latent although it sits under character.
  CHECK(has_problem(certify_texts("character: {use_shape: true}\n", "character: {use_shape: true, width: 20}\n",
                                  std::nullopt),
                    "latent keys change (the hidden game differs): character.width"));
}

TEST_CASE("two visual axes fail unless the second is allowed", "[diff]") {
  const std::string eval = "background: {mode: color, color_names: [lime]}\ncharacter: {use_shape: true}\n"
                           "filters: {brightness: 0.5}\n";
  const Certification plain = certify_texts(kTrain, eval, Axis::Background);
  CHECK_FALSE(plain.certified);
  CHECK(has_problem(plain, "axis 'filters' also changes and is not allowed"));
  const Certification any = certify_texts(kTrain, eval, std::nullopt);
  CHECK_FALSE(any.certified);
  CHECK(has_problem(any, "more than one visual axis changes: background, filters"));
  const Certification allowed =
      certify_texts(kTrain, eval, Axis::Background, {Allowance{Axis::Filters, "the pair dims the eval frames"}});
  CHECK(allowed.certified);
  REQUIRE(allowed.used_allowances.size() == 1);
  CHECK(allowed.used_allowances[0].axis == Axis::Filters);
  // An allowance for an axis that does not change is not used.
  const Certification unused = certify_texts(
      kTrain, "background: {mode: color, color_names: [lime]}\ncharacter: {use_shape: true}\n", Axis::Background,
      {Allowance{Axis::Agent, "not needed"}});
  CHECK(unused.certified);
  CHECK(unused.used_allowances.empty());
}

TEST_CASE("a declared axis that does not change fails", "[diff]") {
  const Certification c = certify_texts(kTrain, kTrain + "filters: {brightness: 0.5}\n", Axis::Background);
  CHECK_FALSE(c.certified);
  CHECK(has_problem(c, "declared axis 'background' does not change"));
  CHECK(c.measured == std::set<Axis>{Axis::Filters});
}

TEST_CASE("the certificate carries both spec hashes and the verdict", "[diff]") {
  const Spec a = spec_of(kTrain);
  const Spec b = spec_of(kTrain + "filters: {brightness: 0.5}\n");
  const SpecDiff d = diff_specs(a, b, config_schema());
  const Certification c = certify(d, Axis::Filters, {});
  const Json j = certificate_json({"train.yaml", a.sha256()}, {"eval.yaml", b.sha256()}, d, c);
  CHECK(j.at("train").at("spec_sha256") == a.sha256());
  CHECK(j.at("eval").at("spec_sha256") == b.sha256());
  CHECK(j.at("train").at("name") == "train.yaml");
  CHECK(a.sha256() != b.sha256());
  CHECK(j.at("certified") == true);
  CHECK(j.at("declared_axis") == "filters");
  CHECK(j.at("measured_axes") == Json::array({"filters"}));
  REQUIRE(j.at("changes").size() == 1);
  CHECK(j.at("changes")[0].at("path") == "filters.brightness");
  CHECK(j.at("changes")[0].at("eval") == 0.5);
}

namespace {

struct SuiteRun {
  SourceManager sources;
  DiagEngine diags{sources};
  std::optional<Suite> suite;
  SuiteReport report;
};

void run_manifest(SuiteRun& r, const std::string& path, ResolveOptions options = {}) {
  DiskFileReader reader;
  r.suite = load_suite(path, r.sources, reader, r.diags);
  REQUIRE(r.suite);
  REQUIRE_FALSE(r.diags.has_errors());
  r.report = run_suite(*r.suite, options, r.sources, reader, r.diags, nullptr);
}

const PairResult& result(const SuiteRun& r, const std::string& name) {
  for (const PairResult& p : r.report.results)
    if (p.pair->name == name) return p;
  FAIL("no pair " << name);
  return r.report.results.front();
}

// suites/kage_bench.yaml with every relative config path made absolute.
std::string bench_manifest_text() {
  std::string text = read_text(source_dir() / "suites/kage_bench.yaml");
  const std::string rel = "../configs/", abs = (source_dir() / "configs").string() + "/";
  for (size_t at = text.find(rel); at != std::string::npos; at = text.find(rel, at + abs.size()))
    text.replace(at, rel.size(), abs);
  return text;
}

void replace_once(std::string& text, const std::string& from, const std::string& to) {
  const size_t at = text.find(from);
  REQUIRE(at != std::string::npos);
  text.replace(at, from.size(), to);
}

}  // namespace

TEST_CASE("suites/kage_bench.yaml certifies 34 of 34, distractors/6 by its allowance", "[suite]") {
  fs::current_path(source_dir());
  SuiteRun r;
  run_manifest(r, "suites/kage_bench.yaml");
  REQUIRE(r.report.results.size() == 34);
  CHECK(r.report.passed() == 34);
  std::map<Axis, int> per_axis;
  for (const PairResult& p : r.report.results) {
    INFO(p.pair->name);
    CHECK(p.passed());
    ++per_axis[p.pair->axis];
    if (p.pair->name == "distractors/6") {
      CHECK(p.cert.measured == std::set<Axis>{Axis::Distractors, Axis::Agent});
      REQUIRE(p.cert.used_allowances.size() == 1);
      CHECK(p.cert.used_allowances[0].axis == Axis::Agent);
    } else {
      CHECK(p.cert.measured == std::set<Axis>{p.pair->axis});
      CHECK(p.cert.used_allowances.empty());
    }
  }
  CHECK(per_axis[Axis::Background] == 10);
  CHECK(per_axis[Axis::Agent] == 5);
  CHECK(per_axis[Axis::Distractors] == 6);
  CHECK(per_axis[Axis::Filters] == 9);
  CHECK(per_axis[Axis::Effects] == 3);
  CHECK(per_axis[Axis::Layout] == 1);
  const Json report = suite_report_json(*r.suite, r.report);
  CHECK(report.at("passed") == 34);
  CHECK(report.at("total") == 34);
}

TEST_CASE("edited copies of the suite fail the edited pair only", "[suite]") {
  fs::current_path(source_dir());
  const std::string abs = (source_dir() / "configs").string() + "/";
  const std::string eval_line = "    eval: " + abs + "kage_bench/background/1-eval.yaml\n";
  TempDir tmp("suite_edit");

  SECTION("an eval that also changes a second axis") {
    std::string text = bench_manifest_text();
    replace_once(text, eval_line,
                 "    eval:\n      extends: " + abs + "kage_bench/background/1-eval.yaml\n"
                 "      filters: {brightness: 0.5}\n");
    write_text(tmp.path() / "edited.yaml", text);
    SuiteRun r;
    run_manifest(r, (tmp.path() / "edited.yaml").string());
    CHECK(r.report.passed() == 33);
    const PairResult& p = result(r, "background/1");
    CHECK_FALSE(p.passed());
    CHECK(p.cert.measured == std::set<Axis>{Axis::Background, Axis::Filters});
    CHECK(has_problem(p.cert, "axis 'filters' also changes and is not allowed"));
  }
  SECTION("an eval that changes a latent key") {
    std::string text = bench_manifest_text();
    replace_once(text, eval_line,
                 "    eval:\n      extends: " + abs + "kage_bench/background/1-eval.yaml\n"
                 "      physics: {gravity: 0.9}\n");
    write_text(tmp.path() / "edited.yaml", text);
    SuiteRun r;
    run_manifest(r, (tmp.path() / "edited.yaml").string());
    CHECK(r.report.passed() == 33);
    const PairResult& p = result(r, "background/1");
    CHECK_FALSE(p.passed());
    CHECK(has_problem(p.cert, "latent keys change"));
  }
  SECTION("distractors/6 without its allowance") {
    std::string text = bench_manifest_text();
    const size_t pair = text.find("- name: distractors/6");
    REQUIRE(pair != std::string::npos);
    const size_t allow = text.find("    allow:\n", pair);
    const size_t next = text.find("  - name:", pair + 1);
    REQUIRE(allow < next);
    const size_t comment = text.rfind("\n  #", next);
    const size_t end = comment != std::string::npos && comment > allow ? comment + 1 : next;
    text.erase(allow, end - allow);
    write_text(tmp.path() / "edited.yaml", text);
    SuiteRun r;
    run_manifest(r, (tmp.path() / "edited.yaml").string());
    CHECK(r.report.results.size() == 34);
    CHECK(r.report.passed() == 33);
    const PairResult& p = result(r, "distractors/6");
    CHECK_FALSE(p.passed());
    CHECK(has_problem(p.cert, "axis 'agent' also changes and is not allowed"));
  }
}

TEST_CASE("the original's own files lint clean and certify like ours", "[suite][compat]") {
  const fs::path shared_assets = (source_dir() / "../shared/kage-assets").lexically_normal();
  if (!fs::is_directory(shared_assets)) KAGE_SKIP("the original's assets are not at " << shared_assets.string());
  TempDir root("compat");
  fs::create_directories(root.path() / "src/kage_bench");
  fs::create_directory_symlink(shared_assets, root.path() / "src/kage_bench/assets");
  fs::current_path(source_dir());
  ResolveOptions options;
  options.asset_root = root.path().string();

  DiskFileReader reader;
  size_t files = 0;
  for (const auto& e : fs::recursive_directory_iterator("tests/compat/original")) {
    if (!e.is_regular_file() || e.path().extension() != ".yaml") continue;
    Analysis a;
    analyze(a, e.path().string(), reader, options);
    INFO(e.path().string() << "\n" << a.dump());
    CHECK(a.spec);
    CHECK(a.diags.error_count() == 0);
    ++files;
  }
  CHECK(files == 69);  // 34 pairs and default_config.yaml

  SuiteRun ours, original;
  run_manifest(ours, "suites/kage_bench.yaml");
  run_manifest(original, "tests/compat/kage_bench_original.yaml", options);
  REQUIRE(original.report.results.size() == 34);
  CHECK(original.report.passed() == 34);
  for (const PairResult& p : original.report.results) {
    INFO(p.pair->name);
    const PairResult& mine = result(ours, p.pair->name);
    CHECK(p.passed());
    CHECK(p.pair->axis == mine.pair->axis);
    CHECK(p.cert.measured == mine.cert.measured);
    CHECK(p.cert.used_allowances.size() == mine.cert.used_allowances.size());
  }
}

}  // namespace kage::test

namespace kage::test {

TEST_CASE("the original's files, in its layout, lint clean without flags and hash as with --asset-root",
          "[suite][compat][assets]") {
  const fs::path shared_assets = (source_dir() / "../shared/kage-assets").lexically_normal();
  if (!fs::is_directory(shared_assets)) KAGE_SKIP("the original's assets are not at " << shared_assets.string());
  // The original's repository: configs under configs/, assets under src/kage_bench/assets, and every
  // asset path written relative to the repository root, the working directory.
  TempDir root("original_layout");
  fs::create_directories(root.path() / "src/kage_bench");
  fs::create_directory_symlink(shared_assets, root.path() / "src/kage_bench/assets");
  fs::copy(source_dir() / "tests/compat/original", root.path() / "configs", fs::copy_options::recursive);
  const fs::path home = fs::current_path();
  fs::current_path(root.path());
  DiskFileReader reader;
  ResolveOptions with_root;
  with_root.asset_root = root.path().string();
  size_t files = 0, noted = 0;
  std::map<std::string, std::string> hashes;  // file -> Spec hash, resolved from the root without flags
  for (const auto& e : fs::recursive_directory_iterator("configs")) {
    if (!e.is_regular_file() || e.path().extension() != ".yaml") continue;
    Analysis a;
    analyze(a, e.path().string(), reader);
    INFO(e.path().string() << "\n" << a.dump());
    REQUIRE(a.spec);
    CHECK(a.diags.error_count() == 0);
    noted += a.count("asset-cwd-relative") > 0;
    Analysis b;
    analyze(b, e.path().string(), reader, with_root);
    REQUIRE(b.spec);
    CHECK(b.spec->sha256() == a.spec->sha256());
    hashes[e.path().string()] = a.spec->sha256();
    ++files;
  }
  CHECK(files == 69);
  CHECK(noted > 30);  // most name an image or sprite folder
  // From another directory, with --asset-root: the same hashes (the Spec does not record where it ran).
  fs::current_path(source_dir());
  for (const auto& [file, hash] : hashes) {
    Analysis c;
    analyze(c, (root.path() / file).string(), reader, with_root);
    INFO(file << "\n" << c.dump());
    REQUIRE(c.spec);
    CHECK(c.spec->sha256() == hash);
  }
  fs::current_path(home);
}

TEST_CASE("suites/kage_bench_loo.yaml certifies 18 of 18, each pair training on its axis's other looks", "[suite][mixture]") {
  fs::current_path(source_dir());
  SuiteRun r;
  run_manifest(r, "suites/kage_bench_loo.yaml");
  REQUIRE(r.report.results.size() == 18);
  CHECK(r.report.passed() == 18);
  std::map<Axis, int> per_axis;
  for (const PairResult& p : r.report.results) {
    INFO(p.pair->name);
    CHECK(p.passed());
    REQUIRE(p.pair->mixture);
    ++per_axis[p.pair->axis];
    // The pair's train config of kage_bench.yaml, then the axis's other eval configs on its base.
    const size_t expected = p.pair->axis == Axis::Filters ? 9 : p.pair->axis == Axis::Effects ? 3
                            : p.pair->name <= "distractors/4"   ? 4
                                                                : 2;
    CHECK(p.members.size() == expected);
    for (const std::string& c : p.pair->mixture->configs()) CHECK(c != p.pair->eval.path);
  }
  CHECK(per_axis[Axis::Filters] == 9);
  CHECK(per_axis[Axis::Effects] == 3);
  CHECK(per_axis[Axis::Distractors] == 6);
}

TEST_CASE("a mixture pair's report names its configs, weights and stages; its train hash is their content",
          "[suite][mixture]") {
  fs::current_path(source_dir());
  const std::string abs = (source_dir() / "configs").string() + "/kage_bench/";
  TempDir tmp("suite_mixture");
  write_text(tmp.path() / "schedule.yaml", "- start: 1\n  configs: [" + abs + "bases/image_skeleton.yaml]\n"
             "- start: 50\n  configs: [kage_bench/filters/2-eval, " + abs + "filters/3-eval.yaml]\n  weights: [3, 1]\n");
  write_text(tmp.path() / "suite.yaml",
             "suite: s\npairs:\n"
             "  - {name: m, axis: filters, eval: " + abs + "filters/1-eval.yaml, train: [" + abs +
                 "bases/image_skeleton.yaml, {config: " + abs + "filters/2-eval.yaml, weight: 2}]}\n"
             "  - {name: same, axis: filters, eval: " + abs + "filters/4-eval.yaml, train: [" + abs +
                 "bases/image_skeleton.yaml, {config: " + abs + "filters/2-eval.yaml, weight: 2}]}\n"
             "  - {name: s, axis: filters, eval: " + abs + "filters/1-eval.yaml, train: {schedule: schedule.yaml}}\n"
             "  - {name: plain, axis: filters, eval: " + abs + "filters/1-eval.yaml, train: " + abs +
                 "bases/image_skeleton.yaml}\n");
  SourceManager sources;
  DiagEngine diags(sources);
  DiskFileReader reader;
  const auto suite = load_suite((tmp.path() / "suite.yaml").string(), sources, reader, diags,
                                (source_dir() / "configs").string());
  REQUIRE(suite);
  REQUIRE_FALSE(diags.has_errors());
  const SuiteReport report = run_suite(*suite, {}, sources, reader, diags, nullptr);
  CHECK(report.passed() == 4);
  const Json j = suite_report_json(*suite, report);
  const Json& m = j.at("pairs")[0].at("train");
  CHECK(m.at("name") == "mixture of 2");
  CHECK(m.at("schedule").is_null());
  REQUIRE(m.at("stages").size() == 1);
  CHECK(m.at("stages")[0].at("start") == 1);
  REQUIRE(m.at("stages")[0].at("configs").size() == 2);
  CHECK(m.at("stages")[0].at("configs")[0].at("weight") == 1.0);
  CHECK(m.at("stages")[0].at("configs")[1].at("weight") == 2.0);
  CHECK(m.at("stages")[0].at("configs")[1].at("name") == abs + "filters/2-eval.yaml");
  CHECK(m.at("spec_sha256").get<std::string>().size() == 64);
  // The same training under another pair hashes alike; a plain pair keeps its config's name and Spec hash.
  CHECK(j.at("pairs")[1].at("train").at("spec_sha256") == m.at("spec_sha256"));
  const Json& plain = j.at("pairs")[3].at("train");
  CHECK(plain == Json{{"name", abs + "bases/image_skeleton.yaml"},
                      {"spec_sha256", m.at("stages")[0].at("configs")[0].at("spec_sha256")}});
  // Every change is marked with the training config it belongs to: the base gains brightness, filters/2 too.
  for (const Json& ch : j.at("pairs")[0].at("changes")) CHECK(ch.at("config").is_string());
  const Json& s = j.at("pairs")[2].at("train");
  CHECK(s.at("name") == (tmp.path() / "schedule.yaml").string());
  CHECK(s.at("schedule") == (tmp.path() / "schedule.yaml").string());
  REQUIRE(s.at("stages").size() == 2);
  CHECK(s.at("stages")[1].at("start") == 50);
  CHECK(s.at("stages")[1].at("configs")[0].at("name") == abs + "filters/2-eval.yaml");
  CHECK(s.at("stages")[1].at("configs")[0].at("weight") == 3.0);
}

TEST_CASE("a mixture pair fails where a training config changes another axis or the hidden game",
          "[suite][mixture]") {
  fs::current_path(source_dir());
  const std::string abs = (source_dir() / "configs").string() + "/kage_bench/";
  TempDir tmp("suite_mixture_bad");
  write_text(tmp.path() / "latent.yaml", "extends: " + abs + "filters/2-eval.yaml\nphysics: {gravity: 0.9}\n");
  write_text(tmp.path() / "suite.yaml",
             "suite: s\npairs:\n"
             "  - {name: other-axis, axis: filters, eval: " + abs + "filters/1-eval.yaml, train: [" + abs +
                 "bases/image_skeleton.yaml, " + abs + "background/9-eval.yaml]}\n"
             "  - {name: latent, axis: filters, eval: " + abs + "filters/1-eval.yaml, train: [" + abs +
                 "bases/image_skeleton.yaml, latent.yaml]}\n");
  SuiteRun r;
  run_manifest(r, (tmp.path() / "suite.yaml").string());
  CHECK(r.report.passed() == 0);
  const PairResult& other = result(r, "other-axis");
  CHECK(other.lint_ok);
  CHECK(has_problem(other.cert, "background/9-eval.yaml': axis 'background' also changes and is not allowed"));
  const PairResult& latent = result(r, "latent");
  CHECK_FALSE(latent.lint_ok);
  bool located = false;
  for (const Diagnostic& d : r.diags.sorted())
    located = located || (d.rule == Rule::CertifyMixtureLatent && r.sources.name(d.range.begin.file).find("latent.yaml") !=
                                                                       std::string::npos);
  CHECK(located);
}

}  // namespace kage::test
