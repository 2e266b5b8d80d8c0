// Source buffers and lazy line tables.
#include "compiler/source.h"

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>
#include <system_error>
#include <filesystem>

namespace kage {

std::optional<std::string> DiskFileReader::read(const std::string& path, std::string* err) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec)) {
    *err = "is a directory, not a file";
    return std::nullopt;
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    *err = std::strerror(errno);
    return std::nullopt;
  }
  std::ostringstream buf;
  buf << in.rdbuf();
  return buf.str();
}

FileId SourceManager::add(std::string name, std::string text) {
  auto file = std::make_unique<File>();
  file->name = std::move(name);
  file->text = std::move(text);
  files_.push_back(std::move(file));
  return static_cast<FileId>(files_.size() - 1);
}

std::optional<FileId> SourceManager::find(const std::string& name) const {
  for (size_t i = 0; i < files_.size(); ++i)
    if (files_[i]->name == name) return static_cast<FileId>(i);
  return std::nullopt;
}

const std::vector<uint32_t>& SourceManager::line_starts(FileId id) const {
  File& f = *files_[id];
  if (f.line_starts.empty()) {
    f.line_starts.push_back(0);
    for (uint32_t i = 0; i < f.text.size(); ++i)
      if (f.text[i] == '\n') f.line_starts.push_back(i + 1);
  }
  return f.line_starts;
}

LineCol SourceManager::line_col(Loc loc) const {
  if (!loc.valid()) return {};
  const auto& starts = line_starts(loc.file);
  auto it = std::upper_bound(starts.begin(), starts.end(), loc.offset);
  const uint32_t line = static_cast<uint32_t>(it - starts.begin());
  return {line, loc.offset - starts[line - 1] + 1};
}

std::string_view SourceManager::line_text(Loc loc) const {
  if (!loc.valid()) return {};
  const std::string& text = files_[loc.file]->text;
  const auto& starts = line_starts(loc.file);
  auto it = std::upper_bound(starts.begin(), starts.end(), loc.offset);
  const uint32_t begin = *(it - 1);
  uint32_t end = begin;
  while (end < text.size() && text[end] != '\n' && text[end] != '\r') ++end;
  return std::string_view(text).substr(begin, end - begin);
}

}  // namespace kage
