// Diagnostic collection, filtering and printing.
#include "compiler/basic/diag.h"

#include <algorithm>
#include <nlohmann/json.hpp>
#include <ostream>

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

// `# kagec: disable=RULE[,RULE]` on the diagnostic's line or the line above.
bool DiagEngine::suppressed(const Diagnostic& d) const {
  const char* id = rule_info(d.rule).id;
  if (disabled_.count(id)) return true;
  if (no_warnings_ && d.severity == Severity::Warning) return true;
  if (!d.range.begin.valid()) return false;
  const std::string& text = sources_.text(d.range.begin.file);
  const LineCol lc = sources_.line_col(d.range.begin);
  auto mentions = [&](std::string_view line) {
    const auto at = line.find("kagec: disable=");
    if (at == std::string_view::npos) return false;
    std::string_view list = line.substr(at + 15);
    list = list.substr(0, list.find_first_of(" \t#"));
    while (!list.empty()) {
      const auto comma = list.find(',');
      if (list.substr(0, comma) == id) return true;
      if (comma == std::string_view::npos) break;
      list.remove_prefix(comma + 1);
    }
    return false;
  };
  if (mentions(sources_.line_text(d.range.begin))) return true;
  if (lc.line > 1) {
    uint32_t prev_end = d.range.begin.offset - (lc.col - 1);
    if (prev_end > 0) {
      uint32_t start = prev_end - 1;
      while (start > 0 && text[start - 1] != '\n') --start;
      if (mentions(sources_.line_text(Loc{d.range.begin.file, start}))) return true;
    }
  }
  return false;
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
  for (const Diagnostic& d : sorted()) n += d.severity == Severity::Error;
  return n;
}

size_t DiagEngine::warning_count() const {
  size_t n = 0;
  for (const Diagnostic& d : sorted()) n += d.severity == Severity::Warning;
  return n;
}

namespace {

std::string location_prefix(const SourceManager& sm, Loc loc) {
  if (!loc.valid()) return "kagec";
  const LineCol lc = sm.line_col(loc);
  return sm.name(loc.file) + ":" + std::to_string(lc.line) + ":" + std::to_string(lc.col);
}

/// `text` with control characters as \xNN: a file name or value holding an escape sequence must not
/// drive the terminal, nor a newline split a diagnostic.
std::string printable(std::string_view text) {
  std::string out;
  for (char c : text) {
    const auto u = static_cast<unsigned char>(c);
    if (u < 0x20 || u == 0x7f) {
      static const char kHex[] = "0123456789abcdef";
      out += "\\x";
      out += kHex[u >> 4];
      out += kHex[u & 15];
    } else {
      out += c;
    }
  }
  return out;
}

void print_snippet(const SourceManager& sm, const Range& range, std::ostream& out) {
  if (!range.begin.valid()) return;
  const std::string_view line = sm.line_text(range.begin);
  const LineCol lc = sm.line_col(range.begin);
  out << line << '\n';
  std::string marker;
  for (uint32_t i = 1; i < lc.col && i <= line.size(); ++i) marker += line[i - 1] == '\t' ? '\t' : ' ';
  marker += '^';
  const uint32_t line_end = range.begin.offset - (lc.col - 1) + static_cast<uint32_t>(line.size());
  const uint32_t end = std::min(range.end, line_end);
  for (uint32_t i = range.begin.offset + 1; i < end; ++i) marker += '~';
  out << marker << '\n';
}

}  // namespace

void print_text(const DiagEngine& engine, std::ostream& out, bool color) {
  const SourceManager& sm = engine.sources();
  const char* bold = color ? "\033[1m" : "";
  const char* reset = color ? "\033[0m" : "";
  for (const Diagnostic& d : engine.sorted()) {
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
