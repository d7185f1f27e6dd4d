// The layered solver's default caps: what this machine can give (layered_solver.hpp).

#include <filesystem>
#include <system_error>

#include "ontime/solve/layered_solver.hpp"
#include "ontime/util/memory.hpp"
#include "ontime/util/ranks.hpp"

namespace ontime {

void fill_default_caps(LayeredSolveOptions& options) {
  if (options.max_memory_bytes == 0) {
    if (const auto available = available_memory_bytes()) {
      const int ranks = options.ranks != nullptr ? options.ranks->size() : 1;
      options.max_memory_bytes = *available / 10 * 8 / static_cast<std::uint64_t>(ranks);
    }
  }
  if (options.max_disk_bytes == 0) {
    std::error_code error;
    const std::filesystem::path scratch =
        options.scratch_directory.empty() ? std::filesystem::temp_directory_path(error) : options.scratch_directory;
    const auto space = std::filesystem::space(scratch, error);
    if (!error) options.max_disk_bytes = space.available / 10 * 9;
  }
}

}  // namespace ontime
