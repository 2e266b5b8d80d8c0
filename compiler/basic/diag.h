// Diagnostics: what went wrong, where, under which stable rule id, and how to fix it.
//
// Passes report into a DiagEngine and keep going; the engine applies
// --Werror, --disable and in-file `# kagec: disable=RULE` (a line) and `# kagec: disable-file=RULE` (the
// whole file) comments, and prints
// text (`file:line:col: severity: message [rule]`) or JSON.
#pragma once

#include <iosfwd>
#include <map>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "compiler/basic/source.h"

namespace kage {

enum class Severity { Note, Warning, Error };

enum class Rule {
#define KAGE_RULE(name, id, severity, doc) name,
#include "compiler/basic/diag_rules.def"
#undef KAGE_RULE
};

struct RuleInfo {
  Rule rule;
  const char* id;
  Severity severity;
  const char* doc;
};

/// Every rule, in declaration order.
const std::vector<RuleInfo>& all_rules();
const RuleInfo& rule_info(Rule rule);
/// The rule with this id (e.g. "yaml-syntax"), if any.
const RuleInfo* find_rule(const std::string& id);

/// One rule id of a `kagec: disable=RULE[,RULE]` comment (its line and the next) or a
/// `kagec: disable-file=RULE[,RULE]` one (its whole file), as written in a source text: its offset and the id
/// (empty where the list has an empty item).
struct DisabledRule {
  uint32_t offset;
  std::string_view rule;
  bool whole_file;
};
/// Every rule id of the disable comments of `text`, in order.
std::vector<DisabledRule> find_disabled_rules(std::string_view text);

/// A replacement suggested for a range of the source.
struct FixIt {
  Range range;
  std::string replacement;
};

struct DiagNote {
  Loc loc;  // may be invalid: a note without a place
  std::string message;
};

struct Diagnostic {
  Rule rule;
  Severity severity;
  Range range;
  std::string message;
  std::string path;  // JSON Pointer of the value, e.g. /physics/gravity
  std::vector<DiagNote> notes;
  std::vector<FixIt> fixits;
};

/// Collects diagnostics; never throws.
class DiagEngine {
 public:
  explicit DiagEngine(const SourceManager& sources) : sources_(sources) {}

  /// Reports at a range; returns the stored diagnostic so notes and fix-its can be added.
  Diagnostic& report(Rule rule, Range range, std::string message, std::string path = {});

  void set_werror(bool on) { werror_ = on; }
  void disable(const std::string& rule_id) { disabled_.insert(rule_id); }
  /// Drops every warning from the output (errors stay).
  void disable_warnings() { no_warnings_ = true; }

  /// Diagnostics that survived filtering, sorted by file, offset, rule.
  std::vector<Diagnostic> sorted() const;
  size_t error_count() const;
  size_t warning_count() const;
  bool has_errors() const { return error_count() > 0; }
  const SourceManager& sources() const { return sources_; }

 private:
  bool suppressed(const Diagnostic& d) const;
  /// The rules a file's `kagec: disable=` comments name, by line (1-based), and those of its
  /// `kagec: disable-file=` comments under kWholeFile, found in one pass over its text.
  const std::multimap<uint32_t, std::string_view>& disable_comments(FileId file) const;
  static constexpr uint32_t kWholeFile = 0;
  const SourceManager& sources_;
  std::vector<Diagnostic> diags_;
  mutable std::map<FileId, std::multimap<uint32_t, std::string_view>> disable_comments_;
  std::set<std::string> disabled_;
  bool werror_ = false;
  bool no_warnings_ = false;
};

/// The most diagnostics print_text shows per file; the rest are counted in one closing note.
inline constexpr size_t kMaxShownPerFile = 100;
/// The most bytes of a source line print_text shows (a window around the caret on longer lines).
inline constexpr size_t kMaxSnippetBytes = 160;

/// `file:line:col: severity: message [rule]`, the source line with a caret, notes and fix-its; control
/// characters are escaped (\0, \t, \x1b). After kMaxShownPerFile diagnostics of one file, a note
/// says how many more errors and warnings it has.
void print_text(const DiagEngine& engine, std::ostream& out, bool color = false);
/// print_text's output (without colour) as a string.
std::string diagnostics_text(const DiagEngine& engine);
/// The frozen JSON form: {version, diagnostics: [...], summary}.
void print_json(const DiagEngine& engine, std::ostream& out);

const char* severity_name(Severity s);

}  // namespace kage
