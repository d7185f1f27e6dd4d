#include "ontime/util/atomic_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <string>

#include "ontime/util/error.hpp"

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

}  // namespace

AtomicFileWriter::AtomicFileWriter(const std::filesystem::path& path) : target_(path) {
  struct stat link {};
  bool direct = false;
  if (::lstat(path.c_str(), &link) != 0) {
    if (errno != ENOENT) fail(path, "cannot inspect", errno);
  } else {
    struct stat target {};
    if (::stat(path.c_str(), &target) != 0) fail(path, "is a symbolic link that cannot be followed", errno);
    if (S_ISDIR(target.st_mode)) fail(path, "cannot replace", EISDIR);
    // Devices and FIFOs cannot be replaced without destroying them; they get the content directly.
    direct = S_ISCHR(target.st_mode) || S_ISFIFO(target.st_mode);
    if (!direct && !S_ISREG(target.st_mode)) {
      throw UsageError(path.string() + ": is neither a regular file, a character device nor a FIFO");
    }
    if (!direct && S_ISLNK(link.st_mode)) {
      std::error_code error;
      target_ = std::filesystem::canonical(path, error);
      if (error) fail(path, "cannot follow the symbolic link", error.value());
    }
  }
  if (direct) {
    descriptor_ = ::open(path.c_str(), O_WRONLY | O_NOCTTY | O_CLOEXEC);
    if (descriptor_ < 0) fail(path, "cannot open", errno);
    return;
  }
  const std::filesystem::path directory =
      target_.has_parent_path() ? target_.parent_path() : std::filesystem::path(".");
  // Built with += : GCC 12 warns falsely (-Wrestrict) on "." + std::string.
  std::string temporary_name(".");
  temporary_name += target_.filename().string();
  temporary_name += ".tmp-XXXXXX";
  temporary_ = (directory / temporary_name).string();
  descriptor_ = ::mkstemp(temporary_.data());
  if (descriptor_ < 0) {
    temporary_.clear();
    fail(target_, "cannot create a temporary file beside it", errno);
  }
}

AtomicFileWriter::~AtomicFileWriter() {
  if (descriptor_ >= 0) ::close(descriptor_);
  if (!committed_ && !temporary_.empty()) ::unlink(temporary_.c_str());
}

void AtomicFileWriter::write(std::string_view piece) {
  if (const int error = write_all(descriptor_, piece); error != 0) fail(target_, "cannot write", error);
}

void AtomicFileWriter::commit() {
  if (temporary_.empty()) {  // a device or FIFO: written already
    const int error = ::close(descriptor_) != 0 ? errno : 0;
    descriptor_ = -1;
    committed_ = true;
    if (error != 0) fail(target_, "cannot write", error);
    return;
  }
  if (::fchmod(descriptor_, 0644) != 0) fail(target_, "cannot set permissions", errno);
  if (::fsync(descriptor_) != 0) fail(target_, "cannot flush", errno);
  const int closed = ::close(descriptor_);
  descriptor_ = -1;
  if (closed != 0) fail(target_, "cannot close", errno);
  if (std::rename(temporary_.c_str(), target_.c_str()) != 0) fail(target_, "cannot replace", errno);
  committed_ = true;
}

void write_file_atomically(const std::filesystem::path& path, std::string_view content) {
  AtomicFileWriter writer(path);
  writer.write(content);
  writer.commit();
}

}  // namespace ontime
