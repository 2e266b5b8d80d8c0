// Source buffers and locations: every diagnostic points into a buffer held here.
//
// Locations are byte offsets; line and column are computed only when printed.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace kage {

using FileId = uint32_t;
inline constexpr FileId kNoFile = 0xFFFFFFFFu;

/// A point in a source buffer.
struct Loc {
  FileId file = kNoFile;
  uint32_t offset = 0;
  bool valid() const { return file != kNoFile; }
};

/// A half-open byte range [begin, end) in one buffer.
struct Range {
  Loc begin;
  uint32_t end = 0;
};

/// 1-based line and byte column.
struct LineCol {
  uint32_t line = 0;
  uint32_t col = 0;
};

/// Reads files; tests substitute an in-memory map.
class FileReader {
 public:
  virtual ~FileReader() = default;
  /// The file's bytes, or nullopt (with a reason in *err) when it cannot be read.
  virtual std::optional<std::string> read(const std::string& path, std::string* err) = 0;
};

/// The largest config file read (configs are a few KB; this bounds memory on hostile input).
inline constexpr uint64_t kMaxConfigBytes = uint64_t(16) << 20;

/// The real file system: regular files only, at most kMaxConfigBytes, every read error an error.
class DiskFileReader final : public FileReader {
 public:
  std::optional<std::string> read(const std::string& path, std::string* err) override;
};

/// Owns every loaded buffer and maps offsets to lines.
class SourceManager {
 public:
  /// Adds a buffer under a display name (usually the path as given).
  FileId add(std::string name, std::string text);
  /// The id of a buffer already added under this name, if any.
  std::optional<FileId> find(const std::string& name) const;

  const std::string& name(FileId id) const { return files_[id]->name; }
  const std::string& text(FileId id) const { return files_[id]->text; }
  LineCol line_col(Loc loc) const;
  /// The full text of the line containing loc, without its newline.
  std::string_view line_text(Loc loc) const;

 private:
  struct File {
    std::string name;
    std::string text;
    mutable std::vector<uint32_t> line_starts;  // built on first use
  };
  const std::vector<uint32_t>& line_starts(FileId id) const;
  std::vector<std::unique_ptr<File>> files_;
};

}  // namespace kage
