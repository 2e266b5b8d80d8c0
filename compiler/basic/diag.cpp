// Diagnostic collection, filtering and printing.
#include "compiler/basic/diag.h"

#include <algorithm>
#include <nlohmann/json.hpp>
#include <ostream>
#include <sstream>

namespace kage {

const std::vector<RuleInfo>& all_rules() {
  static const std::vector<RuleInfo> rules = {
#define KAGE_RULE(name, id, severity, doc) {Rule::name, id, Severity::severity, doc},
#include "compiler/basic/diag_rules.def"
#undef KAGE_RULE
  };
  return rules;
}

const RuleInfo& rule_info(Rule rule) { return all_rules()[static_cast<size_t>(rule)]; }

const RuleInfo* find_rule(const std::string& id) {
  for (const RuleInfo& r : all_rules())
    if (id == r.id) return &r;
  return nullptr;
}

std::vector<DisabledRule> find_disabled_rules(std::string_view text) {
  std::vector<DisabledRule> found;
  static constexpr std::string_view kLine = "kagec: disable=", kFile = "kagec: disable-file=";
  for (size_t at = text.find("kagec: disable"); at != std::string_view::npos; at = text.find("kagec: disable", at + 1)) {
    const bool whole_file = text.substr(at, kFile.size()) == kFile;
    if (!whole_file && text.substr(at, kLine.size()) != kLine) continue;
    const size_t start = at + (whole_file ? kFile : kLine).size();
    const std::string_view rest = text.substr(start);
    const std::string_view list = rest.substr(0, rest.find_first_of(" \t#\r\n"));
    for (size_t item = 0; item <= list.size();) {  // comma-separated ids, empty ones included
      const size_t comma = std::min(list.find(',', item), list.size());
      found.push_back({static_cast<uint32_t>(start + item), list.substr(item, comma - item), whole_file});
      item = comma + 1;
    }
  }
  return found;
}

std::string diagnostics_text(const DiagEngine& engine) {
  std::ostringstream s;
  print_text(engine, s);
  return s.str();
}

const char* severity_name(Severity s) {
  switch (s) {
    case Severity::Note: return "note";
    case Severity::Warning: return "warning";
    case Severity::Error: return "error";
  }
  return "error";
}

Diagnostic& DiagEngine::report(Rule rule, Range range, std::string message, std::string path) {
  Diagnostic d;
  d.rule = rule;
  d.severity = rule_info(rule).severity;
  if (werror_ && d.severity == Severity::Warning) d.severity = Severity::Error;
  d.range = range;
  d.message = std::move(message);
  d.path = std::move(path);
  diags_.push_back(std::move(d));
  return diags_.back();
}

const std::multimap<uint32_t, std::string_view>& DiagEngine::disable_comments(FileId file) const {
  const auto found = disable_comments_.find(file);
  if (found != disable_comments_.end()) return found->second;
  std::multimap<uint32_t, std::string_view>& lines = disable_comments_[file];
  for (const DisabledRule& d : find_disabled_rules(sources_.text(file)))
    lines.emplace(d.whole_file ? kWholeFile : sources_.line_col(Loc{file, d.offset}).line, d.rule);
  return lines;
}

// `# kagec: disable=RULE[,RULE]` on the diagnostic's line or the line above, or `# kagec: disable-file=RULE[,RULE]`
// anywhere in the diagnostic's file.
bool DiagEngine::suppressed(const Diagnostic& d) const {
  const char* id = rule_info(d.rule).id;
  if (disabled_.count(id)) return true;
  if (no_warnings_ && d.severity == Severity::Warning) return true;
  if (!d.range.begin.valid()) return false;
  const std::multimap<uint32_t, std::string_view>& comments = disable_comments(d.range.begin.file);
  if (comments.empty()) return false;
  auto mentions = [&](uint32_t line) {
    const auto [first, last] = comments.equal_range(line);
    return std::any_of(first, last, [&](const auto& entry) { return entry.second == id; });
  };
  const uint32_t line = sources_.line_col(d.range.begin).line;
  return mentions(kWholeFile) || mentions(line) || (line > 1 && mentions(line - 1));
}

std::vector<Diagnostic> DiagEngine::sorted() const {
  std::vector<Diagnostic> out;
  for (const Diagnostic& d : diags_)
    if (!suppressed(d)) out.push_back(d);
  std::stable_sort(out.begin(), out.end(), [&](const Diagnostic& a, const Diagnostic& b) {
    const std::string an = a.range.begin.valid() ? sources_.name(a.range.begin.file) : "";
    const std::string bn = b.range.begin.valid() ? sources_.name(b.range.begin.file) : "";
    if (an != bn) return an < bn;
    if (a.range.begin.offset != b.range.begin.offset) return a.range.begin.offset < b.range.begin.offset;
    return std::string(rule_info(a.rule).id) < rule_info(b.rule).id;
  });
  return out;
}

size_t DiagEngine::error_count() const {
  size_t n = 0;
  for (const Diagnostic& d : diags_) n += d.severity == Severity::Error && !suppressed(d);
  return n;
}

size_t DiagEngine::warning_count() const {
  size_t n = 0;
  for (const Diagnostic& d : diags_) n += d.severity == Severity::Warning && !suppressed(d);
  return n;
}

namespace {

std::string location_prefix(const SourceManager& sm, Loc loc) {
  if (!loc.valid()) return "kagec";
  const LineCol lc = sm.line_col(loc);
  return sm.name(loc.file) + ":" + std::to_string(lc.line) + ":" + std::to_string(lc.col);
}

/// How a byte is shown: control characters as escapes (\0, \t, \n, \r, else \xNN), so that a file
/// name, key or source line holding one can neither drive the terminal nor split a diagnostic.
std::string_view shown_byte(char c, char (&buf)[5], bool raw_tab = false) {
  const auto u = static_cast<unsigned char>(c);
  if ((u >= 0x20 && u != 0x7f) || (raw_tab && c == '\t')) {
    buf[0] = c;
    return {buf, 1};
  }
  switch (c) {
    case '\0': return "\\0";
    case '\t': return "\\t";
    case '\n': return "\\n";
    case '\r': return "\\r";
    default: break;
  }
  static const char kHex[] = "0123456789abcdef";
  buf[0] = '\\';
  buf[1] = 'x';
  buf[2] = kHex[u >> 4];
  buf[3] = kHex[u & 15];
  return {buf, 4};
}

std::string printable(std::string_view text) {
  std::string out;
  char buf[5];
  for (char c : text) out += shown_byte(c, buf);
  return out;
}

/// The source line of `range` and a caret line under it: at most kMaxSnippetBytes of the line (a window
/// around the caret, "..." marking what is cut), each byte shown as printable() shows it but a tab,
/// which stays a tab in both lines so that the caret lines up.
void print_snippet(const SourceManager& sm, const Range& range, std::ostream& out) {
  if (!range.begin.valid()) return;
  const std::string_view line = sm.line_text(range.begin);
  const LineCol lc = sm.line_col(range.begin);
  const size_t caret = std::min<size_t>(lc.col - 1, line.size());
  size_t from = 0, to = line.size();
  if (line.size() > kMaxSnippetBytes) {
    from = caret > kMaxSnippetBytes / 3 ? caret - kMaxSnippetBytes / 3 : 0;
    to = std::min(line.size(), from + kMaxSnippetBytes);
    from = to - std::min(to, kMaxSnippetBytes);
  }
  const uint32_t line_begin = range.begin.offset - (lc.col - 1);
  const size_t end = std::max<size_t>(caret + 1, std::min<size_t>(range.end - line_begin, to));
  std::string text = from > 0 ? "..." : "", marker = from > 0 ? "   " : "";
  char buf[5];
  for (size_t i = from; i < to; ++i) {
    const std::string_view shown = shown_byte(line[i], buf, true);
    text += shown;
    const char mark = i == caret ? '^' : i > caret && i < end ? '~' : line[i] == '\t' ? '\t' : ' ';
    marker.append(shown.size(), mark);
  }
  if (caret >= to) marker += '^';
  if (to < line.size()) text += "...";
  while (!marker.empty() && marker.back() == ' ') marker.pop_back();
  out << text << '\n' << marker << '\n';
}

}  // namespace

void print_text(const DiagEngine& engine, std::ostream& out, bool color) {
  const SourceManager& sm = engine.sources();
  const char* bold = color ? "\033[1m" : "";
  const char* reset = color ? "\033[0m" : "";
  const std::vector<Diagnostic> all = engine.sorted();
  size_t shown = 0;  // of the current file
  for (size_t i = 0; i < all.size(); ++i) {
    const Diagnostic& d = all[i];
    const std::string file = d.range.begin.valid() ? sm.name(d.range.begin.file) : "";
    shown = i > 0 && file == (all[i - 1].range.begin.valid() ? sm.name(all[i - 1].range.begin.file) : "") ? shown + 1 : 1;
    if (shown > kMaxShownPerFile) {
      size_t errors = 0, warnings = 0;
      for (; i < all.size(); ++i) {
        const Diagnostic& rest = all[i];
        if ((rest.range.begin.valid() ? sm.name(rest.range.begin.file) : "") != file) break;
        errors += rest.severity == Severity::Error;
        warnings += rest.severity == Severity::Warning;
      }
      --i;  // the loop's ++i moves to the next file
      auto count = [](size_t n, const char* what) { return std::to_string(n) + " more " + what + (n == 1 ? "" : "s"); };
      out << printable(file.empty() ? "kagec" : file) << ": note: "
          << (errors ? count(errors, "error") : "") << (errors && warnings ? " and " : "")
          << (warnings ? count(warnings, "warning") : "") << (errors || warnings ? "" : "more notes")
          << " not shown; fix the ones above first, or list them all with --format json\n";
      continue;
    }
    const char* sev_color = !color ? "" : d.severity == Severity::Error ? "\033[1;31m" : "\033[1;35m";
    out << bold << printable(location_prefix(sm, d.range.begin)) << ": " << reset << sev_color
        << severity_name(d.severity) << ": " << reset << bold << printable(d.message) << " [" << rule_info(d.rule).id
        << "]" << reset << '\n';
    print_snippet(sm, d.range, out);
    for (const FixIt& f : d.fixits)
      if (f.range.begin.valid()) out << "fix-it: replace with '" << printable(f.replacement) << "'\n";
    for (const DiagNote& n : d.notes) {
      if (n.loc.valid()) out << printable(location_prefix(sm, n.loc)) << ": ";
      out << "note: " << printable(n.message) << '\n';
    }
  }
}

void print_json(const DiagEngine& engine, std::ostream& out) {
  const SourceManager& sm = engine.sources();
  nlohmann::ordered_json list = nlohmann::ordered_json::array();
  size_t errors = 0, warnings = 0;
  for (const Diagnostic& d : engine.sorted()) {
    errors += d.severity == Severity::Error;
    warnings += d.severity == Severity::Warning;
    nlohmann::ordered_json j;
    const bool has_loc = d.range.begin.valid();
    const LineCol b = sm.line_col(d.range.begin);
    const LineCol e = sm.line_col(Loc{d.range.begin.file, std::max(d.range.end, d.range.begin.offset)});
    j["file"] = has_loc ? sm.name(d.range.begin.file) : "";
    j["line"] = b.line;
    j["col"] = b.col;
    j["end_line"] = e.line;
    j["end_col"] = e.col;
    j["offset"] = d.range.begin.offset;
    j["severity"] = severity_name(d.severity);
    j["rule"] = rule_info(d.rule).id;
    j["message"] = d.message;
    j["path"] = d.path;
    nlohmann::ordered_json notes = nlohmann::ordered_json::array();
    for (const DiagNote& n : d.notes) {
      nlohmann::ordered_json nj;
      nj["message"] = n.message;
      if (n.loc.valid()) {
        const LineCol lc = sm.line_col(n.loc);
        nj["file"] = sm.name(n.loc.file);
        nj["line"] = lc.line;
        nj["col"] = lc.col;
      }
      notes.push_back(nj);
    }
    j["notes"] = notes;
    nlohmann::ordered_json fixits = nlohmann::ordered_json::array();
    for (const FixIt& f : d.fixits) {
      const LineCol lc = sm.line_col(f.range.begin);
      fixits.push_back({{"line", lc.line}, {"col", lc.col}, {"offset", f.range.begin.offset},
                        {"length", f.range.end - f.range.begin.offset}, {"replacement", f.replacement}});
    }
    j["fixits"] = fixits;
    list.push_back(j);
  }
  nlohmann::ordered_json doc;
  doc["version"] = 1;
  doc["diagnostics"] = list;
  doc["summary"] = {{"errors", errors}, {"warnings", warnings}};
  out << doc.dump(2, ' ', false, nlohmann::ordered_json::error_handler_t::replace) << '\n';
}

}  // namespace kage
