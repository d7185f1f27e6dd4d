#include "ontime/atomic_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <string>

#include "ontime/error.hpp"

namespace ontime {
namespace {

// The error type for a failed system call: the caller's to fix (a path, a permission, a full
// disk) or a failure of the system itself.
[[noreturn]] void fail(const std::filesystem::path& path, const char* what, int error) {
  const std::string message = path.string() + ": " + what + ": " + std::strerror(error);
  switch (error) {
    case EACCES:
    case EPERM:
    case ENOENT:
    case ENOTDIR:
    case EISDIR:
    case EROFS:
    case ENAMETOOLONG:
    case ELOOP:
    case ETXTBSY:
      throw UsageError(message);
    case ENOSPC:
    case EDQUOT:
    case EFBIG:
      throw ResourceLimitError(message);
    default:
      throw std::runtime_error(message);
  }
}

// Writes all of `content` to `descriptor`; returns 0 or the errno of the failed write.
int write_all(int descriptor, std::string_view content) {
  const char* data = content.data();
  std::size_t left = content.size();
  while (left > 0) {
    const ssize_t written = ::write(descriptor, data, left);
    if (written < 0) {
      if (errno == EINTR) continue;
      return errno;
    }
    data += written;
    left -= static_cast<std::size_t>(written);
  }
  return 0;
}

// Devices and FIFOs cannot be replaced without destroying them; they get the content directly.
void write_directly(const std::filesystem::path& path, std::string_view content) {
  const int descriptor = ::open(path.c_str(), O_WRONLY | O_NOCTTY | O_CLOEXEC);
  if (descriptor < 0) fail(path, "cannot open", errno);
  const int error = write_all(descriptor, content);
  ::close(descriptor);
  if (error != 0) fail(path, "cannot write", error);
}

void replace_atomically(const std::filesystem::path& path, std::string_view content) {
  const std::filesystem::path directory = path.has_parent_path() ? path.parent_path() : std::filesystem::path(".");
  // Built with += : GCC 12 warns falsely (-Wrestrict) on "." + std::string.
  std::string temporary_name(".");
  temporary_name += path.filename().string();
  temporary_name += ".tmp-XXXXXX";
  std::string pattern = (directory / temporary_name).string();
  const int descriptor = ::mkstemp(pattern.data());
  if (descriptor < 0) fail(path, "cannot create a temporary file beside it", errno);
  const auto abandon = [&](const char* what, int error) {
    ::close(descriptor);
    ::unlink(pattern.c_str());
    fail(path, what, error);
  };
  if (const int error = write_all(descriptor, content); error != 0) abandon("cannot write", error);
  if (::fchmod(descriptor, 0644) != 0) abandon("cannot set permissions", errno);
  if (::fsync(descriptor) != 0) abandon("cannot flush", errno);
  if (::close(descriptor) != 0) {
    const int error = errno;
    ::unlink(pattern.c_str());
    fail(path, "cannot close", error);
  }
  if (std::rename(pattern.c_str(), path.c_str()) != 0) {
    const int error = errno;
    ::unlink(pattern.c_str());
    fail(path, "cannot replace", error);
  }
}

}  // namespace

void write_file_atomically(const std::filesystem::path& path, std::string_view content) {
  struct stat link {};
  if (::lstat(path.c_str(), &link) != 0) {
    if (errno != ENOENT) fail(path, "cannot inspect", errno);
    replace_atomically(path, content);
    return;
  }
  struct stat target {};
  if (::stat(path.c_str(), &target) != 0) fail(path, "is a symbolic link that cannot be followed", errno);
  if (S_ISCHR(target.st_mode) || S_ISFIFO(target.st_mode)) {
    write_directly(path, content);
    return;
  }
  if (S_ISDIR(target.st_mode)) fail(path, "cannot replace", EISDIR);
  if (!S_ISREG(target.st_mode))
    throw UsageError(path.string() + ": is neither a regular file, a character device nor a FIFO");
  if (!S_ISLNK(link.st_mode)) {
    replace_atomically(path, content);
    return;
  }
  std::error_code error;
  const std::filesystem::path resolved = std::filesystem::canonical(path, error);
  if (error) fail(path, "cannot follow the symbolic link", error.value());
  replace_atomically(resolved, content);
}

}  // namespace ontime
