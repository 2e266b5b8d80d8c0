// Loading a config file and the chain of files it `extends`, merged into one document.
//
// A file's mapping is deep-merged over its base's: mappings merge key by key,
// scalars and lists replace, an explicit null sets null. Every merged node
// keeps the range of the file it came from (provenance for notes and for
// resolving relative asset paths).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "compiler/basic/diag.h"
#include "compiler/basic/source.h"
#include "compiler/parse/yaml_doc.h"

namespace kage {

/// The meta key naming a base config.
inline constexpr const char* kExtendsKey = "extends";
/// The most files an `extends` chain may hold (the file itself included).
inline constexpr size_t kMaxExtendsDepth = 64;

struct ComposedConfig {
  DocNode root;                 // merged mapping (without `extends`)
  FileId file = kNoFile;        // the file named by the user
  std::vector<FileId> chain;    // the file, then its bases, nearest first
};

/// Loads `path` (and its bases). Errors go to diags; nullopt when nothing usable was read.
std::optional<ComposedConfig> load_config(const std::string& path, SourceManager& sources, FileReader& reader,
                                          DiagEngine& diags);

/// Composes an already parsed document (e.g. an inline config of a suite manifest)
/// whose relative `extends` paths are taken from `base_dir`.
std::optional<ComposedConfig> compose_document(DocNode doc, FileId file, const std::string& base_dir,
                                               SourceManager& sources, FileReader& reader, DiagEngine& diags);

/// Deep merge of `over` onto `base` (both mappings).
DocNode merge_documents(const DocNode& base, const DocNode& over);

/// The directory part of a path ("" for a bare file name).
std::string parent_dir(const std::string& path);
/// `rel` taken relative to `dir` unless it is absolute; lexically normalised.
std::string join_path(const std::string& dir, const std::string& rel);

}  // namespace kage
