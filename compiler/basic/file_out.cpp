// Checked file output (see file_out.h).
#include "compiler/basic/file_out.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <random>

namespace kage {
namespace {

namespace fs = std::filesystem;

bool write_all(int fd, const std::string& bytes) {
  size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return false;
    done += static_cast<size_t>(n);
  }
  return true;
}

// Writes into an open descriptor and closes it; both are checked.
bool write_and_close(int fd, const std::string& bytes) {
  const bool wrote = write_all(fd, bytes);
  const int saved = errno;
  const bool closed = ::close(fd) == 0;
  if (!wrote) errno = saved;
  return wrote && closed;
}

}  // namespace

bool write_file(const std::string& path, const std::string& bytes, std::string* error) {
  auto fail = [&](const std::string& what) {
    *error = "cannot write '" + path + "': " + what + (errno ? std::string(": ") + std::strerror(errno) : "");
    return false;
  };
  struct stat st {};
  if (::stat(path.c_str(), &st) == 0 && !S_ISREG(st.st_mode)) {
    if (S_ISDIR(st.st_mode)) {
      errno = 0;
      return fail("it is a directory");
    }
    const int fd = ::open(path.c_str(), O_WRONLY | O_CLOEXEC);
    if (fd < 0) return fail("open failed");
    return write_and_close(fd, bytes) ? true : fail("write failed");
  }
  const fs::path target(path);
  const fs::path tmp = target.parent_path() / ("." + target.filename().string() + ".tmp." + std::to_string(::getpid()));
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) return fail("open failed");
  if (!write_and_close(fd, bytes)) {
    const int saved = errno;
    ::unlink(tmp.c_str());
    errno = saved;
    return fail("write failed");
  }
  if (::rename(tmp.c_str(), path.c_str()) != 0) {
    const int saved = errno;
    ::unlink(tmp.c_str());
    errno = saved;
    return fail("rename failed");
  }
  return true;
}

std::optional<std::string> output_dir_kind_problem(const fs::path& dir) {
  std::error_code ec;
  const fs::path abs = fs::weakly_canonical(fs::absolute(dir, ec), ec);
  if (abs.empty() || abs == abs.root_path()) return "'" + dir.string() + "' is the root directory; name a new directory";
  if (const char* home = std::getenv("HOME"); home && *home && abs == fs::weakly_canonical(home, ec))
    return "'" + dir.string() + "' is the home directory; name a new directory";
  // A trailing '/' would make the status below follow a link: look at the name itself.
  const fs::path clean = dir.has_filename() ? dir : dir.parent_path();
  const fs::file_status st = fs::symlink_status(clean, ec);
  if (!fs::exists(st)) return std::nullopt;
  if (fs::is_symlink(st))
    return "'" + dir.string() + "' is a symbolic link, which this command will not replace; name the directory " +
           "it points to, or a new directory";
  if (!fs::is_directory(st))
    return "'" + dir.string() + "' exists and is not a directory; name a new directory, or move the file away";
  return std::nullopt;
}

std::optional<fs::path> make_staging_dir(const fs::path& dir, std::string* error) {
  const fs::path abs = fs::absolute(dir).lexically_normal();
  const fs::path parent = (abs.has_filename() ? abs : abs.parent_path()).parent_path();
  std::error_code ec;
  fs::create_directories(parent, ec);
  if (ec) {
    *error = "cannot create '" + parent.string() + "': " + ec.message();
    return std::nullopt;
  }
  std::random_device rd;
  const std::string base = (abs.has_filename() ? abs : abs.parent_path()).filename().string();
  const fs::path staging = parent / ("." + base + ".kagec-tmp." + std::to_string(::getpid()) + "." + std::to_string(rd()));
  if (!fs::create_directory(staging, ec) || ec) {
    *error = "cannot create '" + staging.string() + "': " + (ec ? ec.message() : "it exists");
    return std::nullopt;
  }
  return staging;
}

bool publish_staging_dir(const fs::path& staging, const fs::path& dir, std::string* error) {
  std::error_code ec;
  const fs::path target = fs::absolute(dir).lexically_normal();
  const fs::path clean = target.has_filename() ? target : target.parent_path();
  fs::path old;
  if (fs::exists(fs::symlink_status(clean, ec))) {
    old = staging.string() + ".old";
    fs::rename(clean, old, ec);
    if (ec) {
      *error = "cannot move the earlier output '" + dir.string() + "' aside: " + ec.message();
      return false;
    }
  }
  fs::rename(staging, clean, ec);
  if (ec) {
    *error = "cannot move the new output to '" + dir.string() + "': " + ec.message();
    std::error_code back;
    if (!old.empty()) fs::rename(old, clean, back);
    return false;
  }
  if (!old.empty()) fs::remove_all(old, ec);  // a leftover costs only disk; the new output is in place
  return true;
}

}  // namespace kage
