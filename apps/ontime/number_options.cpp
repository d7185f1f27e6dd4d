#include "number_options.hpp"

#include <fmt/format.h>

#include <charconv>
#include <cmath>
#include <concepts>
#include <limits>
#include <optional>
#include <system_error>

#include "ontime/util/error.hpp"

namespace ontime::cli {
namespace {

// " in [a, b]", " >= a", " <= b" or nothing; an unsigned type's 0 counts as a bound.
template <class T>
std::string range_rule(T minimum, T maximum) {
  if constexpr (std::floating_point<T>) {
    if (minimum == kPositive)
      return maximum == std::numeric_limits<T>::max() ? " > 0" : " in (0, " + compact_number(maximum) + "]";
  }
  const bool low = std::unsigned_integral<T> || minimum != std::numeric_limits<T>::lowest();
  const bool high = maximum != std::numeric_limits<T>::max();
  if (low && high) return fmt::format(" in [{}, {}]", compact_number(minimum), compact_number(maximum));
  if (low) return " >= " + compact_number(minimum);
  if (high) return " <= " + compact_number(maximum);
  return "";
}

[[noreturn]] void refuse(std::string_view option, std::string_view rule, std::string_view text) {
  throw UsageError(fmt::format("{}: must be {} (got '{}')", option, rule, text));
}

// The whole text as a T by std::from_chars, or nothing (sign on an unsigned, overflow, trailing text).
template <class T>
std::optional<T> read_whole(std::string_view text) {
  T value{};
  const char* last = text.data() + text.size();
  const auto [end, error] = std::from_chars(text.data(), last, value);
  if (error != std::errc() || end != last || text.empty()) return std::nullopt;
  return value;
}

template <class T>
T parse_integer(std::string_view option, std::string_view text, T minimum, T maximum) {
  const std::optional<T> value = read_whole<T>(text);
  if (!value || *value < minimum || *value > maximum)
    refuse(option, "a whole number" + range_rule(minimum, maximum), text);
  return *value;
}

}  // namespace

std::string compact_number(double value) { return fmt::format("{}", value); }
std::string compact_number(std::int64_t value) { return fmt::format("{}", value); }
std::string compact_number(std::uint64_t value) { return fmt::format("{}", value); }

std::uint64_t parse_unsigned_option(std::string_view option, std::string_view text, std::uint64_t minimum,
                                    std::uint64_t maximum) {
  return parse_integer(option, text, minimum, maximum);
}

std::int64_t parse_signed_option(std::string_view option, std::string_view text, std::int64_t minimum,
                                 std::int64_t maximum) {
  return parse_integer(option, text, minimum, maximum);
}

double parse_real_option(std::string_view option, std::string_view text, double minimum, double maximum) {
  const std::optional<double> value = read_whole<double>(text);
  if (!value || !std::isfinite(*value) || *value < minimum || *value > maximum) {
    refuse(option, "a finite number" + range_rule(minimum, maximum), text);
  }
  return *value;
}

CLI::Option* add_threads_option(CLI::App& command, unsigned& threads, const std::string& help) {
  return add_number_option(command, "--threads", threads, fmt::format("{} (at most {})", help, kMaxThreads), 0U,
                           kMaxThreads);
}

}  // namespace ontime::cli
