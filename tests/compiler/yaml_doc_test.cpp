// The YAML reader against what the original's loader (PyYAML safe_load) does with the same text: one
// document only, tags it refuses or values its tags cannot construct, merge keys, and plain scalars
// typed by the YAML 1.1 rules. Each expected value was worked out with PyYAML 6 by hand.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>

#include "compiler/analysis/suite.h"
#include "compiler/parse/compose.h"
#include "compiler/parse/yaml_doc.h"
#include "test_support.h"

namespace kage::test {
namespace {

struct Parsed {
  SourceManager sources;
  DiagEngine diags{sources};
  std::optional<DocNode> doc;

  /// "line:col rule: message" of every diagnostic.
  std::string dump() const {
    std::string out;
    for (const Diagnostic& d : diags.sorted()) {
      const LineCol lc = sources.line_col(d.range.begin);
      out += std::to_string(lc.line) + ":" + std::to_string(lc.col) + " " + rule_info(d.rule).id + ": " + d.message +
             "\n";
    }
    return out;
  }
  bool has(const std::string& line_col_rule) const { return dump().find(line_col_rule) != std::string::npos; }
};

void parse(Parsed& p, const std::string& text) {
  const FileId id = p.sources.add("t.yaml", text);
  p.doc = parse_yaml(p.sources, id, p.diags);
}

/// The value at `path` ("a/b") of a parsed mapping.
const DocNode& at(const DocNode& root, const std::string& path) {
  const DocNode* n = &root;
  std::istringstream parts(path);
  std::string key;
  while (std::getline(parts, key, '/')) {
    const DocEntry* e = n->find(key);
    INFO("no key '" << key << "' in " << path);
    REQUIRE(e);
    n = &e->value;
  }
  return *n;
}

std::vector<std::string> keys(const DocNode& map) {
  std::vector<std::string> out;
  for (const DocEntry& e : map.entries) out.push_back(e.key);
  return out;
}

}  // namespace

TEST_CASE("a file of several YAML documents is refused at the second one", "[yaml][documents]") {
  struct Case {
    const char* text;
    const char* where;  // line:col of the second document
  };
  const Case cases[] = {
      {"H: 64\n---\nW: 32\n", "2:1 "},
      {"H: 64\n--- # the rest\n", "2:1 "},                           // an empty second document
      {"---\nH: 64\n---\nW: 32\n", "3:1 "},                          // the first one explicit too
      {"%YAML 1.1\n---\nH: 64\n---\nW: 32\n", "4:1 "},               // after a directive
      {"H: 64\n...\n---\nW: 32\n", "3:1 "},                          // the first one closed with '...'
      {"H: &size 64\n---\nW: *size\n", "2:1 "},                      // an alias across documents
      {"physics:\n  gravity: 0.5\n---\nphysics:\n  gravity: 2\n", "3:1 "},
  };
  for (const Case& c : cases) {
    Parsed p;
    parse(p, c.text);
    INFO(c.text << "\n" << p.dump());
    CHECK_FALSE(p.doc);
    CHECK(p.has(std::string(c.where) + "yaml-multiple-documents: a second YAML document starts here"));
    CHECK(p.dump().find("merge them into one mapping or split them into separate files") != std::string::npos);
  }
  // One document, with or without its markers, or with '---' inside a value, is read as before.
  for (const char* one : {"---\nH: 64\n", "H: 64\n...\n", "---\nH: 64\n...\n", "s: \"a --- b ...\"\nH: 64\n",
                          "s: |\n  text\n  --- not a marker inside a block\nH: 64\n"}) {
    Parsed p;
    parse(p, one);
    INFO(one << "\n" << p.dump());
    REQUIRE(p.doc);
    CHECK_FALSE(p.diags.has_errors());
    CHECK(std::get<int64_t>(scalar_value(at(*p.doc, "H"))) == 64);
  }
  // Text after '...' that starts no new document is not YAML to PyYAML either.
  Parsed bare;
  parse(bare, "H: 64\n...\nW: 32\n");
  INFO(bare.dump());
  CHECK_FALSE(bare.doc);
  CHECK(bare.diags.has_errors());
}

TEST_CASE("every file the front end reads refuses a second document", "[yaml][documents]") {
  MemoryFileReader reader;
  reader.files["c/base.yaml"] = "H: 64\n---\nW: 32\n";
  reader.files["c/child.yaml"] = "extends: base.yaml\nW: 16\n";
  reader.files["c/config.yaml"] = "H: 64\nW: 16\n---\nW: 32\n";
  {
    Analysis a;  // the config itself: no Spec
    analyze(a, "c/config.yaml", reader);
    INFO(a.dump());
    CHECK_FALSE(a.spec);
    CHECK(a.count("yaml-multiple-documents") == 1);
  }
  {
    Analysis a;  // a base named by extends
    analyze(a, "c/child.yaml", reader);
    INFO(a.dump());
    CHECK(a.diags.has_errors());
    CHECK(a.count("yaml-multiple-documents") == 1);
  }
  {
    SourceManager sources;  // a suite manifest
    DiagEngine diags(sources);
    reader.files["s/suite.yaml"] =
        "suite: s\npairs:\n  - {name: p, axis: background, train: a.yaml, eval: b.yaml}\n---\nsuite: t\n";
    const auto suite = load_suite("s/suite.yaml", sources, reader, diags);
    CHECK_FALSE(suite);
    size_t n = 0;
    for (const Diagnostic& d : diags.sorted()) n += std::string(rule_info(d.rule).id) == "yaml-multiple-documents";
    CHECK(n == 1);
  }
}

TEST_CASE("tags: PyYAML's meaning, or a located error where it refuses", "[yaml][tags]") {
  Parsed p;
  parse(p,
        "a: !!int \"0x1F\"\n"   // 31
        "b: !!float 1\n"        // 1.0, a number, not an integer
        "c: !!bool Yes\n"       // True
        "d: !!null anything\n"  // None
        "e: !!str 5\n"          // '5'
        "f: !!float 1e5\n"      // 100000.0 (untagged, 1e5 is a string)
        "g: !!int 1_000\n"      // 1000
        "h: !!int 0b101\n"      // 5
        "i: !!float -.inf\n"    // -inf
        "j: !!map {k: 1}\n"
        "k: !!seq [1]\n"
        "l: ! 5\n");            // '5': the non-specific tag makes a string
  INFO(p.dump());
  REQUIRE(p.doc);
  CHECK_FALSE(p.diags.has_errors());
  const DocNode& d = *p.doc;
  CHECK(std::get<int64_t>(scalar_value(at(d, "a"))) == 31);
  CHECK(std::get<double>(scalar_value(at(d, "b"))) == 1.0);
  CHECK(std::string(kind_name(at(d, "b"))) == "number");
  CHECK(std::get<bool>(scalar_value(at(d, "c"))));
  CHECK(at(d, "d").is_null());
  CHECK(std::get<std::string>(scalar_value(at(d, "e"))) == "5");
  CHECK(std::get<double>(scalar_value(at(d, "f"))) == 100000.0);
  CHECK(std::get<int64_t>(scalar_value(at(d, "g"))) == 1000);
  CHECK(std::get<int64_t>(scalar_value(at(d, "h"))) == 5);
  CHECK(std::get<double>(scalar_value(at(d, "i"))) == -INFINITY);
  CHECK(at(d, "j").is_map());
  CHECK(std::get<std::string>(scalar_value(at(d, "l"))) == "5");

  struct Refused {
    const char* text;
    const char* says;  // with its line:col
  };
  const Refused refused[] = {
      {"a: !!python/object:os.system x\n", "1:4 yaml-tag: unknown tag '!!python/object:os.system'"},
      {"a: !!python/name:builtins.print\n", "1:4 yaml-tag: unknown tag '!!python/name:builtins.print'"},
      {"physics:\n  gravity: !custom 0.5\n", "2:12 yaml-tag: unknown tag '!custom'"},
      {"a: !!timestamp 2001-01-01\n", "1:4 yaml-tag: '!!timestamp' makes a value that no config key takes"},
      {"a: !!binary aGVsbG8=\n", "1:4 yaml-tag: '!!binary' makes a value"},
      {"a: !!set {x, y}\n", "1:4 yaml-tag: '!!set' makes a value"},
      {"a: !!int abc\n", "1:4 yaml-tag: '!!int abc' is not an integer"},
      {"a: !!int 99999999999999999999\n", "1:4 yaml-tag: '!!int 99999999999999999999' is not an integer"},
      {"a: !!float x1\n", "1:4 yaml-tag: '!!float x1' is not a number"},
      {"a: !!bool y\n", "1:4 yaml-tag: '!!bool y' is not true, false"},
      {"a: !!map [1]\n", "1:4 yaml-tag: '!!map' needs a mapping, not a list"},
      {"a: !!seq {b: 1}\n", "1:4 yaml-tag: '!!seq' needs a list, not a mapping"},
      {"a: !!str {b: 1}\n", "1:4 yaml-tag: '!!str' needs a single value, not a mapping"},
      {"!!python/name:os.system x: 1\n", "1:1 yaml-tag: key 'x' has the tag '!!python/name:os.system'"},
  };
  for (const Refused& r : refused) {
    Parsed q;
    parse(q, r.text);
    INFO(r.text << "\n" << q.dump());
    CHECK(q.has(r.says));
    CHECK(q.dump().find("remove the tag") != std::string::npos);
  }
}

TEST_CASE("merge keys expand as PyYAML's safe loader expands them", "[yaml][merge]") {
  Parsed p;
  parse(p,
        "base: &b {x: 1, y: 2}\n"
        "other: &o {x: 10, z: 30}\n"
        "one:\n  <<: *b\n  y: 3\n"                     // {x: 1, y: 3}: a written key wins
        "list: {<<: [*b, *o], q: 4}\n"                 // {x: 1, y: 2, z: 30, q: 4}: the first mapping wins
        "two: {<<: {x: 1}, <<: {x: 2, w: 5}}\n"        // {x: 2, w: 5}: the later merge key wins
        "nested:\n  <<: {inner: {a: 1}}\n  inner: {b: 2}\n"  // shallow: inner is {b: 2}
        "quoted: {\"<<\": 7}\n");                      // a quoted << is an ordinary key
  INFO(p.dump());
  REQUIRE(p.doc);
  CHECK_FALSE(p.diags.has_errors());
  const DocNode& d = *p.doc;
  auto num = [&](const std::string& path) { return std::get<int64_t>(scalar_value(at(d, path))); };
  CHECK(keys(at(d, "one")) == std::vector<std::string>{"x", "y"});
  CHECK(num("one/x") == 1);
  CHECK(num("one/y") == 3);
  CHECK(num("list/x") == 1);
  CHECK(num("list/y") == 2);
  CHECK(num("list/z") == 30);
  CHECK(num("list/q") == 4);
  CHECK(at(d, "list").entries.size() == 4);
  CHECK(num("two/x") == 2);
  CHECK(num("two/w") == 5);
  CHECK(keys(at(d, "nested/inner")) == std::vector<std::string>{"b"});
  CHECK(num("quoted/<<") == 7);

  for (const char* bad : {"a: {<<: 5}\n", "a: {<<: [{x: 1}, 2]}\n"}) {
    Parsed q;
    parse(q, bad);
    INFO(bad << "\n" << q.dump());
    CHECK(q.has("yaml-not-mapping: the value of the merge key '<<' must be a mapping or a list of mappings"));
  }
}

TEST_CASE("a merge key in a config gives the values it merges", "[yaml][merge]") {
  MemoryFileReader reader;
  reader.files["c/merged.yaml"] =
      "H: 64\nW: 64\nlayout: {length: 1024}\n"
      "physics:\n  <<: {gravity: 0.5, ground_friction: 0.7}\n  ground_friction: 0.8\n";
  Analysis a;
  analyze(a, "c/merged.yaml", reader);
  INFO(a.dump());
  REQUIRE(a.spec);
  CHECK(a.spec->values.at("physics").at("gravity") == 0.5);
  CHECK(a.spec->values.at("physics").at("ground_friction") == 0.8);
}

TEST_CASE("plain scalars: YAML 1.1 binary and base-60 numbers as PyYAML types them", "[yaml][scalars]") {
  Parsed p;
  parse(p, "a: 0b1000000\nb: 1:30\nc: -1:00:01\nd: 1:30.5\ne: 0b_1_0\nf: 1:60\ng: 0b102\n");
  INFO(p.dump());
  REQUIRE(p.doc);
  const DocNode& d = *p.doc;
  CHECK(std::get<int64_t>(scalar_value(at(d, "a"))) == 64);
  CHECK(std::get<int64_t>(scalar_value(at(d, "b"))) == 90);
  CHECK(std::get<int64_t>(scalar_value(at(d, "c"))) == -3601);
  CHECK(std::get<double>(scalar_value(at(d, "d"))) == 90.5);
  CHECK(std::get<int64_t>(scalar_value(at(d, "e"))) == 2);
  CHECK(std::get<std::string>(scalar_value(at(d, "f"))) == "1:60");  // 60 is no base-60 digit
  CHECK(std::get<std::string>(scalar_value(at(d, "g"))) == "0b102");
}

TEST_CASE("control characters YAML forbids are refused where they are", "[yaml][hostile]") {
  struct Case {
    std::string text;
    const char* says;
  };
  const Case cases[] = {
      {std::string("gra\0vity: 1\n", 12), "1:4 yaml-syntax: the file holds the control character \\0 (NUL)"},
      {"physics:\n  a\x01" "b: 1\n", "2:4 yaml-syntax: the file holds the control character \\x01"},
      {"H: 64\x7f\n", "1:6 yaml-syntax: the file holds the control character \\x7f"},
      {"H: \xc2\x85\x65\n", ""},  // U+0085 (NEL) is allowed, as PyYAML allows it
  };
  for (const Case& c : cases) {
    Parsed p;
    parse(p, c.text);
    INFO(p.dump());
    if (*c.says == 0) {
      CHECK_FALSE(p.has("control character"));
      continue;
    }
    CHECK_FALSE(p.doc);
    CHECK(p.has(c.says));
    CHECK(p.dump().find("remove it") != std::string::npos);
  }
  // A tab and a carriage return are whitespace, and escapes inside double quotes are text.
  Parsed ok;
  parse(ok, "a:\t1\r\nb: \"x\\0y\"\n");
  INFO(ok.dump());
  REQUIRE(ok.doc);
  CHECK_FALSE(ok.diags.has_errors());
  CHECK(std::get<std::string>(scalar_value(at(*ok.doc, "b"))) == std::string("x\0y", 3));
}

TEST_CASE("an empty explicit key is located at its '?'", "[yaml][hostile]") {
  // `?` alone is an explicit key with no content: a null node that yaml-cpp marks at the next token, or at the
  // end of the file, once past it (a fuzz input). PyYAML loads it as {None: None}, which the original ignores.
  struct Case {
    std::string text;
    uint32_t line, col;  // of the `?`
  };
  const Case cases[] = {
      {"?\n", 1, 1},
      {"physics:\n  gravity: 0.5\n?\n", 3, 1},
      {"a: 1\n?  # empty\n", 2, 1},
      {"seed: 1 # why? no\n?\nH: 64\n", 2, 1},  // a `?` in a comment is not the key
      {"title: what?\n? # empty\n", 2, 1},       // nor one in the value before
      {"{seed: 1, ? , H: 64}\n", 1, 11},
  };
  for (const Case& c : cases) {
    Parsed p;
    parse(p, c.text);
    INFO(c.text << "\n" << p.dump());
    REQUIRE(p.doc);
    const auto key = std::find_if(p.doc->entries.begin(), p.doc->entries.end(),
                                  [](const DocEntry& e) { return e.key == "?"; });
    REQUIRE(key != p.doc->entries.end());
    const LineCol at = p.sources.line_col(key->key_range.begin);
    CHECK(at.line == c.line);
    CHECK(at.col == c.col);
    CHECK(key->key_range.end <= c.text.size());
    CHECK(key->value.range.end <= c.text.size());
  }
  // Nested, the `?` is found after the entry before it in its own mapping.
  Parsed nested;
  parse(nested, "physics:\n  gravity: 0.5\n  ?\n  ground_friction: 0.8\n");
  REQUIRE(nested.doc);
  const DocEntry& physics = nested.doc->entries.front();
  REQUIRE(physics.value.entries.size() == 3);
  const LineCol at = nested.sources.line_col(physics.value.entries[1].key_range.begin);
  CHECK(at.line == 3);
  CHECK(at.col == 3);
}

}  // namespace kage::test
