#pragma once
// Where an installed ontime finds the files installed with it, whatever the prefix it was
// installed to (`cmake --install --prefix`, the Debian package's /usr): the install layout puts
// them at a fixed place relative to the executable's folder (bin/../share/ontime/...).

#include <filesystem>

namespace ontime::cli {

// The executable's folder (/proc/self/exe) joined with `relative`, e.g. "../share/ontime/data";
// empty when the executable's path cannot be read.
std::filesystem::path beside_executable(const std::filesystem::path& relative);

}  // namespace ontime::cli
