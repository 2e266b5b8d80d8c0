// Files that commands write: every write and the close are checked, so a full disk or an unwritable
// path is an error with the file's name, never a silent half-written file.
#pragma once

#include <filesystem>
#include <optional>
#include <string>

#include <nlohmann/json.hpp>

namespace kage {

/// Writes `bytes` to `path` through a temporary file in the same directory, then renames it into
/// place, so that a reader sees the old file or the whole new one. False with a message naming the
/// file in `error` when any step fails (the temporary is removed). Device files such as /dev/full,
/// which cannot be renamed over, are written directly and checked just as strictly.
[[nodiscard]] bool write_file(const std::string& path, const std::string& bytes, std::string* error);

/// Why `dir` cannot be a command's output directory whatever it holds: the root or the home directory,
/// a symbolic link, or something that is not a directory. Nullopt when it is absent or a real
/// directory, whose contents the command then judges (only its own earlier output may be replaced).
std::optional<std::string> output_dir_kind_problem(const std::filesystem::path& dir);

/// A fresh, empty directory beside `dir` to build an output into; nullopt with a message in `error`.
std::optional<std::filesystem::path> make_staging_dir(const std::filesystem::path& dir, std::string* error);

/// Moves the finished `staging` directory to `dir`, replacing what is there (a directory the caller
/// has checked is its own earlier output); false with a message in `error` (then `dir` still holds
/// what it held before).
[[nodiscard]] bool publish_staging_dir(const std::filesystem::path& staging, const std::filesystem::path& dir,
                                       std::string* error);

/// `j` as the indented text of a JSON file a command writes. Paths from the command line may hold
/// bytes that are not UTF-8; they become U+FFFD rather than stopping the command.
inline std::string json_file_text(const nlohmann::json& j) {
  return j.dump(2, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
}

}  // namespace kage
