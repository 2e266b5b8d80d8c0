// The fuzz target's entry point without the fuzzer runtime: the seed corpus
// (configs/, tests/lint/) and a deterministic set of mutations of it.
#include <algorithm>
#include <catch2/catch.hpp>

#include "test_support.h"

namespace kage {
std::string fuzz_front_end_one(const uint8_t* data, size_t size, bool* fixpoint);
}

namespace kage::test {
namespace {

std::vector<std::string> seed_corpus() {
  std::vector<fs::path> paths;
  for (const char* dir : {"configs", "tests/lint"})
    for (const auto& e : fs::recursive_directory_iterator(source_dir() / dir))
      if (e.is_regular_file() && e.path().extension() == ".yaml") paths.push_back(e.path());
  std::sort(paths.begin(), paths.end());
  std::vector<std::string> out;
  for (const fs::path& p : paths) out.push_back(read_text(p));
  // Inputs aimed at the corners: extends, aliases, tags, odd numbers, nesting.
  out.push_back("extends: base.yaml\nphysics: {gravity: 0.5}\n");
  out.push_back("extends: config.yaml\n");
  out.push_back("a: &x {gravity: 1}\nphysics: *x\n");
  out.push_back("physics: !!str 3\nH: 0x40\nW: 0o17\nfilters: {brightness: 1_0.0e-1}\n");
  out.push_back("layout: {length: 99999999999999999999999}\nH: -9223372036854775808\n");
  out.push_back("? [a, b]\n: 1\n{x: y}: 2\n");
  out.push_back(std::string(200, '[') + std::string(200, ']'));
  out.push_back("character:\n  fallback_color: [1, 2]\n  shape_types: ''\n");
  out.push_back("");
  out.push_back("\xEF\xBB\xBF" "H: 64\n");
  // Multi-byte characters where a string is read as a list of its characters.
  out.push_back("background: {mode: color, color_names: \"b\xDE\x96\"}\nfilters: {pop_filter_list: \"\xE2\x82\xAC\"}\n");
  // YAML escapes that yaml-cpp writes as single Latin-1 bytes.
  out.push_back("background: {mode: black, image_paths: [\"a\\Nb\\_c.png\"]}\n");
  out.push_back("\"\\N\": 1\n");
  return out;
}

// xorshift64*: deterministic and independent of the standard library.
struct Rng {
  uint64_t s;
  uint64_t next() {
    s ^= s >> 12;
    s ^= s << 25;
    s ^= s >> 27;
    return s * 2685821657736338717ull;
  }
  size_t below(size_t n) { return n ? static_cast<size_t>(next() % n) : 0; }
};

std::string mutate(const std::string& in, const std::vector<std::string>& corpus, Rng& rng) {
  static const std::vector<std::string> tokens = {
      ":", "- ", "{", "}", "[", "]", ",", "\n", "  ", "&a ", "*a", "!!str ", ".inf", "-.nan", "null", "~", "true",
      "\"", "'", "#", "extends: base.yaml\n", "extends: config.yaml\n", "0x7f", "1e400", "-0", "?", "|\n  ",
      "physics:\n  ", "layout:\n  ", "background:\n  mode: image\n  ", "\t", "\x00", "\xff"};
  std::string s = in;
  const int steps = 1 + static_cast<int>(rng.below(4));
  for (int i = 0; i < steps; ++i) {
    const size_t pos = rng.below(s.size() + 1);
    switch (rng.below(5)) {
      case 0:
        if (!s.empty()) s[std::min(pos, s.size() - 1)] ^= static_cast<char>(1 << rng.below(8));
        break;
      case 1: s.erase(pos, rng.below(16)); break;
      case 2: s.insert(pos, tokens[rng.below(tokens.size())]); break;
      case 3: {
        const size_t from = rng.below(s.size() + 1);
        s.insert(pos, s.substr(from, rng.below(40)));
        break;
      }
      default: {
        const std::string& other = corpus[rng.below(corpus.size())];
        s = s.substr(0, pos) + other.substr(rng.below(other.size() + 1));
        break;
      }
    }
  }
  return s;
}

}  // namespace

TEST_CASE("the fuzz entry point holds its properties on the seed corpus", "[fuzz]") {
  const std::vector<std::string> corpus = seed_corpus();
  REQUIRE(corpus.size() > 40);
  size_t fixpoints = 0;
  for (const std::string& input : corpus) {
    INFO(input.substr(0, 400));
    bool fixpoint = false;
    CHECK(fuzz_front_end_one(reinterpret_cast<const uint8_t*>(input.data()), input.size(), &fixpoint) == "");
    fixpoints += fixpoint;
  }
  // The shipped KAGE-Bench configs (38 files) resolve with their real bases and assets.
  CHECK(fixpoints >= 38);
}

TEST_CASE("the fuzz entry point holds its properties on deterministic mutations", "[fuzz]") {
  const std::vector<std::string> corpus = seed_corpus();
  Rng rng{0x9E3779B97F4A7C15ull};
  size_t fixpoints = 0;
  for (int i = 0; i < 400; ++i) {
    const std::string input = mutate(corpus[rng.below(corpus.size())], corpus, rng);
    INFO("mutation " << i << ":\n" << input.substr(0, 400));
    bool fixpoint = false;
    CHECK(fuzz_front_end_one(reinterpret_cast<const uint8_t*>(input.data()), input.size(), &fixpoint) == "");
    fixpoints += fixpoint;
  }
  CHECK(fixpoints >= 40);  // mutations that still resolve exercise the fixpoint
}

}  // namespace kage::test
