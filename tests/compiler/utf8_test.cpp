// UTF-8 handling of the front end: code points as Python counts them, and the YAML escapes that
// yaml-cpp writes as stray Latin-1 bytes restored, so canonical JSON never holds broken UTF-8.
#include <catch2/catch.hpp>

#include "compiler/basic/utf8.h"
#include "test_support.h"

namespace kage::test {
namespace {

TEST_CASE("utf8_characters splits by code point", "[utf8]") {
  const std::vector<std::string> want = {"a", "\xC3\xA9", "\xE2\x82\xAC", "\xF0\x9F\x98\x80"};
  CHECK(utf8_characters("a\xC3\xA9\xE2\x82\xAC\xF0\x9F\x98\x80") == want);
}

TEST_CASE("invalid_utf8_offset finds the first malformed byte", "[utf8]") {
  CHECK_FALSE(invalid_utf8_offset("plain \xC3\xA9").has_value());
  CHECK(invalid_utf8_offset("ab\x85").value() == 2);
  CHECK(invalid_utf8_offset("\xC0\x80").value() == 0);          // overlong
  CHECK(invalid_utf8_offset("x\xED\xA0\x80").value() == 1);     // surrogate
  CHECK(invalid_utf8_offset("\xE2\x82").value() == 0);          // truncated
}

TEST_CASE("stray Latin-1 bytes become their code points", "[utf8]") {
  CHECK(utf8_from_latin1_strays("a\x85" "b\xA0") == "a\xC2\x85" "b\xC2\xA0");
  CHECK(utf8_from_latin1_strays("\xC3\xA9") == "\xC3\xA9");  // well-formed text is kept
}

TEST_CASE("the YAML escapes \\N and \\_ resolve to valid UTF-8", "[utf8][resolve]") {
  MemoryFileReader reader;
  reader.files["c.yaml"] =
      "background:\n  mode: color\n  color_names: [\"red\\_\"]\n\"key\\N\": 1\n";
  Analysis a;
  analyze(a, "c.yaml", reader);
  // Both names are reported (as unknown), with the escapes as U+00A0 and U+0085.
  CHECK(a.count("schema-unknown-name") == 1);
  CHECK(a.count("schema-unknown-key") == 1);
  for (const Diagnostic& d : a.diags.sorted()) CHECK_FALSE(invalid_utf8_offset(d.message).has_value());
  std::ostringstream json;
  print_json(a.diags, json);
  CHECK_FALSE(invalid_utf8_offset(json.str()).has_value());
}

}  // namespace
}  // namespace kage::test
