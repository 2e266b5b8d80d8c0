// Did-you-mean by edit distance.
#include "compiler/basic/spell.h"

#include <algorithm>

namespace kage {

namespace {

char lower(char c) { return c >= 'A' && c <= 'Z' ? static_cast<char>(c - 'A' + 'a') : c; }

bool equal_ignoring_case(const std::string& a, const std::string& b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i)
    if (lower(a[i]) != lower(b[i])) return false;
  return true;
}

}  // namespace

size_t edit_distance(const std::string& a, const std::string& b, bool ignore_case) {
  auto eq = [&](char x, char y) { return ignore_case ? lower(x) == lower(y) : x == y; };
  // Optimal string alignment: three rows, since a transposition looks two rows back. The rows are
  // kept between calls (did-you-mean runs once per unknown key and candidate).
  thread_local std::vector<size_t> before, prev, cur;
  before.assign(b.size() + 1, 0);
  prev.resize(b.size() + 1);
  cur.assign(b.size() + 1, 0);
  for (size_t j = 0; j <= b.size(); ++j) prev[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    cur[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + (eq(a[i - 1], b[j - 1]) ? 0 : 1)});
      if (i > 1 && j > 1 && eq(a[i - 1], b[j - 2]) && eq(a[i - 2], b[j - 1]))
        cur[j] = std::min(cur[j], before[j - 2] + 1);
    }
    std::swap(before, prev);
    std::swap(prev, cur);
  }
  return prev[b.size()];
}

std::optional<std::string> suggest(const std::string& word, const std::vector<std::string>& candidates) {
  for (const std::string& c : candidates)
    if (c != word && equal_ignoring_case(word, c)) return c;
  const size_t limit = std::min<size_t>(3, std::max<size_t>(1, word.size() / 3));
  size_t best = limit + 1;
  std::optional<std::string> pick;
  bool tie = false;
  for (const std::string& c : candidates) {
    // The distance is at least the difference in length: most candidates need no table at all, and
    // a hostile file of a million unknown keys costs a million short comparisons.
    const size_t apart = c.size() > word.size() ? c.size() - word.size() : word.size() - c.size();
    if (apart > limit) continue;
    const size_t d = edit_distance(word, c, true);
    if (d < best) {
      best = d;
      pick = c;
      tie = false;
    } else if (d == best) {
      tie = true;
    }
  }
  if (tie || best > limit) return std::nullopt;
  return pick;
}

}  // namespace kage
