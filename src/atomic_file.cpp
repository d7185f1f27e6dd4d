#include "ontime/atomic_file.hpp"

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fcntl.h>
#include <sys/stat.h>
#include <stdexcept>
#include <string>
#include <unistd.h>

namespace ontime {

void write_file_atomically(const std::filesystem::path& path, std::string_view content) {
  const std::filesystem::path directory = path.has_parent_path() ? path.parent_path() : std::filesystem::path(".");
  // Built with += : GCC 12 warns falsely (-Wrestrict) on "." + std::string.
  std::string temporary_name(".");
  temporary_name += path.filename().string();
  temporary_name += ".tmp-XXXXXX";
  std::string pattern = (directory / temporary_name).string();
  const int descriptor = ::mkstemp(pattern.data());
  if (descriptor < 0) {
    throw std::runtime_error(path.string() + ": cannot create a temporary file: " + std::strerror(errno));
  }
  const auto fail = [&](const char* what) {
    const std::string reason = std::strerror(errno);
    ::close(descriptor);
    ::unlink(pattern.c_str());
    throw std::runtime_error(path.string() + ": " + what + ": " + reason);
  };
  const char* data = content.data();
  std::size_t left = content.size();
  while (left > 0) {
    const ssize_t written = ::write(descriptor, data, left);
    if (written < 0) {
      if (errno == EINTR) continue;
      fail("cannot write");
    }
    data += written;
    left -= static_cast<std::size_t>(written);
  }
  if (::fchmod(descriptor, 0644) != 0) fail("cannot set permissions");
  if (::fsync(descriptor) != 0) fail("cannot flush");
  if (::close(descriptor) != 0) {
    const std::string reason = std::strerror(errno);
    ::unlink(pattern.c_str());
    throw std::runtime_error(path.string() + ": cannot close: " + reason);
  }
  if (std::rename(pattern.c_str(), path.c_str()) != 0) {
    const std::string reason = std::strerror(errno);
    ::unlink(pattern.c_str());
    throw std::runtime_error(path.string() + ": cannot replace: " + reason);
  }
}

}  // namespace ontime
