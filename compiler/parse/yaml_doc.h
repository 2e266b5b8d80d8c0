// YAML documents with source locations: the front end reads YAML only through here (the one other
// user of yaml-cpp is the driver's probe of whether `kagec bench --gpu` was given a suite manifest).
//
// yaml-cpp accepts duplicate keys silently and gives 0-based marks; here every
// node gets a byte Range, duplicates are reported, and plain scalars are typed
// with the same rules as the original's loader (PyYAML safe_load, YAML 1.1).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "compiler/basic/diag.h"
#include "compiler/basic/source.h"

namespace kage {

struct DocEntry;

/// One YAML node.
struct DocNode {
  enum class Kind { Null, Scalar, Sequence, Mapping };
  Kind kind = Kind::Null;
  std::string text;     // scalar text as written (without quotes)
  bool quoted = false;  // quoted or explicitly tagged !!str: always a string
  Range range;          // where the value is written
  std::vector<DocNode> items;     // Sequence
  std::vector<DocEntry> entries;  // Mapping, in file order

  bool is_null() const { return kind == Kind::Null; }
  bool is_map() const { return kind == Kind::Mapping; }
  bool is_seq() const { return kind == Kind::Sequence; }
  bool is_scalar() const { return kind == Kind::Scalar; }
  /// The entry for `key`, if present.
  const DocEntry* find(const std::string& key) const;
  DocEntry* find(const std::string& key);
};

struct DocEntry {
  std::string key;
  Range key_range;
  DocNode value;
};

/// A typed scalar, as PyYAML's safe loader would type it.
using Scalar = std::variant<std::monostate, bool, int64_t, double, std::string>;

/// Types a scalar node (null nodes give monostate).
Scalar scalar_value(const DocNode& node);
/// "integer", "number", "boolean", "string", "null", "list" or "mapping".
const char* kind_name(const DocNode& node);

/// Parses a buffer. Syntax errors and duplicate keys are reported; returns
/// nullopt only when the text is not YAML at all.
std::optional<DocNode> parse_yaml(const SourceManager& sources, FileId file, DiagEngine& diags);

}  // namespace kage
