#include "memory_limits.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <string>
#include <thread>

namespace ontime::cli {

ParameterSpelling flag_spelling() {
  return [](std::string_view parameter) { return "--" + std::string(parameter); };
}

void apply_tool_layered_settings(LayeredSolveOptions& options) {
  options.remove_scratch_on_signal = true;
  options.on_stale_scratch = [](const std::filesystem::path& directory, std::uint64_t bytes) {
    fmt::print(stderr, "ontime: removed {} ({:.1f} MiB), the scratch of a run on this host whose process is gone\n",
               directory.string(), static_cast<double>(bytes) / 1048576.0);
  };
  fill_default_caps(options);
}

}  // namespace ontime::cli
