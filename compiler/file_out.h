// Files that commands write: every write and the close are checked, so a full disk or an unwritable
// path is an error with the file's name, never a silent half-written file.
#pragma once

#include <string>

namespace kage {

/// Writes `bytes` to `path` through a temporary file in the same directory, then renames it into
/// place, so that a reader sees the old file or the whole new one. False with a message naming the
/// file in `error` when any step fails (the temporary is removed). Device files such as /dev/full,
/// which cannot be renamed over, are written directly and checked just as strictly.
[[nodiscard]] bool write_file(const std::string& path, const std::string& bytes, std::string* error);

}  // namespace kage
