#include "ontime/util/input_file.hpp"

#include <atomic>
#include <charconv>
#include <cstdlib>
#include <fstream>
#include <string>
#include <system_error>

#include "ontime/util/error.hpp"

namespace ontime {
namespace {

// 0 stands for "not set": a limit of 0 bytes is refused when set.
std::atomic<std::uint64_t> g_max_input_bytes{0};

constexpr const char* kLimitVariable = "ONTIME_MAX_INPUT_BYTES";

std::string describe_bytes(std::uint64_t bytes) {
  std::string text = std::to_string(bytes) + " bytes";
  if (bytes >= (std::uint64_t{1} << 20) && bytes % (std::uint64_t{1} << 20) == 0) {
    text += " (" + std::to_string(bytes >> 20) + " MiB)";
  }
  return text;
}

}  // namespace

std::uint64_t max_input_bytes() {
  if (const std::uint64_t set = g_max_input_bytes.load(std::memory_order_relaxed); set != 0) return set;
  const char* variable = std::getenv(kLimitVariable);
  if (variable == nullptr || *variable == '\0') return kDefaultMaxInputBytes;
  const std::string_view text(variable);
  std::uint64_t bytes = 0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), bytes);
  if (error != std::errc() || end != text.data() + text.size() || bytes == 0) {
    throw UsageError(std::string(kLimitVariable) + ": must be a whole number of bytes >= 1 (got '" + std::string(text) +
                     "')");
  }
  return bytes;
}

void set_max_input_bytes(std::optional<std::uint64_t> bytes) {
  if (bytes && *bytes == 0) throw UsageError("the input size limit must be at least 1 byte");
  g_max_input_bytes.store(bytes.value_or(0), std::memory_order_relaxed);
}

std::string read_input_file(const std::filesystem::path& path, std::string_view what) {
  const std::string source = path.string();
  const std::string kind(what);
  std::error_code error;
  const std::filesystem::file_status status = std::filesystem::status(path, error);
  if (std::filesystem::is_directory(status)) throw InputError(source, "file", "is a directory, not a file");
  const std::uint64_t limit = max_input_bytes();
  const auto too_large = [&] {
    return InputError(source, "file",
                      "the " + kind + " file is larger than the input size limit of " + describe_bytes(limit) +
                          " (set " + kLimitVariable + " to raise it)");
  };
  std::string content;
  // A regular file's size is known: refuse before reading. Devices and FIFOs report no size
  // (or a wrong one) and are read up to the limit, never beyond.
  if (std::filesystem::is_regular_file(status)) {
    const std::uintmax_t size = std::filesystem::file_size(path, error);
    if (!error && size > limit) throw too_large();
    if (!error) content.reserve(static_cast<std::size_t>(size) + 1);  // one allocation, not a doubling series
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError(source, "file", "cannot be opened for reading (missing or unreadable)");
  constexpr std::size_t kChunk = std::size_t{1} << 16;
  while (in) {
    const std::size_t before = content.size();
    // Read at most one byte beyond the limit: enough to know it was exceeded.
    const std::uint64_t room = limit + 1 - before;
    const std::size_t chunk = room < kChunk ? static_cast<std::size_t>(room) : kChunk;
    content.resize(before + chunk);
    in.read(content.data() + before, static_cast<std::streamsize>(chunk));
    content.resize(before + static_cast<std::size_t>(in.gcount()));
    if (content.size() > limit) throw too_large();
  }
  if (in.bad()) throw InputError(source, "file", "could not be read");
  return content;
}

}  // namespace ontime
