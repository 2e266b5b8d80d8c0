// YAML documents with source locations: the front end reads YAML only through here (the one other
// user of yaml-cpp is the driver's probe of whether `kagec bench --gpu` was given a suite manifest).
//
// yaml-cpp accepts duplicate keys silently, reads only the first of several documents, keeps merge
// keys as plain keys and gives 0-based marks; here every node gets a byte Range, duplicates and extra
// documents are reported, and merge keys, tags and plain scalars get the meaning the original's loader
// (PyYAML safe_load, YAML 1.1) gives them.
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

/// Parses a buffer of one YAML document. Syntax errors, duplicate keys and tags the original's loader
/// refuses are reported; merge keys (`<<: *base`) are expanded as PyYAML's safe loader expands them.
/// Returns nullopt when the text is not YAML at all or holds more than one document.
std::optional<DocNode> parse_yaml(const SourceManager& sources, FileId file, DiagEngine& diags);

}  // namespace kage
