// Did-you-mean over the schema's keys: every key misspelt by one transposition, deletion, insertion or
// substitution gets that key as its suggestion, or none when the misspelling is one edit from two keys.
#include <catch2/catch.hpp>

#include <cctype>
#include <map>
#include <set>

#include "compiler/basic/spell.h"
#include "compiler/sema/schema.h"

namespace kage::test {
namespace {

/// Every string one edit from `word` over `alphabet`, built by the edits themselves (independent of
/// edit_distance).
std::set<std::string> one_edit(const std::string& word, const std::string& alphabet) {
  std::set<std::string> out;
  for (size_t i = 0; i + 1 < word.size(); ++i) {
    std::string t = word;
    std::swap(t[i], t[i + 1]);
    out.insert(t);
  }
  for (size_t i = 0; i < word.size(); ++i) out.insert(word.substr(0, i) + word.substr(i + 1));
  for (size_t i = 0; i <= word.size(); ++i)
    for (char c : alphabet) out.insert(word.substr(0, i) + c + word.substr(i));
  for (size_t i = 0; i < word.size(); ++i)
    for (char c : alphabet) {
      std::string t = word;
      t[i] = c;
      out.insert(t);
    }
  out.erase(word);
  return out;
}

std::string lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

}  // namespace

TEST_CASE("edit distance counts a transposition as one edit", "[spell]") {
  CHECK(edit_distance("widht", "width", false) == 1);
  CHECK(edit_distance("gravtiy", "gravity", false) == 1);
  CHECK(edit_distance("ab", "ba", false) == 1);
  CHECK(edit_distance("abc", "ca", false) == 3);  // optimal string alignment: no edit of a transposed pair
  CHECK(edit_distance("Width", "width", true) == 0);
  CHECK(edit_distance("", "abc", false) == 3);
  CHECK(suggest("widht", {"width", "height", "use_shape"}) == std::optional<std::string>("width"));
}

TEST_CASE("every key misspelt by one edit gets its suggestion, or none when ambiguous", "[spell]") {
  std::map<std::string, std::vector<std::string>> by_section;
  for (const KeySchema& k : config_schema().keys()) by_section[k.section].push_back(k.name);
  REQUIRE(by_section.size() > 8);
  size_t suggested = 0, ambiguous = 0;
  for (const auto& [section, names] : by_section) {
    // Suggestions ignore case, so misspellings are made from the lower-case names.
    std::set<std::string> legal;
    for (const std::string& name : names) legal.insert(lower(name));
    // Inserted or substituted characters: those of the section's keys, and '#' for all others (which
    // are alike: equally far from every key).
    std::string alphabet = "#";
    for (const std::string& name : legal)
      for (char c : name)
        if (alphabet.find(c) == std::string::npos) alphabet += c;
    std::map<std::string, std::set<std::string>> sources;  // misspelling -> the keys one edit away
    for (const std::string& name : names)
      for (const std::string& typo : one_edit(lower(name), alphabet))
        if (!legal.count(typo)) sources[typo].insert(name);
    for (const auto& [typo, from] : sources) {
      const std::optional<std::string> got = suggest(typo, names);
      if (from.size() == 1) {
        if (got != std::optional<std::string>(*from.begin())) {
          FAIL_CHECK("'" << typo << "' in '" << section << "' suggests '" << got.value_or("(none)")
                         << "', not '" << *from.begin() << "'");
        }
        ++suggested;
      } else {
        if (got) FAIL_CHECK("'" << typo << "' in '" << section << "' is one edit from several keys, yet suggests '"
                                << *got << "'");
        ++ambiguous;
      }
    }
  }
  CHECK(suggested > 5000);
  CHECK(ambiguous > 0);
}

}  // namespace kage::test
