#include "ontime/util/memory.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <fstream>
#include <sstream>

#include "ontime/util/error.hpp"

namespace ontime {
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

void check_memory_for(std::string_view what, double bytes) {
  const std::optional<std::uint64_t> available = available_memory_bytes();
  if (available && bytes > static_cast<double>(*available)) {
    throw UsageError(fmt::format("{}: would need up to {} of memory, {} available", what, gib(bytes),
                                 gib(static_cast<double>(*available))));
  }
}

std::string spell_parameter(const ParameterSpelling& spelling, std::string_view parameter) {
  return spelling ? spelling(parameter) : fmt::format("parameter '{}'", parameter);
}

}  // namespace ontime
