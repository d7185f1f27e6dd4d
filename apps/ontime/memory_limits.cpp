#include "memory_limits.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "ontime/mdp/state.hpp"
#include "ontime/util/error.hpp"

namespace ontime::cli {
namespace {

// The first whole number in a file (a cgroup limit); nothing when unreadable or "max".
std::optional<std::uint64_t> number_in(const char* path) {
  std::ifstream in(path);
  std::string text;
  if (!(in >> text)) return std::nullopt;
  std::uint64_t value = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (error != std::errc() || end != text.data() + text.size()) return std::nullopt;
  return value;
}

std::optional<std::uint64_t> meminfo_available() {
  std::ifstream in("/proc/meminfo");
  for (std::string line; std::getline(in, line);) {
    std::istringstream fields(line);
    std::string key;
    std::uint64_t kib = 0;
    if (fields >> key >> kib && key == "MemAvailable:") return kib * 1024;
  }
  return std::nullopt;
}

std::string gib(double bytes) { return fmt::format("{:.3g} GiB", bytes / (1024.0 * 1024.0 * 1024.0)); }

}  // namespace

void apply_tool_layered_settings(LayeredSolveOptions& options) {
  options.remove_scratch_on_signal = true;
  options.on_stale_scratch = [](const std::filesystem::path& directory, std::uint64_t bytes) {
    fmt::print(stderr, "ontime: removed {} ({:.1f} MiB), the scratch of a run on this host whose process is gone\n",
               directory.string(), static_cast<double>(bytes) / 1048576.0);
  };
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

std::optional<std::uint64_t> available_memory_bytes() {
  std::optional<std::uint64_t> available = meminfo_available();
  const auto limit_room = [&](const char* limit_path, const char* usage_path) {
    const std::optional<std::uint64_t> limit = number_in(limit_path);
    if (!limit) return;
    const std::uint64_t used = number_in(usage_path).value_or(0);
    const std::uint64_t room = *limit > used ? *limit - used : 0;
    available = available ? std::min(*available, room) : room;
  };
  limit_room("/sys/fs/cgroup/memory.max", "/sys/fs/cgroup/memory.current");
  limit_room("/sys/fs/cgroup/memory/memory.limit_in_bytes", "/sys/fs/cgroup/memory/memory.usage_in_bytes");
  return available;
}

void check_memory_for(std::string_view option, double bytes) {
  const std::optional<std::uint64_t> available = available_memory_bytes();
  if (available && bytes > static_cast<double>(*available)) {
    throw UsageError(fmt::format("{}: would need up to {} of memory, {} available", option, gib(bytes),
                                 gib(static_cast<double>(*available))));
  }
}

void check_state_cap_memory(const Problem& problem, std::size_t max_states, const std::string& source) {
  if (problem.skeleton_count() > kMaxExactSkeletons) {
    throw InputError(source, "skeletons",
                     fmt::format("{} skeletons; exact solving and exact evaluation take at most {} (sampled "
                                 "evaluation and the approximate allocators take any number)",
                                 problem.skeleton_count(), kMaxExactSkeletons));
  }
  const double slot_bytes =
      problem.skeleton_count() <= 4 && problem.deadline() <= 253 ? 33 : (problem.skeleton_count() <= 10 ? 49 : 99);
  check_memory_for(fmt::format("--max-states {}", max_states), 3.0 * slot_bytes * static_cast<double>(max_states));
}

}  // namespace ontime::cli
