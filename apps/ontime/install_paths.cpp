#include "install_paths.hpp"

#include <system_error>

namespace ontime::cli {

std::filesystem::path beside_executable(const std::filesystem::path& relative) {
  std::error_code error;
  const std::filesystem::path executable = std::filesystem::read_symlink("/proc/self/exe", error);
  if (error || executable.empty()) return {};
  return (executable.parent_path() / relative).lexically_normal();
}

}  // namespace ontime::cli
