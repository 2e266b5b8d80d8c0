// Source buffers and lazy line tables.
#include "compiler/basic/source.h"

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>
#include <system_error>
#include <filesystem>

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

namespace kage {

std::optional<std::string> DiskFileReader::read(const std::string& path, std::string* err) {
  // Opened without blocking, then checked: a FIFO, a device or /proc file is refused before any read
  // could hang, run without end, or return nothing.
  const int fd = ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) {
    *err = std::strerror(errno);
    return std::nullopt;
  }
  struct stat st {};
  std::optional<std::string> out;
  if (::fstat(fd, &st) != 0) {
    *err = std::strerror(errno);
  } else if (S_ISDIR(st.st_mode)) {
    *err = "is a directory, not a file";
  } else if (!S_ISREG(st.st_mode)) {
    *err = "is not a regular file (a FIFO, device or socket); give a config file";
  } else if (static_cast<uint64_t>(st.st_size) > kMaxConfigBytes) {
    *err = "is " + std::to_string(st.st_size) + " bytes; a config may be at most " +
           std::to_string(kMaxConfigBytes >> 20) + " MiB";
  } else {
    // One byte past the stated size must read as the end: /proc files state size 0 and then produce
    // data or fail (/proc/self/mem), and a file that grows is being written.
    std::string text(static_cast<size_t>(st.st_size) + 1, '\0');
    size_t done = 0;
    bool failed = false;
    while (done < text.size()) {
      const ssize_t n = ::read(fd, text.data() + done, text.size() - done);
      if (n < 0 && errno == EINTR) continue;
      if (n < 0) {
        *err = std::string("read failed: ") + std::strerror(errno);
        failed = true;
        break;
      }
      if (n == 0) break;
      done += static_cast<size_t>(n);
    }
    if (!failed && done == static_cast<size_t>(st.st_size)) {
      text.resize(done);
      out = std::move(text);
    } else if (!failed) {
      *err = "does not hold the " + std::to_string(st.st_size) +
             " bytes its size states (a special or changing file); give a config file";
    }
  }
  ::close(fd);
  return out;
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
