// Files that commands write: every write and the close are checked, so a full disk or an unwritable
// path is an error with the file's name, never a silent half-written file.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

namespace kage {

/// Writes `bytes` to `path` through a temporary file in the same directory, then renames it into
/// place, so that a reader sees the old file or the whole new one. False with a message naming the
/// file in `error` when any step fails (the temporary is removed). Device files such as /dev/full,
/// which cannot be renamed over, are written directly and checked just as strictly.
[[nodiscard]] bool write_file(const std::string& path, const std::string& bytes, std::string* error);

/// `j` as the indented text of a JSON file a command writes. Paths from the command line may hold
/// bytes that are not UTF-8; they become U+FFFD rather than stopping the command.
inline std::string json_file_text(const nlohmann::json& j) {
  return j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
}

}  // namespace kage
