// Certification of mixtures (compiler/analysis/mixture.*): configs that differ only on visual axes certify;
// the first latent key or observation side that differs is one located error naming both files.
#include <catch2/catch.hpp>

#include "compiler/analysis/mixture.h"
#include "fileio/sha256.h"
#include "test_support.h"

namespace kage::test {
namespace {

struct Mixture {
  SourceManager sources;
  DiagEngine diags{sources};
  std::optional<std::vector<Spec>> specs;

  /// The errors as "file:line:col: rule: message" ("-" for an error without a place).
  std::vector<std::string> located() const {
    std::vector<std::string> out;
    for (const Diagnostic& d : diags.sorted()) {
      if (d.severity != Severity::Error) continue;
      if (!d.range.begin.valid()) {
        out.push_back(std::string("-: ") + rule_info(d.rule).id + ": " + d.message);
        continue;
      }
      const LineCol lc = sources.line_col(d.range.begin);
      out.push_back(sources.name(d.range.begin.file) + ":" + std::to_string(lc.line) + ":" + std::to_string(lc.col) +
                    ": " + rule_info(d.rule).id + ": " + d.message);
    }
    return out;
  }
};

const std::map<std::string, std::string> kFiles = {
    {"base.yaml", "episode_length: 40\ncharacter:\n  use_shape: true\nphysics:\n  gravity: 0.75\n"},
    {"red.yaml", "extends: base.yaml\nbackground:\n  mode: color\n  color_names: [red]\n"},
    {"noise.yaml", "extends: base.yaml\nbackground:\n  mode: noise\nfilters:\n  gaussian_noise_std: 20.0\n"},
    {"heavy.yaml", "extends: base.yaml\n# heavier\nphysics:\n  gravity: 1.5\n"},
    {"heavy_red.yaml", "extends: heavy.yaml\nbackground:\n  mode: color\n  color_names: [red]\n"},
    // A layout section without `length` gets length 128, not 16 W (spec 11.4): a latent change hidden in a colour.
    {"green_layout.yaml", "extends: base.yaml\nlayout:\n  layout_colors: [green]\n"},
    {"plain.yaml", "background:\n  mode: black\ncharacter:\n  use_shape: true\n"},
    {"small.yaml", "extends: base.yaml\nW: 96\nH: 64\n"},
};

Mixture certify_files(const std::vector<std::string>& names) {
  MemoryFileReader reader;
  reader.files.insert(kFiles.begin(), kFiles.end());
  Mixture m;
  m.specs = analyze_mixture(names, ResolveOptions{}, m.sources, reader, m.diags);
  return m;
}

}  // namespace

TEST_CASE("configs that differ only on visual axes certify as a mixture", "[mixture]") {
  const Mixture m = certify_files({"base.yaml", "red.yaml", "noise.yaml"});
  INFO(m.located().size());
  REQUIRE(m.specs);
  CHECK(m.specs->size() == 3);
  CHECK(m.located().empty());
  const Json cert = mixture_json({"base.yaml", "red.yaml", "noise.yaml"}, *m.specs, config_schema());
  CHECK(cert.at("certified") == true);
  CHECK(cert.at("configs").at(1).at("name") == "red.yaml");
  CHECK(cert.at("configs").at(1).at("spec_sha256") == (*m.specs)[1].sha256());
  CHECK(cert.at("axes") == Json::array({"background", "filters"}));
  // One config alone is a mixture of one.
  CHECK(certify_files({"heavy.yaml"}).specs);
}

TEST_CASE("a latent difference is one error at the later config's key, naming both files", "[mixture]") {
  const Mixture m = certify_files({"base.yaml", "red.yaml", "heavy_red.yaml"});
  CHECK_FALSE(m.specs);
  // heavy_red.yaml takes gravity from heavy.yaml, its base: the error points there.
  REQUIRE(m.located() == std::vector<std::string>{
      "heavy.yaml:4:3: certify-mixture-latent: mixture of 'base.yaml' and 'heavy_red.yaml': latent key "
      "'physics.gravity' is 0.75 in 'base.yaml' but 1.5 in 'heavy_red.yaml'; a mixture's configs must run one hidden "
      "game and differ only on visual axes"});
  CHECK(m.diags.sorted().front().path == "/physics/gravity");
}

TEST_CASE("a key only one config writes is located there and the default named", "[mixture]") {
  const Mixture m = certify_files({"plain.yaml", "base.yaml"});
  CHECK_FALSE(m.specs);
  REQUIRE(m.located().size() == 1);
  // episode_length: base.yaml writes 40, plain.yaml takes the default (500); the first latent key in schema order.
  CHECK(m.located()[0] ==
        "base.yaml:1:1: certify-mixture-latent: mixture of 'plain.yaml' and 'base.yaml': latent key 'episode_length' "
        "is 500 (its default) in 'plain.yaml' but 40 in 'base.yaml'; a mixture's configs must run one hidden game and "
        "differ only on visual axes");
  const Mixture reversed = certify_files({"base.yaml", "plain.yaml"});
  REQUIRE(reversed.located().size() == 1);
  CHECK(reversed.located()[0].rfind("base.yaml:1:1: certify-mixture-latent: mixture of 'base.yaml' and 'plain.yaml': "
                                    "latent key 'episode_length' is 40 in 'base.yaml' but 500 (its default) in "
                                    "'plain.yaml'", 0) == 0);
}

TEST_CASE("a latent key that another key's absence changes is found (the partial layout quirk)", "[mixture]") {
  const Mixture m = certify_files({"base.yaml", "green_layout.yaml"});
  CHECK_FALSE(m.specs);
  REQUIRE(m.located() == std::vector<std::string>{
      "green_layout.yaml:1:1: certify-mixture-latent: mixture of 'base.yaml' and 'green_layout.yaml': latent key "
      "'layout.length' is 2048 (its default) in 'base.yaml' but 128 (its default) in 'green_layout.yaml'; a "
      "mixture's configs must run one hidden game and differ only on visual axes"});
}

TEST_CASE("a different observation shape is its own error, before the latent keys it drags along", "[mixture]") {
  // W also sets layout.length (16 W) when the layout section is absent: the shape is reported, once.
  const Mixture m = certify_files({"base.yaml", "small.yaml"});
  CHECK_FALSE(m.specs);
  REQUIRE(m.located() == std::vector<std::string>{
      "small.yaml:3:1: certify-mixture-shape: mixture of 'base.yaml' and 'small.yaml': observations are 128x128 "
      "(height x width) in 'base.yaml' but 64x96 in 'small.yaml'; one batch has one observation shape"});
}

TEST_CASE("a config with errors is reported as itself, and nothing is certified", "[mixture]") {
  const Mixture m = certify_files({"base.yaml", "missing.yaml"});
  CHECK_FALSE(m.specs);
  REQUIRE(m.located().size() == 1);
  CHECK(m.located()[0].find("file-unreadable") != std::string::npos);
}

TEST_CASE("a mixture's identity is its parts' Spec hashes and counts, in order", "[mixture]") {
  const std::string a(64, 'a'), b(64, 'b');
  const std::string ab = mixture_sha256({{a, 3}, {b, 1}});
  CHECK(ab.size() == 64);
  CHECK(ab == mixture_sha256({{a, 3}, {b, 1}}));
  CHECK(ab != mixture_sha256({{a, 1}, {b, 3}}));
  CHECK(ab != mixture_sha256({{b, 1}, {a, 3}}));
  // The hash of the documented compact JSON.
  CHECK(ab == sha256_hex("{\"kage_mixture\":1,\"parts\":[{\"num_envs\":3,\"spec_sha256\":\"" + a +
                         "\"},{\"num_envs\":1,\"spec_sha256\":\"" + b + "\"}]}"));
}

}  // namespace kage::test
