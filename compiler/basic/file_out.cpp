// Checked file output (see file_out.h).
#include "compiler/basic/file_out.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>

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

}  // namespace kage
